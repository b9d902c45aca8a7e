"""Drivers against closed forms; the wave spectra against DNV-RP-C205 figures.

Times in s, heave in m, angular frequencies in rad/s. Rates are checked
against the closed-form derivative and, independently, against central
differences of the values.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from wire_fmu.master.drivers import (
    DRIVER_KINDS,
    Driver,
    PiecewiseLinearDriver,
    SeaStateDriver,
    jonswap_spectrum,
    make_driver,
    pierson_moskowitz_spectrum,
)
from wire_fmu.master.manipulators import DriverSet
from wire_fmu.master.scene import DriverSpec, VarRef

WHERE = "driver 3 (rope.mover_b.position)"
HS, TP = 4.0, 10.0  # m, s
OMEGA_P = 2.0 * math.pi / TP


def build(spec: dict, base_dir: Path = Path(".")) -> Driver:
    """A driver that must build without problems."""
    driver, problems = make_driver(spec, where=WHERE, base_dir=base_dir)
    assert problems == []
    assert isinstance(driver, Driver)
    return driver


def problems_of(spec: dict, base_dir: Path = Path(".")) -> list[str]:
    """The problems of a spec that must not build."""
    driver, problems = make_driver(spec, where=WHERE, base_dir=base_dir)
    assert driver is None
    assert problems and all(p.startswith(WHERE + ": ") for p in problems)
    return problems


def central_rate(driver: Driver, t: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Rate by central differences of the values, value unit per s."""
    return (driver.value(t + h) - driver.value(t - h)) / (2.0 * h)


def spectral_moment(spectrum, order: int) -> float:
    """``m_n = integral of omega^n S(omega)``, m^2 (rad/s)^n."""
    return quad(lambda w: w**order * spectrum(w), 1e-3, 60.0, points=[OMEGA_P], limit=400)[0]


# ------------------------------------------------------------------ registry


def test_registry_names_the_five_kinds():
    assert set(DRIVER_KINDS) == {"constant", "ramp", "sine", "sea_state", "table"}
    assert all(kind.summary and kind.keys for kind in DRIVER_KINDS.values())
    with pytest.raises(TypeError):
        DRIVER_KINDS["mine"] = DRIVER_KINDS["sine"]  # read-only


def test_constant():
    d = build({"kind": "constant", "value": 2.5})
    assert d.value(7.0) == 2.5 and d.rate(7.0) == 0.0
    assert isinstance(d.value(7.0), float)
    assert np.array_equal(d.value(np.array([0.0, 1.0])), [2.5, 2.5])


# ---------------------------------------------------------------------- ramp


def test_ramp_points_interpolate_and_hold():
    d = build({"kind": "ramp", "points": [[1.0, 0.0], [3.0, 4.0], [4.0, 1.0]]})
    t = np.array([0.0, 1.0, 2.0, 2.5, 3.0, 3.5, 4.0, 9.0])
    assert np.allclose(d.value(t), [0.0, 0.0, 2.0, 3.0, 4.0, 2.5, 1.0, 1.0])
    # right-continuous slope: at a breakpoint, the segment that starts there
    assert np.allclose(d.rate(t), [0.0, 2.0, 2.0, 2.0, -3.0, -3.0, 0.0, 0.0])
    inside = np.array([1.5, 2.5, 3.25, 3.75])
    assert np.allclose(central_rate(d, inside), d.rate(inside))


def test_ramp_short_form_equals_points():
    short = build(
        {"kind": "ramp", "start_time": 2.0, "end_time": 6.0, "start_value": -1.0, "end_value": 3.0}
    )
    points = build({"kind": "ramp", "points": [[2.0, -1.0], [6.0, 3.0]]})
    t = np.linspace(0.0, 8.0, 81)
    assert np.array_equal(short.value(t), points.value(t))
    assert short.rate(4.0) == pytest.approx(1.0)
    assert build({"kind": "ramp", "end_time": 2.0, "start_value": 0.0, "end_value": 1.0}).value(
        1.0
    ) == pytest.approx(0.5)  # start_time 0


