"""Hydraulics physics against closed forms (no FMI involved).

Every expected value comes from a textbook formula (gas laws, Hagen-Poiseuille,
Darcy-Weisbach, a mass on a spring, modal analysis, restitution of a linear
dashpot) computed here from the parameters, never from numbers the code printed.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eigh
from scipy.optimize import brentq, curve_fit

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.core.units.hydraulics.model import (
    damping_ratio_for_restitution,
    restitution_of_damping_ratio,
)
from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit

from .hydraulics_helpers import (
    ALL_EFFECTS,
    make_free_rod,
    make_unit,
    period,
    quiet_cylinder,
    run,
)

AREA = math.pi * 0.2**2 / 4  # bore of quiet_cylinder, m^2
P_EQ = 1.0e7  # Pa, working pressure of the tests below
F_EQ = -P_EQ * AREA  # rod force that P_EQ holds, N
V_EQ = 0.2 * 8.0e6 / P_EQ  # gas volume after charging from 8 MPa (Boyle), m^3
MASS = 1000.0
DAMPED_LINE = dict(
    line_diameter=0.028,
    line_length=5.0,
    oil_viscosity=0.025,
    line_friction_factor=0.0,
    line_loss_coefficient=0.0,
)
"""A laminar line giving the gas spring about half its critical damping."""


def gas_spring(effects: str = "", **params) -> HydraulicsUnit:
    """quiet_cylinder at rest in equilibrium at 10 MPa."""
    return make_unit(effects, force=F_EQ, **quiet_cylinder(**params))


def settled_displacement(n: float, extra_force: float) -> float:
    """Exact static displacement after the rod force changes by ``extra_force`` (N), m."""
    p1 = P_EQ - extra_force / AREA
    v1 = V_EQ * (P_EQ / p1) ** (1.0 / n)
    return (v1 - V_EQ) / AREA


# ----------------------------------------------------------------- gas spring
class TestGasSpring:
    @pytest.mark.parametrize(("effects", "n"), [("", 1.0), ("polytropic_gas", 1.4)])
    def test_natural_frequency_is_sqrt_k_over_m(self, effects, n):
        """A mass on the gas spring oscillates at sqrt(n p A^2 / (V m)), p and V taken
        at the equilibrium it oscillates about."""
        unit = gas_spring(effects)
        k = n * P_EQ * AREA**2 / V_EQ
        assert unit.values["rod.stiffness"] == pytest.approx(k, rel=1e-12)
        push = -500.0
        out = run(unit, 2.5, 0.005, force=lambda t: F_EQ + push)
        p1 = P_EQ - push / AREA
        v1 = V_EQ * (P_EQ / p1) ** (1 / n)
        k1 = n * p1 * AREA**2 / v1
        expected = 2 * math.pi * math.sqrt(MASS / k1)
        assert period(out["time"], out["rod.position"]) == pytest.approx(expected, rel=3e-4)
        centre = 0.5 * (out["rod.position"].max() + out["rod.position"].min()) - 2.0
        assert centre == pytest.approx(settled_displacement(n, push), rel=1e-3)
        assert centre == pytest.approx(push / k, rel=3e-3)  # linear: x = F / k

    def test_gas_follows_its_polytrope_and_the_oil_volume_is_conserved(self):
        unit = gas_spring("polytropic_gas", polytropic_exponent=1.3)
        out = run(
            unit,
            1.0,
            0.01,
            force=lambda t: F_EQ * (1.0 + 0.05 * math.sin(7 * t)),
            record=("rod.position", "gas.pressure", "gas.volume"),
        )
        invariant = out["gas.pressure"] * out["gas.volume"] ** 1.3
        assert np.ptp(invariant) < 1e-12 * invariant[0]
        oil = out["gas.volume"] - AREA * out["rod.position"]
        assert np.ptp(oil) < 1e-14

    @pytest.mark.parametrize("n", [1.2, 1.4])
    def test_work_on_the_gas_is_p1v1_minus_p0v0_over_n_minus_1(self, n):
        """External work minus losses minus kinetic energy is what the gas stored."""
        unit = gas_spring("polytropic_gas,line_losses", polytropic_exponent=n, **DAMPED_LINE)
        extra = -20.0e3
        out = run(
            unit,
            1.5,
            0.01,
            force=lambda t: F_EQ + extra,
            record=(
                "rod.position",
                "rod.velocity",
                "gas.pressure",
                "gas.volume",
                "external_work",
                "dissipated_energy",
            ),
        )
        p1, v1 = out["gas.pressure"][-1], out["gas.volume"][-1]
        closed = (p1 * v1 - P_EQ * V_EQ) / (n - 1.0)
        kinetic = 0.5 * MASS * out["rod.velocity"][-1] ** 2
        work = out["external_work"][-1]
        assert work == pytest.approx((F_EQ + extra) * (out["rod.position"][-1] - 2.0))
        stored = work - out["dissipated_energy"][-1] - kinetic
        assert stored == pytest.approx(closed, rel=1e-5)
        step_work = extra * (out["rod.position"][-1] - 2.0)
        assert out["dissipated_energy"][-1] > 0.3 * step_work  # the line really damped it

    def test_isothermal_and_adiabatic_bracket_the_polytropic_settling(self):
        """Pushed in by the same force, a stiffer gas law gives way less; each
        settles exactly where p1 = p0 (V0/V1)^n holds the new force."""
        extra = -30.0e3
        moved = {}
        for n in (1.0, 1.2, 1.4):
            effects = "line_losses" + (",polytropic_gas" if n > 1.0 else "")
            unit = gas_spring(effects, polytropic_exponent=n, **DAMPED_LINE)
            out = run(unit, 3.0, 0.02, force=lambda t: F_EQ + extra)
            moved[n] = out["rod.position"][-1] - 2.0
            assert moved[n] == pytest.approx(settled_displacement(n, extra), rel=1e-4)
        assert moved[1.0] < moved[1.2] < moved[1.4] < 0.0

    def test_pull_cylinder_pressurises_the_annulus(self):
        """An annulus-side cylinder is pulled in by the gas: a pull on the rod
        extends it and compresses the gas, with stiffness n p A_a^2 / V."""
        annulus = math.pi * (0.2**2 - 0.1**2) / 4
        unit = make_unit(
            "line_losses",
            force=P_EQ * annulus,
            **quiet_cylinder(pressurised_side="annulus", **DAMPED_LINE),
        )
        assert unit.values["gas.pressure"] == pytest.approx(P_EQ, rel=1e-12)
        out = run(
            unit,
            3.0,
            0.02,
            force=lambda t: P_EQ * annulus + 2000.0,
            record=("rod.position", "gas.volume"),
        )
        k = P_EQ * annulus**2 / V_EQ
        assert out["rod.position"][-1] - 2.0 == pytest.approx(2000.0 / k, rel=1e-2)
        assert out["gas.volume"][-1] < V_EQ

    def test_initial_equilibrium_with_ambient_pressure_and_gravity(self):
        """Defaults: a vertical push cylinder; (p - p_amb) A = -F + m g holds it at rest."""
        unit = make_unit(ALL_EFFECTS)
        v = unit.values
        area = math.pi * 0.356**2 / 4
        expected = 101325.0 + (-v["rod.force"] + 3500.0 * 9.81) / area
        assert v["gas.pressure"] == pytest.approx(expected, rel=1e-14)
        assert v["gas.volume"] == pytest.approx(3.6 * 13.5e6 / expected, rel=1e-14)
        out = run(unit, 1.0, 0.01, record=("rod.position", "rod.velocity", "chamber.pressure"))
        assert np.ptp(out["rod.position"]) < 1e-12
        assert np.max(np.abs(out["rod.velocity"])) < 1e-12
        assert np.ptp(out["chamber.pressure"]) < 1e-6
        assert v["seal.stuck"] and v["mode_changes"] == 0


# ------------------------------------------------------------------- the line
class TestLine:
    def test_laminar_line_gives_the_terminal_velocity_of_hagen_poiseuille(self):
        mu, length, d = 0.05, 5.0, 0.02
        unit = make_free_rod(
            "line_losses",
            0.0,
            line_length=length,
            line_diameter=d,
            oil_viscosity=mu,
            line_friction_factor=0.0,
            line_loss_coefficient=0.0,
        )
        r_l = 128 * mu * length / (math.pi * d**4)
        push = 1.0e4
        force = unit.values["rod.force"] + push
        out = run(unit, 0.3, 0.01, force=lambda t: force, record=("rod.velocity",))
        assert out["rod.velocity"][-1] == pytest.approx(push / (r_l * AREA**2), rel=1e-6)

    def test_turbulent_line_gives_the_terminal_velocity_of_darcy_weisbach(self):
        rho, length, d, f, k = 870.0, 5.0, 0.02, 0.02, 2.0
        unit = make_free_rod(
            "line_losses",
            0.0,
            line_length=length,
            line_diameter=d,
            oil_viscosity=0.0,
            oil_density=rho,
            line_friction_factor=f,
            line_loss_coefficient=k,
        )
        pipe = math.pi * d**2 / 4
        r_t = rho * (f * length / d + k) / (2 * pipe**2)
        push = 1.0e4
        force = unit.values["rod.force"] + push
        out = run(
            unit,
            0.3,
            0.01,
            force=lambda t: force,
            record=("rod.velocity", "rod.position", "dissipated_energy"),
        )
        v_t = math.sqrt(push / (r_t * AREA**3))
        assert out["rod.velocity"][-1] == pytest.approx(v_t, rel=1e-6)
        # at terminal speed all the extra push goes into the line
        tail = slice(-11, None)
        dissipated = np.diff(out["dissipated_energy"][tail]).sum()
        assert dissipated == pytest.approx(
            push * np.diff(out["rod.position"][tail]).sum(), rel=1e-5
        )

    def test_pressure_drop_is_laminar_plus_turbulent_at_every_sample(self):
        mu, rho, length, d, f, k = 0.03, 870.0, 8.0, 0.03, 0.025, 4.0
        unit = gas_spring(
            "line_losses",
            line_length=length,
            line_diameter=d,
            oil_viscosity=mu,
            oil_density=rho,
            line_friction_factor=f,
            line_loss_coefficient=k,
        )
        out = run(
            unit,
            1.0,
            0.01,
            force=lambda t: F_EQ * (1 + 0.1 * math.sin(9 * t)),
            record=("gas.pressure", "chamber.pressure", "line.flow", "rod.velocity"),
        )
        pipe = math.pi * d**2 / 4
        r_l = 128 * mu * length / (math.pi * d**4)
        r_t = rho * (f * length / d + k) / (2 * pipe**2)
        q = out["line.flow"]
        assert np.allclose(q, AREA * out["rod.velocity"], rtol=1e-14, atol=0.0)
        drop = out["gas.pressure"] - out["chamber.pressure"]
        assert np.allclose(drop, r_l * q + r_t * q * np.abs(q), rtol=1e-9, atol=1e-6)
        assert np.max(np.abs(q)) > 3 * r_l / r_t  # the run crosses the transition flow


# -------------------------------------------------------- inertance and oil
class TestOilColumn:
    def test_incompressible_line_inertance_adds_mass_l_a2(self):
        rho, length, d = 870.0, 10.0, 0.05
        length = 4.0
        unit = gas_spring("line_inertance", line_length=length, line_diameter=d, oil_density=rho)
        inertance = rho * length / (math.pi * d**2 / 4)
        k = P_EQ * AREA**2 / V_EQ
        out = run(
            unit,
            4.0,
            0.01,
            force=lambda t: F_EQ - 500.0,
            record=("rod.position", "rod.acceleration", "gas.pressure", "chamber.pressure"),
        )
        expected = 2 * math.pi * math.sqrt((MASS + inertance * AREA**2) / k)
        assert period(out["time"], out["rod.position"]) == pytest.approx(expected, rel=2e-3)
        # the port pressure is lower by L dq/dt = L A a
        lag = out["gas.pressure"] - out["chamber.pressure"]
        assert np.allclose(lag, inertance * AREA * out["rod.acceleration"], rtol=1e-9, atol=1e-6)

    def test_oil_column_in_parallel_with_the_gas(self):
        """Without a line element the oil compliance V/K adds to the gas's V/(n p)."""
        oil, bulk = 0.1, 1.5e9
        unit = gas_spring(
            "oil_compressibility",
            oil_volume=oil,
            bulk_modulus=bulk,
            accumulator_volume=0.002,
            accumulator_dead_volume=1e-4,
            precharge_pressure=8.0e6,
            solver_max_step=2e-4,
        )
        v_gas = 0.002 * 8.0e6 / P_EQ
        compliance = v_gas / P_EQ + oil / bulk
        k = AREA**2 / compliance
        assert unit.values["rod.stiffness"] == pytest.approx(k, rel=1e-12)
        out = run(unit, 0.4, 0.002, force=lambda t: F_EQ - 500.0)
        assert period(out["time"], out["rod.position"]) == pytest.approx(
            2 * math.pi * math.sqrt(MASS / k), rel=2e-3
        )

    def test_compressible_line_matches_the_linear_modal_solution(self):
        """Rod, oil column, line inertance and gas: a 2-DOF linear system for small
        motions, solved here by modal analysis (M y'' + K y = f)."""
        oil, bulk, rho, length, d = 0.05, 1.5e9, 870.0, 10.0, 0.05
        unit = gas_spring(
            "oil_compressibility,line_inertance",
            oil_volume=oil,
            bulk_modulus=bulk,
            oil_density=rho,
            line_length=length,
            line_diameter=d,
            solver_max_step=5e-5,
        )
        inertance = rho * length / (math.pi * d**2 / 4)
        c_oil, c_gas = oil / bulk, V_EQ / P_EQ
        # y = (rod x, line volume y): chamber p = (y - A x)/C_oil, gas p = -y / C_gas
        stiffness = np.array(
            [[AREA**2 / c_oil, -AREA / c_oil], [-AREA / c_oil, 1 / c_oil + 1 / c_gas]]
        )
        mass = np.diag([MASS, inertance])
        push = -500.0
        static = np.linalg.solve(stiffness, [push, 0.0])
        omega2, modes = eigh(stiffness, mass)
        coeff = modes.T @ mass @ (-static)  # start at rest, displaced by -static
        out = run(
            unit,
            0.2,
            0.001,
            force=lambda t: F_EQ + push,
            record=("rod.position", "chamber.pressure"),
        )
        t = out["time"]
        y = static[:, None] + modes @ (coeff[:, None] * np.cos(np.sqrt(omega2)[:, None] * t))
        x_exact = 2.0 + y[0]
        p_exact = P_EQ + (y[1] - AREA * y[0]) / c_oil
        scale = np.ptp(x_exact)
        assert np.max(np.abs(out["rod.position"] - x_exact)) < 2e-3 * scale
        assert np.max(np.abs(out["chamber.pressure"] - p_exact)) < 5e-3 * np.ptp(p_exact)

    def test_compressible_line_with_losses_settles_to_the_gas_pressure(self):
        oil, bulk = 0.1, 1.5e9
        unit = gas_spring(
            "oil_compressibility,line_losses", oil_volume=oil, bulk_modulus=bulk, **DAMPED_LINE
        )
        push = -20.0e3
        out = run(
            unit,
            3.0,
            0.01,
            force=lambda t: F_EQ + push,
            record=("rod.position", "gas.pressure", "chamber.pressure"),
        )
        assert out["chamber.pressure"][-1] == pytest.approx(out["gas.pressure"][-1], rel=1e-7)
        assert out["chamber.pressure"][-1] == pytest.approx(P_EQ - push / AREA, rel=1e-6)
        # the gas and the oil column share the displaced volume
        v1 = V_EQ * P_EQ / out["gas.pressure"][-1]
        squeezed = oil / bulk * (out["chamber.pressure"][-1] - P_EQ)
        assert out["rod.position"][-1] - 2.0 == pytest.approx(
            (v1 - V_EQ - squeezed) / AREA, rel=1e-6
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


# ------------------------------------------------------------- energy ledger
@pytest.mark.parametrize(
    "effects",
    [
        "",
        "polytropic_gas,line_losses,seal_friction",
        "oil_compressibility,line_losses,line_inertance",
        ALL_EFFECTS,
    ],
)
def test_energy_ledger_closes_in_normal_operation(effects):
    f0 = -4 * 356.0e3
    unit = make_unit(effects)

    def heave(t):
        return f0 * (1 + 0.04 * math.sin(2 * math.pi * 0.2 * t) + 0.02 * math.sin(8.2 * t))

    out = run(
        unit,
        3.0,
        0.01,
        force=heave,
        record=("energy_balance", "dissipated_energy", "external_work"),
    )
    assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)
    tolerance = 1e-7 * np.max(np.abs(out["external_work"])) + 3e-3 * out["dissipated_energy"][-1]
    assert np.max(np.abs(out["energy_balance"])) < tolerance


