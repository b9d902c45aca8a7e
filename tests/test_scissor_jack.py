"""Paper 003: the screw-nut joint in vector form and the scissor jack, against closed forms.

The jack's numbers are the paper's (130 mm rods, 306 kg with 3000 N weight,
130 mm start height, 2 mm per turn, r_mean 0.01 m, mu 0.1, handle at 2 rev/s);
every expected value below is computed here from the rhombus geometry, not
read from the code under test.
"""

from __future__ import annotations

import importlib.util
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.core.components.screw_nut.bodies import BodyState, RigidBody
from wire_fmu.core.components.screw_nut.joint import ScrewNutJoint
from wire_fmu.core.components.screw_nut.system import ScrewNutSystem
from wire_fmu.core.components.screw_nut.thread import ScrewThread
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import Causality
from wire_fmu.core.units.scissor_jack.unit import ScissorJackUnit

ROOT = Path(__file__).resolve().parents[1]

# the paper's jack, in SI units
ROD = 0.130
HEIGHT0 = 0.130
LEAD = 0.002
WEIGHT = 3000.0
MASS = 306.0
R_MEAN, MU = 0.01, 0.1
HANDLE_SPEED = 2.0 * 2.0 * math.pi  # 2 rev/s
H = LEAD / (2.0 * math.pi)  # lead per radian


def width0() -> float:
    return math.sqrt(4.0 * ROD**2 - HEIGHT0**2)


def rhombus_height(travel: float) -> float:
    """Shoe height for a screw travel (m): the vertical diagonal of the rhombus."""
    return math.sqrt(4.0 * ROD**2 - (width0() - travel) ** 2)


def derived_holding_torque() -> float:
    """(h + r mu) W cot(theta0) from the paper's numbers; theta0 from the start height."""
    theta0 = math.asin(HEIGHT0 / (2.0 * ROD))
    force = WEIGHT / math.tan(theta0)
    return (H + R_MEAN * MU) * force


def make_jack(effects: str = "", **params) -> ScissorJackUnit:
    unit = ScissorJackUnit("jack")
    unit.values["effects"] = effects
    unit.values.update(params)
    unit.configure()
    unit.initialize(0.0)
    return unit


def run(
    unit: ScissorJackUnit, duration: float, step: float, drive=None, record=("load.height",)
) -> dict[str, np.ndarray]:
    """Step ``unit``; ``drive(t, h, unit)`` sets inputs (the master's midpoint hold)."""
    n = int(round(duration / step))
    out = {name: [unit.values[name]] for name in record}
    out["time"] = [0.0]
    for i in range(n):
        t = i * step
        if drive is not None:
            drive(t, step, unit)
        result = unit.advance(t, step)
        assert result.success, result.message
        out["time"].append(t + step)
        for name in record:
            out[name].append(unit.values[name])
    return {k: np.asarray(v) for k, v in out.items()}


def ramp(rate: float):
    def drive(t, h, unit):
        unit.values["handle.torque_command"] = rate * (t + 0.5 * h)

    return drive


# ================================================================= kinematics
def test_paper_geometry_puts_the_rods_at_30_degrees():
    unit = make_jack()
    assert unit.values["rod_angle"] == pytest.approx(math.radians(30.0), rel=1e-14)
    assert unit.values["load.height"] == pytest.approx(HEIGHT0, rel=1e-14)


