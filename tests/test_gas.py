"""The polytropic gas spring against closed forms (no unit, no FMI)."""

from __future__ import annotations

import math

import pytest
from scipy.integrate import quad

from wire_fmu.core.components.gas import (
    ADIABATIC_DIATOMIC,
    ISOTHERMAL,
    PolytropicGas,
    isothermal_charge_volume,
)

P0, V0 = 1.5e7, 3.0


@pytest.mark.parametrize("n", [1.0, 1.2, 1.4])
def test_pressure_follows_p_v_to_the_n(n):
    gas = PolytropicGas(P0, V0, n)
    for volume in (0.5, 2.0, 3.0, 4.5):
        assert gas.pressure(volume) == pytest.approx(P0 * (V0 / volume) ** n, rel=1e-14)
        assert gas.pressure(volume) * volume**n == pytest.approx(P0 * V0**n, rel=1e-13)
        assert gas.volume(gas.pressure(volume)) == pytest.approx(volume, rel=1e-13)


@pytest.mark.parametrize("n", [1.0, 1.3, 1.4])
def test_stiffness_is_n_p_a2_over_v(n):
    """The spring rate n p A^2 / V equals a central difference of p(V) through a piston."""
    gas, area, volume = PolytropicGas(P0, V0, n), 0.1, 2.5
    dx = 1e-5
    force = [gas.pressure(volume + area * s) * area for s in (-dx, dx)]
    numeric = -(force[1] - force[0]) / (2 * dx)
    assert gas.stiffness(volume, area) == pytest.approx(
        n * gas.pressure(volume) * area**2 / volume, rel=1e-14
    )
    assert gas.stiffness(volume, area) == pytest.approx(numeric, rel=1e-8)
    assert gas.compliance(volume) == pytest.approx(volume / (n * gas.pressure(volume)))


@pytest.mark.parametrize("n", [1.2, 1.4])
def test_work_of_compression_is_p1v1_minus_p0v0_over_n_minus_1(n):
    gas, v1 = PolytropicGas(P0, V0, n), 1.7
    p1 = P0 * (V0 / v1) ** n
    closed = (p1 * v1 - P0 * V0) / (n - 1.0)
    integral, _ = quad(lambda v: -gas.pressure(v), V0, v1, epsabs=0.0, epsrel=1e-13)
    assert gas.work_on_gas(V0, v1) == pytest.approx(closed, rel=1e-12)
    assert gas.energy(v1) == pytest.approx(integral, rel=1e-10)


def test_isothermal_work_is_p0v0_ln_v0_over_v1_and_the_limit_is_continuous():
    v1 = 1.7
    iso = PolytropicGas(P0, V0, ISOTHERMAL)
    assert iso.energy(v1) == pytest.approx(P0 * V0 * math.log(V0 / v1), rel=1e-14)
    nearly = PolytropicGas(P0, V0, 1.0 + 1e-9)
    assert nearly.energy(v1) == pytest.approx(iso.energy(v1), rel=1e-8)


def test_isothermal_and_adiabatic_bracket_the_polytropic_result():
    """Compressed from the same state, a higher exponent gives more pressure and
    needs more work; expanded, it gives less pressure and yields less work."""
    gases = [PolytropicGas(P0, V0, n) for n in (ISOTHERMAL, 1.25, ADIABATIC_DIATOMIC)]
    for v1 in (1.5, 2.5):  # compression
        pressures = [g.pressure(v1) for g in gases]
        works = [g.work_on_gas(V0, v1) for g in gases]
        assert pressures[0] < pressures[1] < pressures[2]
        assert 0.0 < works[0] < works[1] < works[2]
    for v1 in (3.5, 5.0):  # expansion: the gas does work
        pressures = [g.pressure(v1) for g in gases]
        yielded = [-g.work_on_gas(V0, v1) for g in gases]
        assert pressures[0] > pressures[1] > pressures[2]
        assert yielded[0] > yielded[1] > yielded[2] > 0.0


def test_isothermal_charge_is_boyles_law():
    assert isothermal_charge_volume(1.0e7, 3.6, 1.5e7) == pytest.approx(3.6 * 1.0e7 / 1.5e7)


def test_problems_name_each_bad_parameter():
    problems = PolytropicGas(-1.0, 0.0, 0.5).problems()
    assert len(problems) == 3
    assert PolytropicGas(P0, V0, 1.4).problems() == []