def test_energy_ledger_closes_through_cushion_and_stop_impacts():
    """A rod whose wire broke: the full gas force drives it into the cushion and stop.

    Without oil compressibility and inertance: with them the released oil column
    swings the chamber pressure down to cavitation (see TestLimits)."""
    unit = make_unit("polytropic_gas,line_losses,seal_friction,end_stops")
    out = run(
        unit,
        2.0,
        0.01,
        force=lambda t: 0.0,
        record=("energy_balance", "dissipated_energy", "rod.position", "rod.velocity"),
    )
    assert unit.values["end_stop.contact"] or out["rod.position"][-1] > 3.6
    assert np.max(out["rod.velocity"]) > 3.0  # it really ran away
    assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)
    assert np.max(np.abs(out["energy_balance"])) < 5e-3 * out["dissipated_energy"][-1]


# ------------------------------------------------------------------- limits
class TestLimits:
    def test_driven_towards_zero_gas_volume_the_step_is_refused(self):
        unit = gas_spring(
            "", accumulator_volume=0.05, accumulator_dead_volume=0.005, precharge_pressure=8.0e6
        )
        unit.values["rod.force"] = F_EQ - 3.0e6
        t, result = 0.0, None
        for _ in range(200):
            before = dict(unit.values)
            state = json.dumps(unit.get_state())
            result = unit.advance(t, 0.01)
            if not result.success:
                break
            t += 0.01
        assert not result.success
        assert "Hydraulics 'test'" in result.message
        assert "gas volume" in result.message and "dead volume 0.005 m3" in result.message
        assert unit.values == before and json.dumps(unit.get_state()) == state
        assert unit.values["gas.volume"] > 0.005
        assert all(math.isfinite(v) for v in unit.values.values() if isinstance(v, float))
        assert not unit.advance(t, 0.01).success  # refused again, deterministically

    def test_an_emptied_accumulator_refuses_the_step(self):
        unit = gas_spring("", accumulator_volume=0.2, precharge_pressure=9.9e6)
        unit.values["rod.force"] = 0.0  # the load is gone: the gas pushes the rod out
        results = [unit.advance(0.01 * i, 0.01) for i in range(100)]
        refused = [r for r in results if not r.success]
        assert refused and "no oil left" in refused[0].message

    def test_cavitation_refuses_the_step(self):
        """A wire break on the default tensioner: released, the rod springs off the
        compressible oil column faster than the 15 m line can feed it, and the
        chamber pressure swings down to cavitation."""
        unit = make_unit("oil_compressibility,line_inertance,line_losses")
        unit.values["rod.force"] = 0.0
        results = [unit.advance(0.01 * i, 0.01) for i in range(20)]
        refused = [r for r in results if not r.success]
        assert refused and "cavitation pressure 10000 Pa" in refused[0].message

    def test_without_end_stops_leaving_the_stroke_refuses_the_step(self):
        unit = gas_spring("", accumulator_volume=1.0, precharge_pressure=1.6e6)
        unit.values["rod.force"] = 0.0
        results = [unit.advance(0.01 * i, 0.01) for i in range(300)]
        refused = [r for r in results if not r.success]
        assert refused and "beyond the stroke 4 m" in refused[0].message
        assert "end_stops" in refused[0].message


