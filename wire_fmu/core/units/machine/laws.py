"""The laws of a machine unit: Fourier series, inertias of the shaft angle, polynomials.

Each law is a callable with its ``derivative`` (and a Fourier series its exact
``integral``), the form paper 004's integrator takes (:mod:`wire_fmu.core.units.machine.model`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["FourierSeries", "CrankSliderInertia", "FourierInertia", "Polynomial"]

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class FourierSeries:
    """``mean + sum_k a_k cos(k w x) + b_k sin(k w x)`` with ``w = 2 pi / period``.

    Parameters
    ----------
    mean : float
        Constant term.
    cos, sin : tuple of float
        Coefficients of harmonics 1, 2, ...
    period : float
        Period in ``x`` (``2 pi`` for a law of the shaft angle).
    """

    mean: float = 0.0
    cos: tuple[float, ...] = ()
    sin: tuple[float, ...] = ()
    period: float = _TWO_PI

    @property
    def rate(self) -> float:
        """``w = 2 pi / period``."""
        return _TWO_PI / self.period

    def __call__(self, x: float) -> float:
        """Value at ``x``."""
        w = self.rate
        total = self.mean
        for k, a in enumerate(self.cos, start=1):
            total += a * math.cos(k * w * x)
        for k, b in enumerate(self.sin, start=1):
            total += b * math.sin(k * w * x)
        return total

    def derivative(self, x: float) -> float:
        """``d/dx``.

        Parameters
        ----------
        x : float
            Where, in the series' variable (rad or s).
        """
        w = self.rate
        total = 0.0
        for k, a in enumerate(self.cos, start=1):
            total -= a * k * w * math.sin(k * w * x)
        for k, b in enumerate(self.sin, start=1):
            total += b * k * w * math.cos(k * w * x)
        return total

    def integral(self, x0: float, x1: float) -> float:
        """``int_x0^x1`` exactly.

        Parameters
        ----------
        x0, x1 : float
            The bounds, in the series' variable (rad or s).
        """
        w = self.rate
        total = self.mean * (x1 - x0)
        for k, a in enumerate(self.cos, start=1):
            total += a * (math.sin(k * w * x1) - math.sin(k * w * x0)) / (k * w)
        for k, b in enumerate(self.sin, start=1):
            total -= b * (math.cos(k * w * x1) - math.cos(k * w * x0)) / (k * w)
        return total

    def amplitude_bound(self) -> float:
        """``sum |a_k| + |b_k|``: the series never strays further from its mean."""
        return float(sum(abs(c) for c in self.cos) + sum(abs(c) for c in self.sin))


@dataclass(frozen=True)
class CrankSliderInertia:
    """``I(phi) = I0 + m x'(phi)^2`` of a central crank-slider mechanism.

    Parameters
    ----------
    base : float
        ``I0``: flywheel, crank and the motor and gears reduced to the shaft, kg m^2.
    crank, rod : float
        Crank radius ``r`` and connecting-rod length ``l > r``, m.
    slider_mass : float
        Mass moving with the slider (with a share of the rod), kg.
    """

    base: float
    crank: float
    rod: float
    slider_mass: float

    def _slider(self, phi: float) -> tuple[float, float]:
        """``(x', x'')``: slider speed and acceleration per crank angle (m/rad, m/rad^2)."""
        r, rod = self.crank, self.rod
        s, c = math.sin(phi), math.cos(phi)
        root = math.sqrt(rod * rod - r * r * s * s)
        x1 = -r * s - r * r * s * c / root
        x2 = -r * c - r * r * (c * c - s * s) / root - r**4 * s * s * c * c / root**3
        return x1, x2

    def __call__(self, phi: float) -> float:
        """``I(phi)``, kg m^2."""
        x1, _ = self._slider(phi)
        return self.base + self.slider_mass * x1 * x1

    def derivative(self, phi: float) -> float:
        """``dI/dphi``, kg m^2/rad.

        Parameters
        ----------
        phi : float
            Crank angle, rad.
        """
        x1, x2 = self._slider(phi)
        return 2.0 * self.slider_mass * x1 * x2

    def problems(self) -> list[str]:
        """Every problem with the mechanism's numbers."""
        out = []
        if not (self.base > 0.0 and math.isfinite(self.base)):
            out.append(f"inertia: 'base' must be > 0 kg m^2, got {self.base}")
        if not (0.0 < self.crank < self.rod):
            out.append(f"inertia: need 0 < crank < rod, got crank {self.crank}, rod {self.rod}")
        if not (self.slider_mass >= 0.0 and math.isfinite(self.slider_mass)):
            out.append(f"inertia: 'slider_mass' must be >= 0 kg, got {self.slider_mass}")
        return out


@dataclass(frozen=True)
class FourierInertia:
    """``I(phi)`` as a Fourier series in the shaft angle (kg m^2)."""

    series: FourierSeries

    def __call__(self, phi: float) -> float:
        """``I(phi)``, kg m^2."""
        return self.series(phi)

    def derivative(self, phi: float) -> float:
        """``dI/dphi``, kg m^2/rad.

        Parameters
        ----------
        phi : float
            Shaft angle, rad.
        """
        return self.series.derivative(phi)

    def problems(self) -> list[str]:
        """The inertia must stay positive for every angle."""
        if self.series.mean - self.series.amplitude_bound() > 0.0:
            return []
        return [
            f"inertia: the Fourier series may reach zero or below (mean "
            f"{self.series.mean}, harmonics up to {self.series.amplitude_bound()} kg m^2)"
        ]


@dataclass(frozen=True)
class Polynomial:
    """``sum_j c_j x^j``."""

    coefficients: tuple[float, ...] = ()

    def __call__(self, x: float) -> float:
        """Value at ``x``."""
        total = 0.0
        for c in reversed(self.coefficients):
            total = total * x + c
        return total

    def derivative(self, x: float) -> float:
        """``d/dx``.

        Parameters
        ----------
        x : float
            Where, in the polynomial's variable (rad/s for ``M_c(omega)``).
        """
        total = 0.0
        for j in range(len(self.coefficients) - 1, 0, -1):
            total = total * x + j * self.coefficients[j]
        return total
