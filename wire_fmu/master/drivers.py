"""Drivers: time signals a scene applies to unit inputs.

A driver gives a value and its time derivative, so that a (position,
velocity) pair of inputs is driven consistently: vessel heave drives
``mover_b.position`` with :meth:`Driver.value` and ``mover_b.velocity`` with
:meth:`Driver.rate`. Values are in the unit of the input they drive (the
driver itself is unit-agnostic), times in s, rates in that unit per second.

A scene describes a driver as a plain TOML table whose ``kind`` selects one
entry of :data:`DRIVER_KINDS`; :func:`make_driver` checks the table and
builds the driver, or lists every problem with it at once.

=============  ==============================================================
kind           keys (defaults)
=============  ==============================================================
``constant``   ``value``
``ramp``       ``points = [[t0, v0], [t1, v1], ...]`` (times strictly
               increasing), or the short form ``start_time`` (0),
               ``end_time``, ``start_value``, ``end_value``
``sine``       ``amplitude``; ``period`` (s) or ``frequency`` (Hz);
               ``phase_deg`` (0), ``offset`` (0), ``start_time`` (0),
               ``ramp_time`` (0)
``sea_state``  ``significant_height`` (m), ``peak_period`` (s);
               ``spectrum`` ("jonswap" or "pierson_moskowitz"), ``gamma``
               (3.3), ``components`` (200), ``seed`` (0), ``cutoff``
               ([0.5, 4.0] times the peak frequency), ``start_time`` (0),
               ``ramp_time`` (0), ``heave_rao`` (1)
``table``      ``file`` (CSV, relative to the scene's folder),
               ``time_column`` ("time"), ``value_column`` ("value")
=============  ==============================================================

Conventions
-----------
* Piecewise linear drivers (``ramp``, ``table``) hold their first value
  before the first point and their last value after the last one (rate 0
  there). Between points the rate is the slope of the segment that starts at
  or before ``t`` (right-continuous: at a breakpoint the rate is that of the
  segment that begins there, which is what a master evaluating at the start
  of a step wants).
* ``sine``: ``offset + amplitude * sin(2 pi (t - start_time) / period +
  phase)`` for ``t >= start_time``, ``offset`` before.
* Fade-in (``ramp_time`` > 0, ``sine`` and ``sea_state``): the oscillating
  part is multiplied by ``w = (1 - cos(pi (t - start_time) / ramp_time)) / 2``
  over ``ramp_time``, so it and its rate both start at exactly zero: a scene
  that starts in static equilibrium has no start-up transient.
* ``sea_state``: see :class:`SeaStateDriver` and :func:`jonswap_spectrum`.
  The default band [0.5, 4] omega_p loses about 0.3-0.5 % of m0 (the tail
  above 4 omega_p); a constant ``heave_rao`` scales the wave elevation to
  vessel heave.
* ``table``: a comma-separated UTF-8 text file (a regular file of at most
  :data:`MAX_TABLE_BYTES`) with a header row naming the columns (names are
  stripped of spaces; a UTF-8 byte-order mark is ignored), then at least
  two data rows; blank lines and lines starting with ``#`` are skipped; the
  time column must be strictly increasing. A file that is not such a table
  is reported without quoting it (the first line of a file pointed at by
  mistake may be a secret): the column names are listed only when the rows
  under them are all numbers, and a bad cell is quoted only if it is short.
* Every number must be finite and so must what the driver computes from it
  (slopes, angular frequencies, wave amplitudes); values quoted in problems
  are shortened, so a huge array in a scene gives a short message.

Every driver's :meth:`~Driver.value` and :meth:`~Driver.rate` also accept an
array of times (s) and then return an array; a float gives a float.
"""

from __future__ import annotations

import csv
import difflib
import io
import logging
import math
import os
import re
import stat
from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "Driver",
    "DriverKind",
    "DRIVER_KINDS",
    "make_driver",
    "ConstantDriver",
    "PiecewiseLinearDriver",
    "SineDriver",
    "SeaStateDriver",
    "pierson_moskowitz_spectrum",
    "jonswap_spectrum",
    "SPECTRA",
    "MAX_TABLE_BYTES",
]

logger = logging.getLogger(__name__)

