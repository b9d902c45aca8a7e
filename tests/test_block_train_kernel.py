"""The block train's compiled kernel with moving geometry, against the Python kernel.

With ``moving_geometry`` the segment lengths come from the planar tangent geometry
and their Jacobian from central differences, which amplify rounding by ``L / (2 h)``
(about 1e7 here): the compiled kernel agrees with the Python one only because it
computes every segment length with the same operations in the same order. Each case
runs a manoeuvre in which the blocks or driven bodies move by metres on inclined
lines (so the tangent points really move) with both kernels, and every output must
agree to :data:`~tests.test_kernels.RELATIVE` of its largest magnitude.

The cases run RK4 and ROS2. With moving geometry the solver's finite-difference
Jacobian differences the geometry's finite-difference Jacobian, so a last-bit
difference in it grows to about 1e-5 of a column within seconds: a 1e-15 m nudge
of the hook's start gives the same with either kernel alone (measured on the
sheave-inertia case). Both kernels therefore take ROS2's Jacobian with the same
coloured differences and factor ``I - g h J`` with the same bordered band
elimination (:mod:`~wire_fmu.core.units.block_train.kernel_jacobian`), and agree
to the last bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled import KERNEL_ENV
from wire_fmu.core.units.block_train import kernel
from wire_fmu.core.units.block_train.reevings import drilling_block_train, riser_tensioner

from .block_train_helpers import make_unit, run
from .test_kernels import assert_tables_agree

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")

STEP = 0.01  # s, communication step
RECORD = (
    "line_a.tension",
    "mover_a.force",
    "mover_b.force",
    "block_a.position",
    "block_a.velocity",
    "path_start.tension",
    "path_end.tension",
    "tension_max",
    "stored_energy",
    "dissipated_energy",
    "external_work",
    "energy_balance",
)


def inclined_block_train() -> dict:
    """A 4-line drilling block train whose travelling sheaves sit 3 m to the side:
    every line between crown and travelling block is inclined, and its tangent points
    move as the block moves."""
    reeving = drilling_block_train(4)
    for name, sheave in reeving["sheaves"].items():
        if name.startswith("travel"):
            sheave["centre"][0] += 3.0
    return reeving


def inclined_riser_tensioner() -> dict:
    """The riser tensioner with its fixed sheaves 1 m and its tension ring 2 m to the side:
    the lines to the rod's sheaves and to the riser are inclined."""
    reeving = riser_tensioner()
    for name, sheave in reeving["sheaves"].items():
        if name.startswith("fixed"):
            sheave["centre"][0] += 1.0
    reeving["anchors"]["tension_ring"]["point"][0] += 2.0
    return reeving


def lower_fast(t: float, unit) -> None:
    """Pay the fast line out at 4 m/s for 2.5 s (the block drops 2.5 m), then hold."""
    unit.values["line_a.payout_rate"] = -4.0 if t < 2.5 - 1e-9 else 0.0


def compensate_heave(t: float, unit) -> None:
    """The riser's ring goes down at 2 m/s for 2 s (4 m) and the rod retracts at 0.5 m/s
    (1 m) to hold the tension, then both stop."""
    moving = t < 2.0 - 1e-9
    unit.values["mover_a.velocity"] = -0.5 if moving else 0.0
    unit.values["mover_b.velocity"] = 2.0 if moving else 0.0


CASES = {
    "block, inclined lines, sheave inertia": (
        inclined_block_train,
        "rope_damping,sheave_inertia,moving_geometry",
        {"initial_equilibrium": True},
        lower_fast,
        3.0,
    ),
    "block, inclined lines, merged spans": (
        inclined_block_train,
        "rope_damping,moving_geometry",
        {"initial_equilibrium": True},
        lower_fast,
        3.0,
    ),
    "riser tensioner, rod and riser moving": (
        inclined_riser_tensioner,
        "rope_damping,sheave_inertia,moving_geometry",
        {"initial_equilibrium": False, "pretension": 5.0e5},
        compensate_heave,
        2.5,
    ),
}


SOLVERS = {"rk4": {"solver": "rk4", "solver_max_step": 5e-4}, "ros2": {"solver": "ros2"}}


