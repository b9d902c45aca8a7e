"""Winch physics against closed forms (no FMI involved).

The band brake is in ``test_winch_brake``; here the motor, the drum and its
rope layers, the drive train, the energy ledger, the kinetostatic winch, the
energy-form solver and the start.

Every expected value comes from a textbook formula, the band-brake equation
(34), the drum geometry worked by hand or SciPy on equations written here,
never from numbers the code printed. Signs: everything positive paying out.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wire_fmu.core.components.drive_train import DriveChain

from .winch_helpers import BRAKE, capacities, make_unit, one_mass, run, two_mass

R = 0.5  # drum radius, m


# ----------------------------------------------------------------- motor
@pytest.mark.parametrize(
    "solver, rel", [("ros2", 1e-5), ("rk4", 1e-9), ("energy", 1e-6), ("energy1", 3e-3)]
)
def test_motor_spin_up_follows_the_exponential(solver, rel):
    """M = a - b omega through a 6:1 gearbox: omega_ss + (omega0 - omega_ss) e^(-b t / J)."""
    jm, jd, ratio, a, b, tension = 2.0, 100.0, 6.0, 600.0, 5.0, 400.0
    train = (
        '{"masses": [{"name": "motor", "inertia": 2.0, "ratio": 6.0},'
        ' {"name": "drum", "inertia": 100.0}], "shafts": [{"stiffness": 1e6}]}'
    )
    unit = make_unit(
        "drum_inertia,motor_characteristic",
        solver=solver,
        drive_train=train,
        drum_radius=R,
        motor_slope=b,
        initial_drum_speed=1.0,
        **{"motor.command": a, "rope.tension": tension},
    )
    j_red, b_red = jm * ratio**2 + jd, b * ratio**2
    w_ss = (ratio * a + tension * R) / b_red
    out = run(unit, 3.0, 0.05, record=("drum.speed", "motor.speed", "motor.torque"))
    expected = w_ss + (1.0 - w_ss) * np.exp(-b_red * out["time"] / j_red)
    np.testing.assert_allclose(out["drum.speed"], expected, rtol=rel)
    np.testing.assert_allclose(out["motor.speed"], ratio * out["drum.speed"], rtol=1e-15)
    np.testing.assert_allclose(out["motor.torque"], a - b * out["motor.speed"], rtol=1e-12)


# ---------------------------------------------------------- drum and layers
LAYERED = {
    "drive_train": one_mass(200.0),
    "drum_radius": 0.5,
    "rope_diameter": 0.1,
    "rope_linear_mass": 50.0,
    "drum_wraps_per_layer": 3,
    "drum_layers": 4,
    "rope_on_drum": 25.0,
}


def hand_layers(phi: np.ndarray, rope: float = 25.0) -> tuple[np.ndarray, np.ndarray]:
    """Winding radius and inertia (drum + rope) at drum angles ``phi``, worked by hand."""
    radii = [0.5 + 0.1 * k for k in range(4)]
    turn = 2 * math.pi * 3
    rest, theta0 = rope, 0.0  # wound angle holding ``rope`` metres: fill layers in turn
    for r in radii:
        take = min(rest, turn * r)
        theta0 += take / r
        rest -= take
    theta = theta0 - np.asarray(phi)
    inertia = np.full(theta.shape, 200.0)
    radius = np.empty(theta.shape)
    for k, r in enumerate(radii):
        on_layer = np.clip(theta - k * turn, 0.0, turn)
        inertia += 50.0 * r**3 * on_layer
        radius = np.where((theta > k * turn) & (theta <= (k + 1) * turn), r, radius)
    return radius, inertia


@pytest.mark.parametrize("solver, rel", [("energy", 1e-11), ("ros2", 1e-6)])
def test_free_drum_keeps_i_omega_squared_and_steps_rope_speed_at_layer_changes(solver, rel):
    w0 = 20.0
    unit = make_unit("drum_inertia,rope_layers", solver=solver, initial_drum_speed=w0, **LAYERED)
    assert unit.values["drum.layer"] == 3
    out = run(
        unit,
        1.5,
        0.01,
        record=("drum.angle", "drum.speed", "rope.payout_rate", "drum.layer", "drum.radius"),
    )
    radius, inertia = hand_layers(out["drum.angle"])
    i0 = hand_layers(np.array([0.0]))[1][0]
    np.testing.assert_allclose(inertia * out["drum.speed"] ** 2, i0 * w0**2, rtol=rel)
    np.testing.assert_allclose(out["drum.radius"], radius, rtol=1e-15)
    np.testing.assert_allclose(out["rope.payout_rate"], radius * out["drum.speed"], rtol=1e-14)
    changes = np.flatnonzero(np.diff(out["drum.layer"]))
    assert list(out["drum.layer"][changes + 1]) == [2, 1]
    for k in changes:  # across a change the rope speed steps by r_new / r_old, omega smooth
        jump = out["rope.payout_rate"][k + 1] / out["rope.payout_rate"][k]
        smooth = out["drum.speed"][k + 1] / out["drum.speed"][k]
        assert jump / smooth == pytest.approx(
            out["drum.radius"][k + 1] / out["drum.radius"][k], rel=1e-12
        )
        assert jump / smooth < 0.9 and abs(smooth - 1.0) < 0.02


def test_payout_is_continuous_through_layer_changes_and_matches_the_geometry():
    """Kinetostatic drum turned at 3 rad/s: the rope paid out is the arc length unwound."""
    unit = make_unit("rope_layers", **LAYERED, **{"drum.speed_command": 3.0})
    out = run(unit, 9.0, 0.1, record=("rope.payout", "drum.layer"))
    phi = 3.0 * out["time"]
    radius, _ = hand_layers(phi)
    # payout = integral of r dphi; the hand radius is piecewise constant in phi
    grid = np.linspace(0.0, phi[-1], 200001)
    arc = np.concatenate(
        (
            [0.0],
            np.cumsum(0.5 * np.diff(grid) * (hand_layers(grid)[0][1:] + hand_layers(grid)[0][:-1])),
        )
    )
    np.testing.assert_allclose(out["rope.payout"], np.interp(phi, grid, arc), atol=1e-4)
    assert out["drum.layer"][0] == 3 and out["drum.layer"][-1] == 1
    assert radius[-1] == 0.5


def test_rope_running_off_the_drum_refuses_the_step():
    unit = make_unit(
        "drum_inertia,rope_layers", initial_drum_speed=20.0, **{**LAYERED, "rope_on_drum": 2.0}
    )
    before = dict(unit.values)
    result = unit.advance(0.0, 0.5)
    assert not result.success and "run off the drum" in result.message
    assert unit.values == before


# ------------------------------------------------------------ drive train
def test_two_mass_chain_response_to_a_torque_step():
    """Free 2-mass chain: rigid-body ramp plus the shaft mode at sqrt(c (J1+J2)/(J1 J2))."""
    j1, j2, c, moment = 10.0, 40.0, 4.0e4, 500.0
    unit = make_unit(
        "drum_inertia,elastic_drive_train",
        solver="rk4",
        solver_max_step=2.5e-4,
        drive_train=two_mass(j1, j2, c),
    )
    unit.values["motor.command"] = moment  # a step at t = 0, from a relaxed shaft
    out = run(unit, 1.0, 0.005, record=("motor.speed", "drum.speed"))
    t = out["time"]
    w = math.sqrt(c * (j1 + j2) / (j1 * j2))
    ramp = moment * t / (j1 + j2)
    np.testing.assert_allclose(
        out["motor.speed"], ramp + moment * j2 / (j1 * (j1 + j2) * w) * np.sin(w * t), atol=1e-7
    )
    np.testing.assert_allclose(
        out["drum.speed"], ramp - moment / ((j1 + j2) * w) * np.sin(w * t), atol=1e-7
    )


@pytest.mark.parametrize("frequency", [4.0, 25.0])
def test_steady_sinusoidal_response_matches_the_input_impedance(frequency):
    """Motor speed per motor torque in steady state is 1/Z_in(j omega) (paper 002)."""
    j, ground = [10.0, 5.0, 40.0], [40.0, 10.0, 160.0]
    c, links = [4.0e4, 9.0e4], [15.0, 30.0]
    train = {
        "masses": [{"name": f"m{i}", "inertia": j[i], "damping": ground[i]} for i in range(3)],
        "shafts": [{"stiffness": c[i], "damping": links[i]} for i in range(2)],
    }
    import json

    unit = make_unit(
        "drum_inertia,elastic_drive_train", solver="rk4", drive_train=json.dumps(train)
    )
    omega, amplitude, h = 2 * math.pi * frequency, 100.0, 1e-3

    def drive(t, u):  # hold the value at the middle of the step: second order in h
        u.values["motor.command"] = amplitude * math.sin(omega * (t + 0.5 * h))

    out = run(unit, 5.0, h, drive, record=("motor.speed",))
    last = out["time"] > 4.0
    t = out["time"][last]
    basis = np.column_stack([np.sin(omega * t), np.cos(omega * t), np.ones_like(t)])
    (sin_part, cos_part, _), *_ = np.linalg.lstsq(basis, out["motor.speed"][last], rcond=None)
    chain = DriveChain(tuple(j), tuple(ground), tuple(c), tuple(links), ("a", "b", "c"))
    mobility = amplitude / chain.input_impedance(omega)
    assert complex(sin_part, cos_part) == pytest.approx(mobility, rel=2e-3)


# ------------------------------------------------------------------ energy
def lively(t: float, unit) -> None:
    """Lower, brake, release, hoist: every mode of the brake and both directions."""
    unit.values["rope.tension"] = 1.2e5 + 2.0e4 * math.sin(3.0 * t)
    unit.values["brake.lever_force"] = 1800.0 if 0.6 < t < 1.4 else (0.0 if t < 2.0 else 900.0)
    unit.values["motor.command"] = -2.2e3 if t > 1.6 else 0.0


@pytest.mark.parametrize(
    "effects, solver, tolerance",
    [
        (
            "drum_inertia,band_brake,motor_characteristic,elastic_drive_train,rope_layers",
            "rk4",
            1e-8,
        ),
        ("drum_inertia,band_brake,elastic_drive_train,rope_layers", "ros2", 1e-4),
        ("drum_inertia,band_brake,rope_layers", "energy", 1e-9),
    ],
)
def test_energy_ledger_closes(effects, solver, tolerance):
    unit = make_unit(effects, solver=solver, rope_on_drum=105.0, motor_slope=50.0)
    out = run(
        unit,
        3.0,
        0.01,
        lively,
        record=("energy_balance", "external_work", "dissipated_energy", "mode_changes"),
    )
    scale = np.abs(out["external_work"]).max() + out["dissipated_energy"][-1]
    assert np.abs(out["energy_balance"]).max() < tolerance * scale
    assert out["mode_changes"][-1] >= 3  # the scenario really switched modes
    assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)


def test_friction_never_injects_energy():
    """No dampers at all: every joule dissipated is the brake's, and it only ever grows;
    the brake torque never has the sign of the drum speed."""
    train = (
        '{"masses": [{"name": "motor", "inertia": 30.0}, {"name": "drum", '
        '"inertia": 900.0}], "shafts": [{"stiffness": 3e6}]}'
    )
    unit = make_unit("drum_inertia,band_brake,elastic_drive_train", solver="rk4", drive_train=train)
    out = run(
        unit,
        3.0,
        0.005,
        lively,
        record=(
            "dissipated_energy",
            "brake.torque",
            "drum.speed",
            "energy_balance",
            "brake.state",
            "external_work",
        ),
    )
    assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)
    assert np.all(out["brake.torque"] * out["drum.speed"] <= 0.0)
    assert set(out["brake.state"]) == {0, 1, 2}
    assert np.abs(out["energy_balance"]).max() < 1e-8 * np.abs(out["external_work"]).max()


# ------------------------------------------------------------ kinetostatic
def test_kinetostatic_drum_follows_eq_32():
    """No inertia: the drive imposes the speed and the motor torque is what (32) needs."""
    lever, tension, ratio = 300.0, 3.0e4, 6.0
    plus, minus = capacities(lever)
    train = (
        '{"masses": [{"name": "motor", "inertia": 1.0, "damping": 2.0, "ratio": 6.0},'
        ' {"name": "drum", "inertia": 1.0, "damping": 40.0}],'
        ' "shafts": [{"stiffness": 1e6, "ratio": 6.0}]}'
    )
    beta = 2.0 * ratio**2 + 40.0
    unit = make_unit(
        "band_brake",
        drive_train=train,
        **BRAKE,
        drum_radius=R,
        **{"brake.lever_force": lever, "rope.tension": tension},
    )
    rope = tension * R
    cases = [(4.0, -plus), (-2.0, minus), (0.0, -min(rope, plus))]
    for i, (speed, brake) in enumerate(cases):
        unit.values["drum.speed_command"] = speed
        payout = unit.values["rope.payout"]
        assert unit.advance(float(i), 1.0).success
        assert unit.values["rope.payout"] - payout == pytest.approx(R * speed, abs=1e-12)
        assert unit.values["brake.torque"] == pytest.approx(brake, rel=1e-14)
        assert unit.values["motor.torque"] == pytest.approx(
            (beta * speed - rope - brake) / ratio, rel=1e-12, abs=1e-9
        )
        assert unit.values["brake.state"] == (2 if speed == 0.0 else 1)
        assert unit.values["stored_energy"] == 0.0
        assert abs(unit.values["energy_balance"]) < 1e-9 * unit.values["dissipated_energy"]
    assert rope > plus  # held at rest: the motor supplies what the brake cannot
    assert unit.values["motor.torque"] == pytest.approx(-(rope - plus) / ratio, rel=1e-12)


def test_kinetostatic_speed_is_taken_up_at_the_next_step():
    """The speed outputs report the last step (left limit): no feedthrough from the command."""
    unit = make_unit("", **{"drum.speed_command": 2.0})
    assert unit.advance(0.0, 0.1).success
    unit.values["drum.speed_command"] = -5.0
    unit.evaluate_outputs()
    assert unit.values["drum.speed"] == 2.0
    assert unit.advance(0.1, 0.1).success
    assert unit.values["drum.speed"] == -5.0


# ------------------------------------------------------- energy-form solver
def test_energy_form_solver_order_in_the_winch():
    """Rigid drum with rope layers and motor characteristic, one layer, against SciPy."""
    params = {**LAYERED, "motor_slope": 40.0, "rope_on_drum": 24.0}
    tension, a, w0 = 3000.0, 1500.0, 4.0
    span = 0.5
    radius, i0 = (v[0] for v in hand_layers(np.array([0.0]), rope=24.0))
    slope = -50.0 * radius**3  # dI/dphi on one layer

    def rhs(t, y):
        phi, w = y
        inertia = i0 + slope * phi
        return [w, (a - 40.0 * w + tension * radius - 0.5 * slope * w * w) / inertia]

    ref = solve_ivp(rhs, (0, span), [0.0, w0], method="DOP853", rtol=1e-13, atol=1e-13)
    for solver, order in (("energy1", 1), ("energy", 2)):
        errors = []
        for max_step in (4e-3, 2e-3, 1e-3):
            unit = make_unit(
                "drum_inertia,motor_characteristic,rope_layers",
                solver=solver,
                solver_max_step=max_step,
                initial_drum_speed=w0,
                **params,
                **{"rope.tension": tension, "motor.command": a},
            )
            run(unit, span, 0.1)
            assert unit.values["drum.layer"] == 3  # stayed on one layer
            errors.append(abs(unit.values["drum.speed"] - ref.y[1, -1]))
        orders = np.log2(np.array(errors[:-1]) / errors[1:])
        np.testing.assert_allclose(orders, order, atol=0.15)


# ------------------------------------------------------------ initial state
def test_starts_in_equilibrium_when_the_brake_holds():
    """Motor torque on at the start, brake holding: the shafts carry it, nothing moves."""
    unit = make_unit(
        "drum_inertia,band_brake,elastic_drive_train",
        solver="rk4",
        **{"brake.lever_force": 2000.0, "rope.tension": 1.0e5, "motor.command": -1.0e3},
    )
    out = run(unit, 1.0, 0.01, record=("motor.speed", "drum.speed", "brake.state"))
    assert np.all(out["drum.speed"] == 0.0) and np.all(out["brake.state"] == 2)
    assert np.abs(out["motor.speed"]).max() < 1e-9
    assert unit.values["mode_changes"] == 0


def test_starts_accelerating_without_shaft_vibration():
    """Free drum under motor and rope torque: the preloaded chain accelerates as one body."""
    train = (
        '{"masses": [{"name": "motor", "inertia": 12.0, "ratio": 6.0},'
        ' {"name": "gearbox", "inertia": 150.0}, {"name": "drum", "inertia": 1200.0}],'
        ' "shafts": [{"stiffness": 2e5, "ratio": 6.0}, {"stiffness": 1.5e7}]}'
    )
    moment, tension = 2.0e3, 5.0e4
    unit = make_unit(
        "drum_inertia,elastic_drive_train",
        solver="rk4",
        drive_train=train,
        drum_radius=R,
        **{"motor.command": moment, "rope.tension": tension},
    )
    out = run(unit, 0.5, 0.01, record=("motor.speed", "drum.speed"))
    acc = (6.0 * moment + tension * R) / (12.0 * 36 + 150 + 1200)
    np.testing.assert_allclose(out["drum.speed"], acc * out["time"], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(out["motor.speed"], 6.0 * acc * out["time"], rtol=1e-9, atol=1e-12)


# ------------------------------------------------------- monolithic ODE view
def test_ode_view_of_the_kinetostatic_winch_pays_out_the_rope_geometry():
    from wire_fmu.core.framework.hybrid import SolverSettings, make_solver

    unit = make_unit("rope_layers", **LAYERED, **{"drum.speed_command": 3.0})
    view = unit.ode()
    solver = make_solver(SolverSettings("rk4", max_step=0.01))
    x, _ = solver.advance(view, 0.0, view.state, 9.0)
    view.publish(9.0, x)
    stepped = make_unit("rope_layers", **LAYERED, **{"drum.speed_command": 3.0})
    run(stepped, 9.0, 0.1)
    assert unit.values["rope.payout"] == pytest.approx(stepped.values["rope.payout"], rel=1e-12)
    assert unit.values["drum.layer"] == 1 and unit.values["drum.speed"] == 3.0