_TWO_PI = 2.0 * math.pi
_CHUNK = 4096  # rows of (time x component) evaluated at once for long time arrays
_MAX_COMPONENTS = 20_000  # wave components a sea state may ask for (cost per call ~ n)
_MAX_REPORTED_ROWS = 5  # bad CSV rows reported one by one, the rest counted
_SHOWN = 60  # characters of a spec value quoted in a problem
_MAX_HINT_WORD = 100  # longer words get no "did you mean" (difflib is quadratic)
_MAX_CELL_SHOWN = 20  # a bad CSV cell longer than this is described, not quoted
_MAX_HEADER_SHOWN = (2, 50, 32)  # column names listed: min and max count, max length
_COLUMN_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_ .()\[\]/%-]*")  # a name we may quote
MAX_TABLE_BYTES = 64 << 20
"""Largest CSV file a ``table`` driver reads, bytes (64 MiB, about two million rows)."""


# ----------------------------------------------------------------------- protocol


@runtime_checkable
class Driver(Protocol):
    """A time signal with its derivative.

    Both methods accept a float time (s) and return a float; they also
    accept an array of times and return an array of the same shape.
    """

    def value(self, t: float) -> float:
        """Signal at time ``t`` (s), in the driven input's unit."""
        ...

    def rate(self, t: float) -> float:
        """Time derivative of :meth:`value` at ``t``, input unit per s."""
        ...


def _out(x: Any, t: Any) -> Any:
    """A float for a scalar time, else the array."""
    return float(x) if np.ndim(t) == 0 else np.asarray(x, dtype=float)


def _fade(t: ArrayLike, start: float, ramp_time: float) -> tuple[Any, Any]:
    """Cosine fade-in weight and its rate at ``t`` (s); 0 before ``start``, 1 after the ramp.

    Returns
    -------
    weight : float or ndarray
        ``(1 - cos(pi tau / ramp_time)) / 2`` with ``tau = t - start``, 1.
    weight_rate : float or ndarray
        Its derivative, 1/s.
    """
    if np.ndim(t) == 0:
        return _fade_scalar(float(t) - start, ramp_time)
    tau = np.asarray(t, dtype=float) - start
    if ramp_time <= 0.0:
        return np.where(tau >= 0.0, 1.0, 0.0), np.zeros_like(tau)
    x = np.clip(tau / ramp_time, 0.0, 1.0)
    inside = (tau > 0.0) & (tau < ramp_time)
    weight = 0.5 * (1.0 - np.cos(math.pi * x))
    weight_rate = np.where(inside, 0.5 * math.pi / ramp_time * np.sin(math.pi * x), 0.0)
    return weight, weight_rate


def _fade_scalar(tau: float, ramp_time: float) -> tuple[float, float]:
    """:func:`_fade` for one time, ``tau = t - start`` (s), with ``math`` (called every step)."""
    if tau <= 0.0:
        return (1.0, 0.0) if tau == 0.0 and ramp_time <= 0.0 else (0.0, 0.0)
    if tau >= ramp_time:
        return 1.0, 0.0
    x = math.pi * tau / ramp_time
    return 0.5 * (1.0 - math.cos(x)), 0.5 * math.pi / ramp_time * math.sin(x)


# ------------------------------------------------------------------------ drivers


@dataclass(frozen=True)
class ConstantDriver:
    """A constant.

    Parameters
    ----------
    constant : float
        The value, in the driven input's unit.
    """

    constant: float

    def value(self, t: float) -> float:
        """The constant (input unit)."""
        return _out(np.full(np.shape(t), self.constant), t)

    def rate(self, t: float) -> float:
        """Zero (input unit per s)."""
        return _out(np.zeros(np.shape(t)), t)


@dataclass(frozen=True, eq=False)
class PiecewiseLinearDriver:
    """Linear interpolation through points, held constant outside them.

    Parameters
    ----------
    times : ndarray, shape (n,)
        Strictly increasing times, s (n >= 2).
    values : ndarray, shape (n,)
        Values at those times, input unit.
    source : str
        Where the points came from (for messages and logs).

    Attributes
    ----------
    slopes : ndarray, shape (n - 1,)
        Slope of each segment, input unit per s.
    """

    times: np.ndarray
    values: np.ndarray
    source: str = "points"
    slopes: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        """Store read-only float copies of the points and the segment slopes."""
        for name in ("times", "values"):
            arr = np.array(getattr(self, name), dtype=float)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        slopes = np.diff(self.values) / np.diff(self.times)
        slopes.flags.writeable = False
        object.__setattr__(self, "slopes", slopes)

    def value(self, t: float) -> float:
        """Interpolated value at ``t`` (s), input unit."""
        return _out(np.interp(t, self.times, self.values), t)

    def rate(self, t: float) -> float:
        """Slope of the segment starting at or before ``t``; 0 outside, input unit per s."""
        slopes = self.slopes
        k = np.searchsorted(self.times, t, side="right") - 1
        inside = (k >= 0) & (k < len(slopes))
        return _out(np.where(inside, slopes[np.clip(k, 0, len(slopes) - 1)], 0.0), t)


