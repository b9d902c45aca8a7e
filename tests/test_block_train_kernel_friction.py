"""The block train's compiled friction links (bearings and grooves that stick) against Python.

Each case lowers a 4-line drilling block train fast, hoists it back and stops the
line, so that sheave bearings and the rope on the grooves break away, slide, stop
and stick again, many times. Both kernels run it and every output must agree to
:data:`~tests.test_kernels.RELATIVE` of its largest magnitude: the compiled
kernel's stuck groups, link forces, guards and projection are those of
:class:`~wire_fmu.core.components.friction.StickSlip`, operation for operation.
ROS2's Jacobian and solves are the same structured arithmetic in both kernels (see
:mod:`tests.test_block_train_kernel`).
"""

from __future__ import annotations

import numpy as np
import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled import KERNEL_ENV
from wire_fmu.core.framework.compiled_step import STATUS_DONE, STATUS_PYTHON
from wire_fmu.core.units.block_train import kernel
from wire_fmu.core.units.block_train.reevings import drilling_block_train

from .block_train_helpers import make_unit, run
from .test_block_train_kernel import RECORD, SOLVERS, STEP, inclined_block_train
from .test_kernels import assert_tables_agree

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")

FRICTION = "rope_damping,sheave_inertia,bearing_friction,rope_slip"

CASES = {
    "fixed geometry": (lambda: drilling_block_train(4), FRICTION),
    "inclined lines, moving geometry": (inclined_block_train, FRICTION + ",moving_geometry"),
}


def lower_hoist_stop(t: float, unit) -> None:
    """Pay out at 4 m/s for 1 s, haul in at 2 m/s for 1 s, then hold the line."""
    rate = -4.0 if t < 1.0 - 1e-9 else 2.0 if t < 2.0 - 1e-9 else 0.0
    unit.values["line_a.payout_rate"] = rate


def run_case(name: str, solver: str, mutate=None) -> tuple[dict, object]:
    """Case ``name`` for 3 s with the kernel ``WIRE_FMU_KERNEL`` names: outputs and unit."""
    reeving, effects = CASES[name]
    unit = make_unit(reeving(), effects, initial_equilibrium=True, **SOLVERS[solver])
    if mutate is not None:
        mutate(unit.model)
    present = tuple(r for r in RECORD if r in unit.values)
    return run(unit, 3.0, STEP, lower_hoist_stop, record=present), unit


def both_kernels(monkeypatch, name: str, solver: str, mutate=None):
    """Case ``name`` with the Python kernel, then compiled: both tables and both units."""
    monkeypatch.setenv(KERNEL_ENV, "python")
    python, python_unit = run_case(name, solver)
    assert not python_unit.model.compiled
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    compiled_run, unit = run_case(name, solver, mutate)
    assert unit.model.compiled, "friction links must run the compiled kernel"
    return python, compiled_run, python_unit, unit


@pytest.mark.parametrize("solver", sorted(SOLVERS))
@pytest.mark.parametrize("name", sorted(CASES))
def test_friction_links_compiled_agree_with_python(monkeypatch, name, solver):
    """Both kernels agree to 1e-10 through dozens of stick and slip switches; the modes
    end the same, and with RK4 the energy ledger (friction losses included) closes.

    Mutation: the compiled groups' accelerations taken from the first member only
    (``force_sum`` loop over ``range(first, first + 1)``) failed (fixed geometry, RK4).
    """
    python, compiled_run, python_unit, unit = both_kernels(monkeypatch, name, solver)
    assert_tables_agree(python, compiled_run, name)
    model = unit.model
    assert model.mode_changes >= 10, "the links must really stick and slip"
    assert model.mode_changes == python_unit.model.mode_changes
    assert model.friction.get_mode() == python_unit.model.friction.get_mode()
    assert float(compiled_run["dissipated_energy"][-1]) > 0.0
    if solver != "rk4":
        return
    scale = max(np.max(np.abs(compiled_run["external_work"])), 1.0)
    assert np.max(np.abs(compiled_run["energy_balance"])) < 1e-6 * scale


def test_a_perturbed_capacity_is_caught(monkeypatch):
    """The comparison can fail: groove capstan factors 1 % high in the compiled kernel."""

    def perturb(model):
        model.kernel_link_params[:, 2] *= 1.01

    python, compiled_run, _, _ = both_kernels(monkeypatch, "fixed geometry", "rk4", perturb)
    with pytest.raises(AssertionError, match="differs by"):
        assert_tables_agree(python, compiled_run, "perturbed capacities")


def quiet_step_with_payout_jump(model, jump: float) -> int:
    """The compiled one-call step from rest with line A's payout jumped by ``jump`` (m)."""
    held = model.held_vector.copy()
    held[1] += jump
    solver = model.solver
    result = kernel.quiet_step(
        solver.method,
        0.0,
        STEP,
        solver.internal_count(0.0, STEP),
        model.settings.event_time_tolerance,
        model.state,
        model._guard_dirs,
        model.kernel_data(),
        held,
        0,
        0.0,
        False,
    )
    return int(result[0])


def test_a_stuck_link_that_cannot_hold_the_new_inputs_leaves_the_step_to_python(monkeypatch):
    """From rest with every link stuck: a payout jump of 1e-9 m is a quiet step; one of
    5 cm breaks bearings loose, so the compiled step hands the step back untouched.

    Mutation: the stuck-link check dropped from ``quiet_step`` (spans and floors only)
    failed the 5 cm case.
    """
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    model = make_unit(drilling_block_train(4), FRICTION, initial_equilibrium=True).model
    assert model.compiled and not any(model.friction.get_mode())
    before = model.state.copy()
    assert quiet_step_with_payout_jump(model, 1e-9) == STATUS_DONE
    assert quiet_step_with_payout_jump(model, 0.05) == STATUS_PYTHON
    assert np.array_equal(model.state, before)
