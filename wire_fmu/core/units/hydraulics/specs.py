"""The physical parameters of a cylinder-accumulator unit: cylinder, accumulator, oil.

Each part is a frozen dataclass in SI units with a ``problems()`` method that
names every bad value; :class:`HydraulicsSpec` gathers them with the line
(:mod:`~wire_fmu.core.components.hydraulic_line`), the seals
(:mod:`~wire_fmu.core.components.rod_seal`) and the end stops
(:mod:`~wire_fmu.core.components.end_stops`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from wire_fmu.core.components.end_stops import EndStopSpec
from wire_fmu.core.components.hydraulic_line import HydraulicLine
from wire_fmu.core.components.rod_seal import SealSpec
from wire_fmu.core.errors import check_positive

__all__ = ["AccumulatorSpec", "CylinderSpec", "HydraulicsSpec", "OilSpec"]


@dataclass(frozen=True)
class CylinderSpec:
    """Geometry and moving mass of a single-acting cylinder.

    Parameters
    ----------
    bore_diameter, rod_diameter : float
        Piston and rod diameters, m.
    stroke : float
        Stroke, m.
    moving_mass : float
        Rod, piston and whatever the rod carries (sheave cluster), kg.
    pressurised_side : str
        ``"bore"`` (push: oil pushes the rod out) or ``"annulus"`` (pull).
    chamber_dead_volume : float
        Oil in the chamber when its working length is zero (ports, clearance), m^3.
    gravity_along_rod : float
        Component of gravity along the extension direction, m/s^2 (-9.81 for
        a vertical cylinder whose rod extends upwards).
    ambient_pressure : float
        Absolute pressure on the vented side and the rod's outer end, Pa.
    """

    bore_diameter: float
    rod_diameter: float
    stroke: float
    moving_mass: float
    pressurised_side: str = "bore"
    chamber_dead_volume: float = 0.01
    gravity_along_rod: float = 0.0
    ambient_pressure: float = 101325.0

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out: list[str] = []
        check_positive("bore_diameter", self.bore_diameter, out, "m")
        check_positive("rod_diameter", self.rod_diameter, out, "m")
        check_positive("stroke", self.stroke, out, "m")
        check_positive("moving_mass", self.moving_mass, out, "kg")
        check_positive("chamber_dead_volume", self.chamber_dead_volume, out, "m3", zero_ok=True)
        check_positive("ambient_pressure", self.ambient_pressure, out, "Pa", zero_ok=True)
        if self.rod_diameter >= self.bore_diameter > 0.0:
            out.append(
                f"parameter 'rod_diameter' ({self.rod_diameter} m) must be smaller than "
                f"'bore_diameter' ({self.bore_diameter} m)"
            )
        if self.pressurised_side not in ("bore", "annulus"):
            out.append(
                "parameter 'pressurised_side' must be 'bore' (push cylinder) or "
                f"'annulus' (pull cylinder), got {self.pressurised_side!r}"
            )
        if not math.isfinite(self.gravity_along_rod):
            out.append(
                f"parameter 'gravity_along_rod' must be finite, got {self.gravity_along_rod}"
            )
        return out

    @property
    def piston_area(self) -> float:
        """``pi D^2 / 4``, m^2."""
        return 0.25 * math.pi * self.bore_diameter**2

    @property
    def annulus_area(self) -> float:
        """``pi (D^2 - d^2) / 4``, m^2."""
        return 0.25 * math.pi * (self.bore_diameter**2 - self.rod_diameter**2)

    @property
    def working_area(self) -> float:
        """Area of the pressurised side, m^2."""
        return self.piston_area if self.pressurised_side == "bore" else self.annulus_area

    @property
    def sign(self) -> float:
        """+1 if the oil pushes the rod out (bore side), -1 if it pulls it in."""
        return 1.0 if self.pressurised_side == "bore" else -1.0

    def chamber_volume(self, x: float) -> float:
        """Oil volume of the pressurised chamber at extension ``x`` (m), m^3.

        Parameters
        ----------
        x : float
            Rod extension, m.
        """
        length = x if self.pressurised_side == "bore" else self.stroke - x
        return self.chamber_dead_volume + self.working_area * length


@dataclass(frozen=True)
class AccumulatorSpec:
    """Accumulator and gas bank.

    Parameters
    ----------
    accumulator_volume : float
        Total volume of the accumulator (gas plus oil side), m^3.
    gas_bank_volume : float
        Volume of the air pressure vessels on its gas side, m^3.
    accumulator_dead_volume : float
        Gas left in the accumulator when it is full of oil, m^3.
    precharge_pressure : float
        Absolute gas pressure with no oil in the accumulator, Pa.
    polytropic_exponent : float
        ``n`` used with the effect ``polytropic_gas``, 1.
    """

    accumulator_volume: float
    gas_bank_volume: float
    accumulator_dead_volume: float
    precharge_pressure: float
    polytropic_exponent: float = 1.4

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out: list[str] = []
        check_positive("accumulator_volume", self.accumulator_volume, out, "m3")
        check_positive("gas_bank_volume", self.gas_bank_volume, out, "m3", zero_ok=True)
        check_positive(
            "accumulator_dead_volume", self.accumulator_dead_volume, out, "m3", zero_ok=True
        )
        check_positive("precharge_pressure", self.precharge_pressure, out, "Pa")
        if self.accumulator_dead_volume >= self.accumulator_volume > 0.0:
            out.append(
                "parameter 'accumulator_dead_volume' must be smaller than 'accumulator_volume'"
            )
        if not self.dead_volume > 0.0:
            out.append(
                "the gas needs a dead volume > 0 m3: set 'gas_bank_volume' or "
                "'accumulator_dead_volume' > 0 (gas cannot be compressed to nothing)"
            )
        if not (1.0 <= self.polytropic_exponent <= 2.0):
            out.append(
                "parameter 'polytropic_exponent' must lie in [1, 2] (1 isothermal, "
                f"1.4 adiabatic), got {self.polytropic_exponent}"
            )
        return out

    @property
    def full_volume(self) -> float:
        """Gas volume with the accumulator empty of oil, m^3."""
        return self.accumulator_volume + self.gas_bank_volume

    @property
    def dead_volume(self) -> float:
        """Gas volume with the accumulator full of oil, m^3."""
        return self.accumulator_dead_volume + self.gas_bank_volume


@dataclass(frozen=True)
class OilSpec:
    """Oil properties beyond those of the line.

    Parameters
    ----------
    bulk_modulus : float
        Effective bulk modulus, Pa.
    volume : float
        Oil volume whose compressibility is modelled, m^3; 0 means the
        chamber at the initial position plus the line.
    cavitation_pressure : float
        Absolute pressure below which the oil column would cavitate, Pa.
    """

    bulk_modulus: float = 1.5e9
    volume: float = 0.0
    cavitation_pressure: float = 1.0e4

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out: list[str] = []
        check_positive("bulk_modulus", self.bulk_modulus, out, "Pa")
        check_positive("oil_volume", self.volume, out, "m3", zero_ok=True)
        check_positive("cavitation_pressure", self.cavitation_pressure, out, "Pa", zero_ok=True)
        return out


@dataclass(frozen=True)
class HydraulicsSpec:
    """Everything physical about one cylinder-accumulator unit."""

    cylinder: CylinderSpec
    accumulator: AccumulatorSpec
    line: HydraulicLine
    oil: OilSpec
    seal: SealSpec
    stops: EndStopSpec

    def problems(self) -> list[str]:
        """Every problem with every part, as sentences."""
        return (
            self.cylinder.problems()
            + self.accumulator.problems()
            + self.line.problems()
            + self.oil.problems()
            + self.seal.problems()
            + self.stops.problems(self.cylinder.stroke)
        )
