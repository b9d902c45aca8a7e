"""Engineering units for plot axes: tension in kN, pressure in MPa, energy in kJ or MJ.

Results are recorded in SI units (N, Pa, J, W, N.m). A plot shows them in the
unit an engineer reads: :func:`display_unit` picks a multiple by the largest
magnitude on the axis, and :func:`pretty_unit` writes the symbol as it is
printed (``N·m``, ``m³``, ``m/s²``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

__all__ = ["DisplayUnit", "display_unit", "pretty_unit"]


@dataclass(frozen=True)
class DisplayUnit:
    """A unit to show values in.

    Attributes
    ----------
    label : str
        The unit as printed (``"kN"``, ``"MPa"``, ``""`` for a pure number).
    factor : float
        Size of one display unit in the recorded unit: shown = recorded / factor.
    """

    label: str
    factor: float = 1.0

    def show(self, value: float) -> float:
        """``value`` (recorded unit) in this unit.

        Parameters
        ----------
        value : float
            A value in the recorded unit.
        """
        return value / self.factor


# Multiples by recorded unit: (smallest magnitude the multiple is used from, factor, symbol),
# largest first. Forces and torques stay in kN (kN·m) up to 10 MN: the unit of the trade.
_MULTIPLES: dict[str, tuple[tuple[float, float, str], ...]] = {
    "N": ((1e7, 1e6, "MN"), (1e3, 1e3, "kN")),
    "N.m": ((1e7, 1e6, "MN.m"), (1e3, 1e3, "kN.m")),
    "Pa": ((1e5, 1e6, "MPa"), (1e3, 1e3, "kPa")),
    "J": ((1e9, 1e9, "GJ"), (1e6, 1e6, "MJ"), (1e3, 1e3, "kJ")),
    "W": ((1e9, 1e9, "GW"), (1e6, 1e6, "MW"), (1e3, 1e3, "kW")),
    "N/m": ((1e6, 1e6, "MN/m"), (1e3, 1e3, "kN/m")),
}

_POWERS = {"2": "²", "3": "³", "4": "⁴", "-1": "⁻¹", "-2": "⁻²"}
_POWER = re.compile(r"(?<=[A-Za-z])(-?[234]|-1)\b")


def display_unit(unit: str, largest: float) -> DisplayUnit:
    """The unit to show values of ``unit`` in, whose largest magnitude is ``largest``.

    Parameters
    ----------
    unit : str
        The recorded unit (``"N"``, ``"Pa"``, ``"J"``, ...; ``"1"`` a pure number).
    largest : float
        The largest magnitude to be shown, in ``unit`` (NaN or 0: none).

    Returns
    -------
    DisplayUnit
        A multiple of ``unit`` for forces, torques, pressures, energies,
        powers and stiffnesses (tension in kN, pressure in MPa from 0.1 MPa);
        ``unit`` itself otherwise, printed with :func:`pretty_unit`.
    """
    size = abs(largest) if math.isfinite(largest) else 0.0
    for least, factor, symbol in _MULTIPLES.get(unit, ()):
        if size >= least:
            return DisplayUnit(pretty_unit(symbol), factor)
    if unit == "Pa" and size == 0.0:
        return DisplayUnit("MPa", 1e6)
    return DisplayUnit(pretty_unit(unit), 1.0)


def pretty_unit(unit: str) -> str:
    """A unit symbol as printed: ``N.m`` as ``N·m``, ``m3`` as ``m³``; a pure number as ``""``.

    Parameters
    ----------
    unit : str
        A unit as the FMUs declare it (``"N.m"``, ``"kg.m2"``, ``"m/s2"``, ``"1"``).

    Returns
    -------
    str
        The symbol to print; empty for ``"1"`` and for no unit.
    """
    if unit in ("1", "", "text"):
        return ""
    text = _POWER.sub(lambda m: _POWERS[m.group(1)], unit)
    return text.replace(".", "·")