@dataclass(frozen=True)
class SineDriver:
    """``offset + w(t) * amplitude * sin(omega (t - start_time) + phase)``.

    Parameters
    ----------
    amplitude : float
        Input unit.
    angular_frequency : float
        ``omega``, rad/s (> 0).
    phase : float
        rad, at ``start_time``.
    offset : float
        Input unit; the value before ``start_time``.
    start_time : float
        s; the oscillation is zero before it.
    ramp_time : float
        Cosine fade-in duration ``w`` from ``start_time``, s (0: none).
    """

    amplitude: float
    angular_frequency: float
    phase: float = 0.0
    offset: float = 0.0
    start_time: float = 0.0
    ramp_time: float = 0.0

    def _parts(self, t: ArrayLike) -> tuple[np.ndarray, ...]:
        weight, weight_rate = _fade(t, self.start_time, self.ramp_time)
        arg = self.angular_frequency * (np.asarray(t, dtype=float) - self.start_time) + self.phase
        return weight, weight_rate, self.amplitude * np.sin(arg), arg

    def value(self, t: float) -> float:
        """Signal at ``t`` (s), input unit."""
        weight, _, wave, _ = self._parts(t)
        return _out(self.offset + weight * wave, t)

    def rate(self, t: float) -> float:
        """Time derivative at ``t``, input unit per s."""
        weight, weight_rate, wave, arg = self._parts(t)
        wave_rate = self.amplitude * self.angular_frequency * np.cos(arg)
        return _out(weight_rate * wave + weight * wave_rate, t)


