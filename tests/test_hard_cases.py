"""Hard cases stay numerically stable (SPEC section 17, issue 7): stiff ropes and macro steps.

Every case runs the real FMUs (BlockTrain, Winch, Hydraulics) in our master
(:class:`~wire_fmu.master.simulation.Simulation`), asserts physics against a
closed form or the monolithic reference, and applies the global criteria of
:func:`~tests.hard_case_helpers.check_global_criteria` (no NaN/Inf, ledgers,
invariants, passive energy bound) and step refinement
(:func:`~tests.hard_case_helpers.assert_converges`). Tolerances are stated
where they are used; each is a measured error with a margin of about two.

Here: a stiff rope inside one unit and across a bond, and a macro step far too
large for the coupled mode. The mode switches and limits (brake, slack rope,
rope break, end stop, gas volume) are in ``test_hard_cases_events``; the
shipped scenes, an algebraic loop and the start in equilibrium in
``test_hard_cases_scenes``; the scenes themselves in
:mod:`~tests.hard_case_scenes`.

Each test's docstring ends with the mutation experiment: the protection the
test checks was removed in a private copy of the repository and the test was
run there (``Mutation:`` says what was removed and what failed).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import eigh

from wire_fmu.master.scene import SceneError
from wire_fmu.master.validate import validate_scene

from .hard_case_helpers import (
    assert_converges,
    build_our_fmus,
    check_global_criteria,
    error_against,
    master_scene,
    reference,
    run_case,
)
from .hard_case_scenes import (
    DRUM_INERTIA,
    DRUM_RADIUS,
    FALL,
    LINE_EA,
    LOAD,
    LONG_SPAN,
    PULLEY_EA,
    PULLEY_MASS,
    PULLEY_PRETENSION,
    PULLEY_RADIUS,
    RIM_MASS,
    SHORT_SPAN,
    G,
    stiff_pulley_scene,
    winch_and_fall_scene,
)

# The other hard cases' scenes: the kernel comparison (test_kernels) imports them from here.
from .hard_case_scenes import brake_scene as brake_scene
from .hard_case_scenes import break_scene as break_scene
from .hard_case_scenes import impact_scene as impact_scene
from .hard_case_scenes import snap_scene as snap_scene
from .hydraulics_helpers import period

pytestmark = pytest.mark.integration

RK4_LIMIT = 2.78
"""|lambda| h beyond which classical RK4 is unstable (real axis; 2.83 imaginary)."""


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    """Our three hoisting FMUs, built once for the module."""
    return build_our_fmus(tmp_path_factory.mktemp("hard_case_fmus"))


# =========================================================== 1. stiff rope
# --- inside one unit: a short, very stiff span on a light sheave -----------------


def pulley_modes() -> tuple[float, float, float]:
    """(slow, fast) angular frequencies, rad/s, and the hook's static stiffness, N/m.

    Coordinates: hook height y and rope s passed over the rim. With spans of
    stiffness k0 (short) and k1 (long): M y'' = -k1 (y + s), m s'' = -k1 (y + s) - k0 s.
    """
    ea, t0, half_arc = PULLEY_EA, PULLEY_PRETENSION, 0.5 * math.pi * PULLEY_RADIUS
    k0 = ea / ((SHORT_SPAN + half_arc) * ea / (ea + t0))  # EA / unstretched length
    k1 = ea / ((LONG_SPAN + half_arc) * ea / (ea + t0))
    stiffness = np.array([[k1, k1], [k1, k0 + k1]])
    omega = np.sqrt(eigh(stiffness, np.diag([PULLEY_MASS, RIM_MASS]), eigvals_only=True))
    return float(omega[0]), float(omega[1]), k0 * k1 / (k0 + k1)


def test_stiff_rope_inside_one_unit_is_stable_with_the_right_frequency_and_energy(fmus, tmp_path):
    """A short stiff span on a light sheave inside the BlockTrain FMU, integrated by the
    L-stable ros2 at 4 and 2 times RK4's stability limit of the fast mode: the hook
    oscillates at the closed-form frequency (within 0.6 % / 0.15 % at the two steps) with
    the closed-form amplitude, and keeps its energy (the ledger residual is ros2's
    numerical damping: within 10 % / 1.5 % of the oscillation energy), both errors
    shrinking as the step is refined.

    Mutation: ros2 made explicit (fixed_step.finite_difference_jacobian returning zeros);
    the fast mode blew up within two macro steps, the unit refused ("rope span 0 has no
    unstretched rope left") and the run stopped at t = 0.004 s: the status assertion failed.
    """
    slow, fast, k_hook = pulley_modes()
    amplitude = (PULLEY_MASS * G - PULLEY_PRETENSION) / k_hook
    energy = 0.5 * k_hook * amplitude**2  # J, released from the off-equilibrium start
    frequency_errors, energy_errors = [], []
    for max_step, tolerance, lost in ((5e-4, 6e-3, 0.1), (2.5e-4, 1.5e-3, 0.015)):
        assert fast * max_step > 2 * RK4_LIMIT  # far beyond any explicit method's reach
        run = run_case(stiff_pulley_scene(max_step), fmus, tmp_path / f"ms{max_step}")
        assert run.result.status == "finished", run.result.message
        y = run["rope.block_a.position"]
        frequency = 2 * math.pi / period(run.time, y)
        frequency_errors.append(abs(frequency / slow - 1))
        assert frequency == pytest.approx(slow, rel=tolerance)
        assert np.ptp(y) == pytest.approx(2 * amplitude, rel=2 * tolerance)
        energy_errors.append(float(np.max(np.abs(run["rope.energy_balance"]))) / energy)
        check_global_criteria(run.columns, ledger_tolerance=lost, energy_scale=energy, passive=True)
    assert_converges(frequency_errors, floor=1e-5, what="hook frequency error")
    assert_converges(energy_errors, floor=1e-5, what="energy lost")


# --- across a unit boundary: rope stiffness between a light drum and the load -------
def coupled_frequency() -> float:
    """Drum (J / r^2) against the load on the rope spring EA / L, rad/s."""
    drum = DRUM_INERTIA / DRUM_RADIUS**2
    return math.sqrt(LINE_EA / FALL * (1 / drum + 1 / LOAD))


@pytest.fixture(scope="module")
def winch_reference():
    """The winch-and-fall scene as one ODE (Radau, rtol 1e-8), outputs every ms."""
    return reference(winch_and_fall_scene(1e-3), output_interval=1e-3)


def coupling_errors(run, ref) -> dict[str, float]:
    """Largest deviations from the monolithic reference."""
    return {
        c: error_against(run, ref, c)
        for c in ("rope.line_a.tension", "rope.block_a.position", "winch.drum.speed")
    }


def assert_close_to_reference(run, ref, *, position: float, tension: float, speed: float) -> None:
    """Within the stated tolerances of the reference, tension inside its envelope."""
    errors = coupling_errors(run, ref)
    tension_ref = ref.values["rope.line_a.tension"]
    assert errors["rope.block_a.position"] <= position, errors
    assert errors["rope.line_a.tension"] <= tension * tension_ref.max(), errors
    assert errors["winch.drum.speed"] <= speed, errors
    t = run["rope.line_a.tension"]
    assert 0.9 * tension_ref.min() <= t.min() and t.max() <= 1.1 * tension_ref.max()


def test_stiff_rope_across_a_unit_boundary_is_stable_with_iteration(
    fmus, tmp_path, winch_reference
):
    """Drum and load coupled through the rope bond at omega H = 1: explicit coupling
    blows up there (the energy guard stops it; unguarded, the tension runs to more than
    twice its peak); iterating each step with rollback stays stable and follows the
    monolithic reference (position within 1 mm of 32 mm, tension within 10 % of its
    peak, drum speed within 0.15 rad/s of 0.85), converging as H is halved; the rope's
    ledger closes to 0.3 % of its throughput.

    Mutation: the iteration removed (Simulation._sweep_iterated doing one sweep only);
    explicit coupling blew up (position 5.4 mm and tension 129 kN off the reference),
    the reference assertion failed.
    """
    step = 2e-3
    assert coupled_frequency() * step > 0.5  # well past explicit coupling's 0.05-0.1
    ref = winch_reference
    explicit = run_case(winch_and_fall_scene(step), fmus, tmp_path / "explicit")
    assert explicit.result.status == "stopped"  # the energy guard: explicit coupling blows up
    assert "bond 'fast_line'" in explicit.result.message
    unguarded = run_case(
        winch_and_fall_scene(step, energy_guard=math.inf), fmus, tmp_path / "unguarded"
    )
    assert unguarded["rope.line_a.tension"].max() > 2 * ref.values["rope.line_a.tension"].max()
    errors = []
    for h in (step, step / 2):
        run = run_case(
            winch_and_fall_scene(h, iterations=10, iteration_tolerance=1e-8),
            fmus,
            tmp_path / f"iterated_{h}",
        )
        assert run.result.status == "finished", run.result.message
        assert_close_to_reference(run, ref, position=1e-3, tension=0.1, speed=0.15)
        assert abs(run.result.bond_residual["fast_line"]) < 1e-3  # J over the run
        check_global_criteria(run.columns, ledger_tolerance=3e-3)
        errors.append(coupling_errors(run, ref))
    for column in ("rope.line_a.tension", "winch.drum.speed"):
        assert_converges([e[column] for e in errors], floor=0.0, what=column)


# ============================================ 7. a macro step far too large
LARGE_STEP = 0.02  # s: omega H = 10 for the 510 rad/s mode across the bond


def test_far_too_large_macro_step_is_shrunk_by_the_adaptive_master(fmus, tmp_path, winch_reference):
    """The winch-and-fall scene at H = 20 ms (omega H = 10) with adaptive steps: rejected
    steps shrink it to what the coupled mode needs, every accepted step keeps the bond's
    energy residual under the tolerance, and the run follows the monolithic reference
    (position within 1 mm, tension within 10 %, drum speed within 0.15 rad/s), closer as
    the energy tolerance is tightened tenfold.

    Mutation: rejection removed (Simulation._attempt never rejecting); no step was
    rejected and the bond created 2.6e5 J: the rejected-steps assertion failed.
    """
    assert coupled_frequency() * LARGE_STEP > 5
    errors = []
    for tolerance in (1e-2, 1e-3):
        run = run_case(
            winch_and_fall_scene(
                LARGE_STEP,
                adaptive=True,
                energy_tolerance=tolerance,
                min_step=1e-5,
                max_step=LARGE_STEP,
            ),
            fmus,
            tmp_path / f"tol{tolerance}",
        )
        assert run.result.status == "finished", run.result.message
        assert run.result.rejected > 0
        steps = np.diff(run.time)
        assert steps.min() < LARGE_STEP / 10  # shrunk where the coupled mode rings
        residual = np.abs(np.diff(run["bond.fast_line.energy_residual"]))
        assert residual.max() <= tolerance * (1 + 1e-9)
        assert_close_to_reference(run, winch_reference, position=1e-3, tension=0.1, speed=0.15)
        check_global_criteria(run.columns, ledger_tolerance=3e-3)
        errors.append(coupling_errors(run, winch_reference))
    for column in ("rope.line_a.tension", "winch.drum.speed"):
        assert_converges([e[column] for e in errors], floor=0.0, what=column)


def unstable_internal_step(unit: str) -> dict:
    """A scene whose unit ``unit`` is set to take rk4 steps far beyond RK4's stability limit.

    ``winch``: 50 ms steps on the default three-mass drive train (fastest eigenvalue
    about 400 1/s). ``rope``: the stiff-span block train at 0.5 ms (|lambda| h = 12).
    """
    if unit == "winch":
        return {
            "name": "unstable_internal_step",
            "units": {
                "winch": {
                    "fmu": "Winch",
                    "effects": ["drum_inertia", "elastic_drive_train"],
                    "parameters": {"solver": "rk4", "solver_max_step": 0.05},
                }
            },
        }
    data = stiff_pulley_scene(5e-4)
    data["units"]["rope"]["parameters"]["solver"] = "rk4"
    return data


@pytest.mark.parametrize(
    "unit",
    [
        "winch",
        "rope",
    ],
)
def test_an_internal_step_that_cannot_be_stable_is_refused_before_the_run(fmus, tmp_path, unit):
    """A unit whose rk4 step is far too large for its own dynamics is refused when the scene
    is validated (through FMI), naming the unit, the parameter and a stable step.

    Mutation: the winch's RK4 stability check removed (WinchUnit._stability_problems
    returning no problem); validation passed and no SceneError was raised. Without the
    BlockTrain's check (BlockTrainUnit._stability_problems) its stiff-span scene with rk4
    at |lambda| h = 3.6 'finished' with 982 kN against 10.8 kN and its ledger 165 kJ open.
    """
    scene = master_scene(unstable_internal_step(unit), fmus, tmp_path)
    with pytest.raises(SceneError) as info:
        validate_scene(scene)
    text = str(info.value)
    assert f"unit '{unit}'" in text and "solver_max_step" in text
    assert "unstable" in text and "set solver_max_step below" in text


SILENT = {
    # settings: (run settings, what the stop message must say)
    "explicit": ({}, ("the coupling blows up", "bond 'fast_line' created and destroyed")),
    "iteration_not_converged": (
        {"iterations": 10, "iteration_tolerance": 1e-8},
        ("the iteration over the step", "diverges"),
    ),
    "adaptive_at_its_minimum_step": (
        {"adaptive": True, "energy_tolerance": 1e-2, "min_step": 0.01, "max_step": LARGE_STEP},
        ("cannot meet the tolerance", "minimum step"),
    ),
}


@pytest.mark.parametrize("settings", list(SILENT))
def test_far_too_large_macro_step_is_never_a_silent_blow_up(
    fmus, tmp_path, winch_reference, settings
):
    """Whatever the settings, H = 20 ms (omega H = 10) must end stable or stopped with a
    message: 'finished' is acceptable only with the tension in its physical envelope and
    the bonds' energy residual under 1 J. Stopped, the message says when, at which step
    and why, the run stops within a few steps of the hoist that excites the coupled mode,
    and every row up to the stop is recorded, finite, with the units' ledgers closed
    (the units integrate correctly: it is their coupling that creates the energy).

    Protections: the energy guard (EnergyGuard.blow_up; explicit coupling), a diverging
    iteration (Simulation._sweep_iterated) and an adaptive step that cannot meet the
    energy tolerance at its minimum step (Simulation._attempt).

    Mutation: the energy guard removed; the explicit run 'finished' silently with the
    rope slack (0 N) and 72 kN against a physical 9.8-14.7 kN, the bond having created
    29 kJ: the envelope assertion failed. The divergence check removed, or the stop at the
    minimum step: the energy guard stopped those runs instead (at 0.05 s, 58 % of the
    carried energy created; at 0.06 s, 158 %), so the message assertions failed; with the
    guard removed as well they 'finished' with the rope going slack and never above 9.8 kN
    (76 kJ created) and with up to 1 MN (610 kJ).
    """
    run_settings, says = SILENT[settings]
    run = run_case(winch_and_fall_scene(LARGE_STEP, **run_settings), fmus, tmp_path)
    result = run.result
    if result.status == "stopped":
        for phrase in says:
            assert phrase in result.message, result.message
        assert f"t = {result.end_time:.6g} s" in result.message
        assert result.end_time <= 0.05 + 5 * LARGE_STEP  # the hoist starts at 0.05 s
        assert run.time[-1] == result.end_time
        summary = run.metadata["result"]
        assert summary["message"] == result.message
        if "the coupling blows up" in result.message:  # the guard's books, as it read them
            error = summary["bond_energy_error"]["fast_line"]
            assert error > max(0.1 * summary["bond_energy_carried"]["fast_line"], 10.0)
        check_global_criteria(run.columns, ledger_tolerance=3e-3)
        return
    tension = run["rope.line_a.tension"]
    expected = winch_reference.values["rope.line_a.tension"]
    residual = result.bond_residual["fast_line"]
    summary = (
        f"'finished' with the tension in {tension.min():.4g}..{tension.max():.4g} N "
        f"(reference {expected.min():.4g}..{expected.max():.4g} N) and a bond energy "
        f"residual of {residual:.3g} J"
    )
    assert 0.5 * expected.min() <= tension.min(), summary
    assert tension.max() <= 1.5 * expected.max(), summary
    assert abs(residual) < 1.0, summary
