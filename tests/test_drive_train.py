"""Multi-mass drive trains (paper 002) against closed forms and scipy.linalg."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from wire_fmu.core.components.drive_train import (
    ChainElement,
    DriveChain,
    default_drive_train,
    parse_drive_train,
)


def chain(inertias, stiffnesses, dampings=None, links=None, motor_ratio=1.0) -> DriveChain:
    n = len(inertias)
    return DriveChain(
        tuple(inertias),
        tuple(dampings or [0.0] * n),
        tuple(stiffnesses),
        tuple(links or [0.0] * (n - 1)),
        tuple(f"m{i}" for i in range(n)),
        motor_ratio,
    )


def state_space_frequencies(j, c, beta=None, beta_link=None) -> np.ndarray:
    """|Im| of the eigenvalues of [[0, I], [-M^-1 K, -M^-1 B]], built here by hand."""
    n = len(j)
    k = np.zeros((n, n))
    b = np.diag(beta if beta is not None else np.zeros(n))
    for i, ci in enumerate(c):
        bi = beta_link[i] if beta_link is not None else 0.0
        for m, s in (((i, i), 1), ((i + 1, i + 1), 1), ((i, i + 1), -1), ((i + 1, i), -1)):
            k[m] += s * ci
            b[m] += s * bi
    minv = np.diag(1.0 / np.asarray(j, dtype=float))
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ b]])
    eig = scipy.linalg.eig(a)[0]
    return np.sort(np.abs(eig.imag))[::2]  # each frequency appears as a +/- pair


def test_two_mass_natural_frequency_closed_form():
    j1, j2, c = 432.0, 1350.0, 7.2e6
    got = chain([j1, j2], [c]).natural_frequencies()
    assert got[0] == pytest.approx(0.0, abs=1e-6)
    assert got[1] == pytest.approx(math.sqrt(c * (j1 + j2) / (j1 * j2)), rel=1e-12)


@pytest.mark.parametrize("n", [3, 5, 12])
def test_n_mass_eigenfrequencies_match_scipy_eig(n):
    rng = np.random.default_rng(n)
    j = rng.uniform(1.0, 500.0, n)
    c = rng.uniform(1e5, 5e7, n - 1)
    got = chain(j, c).natural_frequencies()
    expected = state_space_frequencies(j, c)
    assert got[0] < 1e-3 and expected[0] < 1e-3  # free rotation (round-off ~sqrt(eps) K/J)
    np.testing.assert_allclose(got[1:], expected[1:], rtol=1e-9)


def test_reduction_of_a_massless_interior_mass_is_exact():
    """J_k = 0, beta_k = 0: the two shafts are springs in series, nothing is approximated."""
    full = chain([10.0, 0.0, 30.0, 40.0], [1e6, 3e6, 2e6])
    reduced = full.eliminate(1)
    assert reduced.stiffnesses[0] == pytest.approx(1.0 / (1 / 1e6 + 1 / 3e6), rel=1e-14)
    # the full chain's massless mass makes its matrix singular: compare with a tiny mass
    nearly = chain([10.0, 1e-9, 30.0, 40.0], [1e6, 3e6, 2e6]).natural_frequencies()
    np.testing.assert_allclose(reduced.natural_frequencies(), nearly[:3], rtol=1e-6)


def test_delta_star_lumps_inertia_by_the_compliance_rule():
    """Mass k goes to its neighbours in proportion to the *other* shaft's compliance."""
    j = [10.0, 6.0, 30.0]
    reduced = chain(j, [1e6, 3e6]).eliminate(1)
    e1, e2 = 1e-6, 1 / 3e6
    assert reduced.inertias == pytest.approx((10 + 6 * e2 / (e1 + e2), 30 + 6 * e1 / (e1 + e2)))
    assert sum(reduced.inertias) == pytest.approx(sum(j))


def test_delta_star_damping_equals_the_quasi_static_star():
    """With the eliminated node massless and driven by the springs (quasi-static), its
    speed is the compliance-weighted mean of its neighbours'; the star's three dampers then
    dissipate exactly w^T B' w of the reduced chain, for any neighbour speeds."""
    c1, c2 = 2e6, 5e6
    b1, bk, b2 = 300.0, 40.0, 700.0
    red = chain([10.0, 0.0, 20.0], [c1, c2], dampings=[0.0, bk, 0.0], links=[b1, b2]).eliminate(1)
    e1, e2 = 1 / c1, 1 / c2
    rng = np.random.default_rng(0)
    for w1, w2 in rng.normal(size=(5, 2)):
        wk = (e2 * w1 + e1 * w2) / (e1 + e2)
        star = b1 * (w1 - wk) ** 2 + bk * wk**2 + b2 * (wk - w2) ** 2
        w = np.array([w1, w2])
        assert w @ red.damping_matrix() @ w == pytest.approx(star, rel=1e-12)
    # the link part alone is the series Kelvin-Voigt pair's low-frequency limit
    no_ground = chain([10.0, 0.0, 20.0], [c1, c2], links=[b1, b2]).eliminate(1)
    assert no_ground.link_dampings[0] == pytest.approx(
        (b1 * e1**2 + b2 * e2**2) / (e1 + e2) ** 2, rel=1e-12
    )
    # an eliminated ground damper can make the link damping negative; the total stays >= 0
    strong = chain([10.0, 0.0, 20.0], [c1, c2], dampings=[0.0, 1e6, 0.0]).eliminate(1)
    assert strong.link_dampings[0] < 0.0
    assert np.linalg.eigvalsh(strong.damping_matrix()).min() > -1e-9


