"""SI definitions of the units this project's FMUs use (FMI 2.0 ``BaseUnit``).

A value in unit ``u`` converts to SI base units as
``value_SI = factor * value + offset``, with the dimension given by the
exponents of kg, m, s, A, K, mol, cd and rad (FMI 2.0 spec, section 2.2.2).
An FMU may only use units listed here; add a row to extend the table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = ["DisplayUnit", "UnitDefinition", "UNITS", "unit_definition"]

_BASE_NAMES = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


@dataclass(frozen=True)
class DisplayUnit:
    """A unit for display: ``display = factor * value + offset``."""

    name: str
    factor: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class UnitDefinition:
    """One FMI unit: SI exponents, factor/offset, optional display units."""

    name: str
    exponents: dict[str, int] = field(default_factory=dict)
    factor: float = 1.0
    offset: float = 0.0
    display: tuple[DisplayUnit, ...] = ()

    def __post_init__(self) -> None:
        unknown = set(self.exponents) - set(_BASE_NAMES)
        if unknown:
            raise ValueError(f"unit {self.name!r}: unknown base units {sorted(unknown)}")

    def base_unit_attributes(self) -> dict[str, str]:
        """Attributes of the ``BaseUnit`` element (only non-default ones)."""
        attrs = {k: str(v) for k in _BASE_NAMES if (v := self.exponents.get(k, 0))}
        if self.factor != 1.0:
            attrs["factor"] = repr(self.factor)
        if self.offset != 0.0:
            attrs["offset"] = repr(self.offset)
        return attrs


def _u(name: str, display: tuple[DisplayUnit, ...] = (), factor: float = 1.0, **exps: int):
    return UnitDefinition(name, dict(exps), factor=factor, display=display)


_DEG = DisplayUnit("deg", 180.0 / math.pi)
_RPM = DisplayUnit("rpm", 30.0 / math.pi)

UNITS: dict[str, UnitDefinition] = {
    d.name: d
    for d in (
        _u("1"),
        _u("s", s=1),
        _u("1/s", s=-1),
        _u("Hz", s=-1),
        _u("m", (DisplayUnit("mm", 1e3),), m=1),
        _u("mm", factor=1e-3, m=1),
        _u("m/s", (DisplayUnit("km/h", 3.6),), m=1, s=-1),
        _u("m/s2", m=1, s=-2),
        _u("m2", m=2),
        _u("m3", (DisplayUnit("l", 1e3),), m=3),
        _u("m3/s", (DisplayUnit("l/min", 6e4),), m=3, s=-1),
        _u("rad", (_DEG,), rad=1),
        _u("rad/s", (_RPM,), rad=1, s=-1),
        _u("rad/s2", rad=1, s=-2),
        _u("kg", (DisplayUnit("t", 1e-3),), kg=1),
        _u("kg.m2", kg=1, m=2),
        _u("kg/s", kg=1, s=-1),
        _u("kg/m3", kg=1, m=-3),
        _u("kg/m", kg=1, m=-1),
        _u("N", (DisplayUnit("kN", 1e-3),), kg=1, m=1, s=-2),
        _u("kN", factor=1e3, kg=1, m=1, s=-2),
        _u("N.s", kg=1, m=1, s=-1),
        _u("N/s", (DisplayUnit("kN/s", 1e-3),), kg=1, m=1, s=-3),
        _u("N/m", kg=1, s=-2),
        _u("N.s/m", kg=1, s=-1),
        _u("N.s2/m2", kg=1, m=-1),  # quadratic damping (hydraulic cushion F = c v^2)
        _u("N.m", (DisplayUnit("kN.m", 1e-3),), kg=1, m=2, s=-2),
        _u("N.m.s", kg=1, m=2, s=-1),
        _u("N.m/rad", kg=1, m=2, s=-2, rad=-1),
        _u("N.m.s/rad", kg=1, m=2, s=-1, rad=-1),
        _u("Pa", (DisplayUnit("bar", 1e-5), DisplayUnit("MPa", 1e-6)), kg=1, m=-1, s=-2),
        _u("bar", factor=1e5, kg=1, m=-1, s=-2),
        _u("Pa.s", kg=1, m=-1, s=-1),
        _u("Pa.s/m3", kg=1, m=-4, s=-1),
        _u("m3/(Pa.s)", kg=-1, m=4, s=1),
        _u("m3/Pa", kg=-1, m=4, s=2),
        _u("Pa/m3", kg=1, m=-4, s=-2),
        _u("J", (DisplayUnit("kJ", 1e-3),), kg=1, m=2, s=-2),
        _u("W", (DisplayUnit("kW", 1e-3),), kg=1, m=2, s=-3),
        _u("K", (DisplayUnit("degC", 1.0, -273.15),), K=1),
        _u("J/K", kg=1, m=2, s=-2, K=-1),
        _u("J/(kg.K)", m=2, s=-2, K=-1),
        _u("J/(mol.K)", kg=1, m=2, s=-2, K=-1, mol=-1),
        _u("mol", mol=1),
        _u("m2/s", m=2, s=-1),
        _u("A", A=1),
        _u("V", kg=1, m=2, s=-3, A=-1),
    )
}
"""Every unit an FMU of this project may declare, by FMI unit name."""


def unit_definition(name: str) -> UnitDefinition:
    """The definition of unit ``name``.

    Parameters
    ----------
    name : str
        FMI unit name, e.g. ``"N.m"``.

    Raises
    ------
    KeyError
        If ``name`` is not in :data:`UNITS`; the message lists the known units.
    """
    try:
        return UNITS[name]
    except KeyError:
        known = ", ".join(sorted(UNITS))
        raise KeyError(f"unit {name!r} is not defined; known units: {known}") from None
