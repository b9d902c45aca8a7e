"""Hard cases at mode switches and limits (SPEC section 17, issue 7).

The band brake's stick and slip, a slack rope snapping taut, a rope break, a
cylinder's end-stop impact and an accumulator driven towards zero gas volume,
each through the real FMUs in our master, against a closed form or the
monolithic reference, under the global criteria and step refinement of
:mod:`~tests.hard_case_helpers` (see ``test_hard_cases``). The scenes are in
:mod:`~tests.hard_case_scenes`.

As in ``test_hard_cases``, each test's docstring ends with its mutation
experiment (``Mutation:``): the protection removed, and what failed then.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wire_fmu.core.components.rope import snap_load
from wire_fmu.core.units.hydraulics.model import damping_ratio_for_restitution

from .hard_case_helpers import (
    assert_converges,
    build_our_fmus,
    check_global_criteria,
    error_against,
    reference,
    run_case,
)
from .hard_case_scenes import (
    APPLY,
    BORE_AREA,
    BRAKE_DRUM,
    BRAKE_RADIUS,
    BREAK_DRUM,
    BREAKING_LOAD,
    CAPACITY,
    DROP,
    IMPACT_SPEED,
    RAMP_END,
    RESTITUTION,
    ROD_MASS,
    SNAP_EA,
    SNAP_LENGTH,
    SNAP_MASS,
    STOP_STIFFNESS,
    STROKE,
    T_CAP,
    T_END,
    T_START,
    G,
    brake_scene,
    break_scene,
    impact_scene,
    snap_scene,
)
from .hydraulics_helpers import quiet_cylinder

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    """Our three hoisting FMUs, built once for the module."""
    return build_our_fmus(tmp_path_factory.mktemp("hard_case_fmus"))


# ================================================== 2. band brake stick and slip
def brake_closed_form(t: np.ndarray) -> tuple[np.ndarray, float, float]:
    """Drum speed (rad/s) of the continuous problem, breakaway time and re-stick time, s.

    Held until T r reaches the capacity at t_c; then J w' = T(t) r - C; from 0.5 s
    J w' = T r - 2 C < 0 until the drum stops and the brake holds it again.
    """
    rate = (T_END - T_START) / RAMP_END * BRAKE_RADIUS / BRAKE_DRUM  # d(T r / J)/dt
    t_c = (T_CAP - T_START) / (T_END - T_START) * RAMP_END
    w_ramp_end = 0.5 * rate * (RAMP_END - t_c) ** 2
    excess = (T_END * BRAKE_RADIUS - CAPACITY) / BRAKE_DRUM
    w_apply = w_ramp_end + excess * (APPLY - RAMP_END)
    decel = (2 * CAPACITY - T_END * BRAKE_RADIUS) / BRAKE_DRUM
    t_stop = APPLY + w_apply / decel
    w = np.where(t <= t_c, 0.0, 0.5 * rate * (np.minimum(t, RAMP_END) - t_c) ** 2)
    w = np.where(t > RAMP_END, w_ramp_end + excess * (np.minimum(t, APPLY) - RAMP_END), w)
    w = np.where(t > APPLY, np.maximum(0.0, w_apply - decel * (t - APPLY)), w)
    return w, t_c, t_stop


def test_band_brake_holds_breaks_away_slides_and_resticks_without_chatter(fmus, tmp_path):
    """Through the Winch FMU in the master: the drum is exactly still while the brake holds,
    breaks away when the load torque crosses eq. (34)'s capacity, slides with
    J w' = T r - M_brake (speed within 1 % of the closed form, the decelerating slope
    exact), re-sticks exactly once (two mode changes in all) and then holds the load
    with exactly its torque.

    Mutation: the holding force removed (StickSlip.accelerations giving a stuck cluster
    the acceleration of its free forces, WinchModel.drum_held returning False); the drum
    turned from the first step, "breakaway" at 0 s instead of 0.205 s: the breakaway
    assertion failed.
    """
    errors = []
    for step in (0.01, 0.005):
        run = run_case(brake_scene(step), fmus, tmp_path / f"h{step}")
        assert run.result.status == "finished", run.result.message
        t, w = run.time, run["winch.drum.speed"]
        exact, t_c, t_stop = brake_closed_form(t)
        moving = np.flatnonzero(w != 0.0)
        assert moving.size, "the drum never broke away"
        t_break = t[moving[0]] - step  # the step in which the drum first turned began here
        held = t <= t_break
        assert np.all(w[held] == 0.0) and np.all(run["winch.drum.angle"][held] == 0.0)
        assert np.all(run["winch.brake.state"][held] == 2)
        # breakaway at the first step whose held (midpoint) load exceeds the capacity
        assert t_c - step / 2 - 1e-12 < t_break <= t_c + step / 2 + 1e-12
        assert np.max(np.abs(w - exact)) <= 0.01 * np.max(exact)
        decelerating = (t > APPLY + step) & (t < t_stop - step)
        slope = np.diff(w)[decelerating[1:]] / step
        expected = -(2 * CAPACITY - T_END * BRAKE_RADIUS) / BRAKE_DRUM
        np.testing.assert_allclose(slope, expected, rtol=1e-9)
        restuck = t >= t_stop + step
        assert np.all(w[restuck] == 0.0) and np.all(run["winch.brake.state"][restuck] == 2)
        assert run["winch.brake.torque"][restuck] == pytest.approx(-T_END * BRAKE_RADIUS, rel=1e-12)
        assert run["winch.mode_changes"][-1] == 2  # breakaway, re-stick: no chatter
        assert np.count_nonzero(np.diff(run["winch.brake.state"])) == 2
        check_global_criteria(run.columns, ledger_tolerance=1e-9)
        errors.append(float(np.max(np.abs(w - exact))))
    assert_converges(errors, floor=1e-12, what="drum speed error")


# ================================================ 3. slack rope and snap load
def test_slack_rope_carries_nothing_and_snaps_to_the_closed_form(fmus, tmp_path):
    """Through the BlockTrain FMU in the master: exactly zero tension while slack, the rope
    engages after the free fall of 5 cm, and the snap load is
    T_max = m g (1 + sqrt(1 + k v0^2 / (m g^2))) within 0.3 % / 0.05 % at 2 / 1 ms; the
    ledger closes to 1 % of the fall's energy.

    Mutation: the rope made to push (rope_forces treating every spring as taut); the
    compressed rope pushed the block down with -4.96e4 N from the first step: the
    "exactly zero while slack" assertion failed.
    """
    v0 = math.sqrt(2 * G * DROP)
    k = SNAP_EA / (SNAP_LENGTH + DROP)  # the unstretched rope now includes the drop
    expected = snap_load(SNAP_MASS, k, v0, G)
    t_engage = math.sqrt(2 * DROP / G)
    fall_energy = SNAP_MASS * G * (DROP + expected / k)  # J, down to the lowest point
    errors = []
    for step, tolerance in ((2e-3, 3e-3), (1e-3, 5e-4)):
        run = run_case(snap_scene(step), fmus, tmp_path / f"h{step}")
        assert run.result.status == "finished", run.result.message
        t, tension = run.time, run["rope.line_a.tension"]
        slack = t < t_engage
        assert np.all(tension[slack] == 0.0) and np.all(run["rope.slack_spans"][slack] == 1)
        assert t_engage < t[np.flatnonzero(tension > 0.0)[0]] <= t_engage + step
        assert tension.max() == pytest.approx(expected, rel=tolerance)
        check_global_criteria(
            run.columns, ledger_tolerance=1e-2, energy_scale=fall_energy, passive=True
        )
        errors.append(abs(tension.max() / expected - 1))
    assert_converges(errors, floor=1e-6, what="snap load error")


# ============================================================= 4. rope break
@pytest.mark.parametrize(
    "how",
    [
        "breaking_load",
        "commanded",
    ],
)
def test_rope_break_leaves_zero_tension_free_fall_and_no_phantom_tension(fmus, tmp_path, how):
    """Winch and rope in one scene; after the break the rope's tension is exactly 0, the
    load falls on the parabola y_b + v_b t - g t^2 / 2, the break is a mode event
    (rope.mode_changes moves), and from the step after the break on the winch holds
    exactly 0 N, so its drum spins up at exactly M_motor / J; drum and load speeds
    converge to the monolithic reference as the step is halved.

    Mutation: the master's history reset after a mode event removed (Simulation._accept);
    in the breaking-load case the winch held -7113 N (the tension extrapolated across the
    break) over the second step after it: the "winch sees exactly 0" assertion failed.
    """
    ref = reference(break_scene(2.5e-3, how), output_interval=2.5e-3)
    errors = []
    for step in (5e-3, 2.5e-3):
        run = run_case(break_scene(step, how), fmus, tmp_path / f"{how}_{step}")
        assert run.result.status == "finished", run.result.message
        t, k = run.time, int(np.flatnonzero(run["rope.broken"] > 0)[0])
        assert np.all(run["rope.broken"][k:] == 1)
        assert run["rope.tension_max"][:k].max() <= BREAKING_LOAD * (1 + 1e-6)
        assert run["rope.mode_changes"][k] > run["rope.mode_changes"][k - 1]  # a mode event
        assert np.all(run["rope.line_a.tension"][k:] == 0.0)
        assert np.all(run["rope.tension_max"][k:] == 0.0)
        tau = t[k:] - t[k]
        y_k, v_k = run["rope.block_a.position"][k], run["rope.block_a.velocity"][k]
        np.testing.assert_allclose(
            run["rope.block_a.position"][k:], y_k + v_k * tau - 0.5 * G * tau**2, rtol=0, atol=1e-9
        )
        np.testing.assert_allclose(
            run["rope.block_a.velocity"][k:], v_k - G * tau, rtol=0, atol=1e-9
        )
        # the winch steps first (Gauss-Seidel, flow side): the step containing the break
        # holds the tension from before it; every later step must hold exactly 0
        assert np.all(run["winch.rope.tension"][k + 1 :] == 0.0), run["winch.rope.tension"][
            k : k + 3
        ]
        spin_up = np.diff(run["winch.drum.speed"][k:]) / step
        torque = run["winch.motor.torque"][-1]
        np.testing.assert_allclose(spin_up, torque / BREAK_DRUM, rtol=1e-9)
        check_global_criteria(run.columns, ledger_tolerance=1e-3)
        errors.append(
            max(
                error_against(run, ref, "winch.drum.speed"),
                error_against(run, ref, "rope.block_a.velocity"),
            )
        )
    assert_converges(errors, floor=1e-9, what="speed error after the break")


# ===================================================== 5. cylinder end-stop impact
def peak_penetration() -> float:
    """Largest depth of a free mass in a force-release spring-dashpot contact, m."""
    zeta = damping_ratio_for_restitution(RESTITUTION)
    omega = math.sqrt(STOP_STIFFNESS / ROD_MASS)
    return IMPACT_SPEED / omega * math.exp(-zeta * math.acos(zeta) / math.sqrt(1 - zeta**2))


def test_end_stop_impact_restitution_no_tunnelling_no_pull(fmus, tmp_path):
    """Through the Hydraulics FMU in the master: the rod comes back with -e v0 (within
    0.15 % / 0.05 % as the internal step is halved), never goes past the stop by more than
    the contact's own compliance (the closed-form peak depth), also when the whole contact
    lies inside one 50 ms macro step, and the stop only ever pushes; one contact, no chatter;
    the ledger closes to 0.5 % of the impact energy.

    Mutation: the stop made to pull (HydraulicsModel._guard never releasing a contact);
    the rod stayed glued to the stop (end velocity +6e-6 m/s against -0.15 m/s): the
    restitution assertion failed.
    """
    peak = peak_penetration()
    impact_energy = 0.5 * ROD_MASS * IMPACT_SPEED**2
    errors = []
    cases = ((1e-3, 5e-5, 1.5e-3), (1e-3, 2.5e-5, 5e-4), (5e-2, 5e-5, 1.5e-3))
    for step, max_step, tolerance in cases:
        run = run_case(impact_scene(step, max_step), fmus, tmp_path / f"h{step}_{max_step}")
        assert run.result.status == "finished", run.result.message
        x, v, force = run["cyl.rod.position"], run["cyl.rod.velocity"], run["cyl.end_stop.force"]
        assert v[-1] == pytest.approx(-RESTITUTION * IMPACT_SPEED, rel=tolerance)
        assert np.max(x) <= STROKE + peak * (1 + 1e-2) and x[-1] < STROKE  # no tunnelling
        assert np.all(force <= 0.0)  # pushes the rod back in, never pulls it out
        assert run["cyl.mode_changes"][-1] == 2  # contact begins, ends: no chatter
        if step < 0.01:  # the contact is sampled: its depth is the contact's compliance
            assert np.max(x) - STROKE >= 0.98 * peak and np.min(force) < 0.0
            errors.append(abs(v[-1] / (-RESTITUTION * IMPACT_SPEED) - 1))
        check_global_criteria(
            run.columns,
            ledger_tolerance=5e-3,
            energy_scale=impact_energy,
            passive=True,
            dead_volumes={"cyl": 1.0},
        )
    assert_converges(errors, floor=1e-6, what="restitution error")


# ============================================ 6. accumulator towards zero gas volume
P_EQ = 1.0e7  # Pa, working pressure
F_EQ = -P_EQ * BORE_AREA
EXTRA_LOAD = 5.0e5  # N: added at once, more than the gas can stop before its dead volume
GAS_DEAD, GAS_FULL = 0.005, 0.05  # m^3


def zero_gas_scene(step: float, solver_max_step: float) -> dict:
    """A gas spring at rest at 10 MPa (0.04 m^3 of gas, isothermal); at t = 0 the rod load
    grows by 0.5 MN, which the gas (p0 V0 ln 8 = 0.83 MJ between here and its dead
    volume) cannot stop: the rod drives the gas towards zero volume at about 12 m/s."""
    params = quiet_cylinder(
        accumulator_volume=GAS_FULL,
        accumulator_dead_volume=GAS_DEAD,
        solver_max_step=solver_max_step,
    )
    params["rod.force"] = F_EQ
    return {
        "name": "zero_gas",
        "run": {"stop_time": 1.0, "step": step},
        "units": {"cyl": {"fmu": "Hydraulics", "parameters": params}},
        "events": [
            {"time": 0.0, "label": "load added", "set": {"cyl.rod.force": F_EQ - EXTRA_LOAD}}
        ],
        "outputs": {"variables": "all"},
    }


def dead_volume_time() -> float:
    """When the gas reaches its dead volume: m x'' = F1 + A p0 V0 / V, V = V0 + A (x - x0)."""
    v0 = GAS_FULL * 8.0e6 / P_EQ  # charged isothermally from the 8 MPa pre-charge

    def rhs(t, y):
        volume = v0 + BORE_AREA * y[0]
        return [y[1], (F_EQ - EXTRA_LOAD + BORE_AREA * P_EQ * v0 / volume) / 1000.0]

    def dead(t, y):
        return v0 + BORE_AREA * y[0] - GAS_DEAD

    dead.terminal = True
    sol = solve_ivp(rhs, (0.0, 1.0), [0.0, 0.0], events=dead, rtol=1e-12, atol=1e-14)
    return float(sol.t_events[0][0])


def test_accumulator_driven_to_zero_gas_volume_refuses_the_step(fmus, tmp_path):
    """The Hydraulics FMU refuses the step that would reach the gas dead volume
    (fmi2Discard, reason logged); the master stops, says which unit and when and why,
    and keeps every row recorded up to the stop, with no NaN and the gas volume above
    its dead volume throughout. The limit time the unit locates matches an independent
    ODE solution (within 0.1 ms, converging as the internal step is halved).

    Mutation: the zero-gas-volume guard removed (HydraulicsModel._guard returning +1 for
    "gas_dead"); the run "finished" with the gas squeezed to 0.0039 m3, below its
    0.005 m3 dead volume, and the ledger 47 kJ open: the status assertion failed.
    """
    t_exact = dead_volume_time()
    errors = []
    for step, max_step in ((0.01, 1e-3), (0.01, 5e-4)):
        run = run_case(zero_gas_scene(step, max_step), fmus, tmp_path / f"ms{max_step}")
        result, message = run.result, run.result.message
        assert result.status == "stopped"
        # "refused the step" is the master's word for fmi2Discard (fmi2Error/Fatal read
        # "failed"); the reason after it is the FMU's own log message
        assert f"unit 'cyl' refused the step at t = {result.end_time:.6g} s" in message
        assert "gas volume" in message and f"dead volume {GAS_DEAD:g} m3" in message
        assert "zero gas volume" in message
        t_limit = float(re.search(r"at t = (\S+) s \(accumulator full", message).group(1))
        assert result.end_time <= t_limit <= result.end_time + step
        assert t_limit == pytest.approx(t_exact, abs=1e-4)
        errors.append(abs(t_limit - t_exact))
        # everything up to the stop is kept, and is sound
        assert run.time[-1] == result.end_time
        assert len(run.time) == round(result.end_time / step) + 1
        summary = run.metadata["result"]
        assert summary["status"] == "stopped" and summary["message"] == message
        check_global_criteria(run.columns, ledger_tolerance=1e-3, dead_volumes={"cyl": GAS_DEAD})
    assert_converges(errors, floor=1e-7, what="limit time error")
