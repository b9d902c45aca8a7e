"""Hydraulics rod-side physics against closed forms (no FMI involved).

Seal friction, end stops and a tensioner through a reeving. Every expected value
comes from a textbook formula (restitution of a linear dashpot, a mass on a
spring, modal analysis) computed here from the parameters, never from numbers
the code printed; the oil side is in ``test_hydraulics_physics``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eigh
from scipy.optimize import brentq, curve_fit

from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.core.units.hydraulics.model import (
    damping_ratio_for_restitution,
    restitution_of_damping_ratio,
)

from .hydraulics_helpers import (
    AREA,
    F_EQ,
    MASS,
    gas_spring,
    make_free_rod,
    make_unit,
    quiet_cylinder,
    run,
)

# --------------------------------------------------------------- seal friction
SEAL = dict(
    seal_static_friction=5000.0,
    seal_coulomb_friction=3000.0,
    seal_viscous_friction=1000.0,
    seal_stribeck_velocity=0.01,
)


class TestSealFriction:
    def test_stuck_rod_holds_exactly_inside_the_stick_band(self):
        unit = gas_spring("seal_friction", **SEAL)
        assert unit.values["seal.stuck"]
        for offset in (0.5, -0.5, 0.99, -0.99):
            extra = offset * 5000.0
            out = run(
                unit,
                0.2,
                0.01,
                force=lambda t, e=extra: F_EQ + e,
                record=("rod.position", "rod.velocity", "seal.friction_force"),
            )
            assert np.all(out["rod.position"] == 2.0)
            assert np.all(out["rod.velocity"] == 0.0)
            assert out["seal.friction_force"][-1] == pytest.approx(-extra, abs=1e-6)
            assert unit.values["seal.stuck"]

    def test_breakaway_at_the_static_capacity_then_restick_inside_the_band(self):
        unit = gas_spring("seal_friction", **SEAL)
        step = 10.0  # N per communication step
        i = 0
        while unit.values["seal.stuck"]:
            unit.values["rod.force"] = F_EQ - (i + 1) * step
            assert unit.advance(i * 0.01, 0.01).success
            i += 1
            assert i < 1000
        assert (i - 1) * step <= 5000.0 < i * step  # broke away at the capacity
        hold = unit.values["rod.force"]
        run(unit, 3.0, 0.01, force=lambda t: hold, start=i * 0.01)
        v = unit.values
        assert v["seal.stuck"] and v["rod.velocity"] == 0.0
        net = hold + AREA * v["chamber.pressure"]  # all forces but friction
        assert abs(net) <= 5000.0
        assert v["seal.friction_force"] == pytest.approx(-net, abs=1e-6)

    def test_sliding_friction_follows_stribeck_and_viscous_laws(self):
        unit = gas_spring("seal_friction", **SEAL)
        out = run(
            unit,
            2.0,
            0.01,
            force=lambda t: F_EQ * (1 + 0.08 * math.sin(4 * t)),
            record=("rod.velocity", "seal.friction_force"),
        )
        v = out["rod.velocity"]
        sliding = np.abs(v) > 0.0
        assert sliding.sum() > 50
        law = -np.sign(v) * (3000.0 + 2000.0 * np.exp(-((v / 0.01) ** 2))) - 1000.0 * v
        assert np.allclose(out["seal.friction_force"][sliding], law[sliding], rtol=1e-12)

    def test_friction_never_injects_energy(self):
        rng = np.random.default_rng(4)
        forces = F_EQ * (1 + 0.03 * rng.standard_normal(300))
        unit = gas_spring("seal_friction,line_losses", **SEAL)
        out = run(
            unit,
            3.0,
            0.01,
            force=lambda t: forces[int(round(t / 0.01))],
            record=(
                "rod.velocity",
                "seal.friction_force",
                "dissipated_energy",
                "energy_balance",
                "external_work",
            ),
        )
        assert np.all(out["seal.friction_force"] * out["rod.velocity"] <= 0.0)
        assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)
        assert abs(out["energy_balance"][-1]) < 5e-3 * out["dissipated_energy"][-1]
        assert unit.values["mode_changes"] > 5


# ------------------------------------------------------------------ end stops
def restitution_by_integration(zeta: float) -> float:
    """Exit speed over entry speed of m x'' = -k x - c x' released when the force vanishes."""
    omega = 1.0

    def contact(t, y):
        return [y[1], -(omega**2) * y[0] - 2 * zeta * omega * y[1]]

    def released(t, y):
        return omega**2 * y[0] + 2 * zeta * omega * y[1]

    released.terminal, released.direction = True, -1
    sol = solve_ivp(contact, (0, 50), [0.0, 1.0], events=released, rtol=1e-12, atol=1e-14)
    return -sol.y_events[0][0][1]


