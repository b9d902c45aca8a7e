"""The winch's band brake against closed forms (no FMI involved).

Holding below capacity, breakaway at the band-brake equation (34), sliding and
re-sticking, both directions, and a brake ramped within a step in the monolithic
ODE view. Every expected value comes from a textbook formula or eq. (34),
never from numbers the code printed. Signs: everything positive paying out.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wire_fmu.core.units.winch.brake import BandBrake

from .winch_helpers import BRAKE, capacities, make_unit, one_mass, run, two_mass

R = 0.5  # drum radius, m
J = 1000.0  # drum inertia, kg m^2
RIGID = {"drive_train": one_mass(J), "drum_radius": R, **BRAKE}


def events_of(unit) -> list[tuple[float, str]]:
    return list(unit.model.last_events)


def step_until(unit, text, step, limit, drive=None, start=0.0):
    """Step until an event containing ``text``; return its time."""
    t = start
    while t < start + limit:
        if drive:
            drive(t, unit)
        result = unit.advance(t, step)
        assert result.success, result.message
        hits = [te for te, msg in events_of(unit) if text in msg]
        if hits:
            return hits[0]
        t += step
    raise AssertionError(f"no event {text!r} within {limit} s")


# ----------------------------------------------------------------- band brake
def test_band_brake_factors_are_eq_34_both_ways():
    brake = BandBrake(0.6, 10.0, 0.9, 0.35, 4.7)
    plus, minus = brake.capacities(1000.0)
    assert (plus, minus) == pytest.approx(capacities(1000.0), rel=1e-14)
    assert plus / minus == pytest.approx(math.exp(0.35 * 4.7), rel=1e-13)
    assert brake.capacities(0.0) == (0.0, 0.0) and brake.capacities(-50.0) == (0.0, 0.0)


@pytest.mark.parametrize("solver", ["ros2", "rk4", "radau", "energy"])
def test_brake_holds_below_capacity_with_zero_speed_for_ever(solver):
    lever = 1000.0
    tension = 0.95 * capacities(lever)[0] / R
    unit = make_unit(
        "drum_inertia,band_brake",
        solver=solver,
        solver_max_step=0.25,
        **RIGID,
        **{"brake.lever_force": lever, "rope.tension": tension},
    )
    out = run(
        unit,
        200.0,
        1.0,
        record=(
            "drum.speed",
            "drum.angle",
            "rope.payout",
            "rope.payout_rate",
            "brake.state",
            "brake.torque",
        ),
    )
    for name in ("drum.speed", "drum.angle", "rope.payout", "rope.payout_rate"):
        assert np.all(out[name] == 0.0), name
    assert np.all(out["brake.state"] == 2)
    assert np.all(out["brake.torque"] == -tension * R)  # exactly the holding torque
    assert unit.values["mode_changes"] == 0 and unit.values["energy_balance"] == 0.0


def test_breakaway_exactly_when_the_load_crosses_capacity():
    """Rope tension raised in steps: held up to capacity, sliding at the first step above."""
    lever = 500.0
    cap = capacities(lever)[0]
    unit = make_unit("drum_inertia,band_brake", **RIGID, **{"brake.lever_force": lever})
    torques = cap * np.array([0.5, 0.9, 0.999, 1.0, 1.001, 1.1])
    states = []
    for i, torque in enumerate(torques):
        unit.values["rope.tension"] = torque / R
        assert unit.advance(0.01 * i, 0.01).success
        states.append((unit.values["brake.state"], unit.values["drum.speed"]))
    assert states[:4] == [(2, 0.0)] * 4
    assert states[4][0] == 1 and states[4][1] == pytest.approx(0.001 * cap * 0.01 / J, rel=1e-9)


def test_breakaway_time_on_an_elastic_drive_train_matches_the_closed_form():
    """Drum held, motor torque stepped on: the shaft winds up as M (1 - cos W t) and the
    brake lets go when rope torque + shaft torque reach its capacity."""
    lever, jm, c, moment = 400.0, 20.0, 2.0e6, 1.0e4
    cap = capacities(lever)[0]
    rope_torque = cap - 0.6 * moment  # breakaway at 1 - cos W t = 0.6
    unit = make_unit(
        "drum_inertia,band_brake,elastic_drive_train",
        solver="rk4",
        solver_max_step=1e-4,
        **{**RIGID, "drive_train": two_mass(jm, J, c)},
        **{"brake.lever_force": lever, "rope.tension": rope_torque / R},
    )
    unit.values["motor.command"] = moment
    omega = math.sqrt(c / jm)
    expected = math.acos(1.0 - 0.6) / omega

    def held(t, u):
        assert u.values["drum.angle"] == 0.0 and u.values["drum.speed"] == 0.0

    t = step_until(unit, "brake slipping", 1e-3, 0.1, drive=held)
    assert abs(t - expected) < 1e-4  # within one internal step (located to 1e-9 s)
    assert t == pytest.approx(expected, abs=1e-7)


# --------------------------------------------------------------- sliding
@pytest.mark.parametrize("solver", ["ros2", "rk4", "energy"])
def test_sliding_deceleration_and_clean_restick(solver):
    """Paying out at 10 rad/s into the brake: omega' = -(M_brake - T r)/J, then held."""
    lever, w0, tension = 1000.0, 10.0, 2000.0
    cap = capacities(lever)[0]
    decel = (cap - tension * R) / J
    unit = make_unit(
        "drum_inertia,band_brake",
        solver=solver,
        initial_drum_speed=w0,
        **RIGID,
        **{"brake.lever_force": lever, "rope.tension": tension},
    )
    assert unit.values["brake.state"] == 1 and unit.values["brake.torque"] == -cap
    stop = w0 / decel
    out = run(unit, 1.0, 0.01, record=("drum.speed", "rope.payout", "brake.state"))
    sliding = out["time"] < stop
    np.testing.assert_allclose(
        out["drum.speed"][sliding], w0 - decel * out["time"][sliding], rtol=1e-9, atol=1e-9
    )
    assert np.all(out["drum.speed"][~sliding] == 0.0)
    assert np.all(out["brake.state"][~sliding] == 2)
    held = out["rope.payout"][~sliding]
    assert np.all(held == held[0])
    assert held[0] == pytest.approx(R * w0**2 / (2 * decel), rel=1e-9)
    assert unit.values["mode_changes"] == 1  # one stop, no chatter