@dataclass(frozen=True, eq=False)
class SeaStateDriver:
    """Irregular vessel heave as a sum of harmonic wave components.

    ``value(t) = rao * w(t) * sum_i a_i cos(omega_i (t - start_time) + phi_i)``,
    with ``a_i = sqrt(2 S(omega_i) d_omega)`` so that the variance of the
    signal is ``sum a_i^2 / 2``, approximately the spectrum's zeroth moment
    ``m0 = Hs^2 / 16``. Build one with :meth:`from_spectrum`.

    Parameters
    ----------
    amplitudes : ndarray, shape (n,)
        ``a_i``, m.
    angular_frequencies : ndarray, shape (n,)
        ``omega_i``, rad/s.
    phases : ndarray, shape (n,)
        ``phi_i``, rad.
    heave_rao : float
        Constant heave response factor, 1.
    start_time : float
        s; the signal is zero before it.
    ramp_time : float
        Cosine fade-in duration ``w`` from ``start_time``, s (0: none).
    """

    amplitudes: np.ndarray
    angular_frequencies: np.ndarray
    phases: np.ndarray
    heave_rao: float = 1.0
    start_time: float = 0.0
    ramp_time: float = 0.0

    def __post_init__(self) -> None:
        """Store read-only float copies of the component arrays."""
        for name in ("amplitudes", "angular_frequencies", "phases"):
            arr = np.array(getattr(self, name), dtype=float)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)

    @classmethod
    def from_spectrum(
        cls,
        spectrum: Callable[[np.ndarray], np.ndarray],
        peak_period: float,
        *,
        components: int = 200,
        seed: int = 0,
        cutoff: tuple[float, float] = (0.5, 4.0),
        heave_rao: float = 1.0,
        start_time: float = 0.0,
        ramp_time: float = 0.0,
    ) -> SeaStateDriver:
        """Discretise a wave spectrum into random-phase components.

        The band ``[cutoff[0], cutoff[1]] * omega_p`` (``omega_p = 2 pi /
        peak_period``) is cut into ``components`` equal bins of width
        ``d_omega``. Each component's frequency is drawn uniformly inside its
        bin (not at the bin centre), so the record does not repeat after
        ``2 pi / d_omega`` as it would with equally spaced frequencies; its
        amplitude is ``sqrt(2 S(omega_i) d_omega)`` and its phase is uniform
        in [0, 2 pi). Random numbers come from
        ``numpy.random.default_rng(seed)``: first the ``components`` offsets
        in the bins, then the ``components`` phases, so a seed reproduces the
        record exactly.

        Parameters
        ----------
        spectrum : callable
            ``S(omega)``, m^2 s/rad, vectorised over omega (rad/s).
        peak_period : float
            Tp, s.
        components : int
            Number of harmonic components.
        seed : int
            Seed of the random generator.
        cutoff : (float, float)
            Frequency band in multiples of the peak frequency.
        heave_rao : float
            Constant heave response factor, 1.
        start_time, ramp_time : float
            Start and cosine fade-in duration, s.

        Returns
        -------
        SeaStateDriver
        """
        rng = np.random.default_rng(seed)
        omega_p = _TWO_PI / peak_period
        low, high = cutoff[0] * omega_p, cutoff[1] * omega_p
        d_omega = (high - low) / components
        omegas = low + (np.arange(components) + rng.random(components)) * d_omega
        phases = rng.uniform(0.0, _TWO_PI, components)
        amplitudes = np.sqrt(2.0 * spectrum(omegas) * d_omega)
        return cls(amplitudes, omegas, phases, heave_rao, start_time, ramp_time)

    @property
    def variance(self) -> float:
        """Long-run variance of the faded-in signal, ``rao^2 sum a_i^2 / 2``, m^2."""
        return float(self.heave_rao**2 * 0.5 * np.sum(self.amplitudes**2))

    def _sum(self, t: ArrayLike, trig: Callable, coefficients: np.ndarray) -> Any:
        """``sum_i c_i trig(omega_i (t - start_time) + phi_i)`` at ``t`` (s)."""
        if np.ndim(t) == 0:
            arg = self.angular_frequencies * (float(t) - self.start_time) + self.phases
            return float(trig(arg) @ coefficients)
        tau = np.asarray(t, dtype=float) - self.start_time
        flat = tau.reshape(-1)
        out = np.empty_like(flat)
        for i in range(0, flat.size, _CHUNK):
            rows = slice(i, i + _CHUNK)
            arg = np.multiply.outer(flat[rows], self.angular_frequencies) + self.phases
            out[rows] = trig(arg) @ coefficients
        return out.reshape(tau.shape)

    def value(self, t: float) -> float:
        """Heave at ``t`` (s), m."""
        weight, _ = _fade(t, self.start_time, self.ramp_time)
        wave = self._sum(t, np.cos, self.amplitudes)
        return _out(self.heave_rao * weight * wave, t)

    def rate(self, t: float) -> float:
        """Heave velocity at ``t`` (s), m/s."""
        weight, weight_rate = _fade(t, self.start_time, self.ramp_time)
        wave_rate = -self._sum(t, np.sin, self.amplitudes * self.angular_frequencies)
        rate = weight * wave_rate
        if np.any(weight_rate != 0.0):  # only while fading in
            rate = rate + weight_rate * self._sum(t, np.cos, self.amplitudes)
        return _out(self.heave_rao * rate, t)


# ------------------------------------------------------------------------ spectra


def pierson_moskowitz_spectrum(
    omega: ArrayLike, significant_height: float, peak_period: float
) -> np.ndarray:
    """Pierson-Moskowitz wave spectrum (DNV-RP-C205 sec. 3.5.5, DNV-RP-H103).

    ``S(omega) = 5/16 Hs^2 omega_p^4 omega^-5 exp(-5/4 (omega / omega_p)^-4)``,
    ``omega_p = 2 pi / Tp``; its zeroth moment is exactly ``Hs^2 / 16``.

    Parameters
    ----------
    omega : array_like
        Angular frequency, rad/s (> 0).
    significant_height : float
        Hs, m.
    peak_period : float
        Tp, s.

    Returns
    -------
    ndarray
        Spectral density, m^2 s/rad.
    """
    w = np.asarray(omega, dtype=float)
    wp = _TWO_PI / peak_period
    ratio = w / wp
    return 5.0 / 16.0 * significant_height**2 * wp**4 * w**-5.0 * np.exp(-1.25 * ratio**-4.0)