def test_ramp_problems():
    problems = problems_of({"kind": "ramp", "points": [[0, 0], [2, 1], [1, 3]]})
    assert "strictly increasing" in problems[0] and "t = 1 s" in problems[0]
    assert (
        "not both" in problems_of({"kind": "ramp", "points": [[0, 0], [1, 1]], "end_value": 2})[0]
    )
    assert "pairs" in problems_of({"kind": "ramp", "points": [[0, 0]]})[0]
    assert (
        "later than"
        in problems_of(
            {"kind": "ramp", "start_time": 3, "end_time": 1, "start_value": 0, "end_value": 1}
        )[0]
    )


# ---------------------------------------------------------------------- sine


def test_sine_value_and_rate_match_closed_form():
    a, period, phase_deg, offset = 0.7, 4.0, 30.0, 1.5
    d = build(
        {"kind": "sine", "amplitude": a, "period": period, "phase_deg": phase_deg, "offset": offset}
    )
    omega, phase = 2.0 * math.pi / period, math.radians(phase_deg)
    t = np.linspace(0.1, 10.0, 37)
    assert np.allclose(d.value(t), offset + a * np.sin(omega * t + phase), atol=1e-14)
    assert np.allclose(d.rate(t), a * omega * np.cos(omega * t + phase), atol=1e-14)
    assert np.allclose(central_rate(d, t), d.rate(t), atol=1e-7)
    by_frequency = build(
        {
            "kind": "sine",
            "amplitude": a,
            "frequency": 1.0 / period,
            "phase_deg": phase_deg,
            "offset": offset,
        }
    )
    assert np.allclose(by_frequency.value(t), d.value(t), atol=1e-14)


def test_sine_fade_in_starts_at_zero_with_zero_rate():
    start, ramp = 2.0, 5.0
    d = build(
        {
            "kind": "sine",
            "amplitude": 1.0,
            "period": 3.0,
            "phase_deg": 90.0,
            "start_time": start,
            "ramp_time": ramp,
        }
    )
    assert d.value(start) == 0.0 and d.rate(start) == 0.0  # phase 90: sin part is 1 here
    assert d.value(0.0) == 0.0 and d.rate(0.0) == 0.0
    t = np.linspace(start + 0.01, start + 3 * ramp, 200)
    assert np.allclose(central_rate(d, t), d.rate(t), atol=1e-6)
    after = t[t > start + ramp]
    omega = 2.0 * math.pi / 3.0
    assert np.allclose(d.value(after), np.cos(omega * (after - start)), atol=1e-14)
    # near the start, the signal grows like tau^2: value / tau stays bounded -> rate 0
    tau = 1e-3
    assert abs(d.value(start + tau)) < 1e-5 and abs(d.rate(start + tau)) < 1e-2


def test_sine_problems_all_at_once():
    problems = problems_of(
        {"kind": "sine", "amplitud": 1.0, "period": -2.0, "ramp_time": -1.0, "phase_deg": "ninety"}
    )
    text = "\n".join(problems)
    assert len(problems) == 5
    assert "unknown key 'amplitud'" in text and "did you mean 'amplitude'" in text
    assert "'amplitude' is required" in text
    assert "'period' must be > 0 s, got -2.0" in text
    assert "'ramp_time' must be >= 0" in text
    assert "'phase_deg' must be a finite number in deg" in text
    assert (
        "not both" in problems_of({"kind": "sine", "amplitude": 1, "period": 1, "frequency": 1})[0]
    )
    assert "is required" in problems_of({"kind": "sine", "amplitude": 1})[0]
    assert (
        "'period' must be > 0 s, got 0"
        in problems_of({"kind": "sine", "amplitude": 1, "period": 0})[0]
    )


# ----------------------------------------------------------------- sea state