@pytest.mark.parametrize("keep", [2, 3])
def test_reduced_chain_keeps_the_lowest_frequencies(keep):
    """Small interior masses carry high frequencies: eliminating them leaves the low ones."""
    full = chain([400.0, 3.0, 10.0, 1.0, 1200.0], [7e6, 5e7, 2e7, 6e7])
    reduced = full.reduced(keep)
    assert reduced.n == keep
    f_full, f_red = full.natural_frequencies(), reduced.natural_frequencies()
    np.testing.assert_allclose(f_red[1:keep], f_full[1:keep], rtol=0.02)


def test_reduction_error_shrinks_with_the_eliminated_mass():
    """The lumping is first order in the eliminated inertia: 10x smaller, ~10x closer."""

    def error(j_mid):
        full = chain([400.0, j_mid, 1200.0], [7e6, 2e7])
        return abs(full.reduced(2).natural_frequencies()[1] / full.natural_frequencies()[1] - 1)

    assert error(15.0) < 0.2 * error(150.0)
    assert error(1.5) < 0.2 * error(15.0)


def test_default_drawworks_chain_reduces_to_two_masses():
    full, _ = parse_drive_train(default_drive_train())
    two = full.reduced(2)
    assert two.n == 2 and two.names == ("motor rotor", "drum")
    # the gearbox (150 of 1782 kg m^2) is not small: the 2-mass model is 5 % low
    assert two.natural_frequencies()[1] == pytest.approx(full.natural_frequencies()[1], rel=0.06)
    rigid = full.reduced(1)
    assert rigid.inertias[0] == pytest.approx(12 * 36 + 150 + 1200)
    assert rigid.dampings[0] == pytest.approx(2 * 36 + 20 + 50)


def test_input_impedance_two_mass_formula_and_linear_solve():
    c = chain([5.0, 20.0], [4e4], dampings=[1.0, 3.0], links=[12.0])
    for omega in (0.3, 10.0, 95.0, 400.0):
        z1 = c.mass_impedance(0, omega)
        z2 = c.mass_impedance(1, omega)
        z12 = c.link_impedance(0, omega)
        assert z1 == 5.0 * 1j * omega + 1.0 and z12 == 4e4 / (1j * omega) + 12.0
        paper_in = (z1 * z2 + z1 * z12 + z12 * z2) / (z2 + z12)
        paper_out = (z1 * z2 + z1 * z12 + z12 * z2) / (z1 + z12)
        assert c.input_impedance(omega) == pytest.approx(paper_in, rel=1e-12)
        assert c.output_impedance(omega) == pytest.approx(paper_out, rel=1e-12)
        assert 1 / c.input_impedance(omega) == pytest.approx(
            c.speeds_per_torque(omega)[0], rel=1e-10
        )


def test_n_mass_input_impedance_matches_the_linear_solve():
    c = chain(
        [12.0, 3.0, 150.0, 1200.0], [7e6, 5e7, 2e7], dampings=[2, 1, 20, 50], links=[60, 30, 3e3]
    )
    for omega in np.geomspace(0.1, 5e3, 15):
        assert 1 / c.input_impedance(omega) == pytest.approx(
            c.speeds_per_torque(omega)[0], rel=1e-9
        )


def test_elements_are_reduced_through_the_gear_ratio():
    motor = ChainElement("motor", 12.0, 2.0, 6.0)
    assert motor.reduced_value == 12.0 * 36 and motor.reduced_damping == 72.0
    c = DriveChain.from_elements(
        [motor, ChainElement("drum", 1200.0)], [ChainElement("coupling", 2e5, 60.0, 6.0)]
    )
    assert c.motor_ratio == 6.0 and c.stiffnesses == (7.2e6,)


def test_parse_lists_every_problem():
    chain_, problems = parse_drive_train(
        {
            "masses": [
                {"name": "motor", "inertia": -1.0, "ratio": 0.0},
                {"name": "drum", "inertia": 10.0, "ratio": 2.0},
            ],
            "shafts": [],
            "gear": 3,
        }
    )
    assert chain_ is None
    text = "\n".join(problems)
    for needle in (
        "unknown keys ['gear']",
        "'inertia' must be finite and > 0",
        "'ratio' must be finite and > 0",
        "need 1 shafts, got 0",
        "must have ratio 1",
    ):
        assert needle in text, needle