def jonswap_spectrum(
    omega: ArrayLike, significant_height: float, peak_period: float, gamma: float = 3.3
) -> np.ndarray:
    """JONSWAP wave spectrum in the DNV-RP-C205 (sec. 3.5.5) / DNV-RP-H103 form.

    ``S_J = A_gamma S_PM(omega) gamma^exp(-(omega - omega_p)^2 / (2 sigma^2 omega_p^2))``
    with the normalising factor ``A_gamma = 1 - 0.287 ln(gamma)`` and
    ``sigma = 0.07`` for ``omega <= omega_p``, ``0.09`` above. ``gamma = 1``
    gives Pierson-Moskowitz. ``A_gamma`` is an approximation: the zeroth
    moment is ``Hs^2 / 16`` within about 0.3 % for ``gamma`` in [1, 5] and
    within 2 % up to ``gamma = 7``.

    Parameters
    ----------
    omega : array_like
        Angular frequency, rad/s (> 0).
    significant_height : float
        Hs, m.
    peak_period : float
        Tp, s.
    gamma : float
        Peak enhancement factor, 1 (DNV: 1 to 7).

    Returns
    -------
    ndarray
        Spectral density, m^2 s/rad.
    """
    w = np.asarray(omega, dtype=float)
    wp = _TWO_PI / peak_period
    sigma = np.where(w <= wp, 0.07, 0.09)
    peak = gamma ** np.exp(-0.5 * ((w - wp) / (sigma * wp)) ** 2)
    pm = 5.0 / 16.0 * significant_height**2 * wp**4 * w**-5.0 * np.exp(-1.25 * (w / wp) ** -4.0)
    return (1.0 - 0.287 * math.log(gamma)) * pm * peak


SPECTRA: Mapping[str, str] = MappingProxyType(
    {"jonswap": "JONSWAP (DNV-RP-C205)", "pierson_moskowitz": "Pierson-Moskowitz"}
)
"""Wave spectra a ``sea_state`` driver knows, name -> description."""


# ------------------------------------------------------------------ spec reading


def _close_hint(word: str, choices: Collection[str]) -> str:
    if len(word) > _MAX_HINT_WORD:
        return ""
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def _real(x: Any) -> float | None:
    """``x`` as a finite float; None if it is no finite number (or an int too large)."""
    if not _is_number(x):
        return None
    try:
        value = float(x)
    except OverflowError:
        return None
    return value if math.isfinite(value) else None


def _show(value: Any) -> str:
    """``repr(value)`` for a problem, shortened (a spec may hold a huge array)."""
    if isinstance(value, str) and len(value) > 10_000:
        return f"a text of {len(value)} characters"
    if isinstance(value, list | tuple | dict) and len(value) > 10_000:
        return f"a {type(value).__name__} of {len(value)} items"
    text = repr(value)
    return text if len(text) <= _SHOWN else f"{text[: _SHOWN - 5]} ..."