def test_pierson_moskowitz_zeroth_moment_and_peak():
    def pm(w):
        return pierson_moskowitz_spectrum(w, HS, TP)

    assert spectral_moment(pm, 0) == pytest.approx(HS**2 / 16.0, rel=1e-6)
    omega = np.linspace(0.2, 2.0, 180001)
    assert omega[np.argmax(pm(omega))] == pytest.approx(OMEGA_P, abs=1e-4)


@pytest.mark.parametrize("gamma", [1.0, 2.0, 3.3, 5.0])
def test_jonswap_zeroth_moment_peak_and_zero_crossing_period(gamma):
    """m0 = Hs^2/16 (A_gamma normalisation, within 0.3 %); peak at Tp; Tz from DNV-RP-C205."""

    def js(w):
        return jonswap_spectrum(w, HS, TP, gamma)

    m0, m2 = spectral_moment(js, 0), spectral_moment(js, 2)
    assert m0 == pytest.approx(HS**2 / 16.0, rel=3e-3)
    omega = np.linspace(0.2, 2.0, 180001)
    assert omega[np.argmax(js(omega))] == pytest.approx(OMEGA_P, abs=1e-4)
    # DNV-RP-C205 eq. 3.5.5: Tz / Tp = 0.6673 + 0.05037 g - 0.006230 g^2 + 0.0003341 g^3 (a fit)
    tz_dnv = TP * (0.6673 + 0.05037 * gamma - 0.006230 * gamma**2 + 0.0003341 * gamma**3)
    assert 2.0 * math.pi * math.sqrt(m0 / m2) == pytest.approx(tz_dnv, rel=3e-3)


