"""The winch's band brake (eq. 34): capacities by direction, and the brake's states.

Capacity against paying out (the self-energising direction of a drawworks
band, whose dead end is anchored so that a lowering load pulls the band
tighter): ``r_f F (L/l) eta (e^(mu alpha) - 1)``; against hauling in:
``r_f F (L/l) eta (1 - e^(-mu alpha))``. A lever force ``F <= 0`` releases
the brake (a band cannot push). While the drum is stopped the brake holds
it exactly (:class:`~wire_fmu.core.components.friction.StickSlip`, holding torque from
the known net torque), breaks away at capacity, slides with the capacity
of the direction of motion and re-sticks when the motion stops.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["BandBrake", "BRAKE_FREE", "BRAKE_SLIPPING", "BRAKE_HOLDING"]

BRAKE_FREE, BRAKE_SLIPPING, BRAKE_HOLDING = 0, 1, 2
_BRAKE_WORDS = ("released", "slipping", "holding")  # indexed by brake state


@dataclass(frozen=True)
class BandBrake:
    """Band brake (eq. 34).

    Parameters
    ----------
    rim_radius : float
        Brake-rim radius ``r_f``, m.
    lever_ratio : float
        ``L/l``, the lever's force ratio (1).
    efficiency : float
        ``eta`` of the linkage (0, 1].
    friction : float
        Band friction coefficient ``mu`` (1).
    wrap_angle : float
        Band wrap angle ``alpha``, rad.
    """

    rim_radius: float = 0.62
    lever_ratio: float = 15.0
    efficiency: float = 0.9
    friction: float = 0.4
    wrap_angle: float = 5.24

    def band_tension(self, lever_force: float) -> float:
        """Tension the lever puts into the band's live end, N (0 if not pulled).

        Parameters
        ----------
        lever_force : float
            Force on the brake lever, N.
        """
        return max(lever_force, 0.0) * self.lever_ratio * self.efficiency

    def capacities(self, lever_force: float) -> tuple[float, float]:
        """Torque capacities (against paying out, against hauling in), N m.

        Parameters
        ----------
        lever_force : float
            Force on the brake lever, N (<= 0: released).
        """
        base = self.rim_radius * self.band_tension(lever_force)
        mu_alpha = self.friction * self.wrap_angle
        return base * math.expm1(mu_alpha), -base * math.expm1(-mu_alpha)

    def problems(self) -> list[str]:
        """Every problem with these parameters."""
        checks = (
            ("brake_rim_radius", self.rim_radius, self.rim_radius > 0, "> 0 m"),
            ("brake_lever_ratio", self.lever_ratio, self.lever_ratio > 0, "> 0"),
            ("brake_efficiency", self.efficiency, 0 < self.efficiency <= 1, "in (0, 1]"),
            ("brake_friction", self.friction, self.friction > 0, "> 0"),
            ("brake_wrap_angle", self.wrap_angle, self.wrap_angle > 0, "> 0 rad"),
        )
        return [
            f"parameter {name!r} must be {bound}, got {value}"
            for name, value, ok, bound in checks
            if not (ok and math.isfinite(value))
        ]
