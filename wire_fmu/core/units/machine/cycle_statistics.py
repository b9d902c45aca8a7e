"""Steady motion and its non-uniformity: per-revolution speed statistics of the main shaft.

:class:`CycleStatistics` watches the main shaft complete each revolution
(``phi`` passing a multiple of ``2 pi``, located by cubic Hermite
interpolation between steps) and reports the revolution's period, mean
speed ``omega_mean = 2 pi / period`` and the coefficient of non-uniformity
(Artobolevsky) ``delta = (omega_max - omega_min) / omega_mean``, the extremes
taken over the step ends.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = ["CycleStatistics"]

_TWO_PI = 2.0 * math.pi


@dataclass
class CycleStatistics:
    """Per-revolution speed statistics of the main shaft (the module docstring).

    Attributes
    ----------
    count : int
        Revolutions completed.
    start_time : float
        When the current revolution began, s.
    omega_max, omega_min : float
        Extremes so far in the current revolution, rad/s.
    last : dict
        ``period`` (s), ``omega_mean``, ``omega_max``, ``omega_min`` (rad/s)
        and ``delta`` of the last completed revolution (zeros before the first).
    """

    count: int = 0
    start_time: float = 0.0
    omega_max: float = -math.inf
    omega_min: float = math.inf
    last: dict[str, float] = field(
        default_factory=lambda: dict.fromkeys(
            ("period", "omega_mean", "omega_max", "omega_min", "delta"), 0.0
        )
    )
    _turn: int = field(default=0, repr=False)

    def start(self, t: float, phi: float, omega: float) -> None:
        """Begin counting at ``(t, phi, omega)``; revolutions end at multiples of ``2 pi``.

        Parameters
        ----------
        t : float
            Time, s.
        phi : float
            Shaft angle, rad.
        omega : float
            Shaft speed, rad/s.
        """
        self.count = 0
        self.start_time = t
        self.omega_max = self.omega_min = omega
        self._turn = math.floor(phi / _TWO_PI)

    def update(self, t0: float, x0: Sequence[float], t1: float, x1: Sequence[float]) -> None:
        """Account for the step from ``(t0, x0)`` to ``(t1, x1)`` (states ``[phi, omega, ...]``).

        Parameters
        ----------
        t0, t1 : float
            Start and end of the step, s.
        x0, x1 : sequence of float
            States at ``t0`` and ``t1``: angle (rad) and speed (rad/s) first.
        """
        turn = math.floor(x1[0] / _TWO_PI)
        if turn > self._turn:  # a revolution ended within the step
            t_end = _crossing_time(t0, x0, t1, x1, turn * _TWO_PI)
            if self.count > 0 or self.start_time != t_end:
                self._close(t_end)
            self.start_time = t_end
            self.omega_max = self.omega_min = float(x1[1])
        self._turn = turn
        self.omega_max = max(self.omega_max, float(x1[1]))
        self.omega_min = min(self.omega_min, float(x1[1]))

    def _close(self, t_end: float) -> None:
        period = t_end - self.start_time
        mean = _TWO_PI / period
        self.last = {
            "period": period,
            "omega_mean": mean,
            "omega_max": self.omega_max,
            "omega_min": self.omega_min,
            "delta": (self.omega_max - self.omega_min) / mean,
        }
        self.count += 1

    def get_state(self) -> dict[str, Any]:
        """Plain data."""
        return {
            "count": self.count,
            "start_time": self.start_time,
            "omega_max": self.omega_max,
            "omega_min": self.omega_min,
            "last": dict(self.last),
            "turn": self._turn,
        }

    def set_state(self, data: Mapping[str, Any]) -> None:
        """Restore :meth:`get_state`.

        Parameters
        ----------
        data : mapping
            Statistics from :meth:`get_state`.
        """
        self.count = int(data["count"])
        self.start_time = float(data["start_time"])
        self.omega_max = float(data["omega_max"])
        self.omega_min = float(data["omega_min"])
        self.last = {k: float(v) for k, v in data["last"].items()}
        self._turn = int(data["turn"])


def _crossing_time(
    t0: float, x0: Sequence[float], t1: float, x1: Sequence[float], level: float
) -> float:
    """When the cubic Hermite interpolant of ``phi`` (with ``omega`` as slope) reaches ``level``."""
    h = t1 - t0
    p0, p1, m0, m1 = float(x0[0]), float(x1[0]), float(x0[1]) * h, float(x1[1]) * h

    def hermite(s: float) -> float:
        """The interpolant minus ``level`` at the step fraction ``s``, rad.

        Parameters
        ----------
        s : float
            Fraction of the step, 0 to 1.
        """
        s2, s3 = s * s, s * s * s
        return (
            (2 * s3 - 3 * s2 + 1) * p0
            + (s3 - 2 * s2 + s) * m0
            + (-2 * s3 + 3 * s2) * p1
            + (s3 - s2) * m1
        ) - level

    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if hermite(mid) < 0.0:
            lo = mid
        else:
            hi = mid
    return t0 + 0.5 * (lo + hi) * h