def test_driven_lift_follows_the_rhombus_kinematics():
    """2 rev/s for 10 s: 20 turns, 40 mm of screw travel, height from the rhombus."""
    unit = make_jack(handle_drive="speed", **{"handle.speed_command": HANDLE_SPEED})
    rec = run(
        unit,
        10.0,
        0.01,
        record=("load.height", "screw.travel", "screw.displacement", "handle.angle"),
    )
    travel = LEAD * 2.0 * rec["time"]
    expected = np.array([rhombus_height(s) for s in travel])
    np.testing.assert_allclose(rec["load.height"], expected, rtol=1e-13, atol=0)
    np.testing.assert_allclose(rec["screw.travel"], travel, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(rec["screw.displacement"], travel / 2, rtol=1e-12, atol=1e-15)
    assert rec["handle.angle"][-1] == pytest.approx(20 * 2 * math.pi, rel=1e-13)
    assert rec["load.height"][-1] == pytest.approx(0.182519, abs=1e-6)  # 130 -> 182.5 mm


@pytest.mark.parametrize("effects, friction_factor", [("", 0.0), ("thread_friction", 1.0)])
def test_driven_lift_forces_and_handle_torque(effects, friction_factor):
    """F = (W + m y'') w / y with y'' by differences of the closed form; M = (h + r mu) F."""
    unit = make_jack(effects, handle_drive="speed", **{"handle.speed_command": HANDLE_SPEED})
    rec = run(
        unit, 10.0, 0.1, record=("screw.axial_force", "handle.torque", "thread.friction_torque")
    )
    t = rec["time"][1:-1]
    speed = LEAD * 2.0  # m/s of screw travel
    dt = 1e-3
    y = [np.array([rhombus_height(speed * (tt + k * dt)) for tt in t]) for k in (-1, 0, 1)]
    accel = (y[2] - 2 * y[1] + y[0]) / dt**2
    width = width0() - speed * t
    force = (WEIGHT + MASS * accel) * width / y[1]
    np.testing.assert_allclose(rec["screw.axial_force"][1:-1], force, rtol=1e-7)
    np.testing.assert_allclose(
        rec["handle.torque"][1:-1], (H + friction_factor * R_MEAN * MU) * force, rtol=1e-7
    )
    np.testing.assert_allclose(
        rec["thread.friction_torque"][1:-1],
        -friction_factor * R_MEAN * MU * force,
        rtol=1e-7,
        atol=1e-12,
    )
    assert rec["handle.torque"][0] == pytest.approx(1.654 if not effects else 6.850, abs=1e-3)


# ================================================================= self-locking
def test_holding_torque_derived_from_geometry_lead_and_friction():
    """About 7 N m (paper's Fig. 8): 5.196 kN axial force, 1.654 + 5.196 N m."""
    torque = derived_holding_torque()
    assert torque == pytest.approx(6.8501, abs=1e-4)
    unit = make_jack("thread_friction", handle_drive="torque")
    lift, lower = unit.model.config.breakaway_torques(0.0)
    assert lift == pytest.approx(torque, rel=1e-13)
    assert lower < 0.0  # self-locking: the load alone cannot turn the screw
    assert unit.values["thread.state"] == 2
    assert unit.values["thread.friction_torque"] == pytest.approx(
        H * WEIGHT * math.sqrt(3), rel=1e-13
    )


def test_rising_torque_holds_the_load_exactly_until_the_derived_torque():
    """Exact stick: height and angle do not change by one bit until breakaway."""
    unit = make_jack("thread_friction", handle_drive="torque")
    rate, step = 0.75, 0.01
    rec = run(
        unit,
        10.0,
        step,
        ramp(rate),
        record=("load.height", "handle.angle", "thread.state", "handle.speed", "mode_changes"),
    )
    moving = np.flatnonzero(rec["handle.angle"] != 0.0)
    first = moving[0]  # the record after the first step that moved
    held_torques = rate * (rec["time"][:first] + 0.5 * step)  # torques of the held steps
    moved_torque = rate * (rec["time"][first - 1] + 0.5 * step)
    torque = derived_holding_torque()
    assert held_torques[-2] < torque <= moved_torque
    assert moved_torque - torque < rate * step
    assert np.all(rec["load.height"][:first] == rec["load.height"][0])  # no creep at all
    assert np.all(rec["thread.state"][:first] == 2)
    assert np.all(rec["mode_changes"][:first] == 0) and rec["mode_changes"][first] == 1
    assert rec["thread.state"][-1] == 1 and rec["handle.speed"][-1] > 10.0
    assert rec["load.height"][-1] > HEIGHT0 + 5e-3  # it lifts after breakaway


def test_breakaway_torque_converges_to_the_derived_value_with_finer_steps():
    errors = []
    for step in (0.02, 0.005):
        unit = make_jack("thread_friction", handle_drive="torque")
        rec = run(unit, 9.5, step, ramp(0.75), record=("handle.angle",))
        first = np.flatnonzero(rec["handle.angle"] != 0.0)[0]
        errors.append(0.75 * (rec["time"][first - 1] + 0.5 * step) - derived_holding_torque())
    assert 0.0 <= errors[1] < errors[0] + 1e-12 and errors[1] < 0.75 * 0.005


@pytest.mark.parametrize("shape", ["linear", "tanh"])
def test_regularised_thread_creeps_at_the_predicted_speed(shape):
    """Paper 003's regularised friction: held with no handle torque, the load creeps down
    at w1 x (linear) or w1 atanh(x) (tanh), x = h / (r mu) -- never truly holds."""
    w1 = 1e-6
    unit = make_jack(
        "thread_friction",
        handle_drive="torque",
        friction_model=shape,
        solver="radau",
        solver_max_step=0.05,
        friction_speed_scale=w1,
    )
    rec = run(
        unit, 2.0, 0.05, record=("handle.speed", "load.height", "handle.angle", "thread.state")
    )
    ratio = H / (R_MEAN * MU)
    creep = w1 * (ratio if shape == "linear" else math.atanh(ratio))
    assert rec["handle.speed"][-1] == pytest.approx(-creep, rel=1e-6)
    assert rec["handle.angle"][-1] == pytest.approx(-creep * 2.0, rel=1e-3)
    drop = HEIGHT0 - rec["load.height"][-1]
    assert drop == pytest.approx(creep * 2.0 * H * math.sqrt(3.0), rel=2e-3)  # dy = h cot psi
    assert drop > 0.0 and set(rec["thread.state"]) == {3}


def test_regularised_thread_needs_a_stiff_solver():
    with pytest.raises(ConfigurationError, match="radau"):
        make_jack("thread_friction", handle_drive="torque", friction_model="linear", solver="rk4")


# ================================================================= energy and configuration
@pytest.mark.parametrize(
    "effects, drive",
    [("", "speed"), ("thread_friction", "speed"), ("thread_friction", "torque"), ("", "torque")],
)
def test_energy_ledger_closes(effects, drive):
    unit = make_jack(effects, handle_drive=drive, **{"handle.speed_command": HANDLE_SPEED})
    torque = (
        ramp(0.75)
        if effects
        else (lambda t, h, u: u.values.update({"handle.torque_command": 1.66}))
    )  # just above the lead torque h W cot 30 deg
    duration = 3.0 if drive == "torque" and not effects else 10.0  # unlocked: it speeds up
    rec = run(
        unit,
        duration,
        0.05,
        torque if drive == "torque" else None,
        record=("energy_balance", "external_work", "dissipated_energy"),
    )
    assert np.max(np.abs(rec["energy_balance"])) < 1e-8 * max(1.0, rec["external_work"][-1])
    if effects:
        assert rec["dissipated_energy"][-1] > 0.0


def test_speed_jump_work_is_booked_to_the_drive():
    unit = make_jack(handle_drive="speed")
    run(unit, 0.2, 0.05, lambda t, h, u: u.values.update({"handle.speed_command": 30.0}))
    assert abs(unit.values["energy_balance"]) < 1e-9


def test_light_handle_is_refused_painleve():
    with pytest.raises(ConfigurationError, match="Painleve"):
        make_jack("thread_friction", handle_drive="torque", handle_inertia=1e-4)


def test_bad_parameters_are_all_reported():
    with pytest.raises(ConfigurationError) as info:
        make_jack(
            "thread_friction,nonsense", handle_drive="pedal", friction_model="glue", rod_length=0.05
        )
    text = str(info.value)
    for word in ("nonsense", "pedal", "glue", "initial_height"):
        assert word in text


@pytest.mark.parametrize("initial", [{}, {"initial_height": 0.15}], ids=["default", "0.15 m"])
def test_ends_of_travel_the_wrong_way_round_are_named_not_the_initial_height(initial):
    with pytest.raises(ConfigurationError) as info:
        make_jack(min_height=0.2, max_height=0.1, **initial)
    text = str(info.value)
    assert "min_height 0.2 m must be below max_height 0.1 m" in text
    assert "initial_height" not in text
    with pytest.raises(ConfigurationError, match=r"initial_height 0.05 m must lie within"):
        make_jack(min_height=0.1, max_height=0.2, initial_height=0.05)


def test_a_speed_command_past_the_whole_travel_in_one_step_is_named():
    unit = make_jack(handle_drive="speed", **{"handle.speed_command": 1.0e6})
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy RuntimeWarning would fail here
        result = unit.advance(0.0, 0.01)
    assert not result.success
    assert "handle.speed_command = 1e+06 rad/s" in result.message
    assert "beyond the jack's whole travel" in result.message


def test_end_of_travel_refuses_the_step():
    unit = make_jack(handle_drive="speed", **{"handle.speed_command": 400.0})
    results = [unit.advance(i * 0.1, 0.1) for i in range(20)]
    refused = [r for r in results if not r.success]
    assert refused and "end of travel" in refused[0].message
    assert unit.values["load.height"] <= 0.25


# ================================================================= unit declarations
def test_declarations_are_sound():
    assert ScissorJackUnit.check_declarations() == []
    for name in ("load.height", "handle.angle", "screw.travel", "dissipated_energy"):
        assert ScissorJackUnit.variable(name).depends_on == ()


@pytest.mark.parametrize("drive", ["speed", "torque"])
def test_declared_feedthrough_matches_the_numbers(drive):
    unit = make_jack(
        "thread_friction", handle_drive=drive, **{"handle.speed_command": HANDLE_SPEED}
    )
    run(unit, 0.5, 0.05, ramp(8.0) if drive == "torque" else None)
    outputs = [v for v in ScissorJackUnit.VARIABLES if v.causality is Causality.output]
    state = json.dumps(unit.get_state())
    for name, delta in (("handle.speed_command", 1.0), ("handle.torque_command", 1.0)):
        before = dict(unit.values)
        unit.values[name] += delta
        unit.evaluate_outputs()
        after = dict(unit.values)
        unit.values[name] -= delta
        unit.evaluate_outputs()
        for var in outputs:
            if name not in var.depends_on:
                assert after[var.name] == before[var.name], (name, var.name)
    assert json.dumps(unit.get_state()) == state


def load_facade_class():
    spec = importlib.util.spec_from_file_location(
        "scissor_jack_facade", ROOT / "models" / "scissor_jack.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.ScissorJack


def test_facade_steps_like_the_core():
    facade = load_facade_class()(instance_name="jack", resources=None)
    refs = {v.name: v.value_reference for v in facade.vars.values()}
    assert list(refs) == [v.name for v in ScissorJackUnit.VARIABLES] + ["physics_seconds"]
    facade.set_string([refs["effects"], refs["handle_drive"]], ["thread_friction", "torque"])
    facade.setup_experiment(0.0, None, None)
    facade.enter_initialization_mode()
    facade.exit_initialization_mode()
    unit = make_jack("thread_friction", handle_drive="torque")
    for i in range(30):
        torque = 7.0 + 0.1 * i
        facade.set_real([refs["handle.torque_command"]], [torque])
        facade.do_step(i * 0.01, 0.01)
        unit.values["handle.torque_command"] = torque
        unit.advance(i * 0.01, 0.01)
    names = ["load.height", "handle.speed", "energy_balance"]
    assert facade.get_real([refs[n] for n in names]) == [unit.values[n] for n in names]


# ================================================================= the 3-D joint
def nut_on_fixed_screw(axis, stabilise=True, lead_per_radian=0.01):
    """A 2 kg nut with axial inertia 1e-3 kg m^2 on a fixed screw along ``axis``."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    thread = ScrewThread(2 * math.pi * lead_per_radian)
    ground = RigidBody(1.0, np.eye(3), fixed=True)
    # inertia 1e-3 about the axis, 5e-3 across: I = 5e-3 (1 - a a^T) + 1e-3 a a^T
    inertia = 5e-3 * (np.eye(3) - np.outer(axis, axis)) + 1e-3 * np.outer(axis, axis)
    nut = RigidBody(2.0, inertia)
    s1, s2 = BodyState.at_rest(), BodyState.at_rest(0.5 * axis)
    joint = ScrewNutJoint(thread, (0, 0, 0), axis, s1, s2)
    return ScrewNutSystem(
        ground, nut, joint, s1, s2, gravity=(0.0, 0.0, -9.81), stabilise=stabilise
    )


@pytest.mark.parametrize("axis", [(0, 0, 1), (0, 1, 1)], ids=["c_x = 0 (vertical)", "tilted"])
def test_nut_on_a_fixed_screw_falls_as_the_closed_form(axis):
    """(m + J/h^2) s'' = m g_axial: the nut screws down; M_a = h F_axial = J psi''."""
    system = nut_on_fixed_screw(axis)
    for _ in range(300):
        system.step(1e-3)
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    g_axial = -9.81 * a[2]
    acc = 2.0 * g_axial / (2.0 + 1e-3 / 0.01**2)
    t = system.time
    position = system.states[1].position
    np.testing.assert_allclose(position, (0.5 + 0.5 * acc * t * t) * a, atol=1e-12)
    assert system.joint.angle == pytest.approx(0.5 * acc * t * t / 0.01, rel=1e-9)
    wrench = system.joint.wrenches(*system.states, system.last_multipliers)
    assert wrench["axis_torque"] == pytest.approx(-1e-3 * acc / 0.01, rel=1e-9)
    assert wrench["axial_force"] == pytest.approx(2.0 * (acc - g_axial), rel=1e-9)


def free_pair(stabilise: bool) -> ScrewNutSystem:
    """Screw and nut floating free, tilted axis, spinning: no external forces."""
    axis = np.array([0.3, -0.5, 0.8])
    thread = ScrewThread(0.05)
    screw = RigidBody(3.0, np.diag([0.02, 0.03, 0.01]))
    nut = RigidBody(1.0, np.diag([4e-3, 5e-3, 2e-3]))
    s1 = BodyState.at_rest((0.1, 0.0, 0.0), (0.9, 0.1, -0.2, 0.3))
    s2 = BodyState.at_rest((0.2, 0.1, 0.3), (0.8, -0.3, 0.1, 0.2))
    joint = ScrewNutJoint(thread, (0.05, 0.0, 0.1), axis, s1, s2)
    system = ScrewNutSystem(screw, nut, joint, s1, s2, stabilise=stabilise)
    s1.velocity[:] = (0.1, 0.0, -0.2)
    s1.angular_velocity[:] = (1.0, -2.0, 0.5)
    s2.angular_velocity[:] = (-3.0, 4.0, 2.0)
    system.project()  # velocities consistent with the joint
    return system


def test_free_screw_pair_conserves_momentum_and_energy():
    system = free_pair(stabilise=True)
    p0, l0 = system.momentum()
    e0 = system.kinetic_energy()
    for _ in range(400):
        system.step(2e-3)
    p1, l1 = system.momentum()
    np.testing.assert_allclose(p1, p0, atol=1e-13)
    np.testing.assert_allclose(l1, l0, rtol=1e-6, atol=1e-8)
    assert system.kinetic_energy() == pytest.approx(e0, rel=1e-6)
    assert np.max(np.abs(system.joint.position_residual(*system.states))) < 1e-14
    assert abs(system.joint.angle) > 1.0  # the nut really turned


def test_position_constraint_prevents_the_drift_of_the_velocity_form():
    """Paper 003's second defect: velocity-level equations let the bodies drift apart,
    the more the longer the run; the position-level constraint keeps them together."""
    drift: dict[bool, list[float]] = {False: [], True: []}
    for stabilise in (False, True):
        system = free_pair(stabilise)
        for _ in range(4):
            for _ in range(100):
                system.step(2e-2)
            residual = system.joint.position_residual(*system.states)
            drift[stabilise].append(float(np.max(np.abs(residual))))
    assert drift[False][-1] > 3.0 * drift[False][0] and drift[False][-1] > 1e-7
    assert max(drift[True]) < 1e-14


# ================================================================= 3-D thread friction
def nut_with_thread_friction(
    lead_per_radian: float, mu: float, axial_inertia: float, speed: float = 0.0
) -> ScrewNutSystem:
    """A 2 kg nut on a fixed vertical screw (r_mean 0.01 m), moving up at ``speed``."""
    thread = ScrewThread(2 * math.pi * lead_per_radian, 0.01, mu)
    ground = RigidBody(1.0, np.eye(3), fixed=True)
    nut = RigidBody(2.0, np.diag([5e-3, 5e-3, axial_inertia]))
    s1, s2 = BodyState.at_rest(), BodyState.at_rest((0.0, 0.0, 0.5))
    joint = ScrewNutJoint(thread, (0, 0, 0), (0, 0, 1), s1, s2)
    system = ScrewNutSystem(
        ground, nut, joint, s1, s2, gravity=(0.0, 0.0, -9.81), thread_friction=True
    )
    nut_state = system.states[1]
    nut_state.velocity[:] = (0.0, 0.0, speed)
    nut_state.angular_velocity[:] = (0.0, 0.0, speed / lead_per_radian)
    system.project()
    return system


def test_3d_thread_friction_slows_a_sliding_nut_as_the_closed_form():
    """Lead above r mu: it slides down, (m + J / (h (h - r mu))) z'' = -m g."""
    h, r_mu, inertia = 0.01, 0.003, 1e-3
    system = nut_with_thread_friction(h, 0.3, inertia)
    assert system.mode == -1
    for _ in range(200):
        system.step(1e-3)
    acc = -2.0 * 9.81 / (2.0 + inertia / (h * (h - r_mu)))
    assert system.states[1].position[2] == pytest.approx(
        0.5 + 0.5 * acc * system.time**2, abs=1e-11
    )
    axial = system.last_multipliers[4]
    assert system.friction_torque == pytest.approx(r_mu * abs(axial), rel=1e-12)


def test_3d_self_locking_thread_stops_a_thrown_nut_and_holds_it_exactly():
    """Lead below r mu: thrown up at 0.5 m/s it decelerates at m g / (m + J / (h (h + r mu))),
    sticks where the closed form says, and from then on does not move by one bit."""
    h, r_mu, inertia = 2e-3, 3e-3, 1e-5
    system = nut_with_thread_friction(h, 0.3, inertia, speed=0.5)
    assert system.mode == 1
    heights = []
    for _ in range(200):
        system.step(1e-3)
        heights.append(system.states[1].position[2])
    deceleration = 2.0 * 9.81 / (2.0 + inertia / (h * (h + r_mu)))
    assert system.events[-1][0] == pytest.approx(0.5 / deceleration, abs=1e-9)
    assert system.mode == 0 and "stuck" in system.events[-1][1]
    assert heights[-1] == pytest.approx(0.5 + 0.25 / (2.0 * deceleration), abs=1e-8)
    assert heights[-1] == heights[100]  # exact stick: no creep at all
    assert system.friction_torque == pytest.approx(h * 2.0 * 9.81, rel=1e-12)  # holds h m g


def test_3d_self_locking_thread_holds_a_nut_at_rest():
    system = nut_with_thread_friction(2e-3, 0.3, 1e-5)
    start = system.states[1].position.copy()
    for _ in range(100):
        system.step(1e-3)
    assert system.mode == 0 and np.all(system.states[1].position == start)