class _Reader:
    """Reads keys of one driver table, collecting every problem."""

    def __init__(self, spec: Mapping[str, Any], where: str) -> None:
        self.spec = spec
        self.where = where
        self.problems: list[str] = []

    def add(self, text: str) -> None:
        """Record a problem, prefixed with where it is."""
        self.problems.append(f"{self.where}: {text}")

    def has(self, key: str) -> bool:
        """Whether the table sets ``key``."""
        return key in self.spec

    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        unit: str = "",
        minimum: float | None = None,
        positive: bool = False,
    ) -> float:
        """A finite number (NaN after a problem); ``default`` None means required."""
        if key not in self.spec:
            if default is None:
                self.add(f"'{key}' is required")
                return math.nan
            return default
        raw = self.spec[key]
        suffix = f" {unit}" if unit else ""
        value = _real(raw)
        if value is None:
            in_unit = f" in {unit}" if unit else ""
            self.add(f"'{key}' must be a finite number{in_unit}, got {_show(raw)}")
            return math.nan
        if positive and not value > 0:
            self.add(f"'{key}' must be > 0{suffix}, got {_show(raw)}")
            return math.nan
        if minimum is not None and value < minimum:
            self.add(f"'{key}' must be >= {minimum:g}{suffix}, got {_show(raw)}")
            return math.nan
        return value

    def integer(self, key: str, default: int, *, minimum: int, maximum: int | None = None) -> int:
        """An integer in [``minimum``, ``maximum``] (``default`` after a problem)."""
        raw = self.spec.get(key, default)
        if not isinstance(raw, int) or isinstance(raw, bool):
            self.add(f"'{key}' must be an integer, got {_show(raw)}")
            return default
        if raw < minimum:
            self.add(f"'{key}' must be an integer >= {minimum}, got {_show(raw)}")
            return default
        if maximum is not None and raw > maximum:
            self.add(f"'{key}' must be an integer <= {maximum}, got {_show(raw)}")
            return default
        return raw

    def choice(self, key: str, default: str, choices: Collection[str]) -> str:
        """One of ``choices`` (``default`` after a problem)."""
        raw = self.spec.get(key, default)
        if not isinstance(raw, str) or raw not in choices:
            hint = _close_hint(raw, choices) if isinstance(raw, str) else ""
            self.add(f"'{key}' must be one of {', '.join(choices)}, got {_show(raw)}{hint}")
            return default
        return raw

    def text(self, key: str, default: str | None = None) -> str:
        """A non-empty string ('' after a problem)."""
        raw = self.spec.get(key, default)
        if raw is None:
            self.add(f"'{key}' is required")
            return ""
        if not isinstance(raw, str) or not raw.strip():
            self.add(f"'{key}' must be a non-empty string, got {_show(raw)}")
            return ""
        return raw

    def unknown_keys(self, allowed: Collection[str]) -> None:
        """Report keys the kind does not know."""
        for key in self.spec:
            if key not in allowed:
                hint = _close_hint(str(key), allowed)
                self.add(
                    f"unknown key {_show(key)} for kind {self.spec['kind']!r}{hint}; "
                    f"known keys: {', '.join(sorted(allowed))}"
                )


def _finite_slopes(times: np.ndarray, values: np.ndarray, label: str, r: _Reader) -> bool:
    """Check every segment's slope is finite (no overflow); report the first offence."""
    with np.errstate(all="ignore"):
        slopes = np.diff(values) / np.diff(times)
    bad = np.flatnonzero(~np.isfinite(slopes))
    if bad.size == 0:
        return True
    k = int(bad[0])
    r.add(
        f"{label}: the slope between entries {k} and {k + 1} (t = {times[k]:g} s and "
        f"{times[k + 1]:g} s) is too large to represent"
    )
    return False


def _increasing(times: np.ndarray, label: str, r: _Reader) -> bool:
    """Check times are strictly increasing; report the first offence and the count."""
    bad = np.flatnonzero(np.diff(times) <= 0.0)
    if bad.size == 0:
        return True
    k = int(bad[0])
    more = f" ({bad.size - 1} more)" if bad.size > 1 else ""
    r.add(
        f"{label} must be strictly increasing: entry {k + 1} (t = {times[k + 1]:g} s) does not "
        f"follow entry {k} (t = {times[k]:g} s){more}"
    )
    return False


# ------------------------------------------------------------------ builders


@dataclass(frozen=True)
class _Context:
    """What a builder may need besides the table."""

    base_dir: Path


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


_EXPECTED_TABLE = "a CSV text file with a header row naming the columns, then rows of numbers"


def _shown_path(path: Path) -> str:
    """The table file's path for a problem (shortened if absurdly long)."""
    text = str(path)
    return text if len(text) <= 200 else f"{text[:100]}...{text[-60:]}"