class TestEndStops:
    @pytest.mark.parametrize("zeta", [0.05, 0.5, 0.9, 1.0, 2.0])
    def test_restitution_formula_of_the_force_release_dashpot(self, zeta):
        assert restitution_of_damping_ratio(zeta) == pytest.approx(
            restitution_by_integration(zeta), rel=1e-8
        )
        assert damping_ratio_for_restitution(restitution_of_damping_ratio(zeta)) == (
            pytest.approx(zeta, rel=1e-9)
        )

    @pytest.mark.parametrize(("end", "speed"), [("extension", 2.0), ("retraction", -2.0)])
    def test_quadratic_cushion_decelerates_as_v0_exp_minus_c_x_over_m(self, end, speed):
        c, length = 2.0e4, 0.5
        start = 3.4 if end == "extension" else 0.6
        unit = make_free_rod(
            "end_stops", speed, cushion_length=length, cushion_coefficient=c, initial_position=start
        )
        out = run(
            unit,
            0.3,
            0.002,
            record=("rod.position", "rod.velocity", "dissipated_energy", "energy_balance"),
        )
        boundary = 4.0 - length if end == "extension" else length
        depth = np.abs(out["rod.position"] - boundary)
        inside = (np.sign(out["rod.position"] - boundary) == np.sign(speed)) & (depth < 0.25)
        assert inside.sum() > 20
        exact = speed * np.exp(-c * depth[inside] / MASS)
        assert np.allclose(out["rod.velocity"][inside], exact, rtol=2e-3)
        lost = 0.5 * MASS * (speed**2 - out["rod.velocity"][-1] ** 2)
        assert out["dissipated_energy"][-1] == pytest.approx(lost, rel=2e-3)

    @pytest.mark.parametrize("restitution", [0.3, 0.8, 1.0])
    @pytest.mark.parametrize("speed", [0.5, -0.5])
    def test_end_stop_returns_the_set_restitution_and_never_pulls(self, restitution, speed):
        unit = make_free_rod(
            "end_stops",
            speed,
            cushion_length=0.0,
            stop_stiffness=1e8,
            stop_restitution=restitution,
            initial_position=3.95 if speed > 0 else 0.05,
        )
        out = run(
            unit,
            0.3,
            0.001,
            record=("rod.velocity", "end_stop.force", "energy_balance", "dissipated_energy"),
        )
        assert out["rod.velocity"][-1] == pytest.approx(-restitution * speed, rel=2e-3)
        assert np.all(np.sign(speed) * out["end_stop.force"] <= 0.0)  # pushes back only
        assert unit.values["mode_changes"] == 2
        loss = 0.5 * MASS * speed**2 * (1 - restitution**2)
        assert out["dissipated_energy"][-1] == pytest.approx(loss, rel=5e-3, abs=1e-3)
        assert abs(out["energy_balance"][-1]) < 5e-3 * 0.5 * MASS * speed**2

    @pytest.mark.parametrize("solver", ["ros2", "rk4", "radau"])
    def test_no_tunnelling_with_steps_far_longer_than_the_contact(self, solver):
        """The contact (4 ms) lies inside one 50 ms step: located, never crossed."""
        k, e, speed = 1e9, 0.5, 3.0
        unit = make_free_rod(
            "end_stops",
            speed,
            cushion_length=0.0,
            stop_stiffness=k,
            stop_restitution=e,
            initial_position=3.9,
            solver=solver,
            solver_max_step=0.05,
        )
        out = run(unit, 0.5, 0.05, record=("rod.position", "rod.velocity"))
        assert np.all(out["rod.position"] < 4.0)
        assert out["rod.velocity"][-1] == pytest.approx(-e * speed, rel=1e-2)
        assert unit.values["mode_changes"] == 2
        assert all(math.isfinite(v) for v in unit.values.values() if isinstance(v, float))

    def test_penetration_is_that_of_the_damped_contact(self):
        k, e, speed = 1e8, 0.5, 1.0
        unit = make_free_rod(
            "end_stops",
            speed,
            cushion_length=0.0,
            stop_stiffness=k,
            stop_restitution=e,
            initial_position=3.99,
        )
        out = run(unit, 0.05, 2e-4, record=("rod.position",))
        zeta = brentq(
            lambda z: math.exp(-2 * z * math.acos(z) / math.sqrt(1 - z * z)) - e, 1e-9, 1 - 1e-9
        )
        omega = math.sqrt(k / MASS)
        peak = speed / omega * math.exp(-zeta * math.acos(zeta) / math.sqrt(1 - zeta**2))
        assert out["rod.position"].max() - 4.0 == pytest.approx(peak, rel=1e-2)


