"""The oil line: Hagen-Poiseuille, Darcy-Weisbach, the blend between them, inertance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wire_fmu.core.components.hydraulic_line import HydraulicLine

LINE = HydraulicLine(
    length=15.0,
    diameter=0.15,
    density=870.0,
    viscosity=0.028,
    friction_factor=0.025,
    loss_coefficient=5.0,
)


def test_laminar_resistance_is_hagen_poiseuille():
    # dp = 128 mu l q / (pi d^4), by hand: 128 * 0.028 * 15 / (pi * 0.15^4)
    assert LINE.laminar_resistance == pytest.approx(53.76 / (math.pi * 5.0625e-4), rel=1e-12)


def test_turbulent_resistance_is_darcy_weisbach_plus_minor_losses():
    area = math.pi * 0.15**2 / 4
    k_total = 0.025 * 15.0 / 0.15 + 5.0  # 7.5
    assert LINE.turbulent_resistance == pytest.approx(870.0 * k_total / (2 * area**2), rel=1e-12)
    # the velocity-head form: dp = K rho u^2 / 2 with u = q / A
    q = 0.05
    assert LINE.turbulent_resistance * q * q == pytest.approx(
        k_total * 870.0 * (q / area) ** 2 / 2, rel=1e-12
    )


def test_inertance_is_rho_l_over_a_and_stores_the_columns_kinetic_energy():
    area = math.pi * 0.15**2 / 4
    q = 0.08
    assert LINE.inertance == pytest.approx(870.0 * 15.0 / area, rel=1e-12)
    column_mass, speed = 870.0 * area * 15.0, q / area
    assert 0.5 * LINE.inertance * q * q == pytest.approx(0.5 * column_mass * speed**2)


def test_pure_regimes():
    laminar = HydraulicLine(10.0, 0.05, 870.0, 0.05, friction_factor=0.0, loss_coefficient=0.0)
    turbulent = HydraulicLine(10.0, 0.05, 870.0, 0.0, friction_factor=0.02, loss_coefficient=1.0)
    for q in (-0.01, 1e-4, 0.02):
        assert laminar.pressure_drop(q) == pytest.approx(laminar.laminar_resistance * q)
        assert turbulent.pressure_drop(q) == pytest.approx(
            turbulent.turbulent_resistance * q * abs(q)
        )
        assert turbulent.flow(turbulent.pressure_drop(q)) == pytest.approx(q, rel=1e-12)
        assert laminar.flow(laminar.pressure_drop(q)) == pytest.approx(q, rel=1e-12)


def test_blend_is_continuous_and_monotonic_across_the_transition():
    q_star = LINE.transition_flow
    assert LINE.laminar_resistance * q_star == pytest.approx(
        LINE.turbulent_resistance * q_star**2, rel=1e-12
    )
    flows = np.linspace(-20 * q_star, 20 * q_star, 4001)
    drops = np.array([LINE.pressure_drop(q) for q in flows])
    assert np.all(np.diff(drops) > 0.0)
    slopes = np.diff(drops) / np.diff(flows)
    assert np.max(np.abs(np.diff(slopes))) < 1e-2 * np.max(slopes)  # no kink (C^1)
    # laminar far below the transition, turbulent far above
    assert LINE.pressure_drop(1e-3 * q_star) == pytest.approx(
        LINE.laminar_resistance * 1e-3 * q_star, rel=2e-3
    )
    assert LINE.pressure_drop(1e3 * q_star) == pytest.approx(
        LINE.turbulent_resistance * (1e3 * q_star) ** 2, rel=2e-3
    )


@pytest.mark.parametrize("q", [-0.3, -1e-7, 0.0, 3e-6, 0.11])
def test_flow_inverts_the_pressure_drop(q):
    assert LINE.flow(LINE.pressure_drop(q)) == pytest.approx(q, rel=1e-12, abs=1e-18)


def test_reynolds_number():
    q = 0.05
    u = q / LINE.area
    assert LINE.reynolds(q) == pytest.approx(870.0 * u * 0.15 / 0.028, rel=1e-12)


def test_problems():
    assert LINE.problems() == []
    bad = HydraulicLine(0.0, -1.0, 870.0, -0.1, friction_factor=-1.0, loss_coefficient=1.0)
    assert len(bad.problems()) == 4
