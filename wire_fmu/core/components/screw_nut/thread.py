"""The thread of a screw pair: lead, dry friction and the paper's regularised forms.

The paper's regularised friction torque (paper 003, section 4) and the
creep speed it implies are described in :mod:`wire_fmu.core.components.screw_nut`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

__all__ = ["ScrewThread", "REGULARISATIONS"]

_TWO_PI = 2.0 * math.pi


def _linear_saturated(x: float) -> float:
    return min(1.0, max(-1.0, x))


def _linear_inverse(x: float) -> float:
    return x


REGULARISATIONS: Mapping[str, tuple[Callable[[float], float], Callable[[float], float]]] = (
    MappingProxyType(
        {
            "linear": (_linear_saturated, _linear_inverse),  # paper 003, Fig. 7
            "tanh": (math.tanh, math.atanh),
        }
    )
)
"""Regularised friction shapes ``s(w / w1)`` and the inverse used for creep speeds."""


@dataclass(frozen=True)
class ScrewThread:
    """The thread of a screw pair: lead and dry friction.

    Parameters
    ----------
    lead : float
        Axial travel per turn, m (paper 003's jack: 2 mm per turn).
    mean_radius : float
        Mean thread radius ``r_mean``, m (paper: 0.01 m).
    friction : float
        Friction coefficient ``mu`` (paper: 0.1, steel on steel).
    """

    lead: float
    mean_radius: float = 0.01
    friction: float = 0.1

    @property
    def lead_per_radian(self) -> float:
        """``h = lead / (2 pi)``, m/rad."""
        return self.lead / _TWO_PI

    def axial_travel(self, relative_angle: float) -> float:
        """Axial travel of the nut for a relative angle (rad), m.

        Parameters
        ----------
        relative_angle : float
            Angle of the nut relative to the screw, rad.
        """
        return self.lead_per_radian * relative_angle

    def lead_torque(self, axial_force: float) -> float:
        """Torque ``M_a = h F_axial`` the axial force exerts about the axis, N m.

        Parameters
        ----------
        axial_force : float
            Axial force in the thread, N.
        """
        return self.lead_per_radian * axial_force

    def friction_capacity(self, axial_force: float) -> float:
        """``M1 = r_mean mu |F_axial|``, N m.

        Parameters
        ----------
        axial_force : float
            Axial force in the thread, N.
        """
        return self.mean_radius * self.friction * abs(axial_force)

    def self_locking(self) -> bool:
        """Whether no axial load can back-drive the thread (``h < r_mean mu``)."""
        return self.lead_per_radian < self.mean_radius * self.friction

    def regularised_torque(
        self, relative_speed: float, axial_force: float, speed_scale: float, shape: str = "linear"
    ) -> float:
        """The paper's regularised friction torque on the nut, N m (opposes ``relative_speed``).

        Parameters
        ----------
        relative_speed : float
            Nut speed relative to the screw about the axis, rad/s.
        axial_force : float
            Axial force in the thread, N.
        speed_scale : float
            ``w1``, rad/s (paper: 1e-6).
        shape : str
            ``"linear"`` (linear inside ``|w| < w1``, saturated outside) or ``"tanh"``.
        """
        s, _ = REGULARISATIONS[shape]
        return -self.friction_capacity(axial_force) * s(relative_speed / speed_scale)

    def creep_speed(
        self, held_torque: float, axial_force: float, speed_scale: float, shape: str = "linear"
    ) -> float:
        """Steady creep speed of a regularised thread holding ``held_torque`` (N m), rad/s.

        The speed at which the regularised torque balances the torque that
        drives the thread (sign: that torque's); ``inf`` when the torque
        exceeds the capacity (the thread slides).

        Parameters
        ----------
        held_torque : float
            Torque that drives the thread, N m.
        axial_force : float
            Axial force in the thread, N.
        speed_scale : float
            ``w1``, rad/s.
        shape : str
            ``"linear"`` or ``"tanh"``.
        """
        capacity = self.friction_capacity(axial_force)
        ratio = abs(held_torque) / capacity if capacity > 0.0 else math.inf
        if ratio >= 1.0:
            return math.copysign(math.inf, held_torque)
        _, inverse = REGULARISATIONS[shape]
        return math.copysign(speed_scale * inverse(ratio), held_torque)

    def problems(self) -> list[str]:
        """Every problem with the thread's numbers, as sentences."""
        out = []
        for name, value in (("lead", self.lead), ("mean_radius", self.mean_radius)):
            if not (value > 0.0 and math.isfinite(value)):
                out.append(f"thread {name} must be a positive number of metres, got {value}")
        if not (self.friction >= 0.0 and math.isfinite(self.friction)):
            out.append(f"thread friction coefficient must be >= 0, got {self.friction}")
        return out