def _file_kind(mode: int) -> str:
    # this module is also bundled alone into the signals FMU: stdlib and numpy only
    for test, kind in (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISFIFO, "a pipe"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return kind
    return "not a regular file"


def _read_table_bytes(path: Path, shown: str, r: _Reader) -> bytes | None:
    """The bytes of a regular file of at most :data:`MAX_TABLE_BYTES` (None after a problem).

    Opened without blocking (a pipe does not hang the read) and checked on
    the open descriptor, so what is checked is what is read.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        r.add(f"cannot read table file '{shown}': {reason}")
        return None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            r.add(f"table file '{shown}' is {_file_kind(info.st_mode)}; expected {_EXPECTED_TABLE}")
            return None
        if info.st_size > MAX_TABLE_BYTES:
            r.add(
                f"table file '{shown}' is {info.st_size / 2**20:.0f} MiB, more than the "
                f"{MAX_TABLE_BYTES >> 20} MiB a table may have"
            )
            return None
        with os.fdopen(os.dup(fd), "rb") as handle:
            data = handle.read(MAX_TABLE_BYTES + 1)
    except OSError as exc:
        r.add(f"cannot read table file '{shown}': {exc.strerror or type(exc).__name__}")
        return None
    finally:
        os.close(fd)
    if len(data) > MAX_TABLE_BYTES:  # it grew while we looked
        r.add(f"table file '{shown}' is more than the {MAX_TABLE_BYTES >> 20} MiB a table may have")
        return None
    return data


def _csv_rows(path: Path, r: _Reader) -> list[list[str]] | None:
    """Non-empty, non-comment rows of a CSV file (None after a problem).

    No problem quotes the file: it may not be a table at all.
    """
    shown = _shown_path(path)
    data = _read_table_bytes(path, shown, r)
    if data is None:
        return None
    try:
        if b"\0" in data:
            raise UnicodeError("NUL byte")
        text = data.decode("utf-8-sig")
    except UnicodeError:
        r.add(
            f"table file '{shown}' is not UTF-8 text (a binary file?); expected {_EXPECTED_TABLE}"
        )
        return None
    try:
        rows = [
            row for row in csv.reader(io.StringIO(text, newline="")) if any(c.strip() for c in row)
        ]
    except csv.Error as exc:
        r.add(f"table file '{shown}' is not a CSV table ({exc}); expected {_EXPECTED_TABLE}")
        return None
    rows = [row for row in rows if not row[0].lstrip().startswith("#")]
    if len(rows) < 3:
        r.add(f"table file '{shown}' needs a header row and at least two data rows")
        return None
    return rows


def _numeric_table(rows: list[list[str]]) -> bool:
    """Whether the rows under the header are all numbers, as many as the header names.

    Only then is the first row taken for column names that may be quoted in
    a problem: the first line of any other file may be a secret.
    """
    header = rows[0]
    least, most, longest = _MAX_HEADER_SHOWN
    if not least <= len(header) <= most or any(
        len(c) > longest or not _COLUMN_NAME.fullmatch(c) for c in header
    ):
        return False
    for row in rows[1:]:
        if len(row) != len(header):
            return False
        for cell in row:
            try:
                float(cell)
            except ValueError:
                return False
    return True


def _csv_column(rows: list[list[str]], index: int, name: str, path: Path, r: _Reader):
    """Floats of one column (None after a problem); reports the first bad rows."""
    values, bad = [], []
    for line, row in enumerate(rows[1:], start=2):
        try:
            x = float(row[index])
            if not math.isfinite(x):
                raise ValueError
            values.append(x)
        except (IndexError, ValueError):
            if index >= len(row):
                cell = "missing"
            elif len(row[index]) > _MAX_CELL_SHOWN:
                cell = f"a {len(row[index])}-character value"
            else:
                cell = repr(row[index])
            bad.append(f"data row {line - 1} ({cell})")
    if bad:
        more = f" and {len(bad) - _MAX_REPORTED_ROWS} more" if len(bad) > _MAX_REPORTED_ROWS else ""
        shown = "; ".join(bad[:_MAX_REPORTED_ROWS])
        r.add(
            f"table file '{_shown_path(path)}': column {name!r} is not a finite number in "
            f"{shown}{more}"
        )
        return None
    return np.array(values)


def _build_table(r: _Reader, ctx: _Context) -> Driver | None:
    file = r.text("file")
    time_name = r.text("time_column", "time")
    value_name = r.text("value_column", "value")
    if not (file and time_name and value_name):
        return None
    path = Path(file) if Path(file).is_absolute() else ctx.base_dir / file
    rows = _csv_rows(path, r)
    if rows is None:
        return None
    header = [c.strip() for c in rows[0]]
    shown = _shown_path(path)
    missing = [name for name in (time_name, value_name) if name not in header]
    if missing:
        listed = _numeric_table([header, *rows[1:]])
        for name in missing:
            if listed:
                r.add(
                    f"table file '{shown}' has no column {_show(name)}{_close_hint(name, header)}; "
                    f"columns: {', '.join(header)}"
                )
            else:
                r.add(
                    f"table file '{shown}' has no column {_show(name)} (its first row is not "
                    f"quoted: the file does not look like a numeric table); expected "
                    f"{_EXPECTED_TABLE}"
                )
        return None
    columns = [
        _csv_column(rows, header.index(name), name, path, r) for name in (time_name, value_name)
    ]
    if any(c is None for c in columns):
        return None
    label = f"table file '{shown}' column {time_name!r}"
    if not (
        _increasing(columns[0], label, r)
        and _finite_slopes(columns[0], columns[1], f"table file '{shown}'", r)
    ):
        return None
    logger.debug("table driver: %d rows from %s", len(columns[0]), path)
    return PiecewiseLinearDriver(columns[0], columns[1], source=str(path))


# ------------------------------------------------------------------ registry


@dataclass(frozen=True)
class DriverKind:
    """One kind of driver a scene may name.

    Attributes
    ----------
    name : str
        The ``kind`` value in a scene.
    summary : str
        One line on what it does.
    keys : tuple of str
        Keys the table may set besides ``kind``.
    build : callable
        Builds the driver from a key reader; records problems on it.
    """

    name: str
    summary: str
    keys: tuple[str, ...]
    build: Callable[[_Reader, _Context], Driver | None]


_FADE_KEYS = ("start_time", "ramp_time")

DRIVER_KINDS: Mapping[str, DriverKind] = MappingProxyType(
    {
        k.name: k
        for k in (
            DriverKind("constant", "a constant value", ("value",), _build_constant),
            DriverKind(
                "ramp",
                "piecewise linear through points, held outside them",
                ("points", *_RAMP_SHORT),
                _build_ramp,
            ),
            DriverKind(
                "sine",
                "offset + amplitude sin(2 pi t / period + phase), optional fade-in",
                ("amplitude", "period", "frequency", "phase_deg", "offset", *_FADE_KEYS),
                _build_sine,
            ),
            DriverKind(
                "sea_state",
                "irregular heave from a JONSWAP or Pierson-Moskowitz wave spectrum",
                (
                    "significant_height",
                    "peak_period",
                    "spectrum",
                    "gamma",
                    "components",
                    "seed",
                    "cutoff",
                    "heave_rao",
                    *_FADE_KEYS,
                ),
                _build_sea_state,
            ),
            DriverKind(
                "table",
                "linear interpolation in a CSV file's columns",
                ("file", "time_column", "value_column"),
                _build_table,
            ),
        )
    }
)
"""Driver kinds by name (read-only)."""


def _kind_of(spec: Mapping[str, Any], r: _Reader) -> DriverKind | None:
    known = ", ".join(sorted(DRIVER_KINDS))
    kind = spec.get("kind")
    if kind is None:
        r.add(f"'kind' is required; known kinds: {known}")
        return None
    if not isinstance(kind, str) or kind not in DRIVER_KINDS:
        hint = _close_hint(kind, DRIVER_KINDS) if isinstance(kind, str) else ""
        r.add(f"unknown kind {_show(kind)}{hint}; known kinds: {known}")
        return None
    return DRIVER_KINDS[kind]


def make_driver(
    spec: Mapping[str, Any],
    *,
    where: str,
    base_dir: Path,
    ignore: Collection[str] = (),
) -> tuple[Driver | None, list[str]]:
    """Build a driver from a scene table, or list every problem with it.

    Parameters
    ----------
    spec : mapping
        The table: ``kind`` and that kind's keys (see the module docstring
        and :data:`DRIVER_KINDS`).
    where : str
        Prefix of every problem, e.g. ``"driver 3 (rope.mover_b.position)"``.
    base_dir : Path
        Folder of the scene file; relative table files are found there.
    ignore : collection of str, optional
        Keys that belong to the caller (e.g. the scene's ``target``), neither
        read nor reported as unknown.

    Returns
    -------
    driver : Driver or None
        None if there is any problem.
    problems : list of str
        Every problem found, each prefixed with ``where``; empty on success.
        Bad input never raises.
    """
    if not isinstance(spec, Mapping):
        return None, [f"{where}: a driver must be a table with a 'kind', got {_show(spec)}"]
    r = _Reader({k: v for k, v in spec.items() if k not in ignore}, where)
    kind = _kind_of(r.spec, r)
    if kind is None:
        return None, r.problems
    r.unknown_keys(("kind", *kind.keys))
    driver = kind.build(r, _Context(Path(base_dir)))
    if r.problems:
        return None, r.problems
    return driver, []
