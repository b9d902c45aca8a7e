"""Builders of the constant, ramp, sine and sea-state drivers from a scene table."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .protocol import Driver
from .sea_state import (
    _TWO_PI,
    SPECTRA,
    SeaStateDriver,
    jonswap_spectrum,
    pierson_moskowitz_spectrum,
)
from .simple import ConstantDriver, PiecewiseLinearDriver, SineDriver
from .spec_reading import _Context, _finite_slopes, _increasing, _Reader, _real, _show

_MAX_COMPONENTS = 20_000  # wave components a sea state may ask for (cost per call ~ n)


def _build_constant(r: _Reader, ctx: _Context) -> Driver:
    return ConstantDriver(r.number("value"))


_RAMP_SHORT = ("start_time", "end_time", "start_value", "end_value")


def _ramp_points(r: _Reader) -> tuple[np.ndarray, np.ndarray] | None:
    """Times and values of ``points`` (None after a problem)."""
    raw = r.spec["points"]
    ok_shape = isinstance(raw, list | tuple) and len(raw) >= 2
    rows = raw if ok_shape else []
    good = all(
        isinstance(p, list | tuple) and len(p) == 2 and all(_real(x) is not None for x in p)
        for p in rows
    )
    if not ok_shape or not good:
        r.add(
            "'points' must be a list of at least two [time (s), value] pairs of finite numbers, "
            f"got {_show(raw)}"
        )
        return None
    times = np.array([p[0] for p in rows], dtype=float)
    values = np.array([p[1] for p in rows], dtype=float)
    ok = _increasing(times, "'points' times", r) and _finite_slopes(times, values, "'points'", r)
    return (times, values) if ok else None


def _ramp_short(r: _Reader) -> tuple[np.ndarray, np.ndarray] | None:
    """Times and values of the short form (None after a problem)."""
    t0 = r.number("start_time", 0.0, unit="s")
    t1 = r.number("end_time", unit="s")
    v0, v1 = r.number("start_value"), r.number("end_value")
    if math.isfinite(t0) and math.isfinite(t1) and not t1 > t0:
        r.add(f"'end_time' ({t1:g} s) must be later than 'start_time' ({t0:g} s)")
        return None
    if not all(math.isfinite(x) for x in (t0, t1, v0, v1)):
        return None
    times, values = np.array([t0, t1]), np.array([v0, v1])
    return (times, values) if _finite_slopes(times, values, "the ramp", r) else None


def _build_ramp(r: _Reader, ctx: _Context) -> Driver | None:
    short = [k for k in _RAMP_SHORT if r.has(k)]
    if r.has("points") and short:
        r.add(f"give either 'points' or the short form, not both (also set: {', '.join(short)})")
        return None
    points = _ramp_points(r) if r.has("points") else _ramp_short(r)
    return None if points is None else PiecewiseLinearDriver(*points, source="ramp")


def _build_sine(r: _Reader, ctx: _Context) -> Driver | None:
    amplitude = r.number("amplitude")
    if r.has("period") and r.has("frequency"):
        r.add("give either 'period' (s) or 'frequency' (Hz), not both")
        omega = math.nan
    elif r.has("frequency"):
        omega = _TWO_PI * r.number("frequency", unit="Hz", positive=True)
    elif r.has("period"):
        omega = _TWO_PI / r.number("period", unit="s", positive=True)
    else:
        r.add("'period' (s) or 'frequency' (Hz) is required")
        omega = math.nan
    driver = SineDriver(
        amplitude,
        omega,
        math.radians(r.number("phase_deg", 0.0, unit="deg")),
        r.number("offset", 0.0),
        r.number("start_time", 0.0, unit="s"),
        r.number("ramp_time", 0.0, unit="s", minimum=0.0),
    )
    if r.problems:
        return None
    if not math.isfinite(omega):
        r.add("the angular frequency (from 'period' or 'frequency') is too large to represent")
    elif not (
        math.isfinite(amplitude * omega) and math.isfinite(abs(amplitude) + abs(driver.offset))
    ):
        r.add("'amplitude' is too large: the signal or its rate cannot be represented")
    return None if r.problems else driver


def _cutoff(r: _Reader) -> tuple[float, float]:
    raw = r.spec.get("cutoff", [0.5, 4.0])
    ok = (
        isinstance(raw, list | tuple)
        and len(raw) == 2
        and all(_real(x) is not None for x in raw)
        and 0.0 < raw[0] < 1.0 < raw[1]
    )
    if not ok:
        r.add(
            "'cutoff' must be [low, high] in multiples of the peak frequency with "
            f"0 < low < 1 < high, got {_show(raw)}"
        )
        return (0.5, 4.0)
    return (float(raw[0]), float(raw[1]))


def _spectrum(r: _Reader, hs: float, tp: float) -> Callable[[np.ndarray], np.ndarray]:
    """``S(omega)`` (m^2 s/rad) for significant height ``hs`` (m) and peak period ``tp`` (s)."""
    kind = r.choice("spectrum", "jonswap", SPECTRA)
    if kind == "pierson_moskowitz":
        if r.has("gamma") and r.spec["gamma"] != 1:
            r.add("'gamma' applies to spectrum 'jonswap' only (Pierson-Moskowitz is gamma = 1)")
        return lambda w: pierson_moskowitz_spectrum(w, hs, tp)
    gamma = r.number("gamma", 3.3)
    if math.isfinite(gamma) and not 1.0 <= gamma <= 7.0:
        r.add(
            f"'gamma' must be in [1, 7] (where A_gamma = 1 - 0.287 ln gamma normalises the "
            f"JONSWAP spectrum), got {gamma:g}"
        )
    return lambda w: jonswap_spectrum(w, hs, tp, gamma)


def _build_sea_state(r: _Reader, ctx: _Context) -> Driver | None:
    significant_height = r.number("significant_height", unit="m", minimum=0.0)
    peak_period = r.number("peak_period", unit="s", positive=True)
    spectrum = _spectrum(r, significant_height, peak_period)
    components = r.integer("components", 200, minimum=1, maximum=_MAX_COMPONENTS)
    seed = r.integer("seed", 0, minimum=0)
    cutoff = _cutoff(r)
    rao = r.number("heave_rao", 1.0)
    start = r.number("start_time", 0.0, unit="s")
    ramp = r.number("ramp_time", 0.0, unit="s", minimum=0.0)
    if r.problems:
        return None
    with np.errstate(all="ignore"):  # overflow is checked for below, not warned about
        try:
            driver = SeaStateDriver.from_spectrum(
                spectrum,
                peak_period,
                components=components,
                seed=seed,
                cutoff=cutoff,
                heave_rao=rao,
                start_time=start,
                ramp_time=ramp,
            )
        except (OverflowError, ZeroDivisionError, ValueError):  # Python floats raise
            driver = None
        if driver is not None:
            scale = abs(rao) * np.sum(driver.amplitudes * (1.0 + driver.angular_frequencies))
    if driver is None or not (np.all(np.isfinite(driver.amplitudes)) and np.isfinite(scale)):
        r.add(
            "'significant_height', 'peak_period' and 'heave_rao' give wave components too "
            "large to represent"
        )
        return None
    return driver
