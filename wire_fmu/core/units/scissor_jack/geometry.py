"""The scissor jack's rhombus of tie rods: shoe height over the screw travel.

Four rods of length ``L`` at angle ``theta`` to the horizontal: height
``y = 2 L sin(theta)``, width ``w = 2 L cos(theta)``; the screw travel ``s``
draws the side joints together, ``w = w0 - s`` (:mod:`wire_fmu.core.units.scissor_jack.model`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["JackGeometry"]


@dataclass(frozen=True)
class JackGeometry:
    """The rhombus of tie rods.

    Parameters
    ----------
    rod_length : float
        ``L``, m (paper 003: 130 mm).
    initial_height : float
        Height of the shoe above the base joint at ``psi = 0``, m (paper: 130 mm).
    min_height, max_height : float
        Travel of the jack, m: steps beyond are refused (end of travel).
    """

    rod_length: float = 0.130
    initial_height: float = 0.130
    min_height: float = 0.04
    max_height: float = 0.25

    @property
    def initial_width(self) -> float:
        """``w0 = sqrt(4 L^2 - y0^2)``, m."""
        return math.sqrt(4.0 * self.rod_length**2 - self.initial_height**2)

    def height(self, travel: float) -> float:
        """``y(s)``, m (nan outside the rhombus).

        Parameters
        ----------
        travel : float
            Screw travel through the nut since the start, m.
        """
        width = self.initial_width - travel
        square = 4.0 * self.rod_length**2 - width * width
        return math.sqrt(square) if square > 0.0 and width > 0.0 else math.nan

    def slopes(self, travel: float) -> tuple[float, float, float]:
        """``(y, dy/ds, d2y/ds2)`` at screw travel ``s`` (m, 1, 1/m).

        Parameters
        ----------
        travel : float
            Screw travel through the nut since the start, m.
        """
        width = self.initial_width - travel
        y = self.height(travel)
        return y, width / y, -4.0 * self.rod_length**2 / y**3

    def rod_angle(self, travel: float) -> float:
        """``theta``, rad.

        Parameters
        ----------
        travel : float
            Screw travel through the nut since the start, m.
        """
        return math.atan2(self.height(travel), self.initial_width - travel)

    def travel_at_height(self, height: float) -> float:
        """Screw travel that puts the shoe at ``height`` (m), m.

        Parameters
        ----------
        height : float
            Shoe height above the base joint, m.
        """
        return self.initial_width - math.sqrt(4.0 * self.rod_length**2 - height * height)

    def problems(self) -> list[str]:
        """Every problem with the geometry, as sentences."""
        two_l = 2.0 * self.rod_length
        if not (self.rod_length > 0.0 and math.isfinite(self.rod_length)):
            return [f"rod_length must be a positive number of metres, got {self.rod_length}"]
        out, bad = [], set()
        for name in ("min_height", "initial_height", "max_height"):
            value = getattr(self, name)
            if not (0.0 < value < two_l):
                bad.add(name)
                out.append(
                    f"{name} must lie strictly between 0 and twice the rod length "
                    f"({two_l:.6g} m), got {value}"
                )
        if not bad & {"min_height", "max_height"} and not self.min_height < self.max_height:
            out.append(
                f"min_height {self.min_height} m must be below max_height {self.max_height} m "
                "(the ends of the travel)"
            )
        elif not out and not self.min_height <= self.initial_height <= self.max_height:
            out.append(
                f"initial_height {self.initial_height} m must lie within the travel "
                f"[{self.min_height}, {self.max_height}] m"
            )
        return out