def run_case(name: str, solver: str = "rk4", mutate=None) -> tuple[dict, object]:
    """Run case ``name`` with the kernel ``WIRE_FMU_KERNEL`` names; its outputs and unit.

    ``mutate(model)``, if given, changes the model before the run.
    """
    reeving, effects, params, drive, duration = CASES[name]
    unit = make_unit(reeving(), effects, **params, **SOLVERS[solver])
    if mutate is not None:
        mutate(unit.model)
    present = tuple(r for r in RECORD if r in unit.values)
    return run(unit, duration, STEP, drive, record=present), unit


def both_kernels(
    monkeypatch, name: str, solver: str = "rk4", mutate=None
) -> tuple[dict, dict, object]:
    """Case ``name`` with the Python kernel, then compiled: both tables and the compiled unit."""
    monkeypatch.setenv(KERNEL_ENV, "python")
    python, unit = run_case(name, solver)
    assert not unit.model.compiled
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    compiled_run, unit = run_case(name, solver, mutate)
    assert unit.model.compiled, "moving planar geometry must run the compiled kernel"
    return python, compiled_run, unit


@pytest.mark.parametrize("solver", sorted(SOLVERS))
@pytest.mark.parametrize("name", sorted(CASES))
def test_moving_geometry_compiled_agrees_with_python(monkeypatch, name, solver):
    """Both kernels agree to 1e-10 while bodies move by metres; with RK4 the ledger closes.

    Mutation: the kernel's half arc added to one neighbouring segment only (``seg[i + 1]``
    loop dropped) failed every case; the differencing step mutated is the test below.
    """
    python, compiled_run, unit = both_kernels(monkeypatch, name, solver)
    assert_tables_agree(python, compiled_run, name)
    model = unit.model
    # the geometry really moved: the length Jacobian is not the one at the start
    nb = len(model.blocks)
    y_end = np.concatenate((model.q[:nb], model.held_parts().mover_positions))
    assert np.ptp(y_end) > 1.0 or np.max(np.abs(y_end)) > 1.0
    _, jac_start = model.span_lengths(np.zeros_like(y_end))
    _, jac_end = model.span_lengths(y_end)
    assert np.max(np.abs(jac_end - jac_start)) > 1e-3
    if solver != "rk4":
        return  # ROS2's ledger closes to its order only (test_block_train_physics)
    # energy ledger: stored change + dissipated - external work, to RK4's error
    scale = max(np.max(np.abs(compiled_run["external_work"])), 1.0)
    scale = max(scale, np.max(np.abs(compiled_run["dissipated_energy"])))
    assert np.max(np.abs(compiled_run["energy_balance"])) < 1e-6 * scale


def test_a_perturbed_geometry_step_is_caught(monkeypatch):
    """The comparison can fail: the compiled kernel differencing with a step 2 % off
    (the same derivative to about 1e-9) no longer agrees to 1e-10."""

    def perturb(model):
        model.kernel_geometry_step[0] *= 1.02

    python, compiled_run, _ = both_kernels(
        monkeypatch, "block, inclined lines, sheave inertia", "rk4", perturb
    )
    with pytest.raises(AssertionError, match="differs by"):
        assert_tables_agree(python, compiled_run, "perturbed step")


def test_segment_lengths_are_those_of_the_python_path_bit_for_bit(monkeypatch):
    """The compiled planar path gives the Python path's segment lengths exactly,
    and the same span lengths and Jacobian to rounding."""
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    model = make_unit(inclined_block_train(), "sheave_inertia,moving_geometry").model
    data = model.kernel_data()
    for y in (0.0, 3.7, -5.2, 11.0):
        at = np.array([y])
        lengths, ok = kernel.segment_lengths(at, data[12], data[13], data[14])
        assert ok
        assert np.array_equal(lengths, model._planar_segment_lengths(at))
        span, jac, ok = kernel.span_geometry(at, data)
        ref_span, ref_jac = model.span_lengths(at)
        assert ok
        np.testing.assert_allclose(span, ref_span, rtol=1e-15, atol=0.0)
        np.testing.assert_allclose(jac, ref_jac, rtol=1e-14, atol=1e-15)


def test_no_tangent_is_reported_by_the_compiled_kernel(monkeypatch):
    """A block pulled up into the crown (sheaves overlapping): the kernel says not ok."""
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    model = make_unit(inclined_block_train(), "sheave_inertia,moving_geometry").model
    _, ok = kernel.segment_lengths(np.array([30.0]), *model.kernel_data()[12:15])
    assert not ok
