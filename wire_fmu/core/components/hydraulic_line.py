"""The oil line between a cylinder and its accumulator: resistance and inertance.

Pressure drop
-------------
For a volume flow ``q`` (m^3/s, positive from the accumulator towards the
cylinder) the line loses

    dp(q) = R_l q + R_t q |q|

where

* ``R_l = 128 mu l / (pi d^4)`` is the Hagen-Poiseuille resistance of a
  round pipe of length ``l`` and inner diameter ``d`` with oil of dynamic
  viscosity ``mu`` (laminar, exact for Re < ~2300);
* ``R_t = rho (f l / d + K) / (2 A^2)`` is the Darcy-Weisbach loss with a
  turbulent friction factor ``f`` plus the minor losses ``K`` of fittings,
  valves, entry and exit (sum of loss coefficients), ``A = pi d^2 / 4``.

The sum is one smooth (C^1) law across the regimes: at small flows the
linear term dominates and the line is laminar; at large flows the quadratic
term does. The two terms are equal at the transition flow ``q* = R_l / R_t``.
In either limit the other term is the small error of the blend (at high
Reynolds numbers the laminar term adds ``64 / Re`` to ``f``). The law is
strictly increasing, so it has a unique inverse, :meth:`HydraulicLine.flow`,
written without cancellation.

Inertance
---------
The oil in the line has mass ``rho A l`` and moves at ``q / A``; its kinetic
energy ``rho l q^2 / (2 A)`` defines the inertance ``L = rho l / A``
(Pa s^2/m^3): a pressure difference ``L dq/dt`` accelerates the column.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["HydraulicLine"]


@dataclass(frozen=True)
class HydraulicLine:
    """A straight round oil line.

    Parameters
    ----------
    length : float
        Line length, m.
    diameter : float
        Inner diameter, m.
    density : float
        Oil density, kg/m^3.
    viscosity : float
        Oil dynamic viscosity, Pa s.
    friction_factor : float
        Darcy friction factor for turbulent flow, 1.
    loss_coefficient : float
        Sum of the minor-loss coefficients (valves, bends, entry, exit), 1.
    """

    length: float
    diameter: float
    density: float
    viscosity: float
    friction_factor: float = 0.025
    loss_coefficient: float = 3.0

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences (parameter names as in the unit)."""
        out = []
        for name, value in (
            ("line_length", self.length),
            ("line_diameter", self.diameter),
            ("oil_density", self.density),
        ):
            if not (value > 0.0 and math.isfinite(value)):
                out.append(f"parameter {name!r} must be > 0, got {value}")
        for name, value in (
            ("oil_viscosity", self.viscosity),
            ("line_friction_factor", self.friction_factor),
            ("line_loss_coefficient", self.loss_coefficient),
        ):
            if not (value >= 0.0 and math.isfinite(value)):
                out.append(f"parameter {name!r} must be >= 0, got {value}")
        return out

    @property
    def area(self) -> float:
        """Flow cross-section, m^2."""
        return 0.25 * math.pi * self.diameter**2

    @property
    def volume(self) -> float:
        """Oil volume in the line, m^3."""
        return self.area * self.length

    @property
    def laminar_resistance(self) -> float:
        """``R_l = 128 mu l / (pi d^4)``, Pa s/m^3."""
        return 128.0 * self.viscosity * self.length / (math.pi * self.diameter**4)

    @property
    def turbulent_resistance(self) -> float:
        """``R_t = rho (f l / d + K) / (2 A^2)``, Pa s^2/m^6."""
        k_total = self.friction_factor * self.length / self.diameter + self.loss_coefficient
        return self.density * k_total / (2.0 * self.area**2)

    @property
    def inertance(self) -> float:
        """``L = rho l / A``, Pa s^2/m^3 (kg/m^4)."""
        return self.density * self.length / self.area

    @property
    def transition_flow(self) -> float:
        """Flow at which the laminar and turbulent terms are equal, m^3/s (inf if R_t = 0)."""
        r_t = self.turbulent_resistance
        return self.laminar_resistance / r_t if r_t > 0.0 else math.inf

    def reynolds(self, flow: float) -> float:
        """Reynolds number ``rho |q| d / (mu A)`` at ``flow`` (m^3/s), 1.

        Parameters
        ----------
        flow : float
            Volume flow through the line, m^3/s.
        """
        return self.density * abs(flow) * self.diameter / (self.viscosity * self.area)

    def pressure_drop(self, flow: float) -> float:
        """``R_l q + R_t q |q|`` at ``flow`` (m^3/s), Pa (same sign as the flow).

        Parameters
        ----------
        flow : float
            Volume flow through the line, m^3/s.
        """
        return (self.laminar_resistance + self.turbulent_resistance * abs(flow)) * flow

    def flow(self, pressure_drop: float) -> float:
        """Inverse of :meth:`pressure_drop`: the flow a drop of ``pressure_drop`` Pa drives, m^3/s.

        ``q = 2 dp / (R_l + sqrt(R_l^2 + 4 R_t |dp|))``, the rationalised root
        of the quadratic (no cancellation when either term is small).

        Parameters
        ----------
        pressure_drop : float
            Pressure drop along the line, Pa.

        Raises
        ------
        ZeroDivisionError
            If both resistances are zero (a lossless line has no such inverse).
        """
        r_l, r_t = self.laminar_resistance, self.turbulent_resistance
        return 2.0 * pressure_drop / (r_l + math.sqrt(r_l * r_l + 4.0 * r_t * abs(pressure_drop)))