# ------------------------------------------------------- through a reeving
def two_to_one_reeving(axial_stiffness: float, riser_mass: float) -> dict:
    """Rope from a fixed line end round a sheave on the rod (180 deg), back round a
    fixed sheave and down to a hanging riser: rope length L0 + 2 x_rod - y_riser."""
    return {
        "rope": {"axial_stiffness": axial_stiffness},
        "gravity": [0.0, -9.81, 0.0],
        "bodies": {
            "rod": {"kind": "driven", "direction": [1, 0, 0], "port": "mover_a"},
            "riser": {
                "kind": "block",
                "mass": riser_mass,
                "direction": [0, 1, 0],
                "port": "block_a",
            },
        },
        "sheaves": {
            "moving": {"body": "rod", "centre": [2, 5, 0], "radius": 0.5},
            "fixed": {"centre": [-3, 4, 0], "radius": 0.5},
        },
        "anchors": {"ring": {"body": "riser", "point": [-3.5, 0, 0]}},
        "path": [
            {"line_end": "line_a", "point": [-3, 5.5, 0]},
            {"sheave": "moving", "wrap": "cw"},
            {"sheave": "fixed", "wrap": "ccw"},
            {"anchor": "ring"},
        ],
    }


def test_tensioner_stiffness_through_an_r_to_1_reeving_is_k_over_r_squared():
    """Hydraulics coupled by hand to a block train (2:1): the riser oscillates at the
    frequency of the cylinder spring k/r^2 in series with the rope, with the rod's
    mass reflected; the exact 2-DOF eigenfrequency, not the r^1 law."""
    ea, riser, rod, ratio, step = 3.15e6, 2000.0, 2000.0, 2, 1.5e-3
    train = BlockTrainUnit("bt")
    train.values["reeving"] = json.dumps(two_to_one_reeving(ea, riser))
    train.values["solver_max_step"] = step
    train.configure()
    train.initialize(0.0)
    force, tension = train.values["mover_a.force"], train.values["line_a.tension"]
    assert force == pytest.approx(-ratio * riser * 9.81, rel=1e-9)
    p_eq = -force / AREA
    hyd = make_unit(
        "",
        force=force,
        **quiet_cylinder(
            moving_mass=rod,
            accumulator_volume=0.01,
            accumulator_dead_volume=0.001,
            precharge_pressure=1.0e6,
            initial_equilibrium=False,
            initial_gas_pressure=1.01 * p_eq,
            solver_max_step=step,
        ),
    )
    k_cyl = p_eq * AREA**2 / (0.01 * 1.0e6 / p_eq)
    rope_length = 5.0 + 5.0 + 4.0 + 0.75 * math.pi * 0.5 * 2  # straight parts and wraps
    k_rope = ea / (rope_length * ea / (ea + tension))  # EA over the unstretched length
    stiffness = np.array([[k_cyl + ratio**2 * k_rope, -ratio * k_rope], [-ratio * k_rope, k_rope]])
    omega = math.sqrt(eigh(stiffness, np.diag([rod, riser]), eigvals_only=True)[0])
    n = int(round(2.2 / step))
    times, ys = np.arange(n + 1) * step, np.empty(n + 1)
    ys[0] = train.values["block_a.position"]
    for i in range(n):  # Jacobi coupling at the rod's inertia
        hyd.values["rod.force"] = train.values["mover_a.force"]
        train.values["mover_a.position"] = hyd.values["rod.displacement"]
        train.values["mover_a.velocity"] = hyd.values["rod.velocity"]
        assert hyd.advance(i * step, step).success
        assert train.advance(i * step, step).success
        ys[i + 1] = train.values["block_a.position"]

    def wave(t, a, b, c, w):
        return a + b * np.cos(w * t) + c * np.sin(w * t)

    fitted, _ = curve_fit(wave, times, ys, p0=[ys.mean(), -np.ptp(ys) / 2, 0.0, omega])
    assert fitted[3] == pytest.approx(omega, rel=3e-3)
    wrong = math.sqrt(1 / (ratio / k_cyl + 1 / k_rope) / (riser + rod / ratio))  # k/r
    assert abs(fitted[3] / wrong - 1) > 0.1
