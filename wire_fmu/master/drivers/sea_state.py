"""Irregular vessel heave from a wave spectrum: the sea-state driver and the spectra."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .protocol import _fade, _fade_scalar, _out

__all__ = ["SeaStateDriver", "pierson_moskowitz_spectrum", "jonswap_spectrum", "SPECTRA"]

_TWO_PI = 2.0 * math.pi
_CHUNK = 4096  # rows of (time x component) evaluated at once for long time arrays


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
        """Heave at ``t`` (s), m.

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.value`.
        """
        if isinstance(t, float):  # one time: the row summed as values_at sums each
            tau = float(t) - self.start_time
            weight, _ = _fade_scalar(tau, self.ramp_time)
            waves = np.cos(self.angular_frequencies * tau + self.phases) * self.amplitudes
            return float(self.heave_rao * weight * float(np.add.reduce(waves)))
        weight, _ = _fade(t, self.start_time, self.ramp_time)
        wave = self._sum(t, np.cos, self.amplitudes)
        return _out(self.heave_rao * weight * wave, t)

    def values_at(self, times: Sequence[float]) -> list[float]:
        """:meth:`value` at each of ``times`` (s), m: the same numbers, computed together.

        The cosines of all times and components are evaluated in one call and
        each time's row summed by numpy's pairwise sum, as :meth:`value` sums its
        one row, so every value is identical to it to the last bit.

        Parameters
        ----------
        times : sequence of float
            Times, s.

        Returns
        -------
        list of float
            The heave at each time, m.
        """
        taus = np.array(times, dtype=float) - self.start_time
        waves = np.cos(np.multiply.outer(taus, self.angular_frequencies) + self.phases)
        sums = np.add.reduce(waves * self.amplitudes, axis=1).tolist()
        rao, ramp_time = self.heave_rao, self.ramp_time
        return [
            rao * _fade_scalar(tau, ramp_time)[0] * wave
            for tau, wave in zip(taus.tolist(), sums, strict=True)
        ]

    def rate(self, t: float) -> float:
        """Heave velocity at ``t`` (s), m/s.

        Parameters and return as in :meth:`~wire_fmu.master.drivers.Driver.rate`.
        """
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
