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

__all__ = [
    "BandBrake",
    "BRAKE_FREE",
    "BRAKE_SLIPPING",
    "BRAKE_HOLDING",
    "BRAKE_FRICTION_MAX",
    "BRAKE_WRAP_ANGLE_MAX",
]

BRAKE_FREE, BRAKE_SLIPPING, BRAKE_HOLDING = 0, 1, 2
_BRAKE_WORDS = ("released", "slipping", "holding")  # indexed by brake state

BRAKE_FRICTION_MAX = 1.0
"""Largest band friction coefficient taken. Dry brake linings on steel or cast iron lie
between about 0.3 and 0.65 (moulded, woven and sintered linings; leather and cork up to
about 0.6; e.g. Shigley's Mechanical Engineering Design, friction materials for brakes
and clutches), so 1 leaves half as much again above the grippiest lining; beyond it the
value is a typing slip (12 for 0.12), and the self-energising factor e^(mu alpha) of
300 deg of wrap would be about 2e27 at mu = 12."""

BRAKE_WRAP_ANGLE_MAX = 2.0 * math.pi
"""Largest band wrap angle taken, rad: a band brake's band, its dead end anchored and its
live end on the lever, both leaving the rim, wraps at most one turn (270-330 deg in
drawworks)."""


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
            (
                "brake_friction",
                self.friction,
                0 < self.friction <= BRAKE_FRICTION_MAX,
                f"in (0, {BRAKE_FRICTION_MAX:g}] (brake linings: 0.3-0.65)",
            ),
            (
                "brake_wrap_angle",
                self.wrap_angle,
                0 < self.wrap_angle <= BRAKE_WRAP_ANGLE_MAX,
                "in (0, 2 pi] rad (a band wraps at most one turn)",
            ),
        )
        return [
            f"parameter {name!r} must be {bound}, got {value}"
            for name, value, ok, bound in checks
            if not (ok and math.isfinite(value))
        ]