def test_pierson_moskowitz_is_jonswap_with_gamma_one():
    omega = np.linspace(0.05, 5.0, 1000)
    assert np.allclose(
        jonswap_spectrum(omega, HS, TP, 1.0),
        pierson_moskowitz_spectrum(omega, HS, TP),
        rtol=1e-14,
        atol=0.0,
    )
    pm = build(
        {
            "kind": "sea_state",
            "significant_height": HS,
            "peak_period": TP,
            "spectrum": "pierson_moskowitz",
            "seed": 3,
        }
    )
    js = build(
        {"kind": "sea_state", "significant_height": HS, "peak_period": TP, "gamma": 1.0, "seed": 3}
    )
    t = np.linspace(0.0, 100.0, 101)
    assert np.allclose(pm.value(t), js.value(t), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sea_state_record_has_standard_deviation_hs_over_four(seed):
    """Over a three-hour record the heave's standard deviation is sqrt(m0) = Hs/4.

    The components' variance sum a_i^2 / 2 matches m0 to the band cut-off
    (0.3 % of m0 lost above 4 omega_p) and the random bin offsets; a finite
    record adds beating between neighbouring components of a few 0.1 %.
    """
    d = build({"kind": "sea_state", "significant_height": HS, "peak_period": TP, "seed": seed})
    assert isinstance(d, SeaStateDriver) and len(d.amplitudes) == 200
    assert math.sqrt(d.variance) == pytest.approx(HS / 4.0, rel=0.01)
    t = np.arange(0.0, 3 * 3600.0, 0.25)
    heave = d.value(t)
    assert abs(np.mean(heave)) < 0.02 * HS / 4.0
    assert np.std(heave) == pytest.approx(HS / 4.0, rel=0.02)
    # heave velocity: sqrt(m2) of the spectrum over the simulated band [0.5, 4] omega_p
    m2_band = quad(
        lambda w: w**2 * jonswap_spectrum(w, HS, TP), 0.5 * OMEGA_P, 4.0 * OMEGA_P, points=[OMEGA_P]
    )[0]
    assert np.std(d.rate(t)) == pytest.approx(math.sqrt(m2_band), rel=0.02)


def test_sea_state_rate_is_derivative_and_fade_in_starts_at_rest():
    d = build(
        {
            "kind": "sea_state",
            "significant_height": HS,
            "peak_period": TP,
            "ramp_time": 30.0,
            "heave_rao": 0.8,
            "start_time": 5.0,
        }
    )
    assert d.value(5.0) == 0.0 and d.rate(5.0) == 0.0 and d.value(0.0) == 0.0
    t = np.linspace(5.5, 120.0, 300)
    assert np.allclose(central_rate(d, t), d.rate(t), atol=1e-7)
    plain = build(
        {"kind": "sea_state", "significant_height": HS, "peak_period": TP, "start_time": 5.0}
    )
    late = np.array([40.0, 77.7])
    assert np.allclose(d.value(late), 0.8 * plain.value(late), rtol=1e-14)
    assert np.allclose(d.value(t), [d.value(float(x)) for x in t], rtol=1e-12, atol=1e-14)


def test_sea_state_values_at_are_its_values_to_the_last_bit():
    """``values_at`` evaluates many times in one vectorised call (the master asks for the
    ends of the next steps at once): each number is the one ``value`` gives, bit for bit,
    through the fade-in and after it."""
    d = build(
        {
            "kind": "sea_state",
            "significant_height": HS,
            "peak_period": TP,
            "ramp_time": 3.0,
            "start_time": 0.5,
            "heave_rao": 0.9,
        }
    )
    times = [n / 1e9 for n in range(0, 20_000_000_000, 37 * 2_000_000)] + [0.25, 123.456]
    assert d.values_at(times) == [d.value(t) for t in times]


def test_driver_set_step_values_are_its_values():
    """The per-step list of a driver set (each value computed once, a sea state's for the
    next steps at once) holds the very numbers of ``values``: the position at the step's
    start, the mean rate over it, a plain input at its midpoint; also across a shortened
    step, where the values computed ahead do not apply."""
    sea = {"kind": "sea_state", "significant_height": HS, "peak_period": TP, "ramp_time": 2.0}
    specs = (
        DriverSpec(VarRef("rope", "mover_b.position"), sea, VarRef("rope", "mover_b.velocity")),
        DriverSpec(VarRef("rope", "command"), sea),
        DriverSpec(VarRef("winch", "lever"), {"kind": "ramp", "points": [[0, 0], [1, 3]]}),
    )
    drivers, reference = DriverSet(specs, Path(".")), DriverSet(specs, Path("."))
    ends = [2_000_000 * k for k in range(1, 200)] + [398_500_000, 400_000_000, 402_000_000]
    start = 0
    for end in sorted(ends):
        t = start / 1e9
        h = end / 1e9 - t
        for unit in ("rope", "winch"):
            expected = reference.values(unit, t, h)
            assert drivers.targets(unit) == list(expected)
            assert drivers.step_values(unit, t, h) == list(expected.values())
        start = end


def test_sea_state_is_reproducible_with_a_seed():
    spec = {"kind": "sea_state", "significant_height": HS, "peak_period": TP, "seed": 42}
    t = np.linspace(0.0, 600.0, 601)
    a, b = build(spec), build(dict(spec))
    assert np.array_equal(a.value(t), b.value(t))
    other = build({**spec, "seed": 43})
    assert not np.allclose(other.value(t), a.value(t))


def test_sea_state_frequencies_are_offset_inside_their_bins():
    d = build(
        {
            "kind": "sea_state",
            "significant_height": HS,
            "peak_period": TP,
            "components": 50,
            "cutoff": [0.5, 3.0],
        }
    )
    edges = np.linspace(0.5 * OMEGA_P, 3.0 * OMEGA_P, 51)
    w = d.angular_frequencies
    assert np.all((w > edges[:-1]) & (w < edges[1:]))
    spacing = np.diff(w)
    assert np.std(spacing) > 0.1 * np.mean(spacing)  # not equally spaced: no repeat period


def test_sea_state_problems_all_at_once():
    problems = problems_of(
        {
            "kind": "sea_state",
            "significant_height": "4",
            "peak_period": 0,
            "gamma": 9,
            "cutoff": [2, 1],
            "components": 2.5,
            "spectrum": "jonswapp",
            "seed": -1,
        }
    )
    text = "\n".join(problems)
    assert len(problems) == 7, text
    for part in (
        "'significant_height' must be a finite number in m",
        "'peak_period' must be > 0",
        "did you mean 'jonswap'",
        "'gamma' must be in [1, 7]",
        "'cutoff'",
        "'components' must be an integer",
        "'seed' must be an integer >= 0",
    ):
        assert part in text
    assert (
        "'components' must be an integer <= 20000"
        in problems_of(
            {"kind": "sea_state", "significant_height": 1, "peak_period": 8, "components": 10**6}
        )[0]
    )
    assert (
        "'gamma' applies to spectrum 'jonswap' only"
        in problems_of(
            {
                "kind": "sea_state",
                "significant_height": 1,
                "peak_period": 8,
                "spectrum": "pierson_moskowitz",
                "gamma": 3.3,
            }
        )[0]
    )


# --------------------------------------------------------------------- table


def write_csv(folder: Path, text: str, name: str = "heave.csv") -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def test_table_interpolates_relative_to_the_scene_folder(tmp_path):
    write_csv(tmp_path, "# vessel heave\ntime, heave , other\n0, 0.0, 9\n2, 1.0, 9\n3, -0.5, 9\n\n")
    d = build({"kind": "table", "file": "heave.csv", "value_column": "heave"}, tmp_path)
    assert isinstance(d, PiecewiseLinearDriver)
    t = np.array([-1.0, 0.0, 1.0, 2.5, 3.0, 10.0])
    assert np.allclose(d.value(t), [0.0, 0.0, 0.5, 0.25, -0.5, -0.5])
    assert np.allclose(d.rate(t), [0.0, 0.5, 0.5, -1.5, 0.0, 0.0])
    assert np.allclose(central_rate(d, np.array([0.7, 2.2])), [0.5, -1.5])


def test_table_problems(tmp_path):
    assert (
        "cannot read table file" in problems_of({"kind": "table", "file": "nope.csv"}, tmp_path)[0]
    )
    write_csv(tmp_path, "t,heave\n0,1\n1,2\n")
    problems = problems_of({"kind": "table", "file": "heave.csv"}, tmp_path)
    assert len(problems) == 2
    assert "no column 'time'" in problems[0] and "columns: t, heave" in problems[0]
    assert "no column 'value'" in problems[1]
    write_csv(tmp_path, "time,value\n0,1\n2,x\n1,3\n")
    assert (
        "'value' is not a finite number in data row 2 ('x')"
        in problems_of({"kind": "table", "file": "heave.csv"}, tmp_path)[0]
    )
    write_csv(tmp_path, "time,value\n0,1\n2,2\n1,3\n")
    problems = problems_of({"kind": "table", "file": "heave.csv"}, tmp_path)
    assert "column 'time' must be strictly increasing" in problems[0]


# ------------------------------------------------------------ error reporting


def test_unknown_kind_names_the_known_kinds_and_a_close_match():
    (problem,) = problems_of({"kind": "sine_wave", "amplitude": 1})
    assert problem == (
        f"{WHERE}: unknown kind 'sine_wave' (did you mean 'sine'?); known kinds: "
        "constant, ramp, sea_state, sine, table"
    )
    assert "'kind' is required" in problems_of({"amplitude": 1})[0]
    assert "a driver must be a table" in problems_of(["sine"])[0]  # type: ignore[arg-type]
    assert "unknown kind [1]" in problems_of({"kind": [1]})[0]


def test_caller_keys_can_be_ignored():
    spec = {"kind": "constant", "value": 1.0, "target": "rope.mover_b.position"}
    assert "unknown key 'target'" in problems_of(spec)[0]
    driver, problems = make_driver(spec, where=WHERE, base_dir=Path("."), ignore={"target"})
    assert problems == [] and driver.value(0.0) == 1.0
