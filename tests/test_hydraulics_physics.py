"""Hydraulics physics against closed forms (no FMI involved).

Every expected value comes from a textbook formula (gas laws, Hagen-Poiseuille,
Darcy-Weisbach, a mass on a spring, modal analysis, restitution of a linear
dashpot) computed here from the parameters, never from numbers the code printed.

Here the oil side: the gas spring, the line and the oil column. The rod side (seal
friction, end stops, a reeving) is in ``test_hydraulics_mechanics``; the energy
ledger, the limits and the configuration checks in ``test_hydraulics_ledger_and_limits``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

from .hydraulics_helpers import (
    ALL_EFFECTS,
    AREA,
    DAMPED_LINE,
    F_EQ,
    MASS,
    P_EQ,
    V_EQ,
    gas_spring,
    make_free_rod,
    make_unit,
    period,
    quiet_cylinder,
    run,
    settled_displacement,
)


# ----------------------------------------------------------------- gas spring
class TestGasSpring:
    @pytest.mark.parametrize(("effects", "n"), [("", 1.0), ("polytropic_gas", 1.4)])
    def test_natural_frequency_is_sqrt_k_over_m(self, effects, n):
        """A mass on the gas spring oscillates at sqrt(n p A^2 / (V m)), p and V taken
        at the equilibrium it oscillates about."""
        unit = gas_spring(effects)
        k = n * P_EQ * AREA**2 / V_EQ
        assert unit.values["hydraulic_stiffness"] == pytest.approx(k, rel=1e-12)
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
        assert unit.values["hydraulic_stiffness"] == pytest.approx(k, rel=1e-12)
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
