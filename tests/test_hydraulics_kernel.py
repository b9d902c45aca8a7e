"""The hydraulic cylinder's compiled kernel against its Python kernel.

The Python kernel (``WIRE_FMU_KERNEL=python``) is the readable reference the physics
tests hold to the closed forms; the compiled kernel must give the same numbers. Every
combination of the six effects runs three manoeuvres with each kernel: from mid stroke
with the rod force swinging by 10 % (the seal sticks and slips); from near the
retracted end with it swinging by 30 % (the rod runs through the cushion onto the
stop, or without stops leaves the stroke and the step is refused); and from mid stroke
with the load let go (the rod runs out until the oil cavitates behind a line or it
meets the extension end). Every Real output must agree to a relative 1e-10 of its
largest magnitude over the run, and a refused step must be refused at the same step
with the same message. The kernel's functions are also compared one by one in every
mode, at states the manoeuvres do not visit, and the one-call quiet step must give the
shared fixed-step loop's numbers to the last bit (the events located after it depend on
every bit of the state it leaves).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled import KERNEL_ENV
from wire_fmu.core.framework.compiled_step import COMPILED_METHODS, STATUS_DONE
from wire_fmu.core.units.hydraulics import kernel
from wire_fmu.core.units.hydraulics.model import HYDRAULICS_EFFECTS
from wire_fmu.core.units.hydraulics.unit import DEFAULT_ROD_FORCE, HydraulicsUnit

from .hydraulics_helpers import make_unit

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")

RELATIVE = 1e-10
"""Largest difference between the kernels, relative to an output's largest magnitude."""
FLOOR = 1e-9
"""Smallest magnitude an output's differences are measured against, in its SI unit
(outputs that stay at zero, such as the stop force of a rod that never reaches a stop)."""
ENERGIES = ("stored_energy", "dissipated_energy", "external_work", "energy_balance")
"""Outputs that are sums of energies: measured against the largest of them (the ledger's
residual is a small difference of large terms)."""
ROD_FORCES = ("hydraulic_force", "end_stop.force", "seal.friction_force")
"""Forces on the rod: measured against the largest of them (what a stuck seal holds is
the small sum of the large gas and rope forces; so is the force that accelerates the rod,
whose acceleration is measured against the largest force over the rod's mass)."""
SHARED_SCALES = (ENERGIES, ROD_FORCES)
"""Groups of outputs that share one scale."""
STEP = 0.002
STEPS = 300

COMBINATIONS = [
    ",".join(chosen)
    for count in range(len(HYDRAULICS_EFFECTS.names) + 1)
    for chosen in itertools.combinations(HYDRAULICS_EFFECTS.names, count)
]


def swinging(swing: float):
    """The rod force by step ``i``: the rated load swinging by ``swing`` at 1.5 and 7 Hz, N.

    Parameters
    ----------
    swing : float
        Largest relative change of the load, 1.
    """

    def force(i: int) -> float:
        t = i * STEP
        wave = 0.7 * math.sin(2.0 * math.pi * 1.5 * t) + 0.3 * math.sin(2.0 * math.pi * 7.0 * t)
        return DEFAULT_ROD_FORCE * (1.0 + swing * wave)

    return force


def let_go(i: int) -> float:
    """Rod force at step ``i``: the rated load, falling to nothing over ten steps, N.

    Parameters
    ----------
    i : int
        Step number, from 0.
    """
    return DEFAULT_ROD_FORCE * max(0.0, 1.0 - 0.1 * i)


MANOEUVRES = {  # start position (m), rod force at step i (N)
    "mid stroke, 10 %": (1.905, swinging(0.10)),
    "near the retracted end, 30 %": (0.25, swinging(0.30)),
    "load let go": (1.905, let_go),
}
REAL_OUTPUTS = tuple(
    v.name for v in HydraulicsUnit.VARIABLES if v.causality.value == "output" and v.type is float
)


def run_with_kernel(monkeypatch, choice: str, effects: str, position: float, force):
    """Step a cylinder built with kernel ``choice``; its Real outputs per step and a refusal.

    Returns
    -------
    outputs : dict of str to numpy.ndarray
        Each Real output after each step taken (the start included).
    refusal : tuple or None
        ``(step, message)`` of the first refused step, where the run stops.
    mass : float
        The mass the rod's forces accelerate, kg.
    """
    monkeypatch.setenv(KERNEL_ENV, choice)
    unit = make_unit(effects, force=DEFAULT_ROD_FORCE, initial_position=position)
    assert unit.model.compiled == (choice == "compiled")
    rows = [[unit.values[name] for name in REAL_OUTPUTS]]
    refusal = None
    for i in range(STEPS):
        unit.values["rod.force"] = force(i)
        result = unit.advance(i * STEP, STEP)
        if not result.success:
            refusal = (i, result.message)
            break
        rows.append([unit.values[name] for name in REAL_OUTPUTS])
    table = np.array(rows, dtype=float)
    outputs = {name: table[:, k] for k, name in enumerate(REAL_OUTPUTS)}
    return outputs, refusal, unit.model.mass


