"""Simple drivers: a constant, piecewise linear points, a sine with fade-in."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from .protocol import _fade, _out

__all__ = ["ConstantDriver", "PiecewiseLinearDriver", "SineDriver"]


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
        """The constant (input unit).

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.value`.
        """
        if isinstance(t, float):  # one time, every macro step
            return float(self.constant)
        return _out(np.full(np.shape(t), self.constant), t)

    def rate(self, t: float) -> float:
        """Zero (input unit per s).

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.rate`.
        """
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
        """Interpolated value at ``t`` (s), input unit.

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.value`.
        """
        if isinstance(t, float):  # one time, every macro step
            return float(np.interp(t, self.times, self.values))
        return _out(np.interp(t, self.times, self.values), t)

    def rate(self, t: float) -> float:
        """Slope of the segment starting at or before ``t``; 0 outside, input unit per s.

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.rate`.
        """
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
        """Signal at ``t`` (s), input unit.

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.value`.
        """
        weight, _, wave, _ = self._parts(t)
        return _out(self.offset + weight * wave, t)

    def rate(self, t: float) -> float:
        """Time derivative at ``t``, input unit per s.

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.rate`.
        """
        weight, weight_rate, wave, arg = self._parts(t)
        wave_rate = self.amplitude * self.angular_frequency * np.cos(arg)
        return _out(weight_rate * wave + weight * wave_rate, t)
