"""The driver protocol and what every driver shares: float-or-array output, fade-in."""

from __future__ import annotations

import math
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["Driver"]


@runtime_checkable
class Driver(Protocol):
    """A time signal with its derivative.

    Both methods accept a float time (s) and return a float; they also
    accept an array of times and return an array of the same shape.
    """

    def value(self, t: float) -> float:
        """Signal at time ``t`` (s), in the driven input's unit.

        Parameters
        ----------
        t : float or ndarray
            Time, s.

        Returns
        -------
        float or ndarray
            The signal, in the driven input's unit: a float for a float time,
            an array of the same shape for an array of times.
        """
        ...

    def rate(self, t: float) -> float:
        """Time derivative of :meth:`value` at ``t``, input unit per s.

        Parameters
        ----------
        t : float or ndarray
            Time, s.

        Returns
        -------
        float or ndarray
            The rate, the driven input's unit per s: a float for a float time,
            an array of the same shape for an array of times.
        """
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