# ------------------------------------------------------------ configuration
def test_bad_parameters_give_one_error_listing_every_problem():
    unit = HydraulicsUnit("bad")
    unit.values.update(
        effects="polytropic_gas, line_loss",
        solver="euler",
        bore_diameter=0.1,
        rod_diameter=0.2,
        stroke=0.0,
        pressurised_side="top",
        stop_restitution=1.5,
        seal_coulomb_friction=9e4,
        initial_velocity=1.0,
        bulk_modulus=-1.0,
        polytropic_exponent=0.7,
    )
    with pytest.raises(ConfigurationError) as info:
        unit.configure()
    text = str(info.value)
    for name in (
        "line_loss",
        "euler",
        "rod_diameter",
        "stroke",
        "pressurised_side",
        "stop_restitution",
        "seal_coulomb_friction",
        "initial_velocity",
        "bulk_modulus",
        "polytropic_exponent",
    ):
        assert name in text, name
    assert len(info.value.problems) == 10
    assert text.startswith("Hydraulics 'bad': 10 problems")


def test_an_impossible_start_is_a_configuration_error():
    unit = HydraulicsUnit("start")
    unit.values.update(quiet_cylinder(precharge_pressure=1.2e7))
    unit.values["rod.force"] = F_EQ  # needs 10 MPa, below the 12 MPa pre-charge
    unit.configure()
    with pytest.raises(ConfigurationError, match="below the pre-charge"):
        unit.initialize(0.0)