def differences(python: dict, compiled_: dict, mass: float) -> dict[str, float]:
    """Largest difference per output, relative to its scale (see :data:`FLOOR`).

    Parameters
    ----------
    python, compiled_ : dict of str to numpy.ndarray
        The outputs of each kernel.
    mass : float
        The mass the rod's forces accelerate, kg.
    """
    scale_of = {name: float(np.max(np.abs(values))) for name, values in python.items()}
    for group in SHARED_SCALES:
        shared = max(scale_of[name] for name in group)
        scale_of.update((name, shared) for name in group)
    scale_of["rod.acceleration"] = max(
        scale_of["rod.acceleration"], scale_of["hydraulic_force"] / mass
    )
    out = {}
    for name in REAL_OUTPUTS:
        scale = scale_of[name]
        difference = float(np.max(np.abs(python[name] - compiled_[name])))
        out[name] = difference / max(scale, FLOOR)
    return out


@pytest.mark.parametrize("manoeuvre", MANOEUVRES)
@pytest.mark.parametrize("effects", COMBINATIONS, ids=lambda e: e or "none")
def test_compiled_kernel_gives_the_python_numbers(monkeypatch, effects, manoeuvre):
    """Both kernels step every effect set alike: outputs to 1e-10, refusals word for word."""
    position, force = MANOEUVRES[manoeuvre]
    python, python_refusal, mass = run_with_kernel(monkeypatch, "python", effects, position, force)
    fast, fast_refusal, _ = run_with_kernel(monkeypatch, "compiled", effects, position, force)
    assert fast_refusal == python_refusal
    assert len(fast["rod.position"]) == len(python["rod.position"])
    worst = differences(python, fast, mass)
    bad = {name: value for name, value in worst.items() if not value <= RELATIVE}
    assert not bad, f"outputs differ by more than {RELATIVE:g} of their scale: {bad}"


def _modes(model, seal_mode: int, contact: tuple, cushion: tuple) -> None:
    """Put ``model``'s seal and stops in the given modes (those it has)."""
    if model.seal is not None:
        model.seal.friction.set_mode([seal_mode])
        model.seal.held_position = 1.0
    if model.stops is not None:
        model.stops.contact = list(contact)
        cushioned = model.stops.spec.cushion_length > 0.0
        model.stops.in_cushion = [cushioned and c for c in cushion]


@pytest.mark.parametrize("effects", COMBINATIONS, ids=lambda e: e or "none")
def test_kernel_functions_match_in_every_mode(monkeypatch, effects):
    """rhs, guards, project and the report agree in every mode, at states off the track."""
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    model = make_unit(effects, force=DEFAULT_ROD_FORCE).model
    model.force = 0.9 * DEFAULT_ROD_FORCE
    rng = np.random.default_rng(7)
    base = model.state.copy()
    assert kernel.guard_count(model.kernel_layout) == len(model.guard_directions())
    modes = itertools.product((-1, 0, 1), itertools.product((False, True), repeat=4))
    for seal_mode, (c0, c1, k0, k1) in modes:
        _modes(model, seal_mode, (c0, c1), (k0, k1))
        for position in (-0.01, 0.1, 1.9, 3.75, 3.82):
            x = base * (1.0 + 0.01 * rng.standard_normal(base.size))
            x[0], x[1] = position, rng.normal(0.0, 2.0)
            data = model.kernel_data()
            fast = (model.rhs(0.0, x), model.guards(0.0, x), kernel.project(x.copy(), data))
            model.state = x
            fast_report = model.report()
            assert len(model.report_values()) == len(kernel.REPORT)  # the unit zips them
            with model.python_kernel():
                python = (model.rhs(0.0, x), model.guards(0.0, x), model.project(x.copy()))
                python_report = model.report()
            for got, want in zip(fast, python, strict=True):
                np.testing.assert_allclose(got, want, rtol=1e-13, atol=0.0)
            for name, want in python_report.items():
                assert fast_report[name] == pytest.approx(want, rel=1e-13, abs=0.0), name


@pytest.mark.parametrize("method", sorted(COMPILED_METHODS))
@pytest.mark.parametrize("effects", COMBINATIONS, ids=lambda e: e or "none")
def test_quiet_step_gives_the_shared_loop_to_the_last_bit(monkeypatch, effects, method):
    """The quiet step and the shared loop (``kernel.advance``) from the same start: the same
    end state and report, bit for bit, wherever nothing happens in the step."""
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    unit = make_unit(effects, force=DEFAULT_ROD_FORCE, initial_position=0.25, solver=method)
    model, step, code = unit.model, 0.01, COMPILED_METHODS[method]
    force, taken = swinging(0.30), 0
    for i in range(60):
        t0, t1 = i * step, (i + 1) * step
        model.force = unit.values["rod.force"] = force(5 * i)
        if model.seal is not None:
            model.seal.held_position = float(model.state[0])  # as the quiet step does
        x, data, directions = model.state, model.kernel_data(), model.guard_directions()
        n = model.solver.internal_count(t0, t1)
        quiet, end, values = kernel.quiet_step(code, t0, t1, n, x, directions, data)
        start = kernel.project(x.copy(), data)
        tol = model.settings.event_time_tolerance
        shared = kernel.advance(code, t0, t1, n, 0, t0, start, directions, tol, data)
        violated, rod_force = kernel.limits_and_force(x, data)
        held = model.seal is not None and model.seal.stuck
        breaks_away = held and abs(rod_force) > model.seal.spec.static
        if violated < 0 and not breaks_away:
            assert quiet == (shared[0] == STATUS_DONE), i
        if quiet:
            taken += 1
            assert end.tobytes() == shared[1].tobytes(), i
            assert values.tobytes() == kernel.report(shared[1], data).tobytes(), i
        if not unit.advance(t0, step).success:
            break
    assert taken > 0
