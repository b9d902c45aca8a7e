"""A polytropic gas spring: the gas side of a hydro-pneumatic accumulator.

The gas (nitrogen or air in the accumulator plus the gas bank of air
pressure vessels) follows ``p V^n = p0 V0^n`` through a reference state
``(p0, V0)`` with a constant exponent ``n``:

* ``n = 1``: isothermal (slow motion, the gas stays at ambient temperature);
* ``n = 1.4``: adiabatic for a diatomic ideal gas (fast motion, no heat
  exchange);
* anything in between: polytropic, the usual engineering fit of a real
  accumulator's behaviour between the two.

Energy
------
The gas is modelled as a *reversible* spring whose potential is the work
done on it, ``E(V) = -integral_{V0}^{V} p dV``:

* ``n = 1``: ``E = p0 V0 ln(V0 / V)``;
* ``n != 1``: ``E = (p V - p0 V0) / (n - 1)``, which for ``n = gamma`` is the
  change of the ideal gas's internal energy.

For ``1 < n < gamma`` a real gas exchanges heat with the vessel walls along
the polytropic path; here that heat is assumed to come back on the way back
(reversible), so the whole ``p dV`` work is stored and nothing is booked as
dissipated. ``dE/dt = -p dV/dt`` holds exactly in every case, which is what
closes the energy ledger of a unit that uses it.

Stiffness
---------
``-dp/dV = n p / V``; seen through a piston of area ``A`` that moves the
gas volume by ``A dx`` the spring rate is ``k = n p A^2 / V`` (N/m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = [
    "PolytropicGas",
    "ISOTHERMAL",
    "ADIABATIC_DIATOMIC",
    "isothermal_charge_volume",
]

ISOTHERMAL = 1.0
"""Polytropic exponent of an isothermal process, 1."""

ADIABATIC_DIATOMIC = 1.4
"""Ratio of specific heats of nitrogen or air near ambient conditions, 1."""


@dataclass(frozen=True)
class PolytropicGas:
    """A fixed amount of gas following ``p V^n = p0 V0^n``.

    Parameters
    ----------
    reference_pressure : float
        Absolute pressure ``p0`` at the reference volume, Pa.
    reference_volume : float
        Reference volume ``V0``, m^3; stored energy is zero there.
    exponent : float
        Polytropic exponent ``n`` (1: isothermal, 1.4: adiabatic), 1.
    """

    reference_pressure: float
    reference_volume: float
    exponent: float = ISOTHERMAL

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out = []
        if not (self.reference_pressure > 0.0 and math.isfinite(self.reference_pressure)):
            out.append(f"gas reference pressure must be > 0 Pa, got {self.reference_pressure}")
        if not (self.reference_volume > 0.0 and math.isfinite(self.reference_volume)):
            out.append(f"gas reference volume must be > 0 m3, got {self.reference_volume}")
        if not (1.0 <= self.exponent <= 2.0):
            out.append(f"polytropic exponent must lie in [1, 2], got {self.exponent}")
        return out

    @property
    def constant(self) -> float:
        """``p0 V0`` (J): the isothermal energy scale."""
        return self.reference_pressure * self.reference_volume

    def pressure(self, volume: float) -> float:
        """Absolute pressure at ``volume`` (m^3), Pa.

        Parameters
        ----------
        volume : float
            Gas volume, m^3.
        """
        return self.reference_pressure * (self.reference_volume / volume) ** self.exponent

    def volume(self, pressure: float) -> float:
        """Volume at absolute ``pressure`` (Pa), m^3.

        Parameters
        ----------
        pressure : float
            Absolute gas pressure, Pa.
        """
        return self.reference_volume * (self.reference_pressure / pressure) ** (1.0 / self.exponent)

    def compliance(self, volume: float) -> float:
        """``-dV/dp = V / (n p)`` at ``volume``, m^3/Pa.

        Parameters
        ----------
        volume : float
            Gas volume, m^3.
        """
        return volume / (self.exponent * self.pressure(volume))

    def stiffness(self, volume: float, area: float) -> float:
        """Spring rate ``n p A^2 / V`` seen through a piston of ``area`` (m^2), N/m.

        Parameters
        ----------
        volume : float
            Gas volume, m^3.
        area : float
            Piston area, m^2.
        """
        return self.exponent * self.pressure(volume) * area * area / volume

    def energy(self, volume: float) -> float:
        """Stored energy relative to the reference volume, J (``-integral p dV``).

        Written as ``p0 V0 expm1((n-1) ln(V0/V)) / (n-1)``, which is exact
        for every ``n`` and tends to the isothermal ``p0 V0 ln(V0/V)`` as
        ``n -> 1`` without cancellation.

        Parameters
        ----------
        volume : float
            Gas volume, m^3.
        """
        log_ratio = math.log(self.reference_volume / volume)
        m = self.exponent - 1.0
        if m == 0.0:
            return self.constant * log_ratio
        return self.constant * math.expm1(m * log_ratio) / m

    def work_on_gas(self, volume_from: float, volume_to: float) -> float:
        """Work done *on* the gas from ``volume_from`` to ``volume_to`` (m^3), J.

        Parameters
        ----------
        volume_from, volume_to : float
            Gas volume before and after, m^3.
        """
        return self.energy(volume_to) - self.energy(volume_from)


def isothermal_charge_volume(
    precharge_pressure: float, full_volume: float, pressure: float
) -> float:
    """Gas volume after slowly pumping oil in until the gas reaches ``pressure``.

    Parameters
    ----------
    precharge_pressure : float
        Absolute gas pressure with no oil in the accumulator, Pa.
    full_volume : float
        Gas volume with no oil in the accumulator (accumulator plus gas
        bank), m^3.
    pressure : float
        Absolute working pressure reached, Pa.

    Returns
    -------
    float
        ``full_volume * precharge_pressure / pressure`` (Boyle's law: charging
        is slow, so isothermal), m^3.
    """
    return full_volume * precharge_pressure / pressure