def test_reverse_direction_slides_on_the_weak_side_and_holds_on_the_strong_one():
    """Hauling in (omega < 0) the band is not self-energising: 1 - e^(-mu alpha)."""
    lever, w0, tension = 1000.0, -10.0, 2000.0
    plus, minus = capacities(lever)
    decel = (minus + tension * R) / J  # both the brake and the rope slow the haul-in
    unit = make_unit(
        "drum_inertia,band_brake",
        initial_drum_speed=w0,
        **RIGID,
        **{"brake.lever_force": lever, "rope.tension": tension},
    )
    assert unit.values["brake.torque"] == pytest.approx(minus, rel=1e-14)
    stop = step_until(unit, "brake holding", 0.01, 3.0)
    assert stop == pytest.approx(-w0 / decel, abs=1e-8)
    assert tension * R < plus  # so it holds afterwards
    run(unit, 0.5, 0.01, start=3.0)
    assert unit.values["drum.speed"] == 0.0


@pytest.mark.parametrize("direction", [+1, -1])
def test_holding_capacity_depends_on_direction(direction):
    """Motor torque against the held drum: breakaway at c+ paying out, c- hauling in."""
    lever = 200.0
    cap = capacities(lever)[0 if direction > 0 else 1]
    for factor, state in ((0.99, 2), (1.01, 1)):
        unit = make_unit("drum_inertia,band_brake", **RIGID, **{"brake.lever_force": lever})
        unit.values["motor.command"] = direction * factor * cap
        assert unit.advance(0.0, 0.01).success
        assert unit.values["brake.state"] == state
        assert np.sign(unit.values["drum.speed"]) == (0 if state == 2 else direction)


# ------------------------------------------------------- monolithic ODE view
class LeverRamp:
    """The winch's ODE view with the lever force a function of time (as a monolithic
    model feeds inputs: at every evaluation, not held over a step)."""

    def __init__(self, unit, lever):
        self.unit, self.view, self.lever = unit, unit.ode(), lever

    def _bind(self, t):
        self.unit.values["brake.lever_force"] = self.lever(t)
        self.view.bind_inputs(t)

    def rhs(self, t, x):
        self._bind(t)
        return self.view.rhs(t, x)

    def guards(self, t, x):
        self._bind(t)
        return self.view.guards(t, x)

    def guard_directions(self):
        return self.view.guard_directions()

    def handle_events(self, t, x, fired):
        self._bind(t)
        return self.view.handle_events(t, x, fired)

    def project(self, x):
        return self.view.project(x)


def test_ode_view_engages_a_ramped_brake_and_stops_the_drum():
    """F = 1000 (t - 0.2) N: omega = omega0 - k 1000 (t - 0.2)^2 / (2 J), then held."""
    from wire_fmu.core.framework.hybrid import SolverSettings, make_solver

    w0 = 10.0
    k = capacities(1.0)[0]  # capacity per newton of lever force
    unit = make_unit("drum_inertia,band_brake", initial_drum_speed=w0, **RIGID)
    system = LeverRamp(unit, lambda t: 1000.0 * (t - 0.2))
    solver = make_solver(SolverSettings("radau", max_step=0.05, rtol=1e-11, atol=1e-12))
    x, t = system.view.state, 0.0
    stop = 0.2 + math.sqrt(2 * J * w0 / (k * 1000.0))
    for t_next in (0.5, 1.0, 1.5):
        x, _ = solver.advance(system, t, x, t_next)
        t = t_next
        expected = max(w0 - k * 1000.0 * (t - 0.2) ** 2 / (2 * J), 0.0)
        assert x[1] == pytest.approx(expected, abs=1e-7)
    assert t > stop and x[1] == 0.0
    system.view.publish(t, x)
    assert unit.values["brake.state"] == 2 and unit.values["mode_changes"] == 2
