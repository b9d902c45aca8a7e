"""The unit of every column of a results file (``metadata.json``'s ``column_units``).

A unit variable's column is in the unit its FMU declares for the variable, read
through FMI (the model description): the variable's own ``unit``, else that of
its declared type. An Integer, Boolean or Enumeration column holds a count, a
state, a mode or a flag, a pure number: :data:`DIMENSIONLESS`. A String column
holds text: :data:`TEXT`. A Real whose FMU declares no unit at all (an FMU not
ours) is :data:`UNDECLARED`.

The master's own columns are in the units the master defines them in:
``time`` in s, each bond's energy channels in J and its power in W, the sum of
the units' ledgers in J.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

__all__ = [
    "TIME_UNIT",
    "BOND_CHANNEL_UNITS",
    "LEDGER_UNIT",
    "DIMENSIONLESS",
    "TEXT",
    "UNDECLARED",
    "variable_unit",
    "ledger_unit_problems",
]

logger = logging.getLogger(__name__)

TIME_UNIT = "s"
"""Unit of the ``time`` column (simulated time)."""

BOND_CHANNEL_UNITS: Mapping[str, str] = MappingProxyType(
    {"energy_residual": "J", "energy_carried": "J", "power": "W"}
)
"""Unit of each bond channel ``bond.<name>.<channel>``, by channel."""

LEDGER_UNIT = "J"
"""Unit of the sum of the units' ``energy_balance`` outputs."""

DIMENSIONLESS = "1"
"""Unit of a pure number: a count, a state or mode, a flag (FMI's symbol for no dimension)."""

TEXT = "text"
"""Marker of a column of text (a String variable): no unit applies."""

UNDECLARED = ""
"""Marker of a Real column whose FMU declares no unit for the variable."""

_NUMBERS = frozenset({"Integer", "Boolean", "Enumeration"})


def variable_unit(variable: Any) -> str:
    """The unit of a variable as its FMU declares it.

    Parameters
    ----------
    variable : fmpy.model_description.ScalarVariable
        The variable, from the FMU's model description.

    Returns
    -------
    str
        The variable's ``unit`` (a Real's; else its declared type's);
        :data:`DIMENSIONLESS` for an Integer, Boolean or Enumeration,
        :data:`TEXT` for a String, :data:`UNDECLARED` for a Real without a unit.
    """
    if variable.type in _NUMBERS:
        return DIMENSIONLESS
    if variable.type == "String":
        return TEXT
    declared = getattr(variable, "declaredType", None)
    unit = getattr(variable, "unit", None) or getattr(declared, "unit", None)
    return unit or UNDECLARED


def ledger_unit_problems(ledgers: Mapping[str, Any]) -> list[str]:
    """Units whose ``energy_balance`` is not in :data:`LEDGER_UNIT`, so their sum is not either.

    Parameters
    ----------
    ledgers : mapping of str to ScalarVariable
        Each summed unit's ``energy_balance`` variable, by unit name.

    Returns
    -------
    list of str
        One sentence per unit whose ledger is declared in another unit; empty if none.
    """
    return [
        f"unit {name!r} declares its energy_balance in {variable_unit(v)!r}, "
        f"not {LEDGER_UNIT!r}: the sum of the ledgers is wrong by that factor"
        for name, v in ledgers.items()
        if variable_unit(v) != LEDGER_UNIT
    ]
