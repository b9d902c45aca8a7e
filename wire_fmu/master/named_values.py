"""A unit's variables set and read by name, every value checked against its FMI type.

:class:`NamedValues` is the part of :class:`~wire_fmu.master.slave.Slave` that
sets values by variable name (parameters, start values, values a driver or an
event sets by name), grouped into one call per FMI type, and reads values by
name. :func:`value_problem` says what is wrong with a value for a variable: no
value is converted silently.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from .unit_errors import UnitFailedError

__all__ = ["NamedValues", "value_problem"]


class NamedValues:
    """Setting and reading variables by name (a mixin of the slave).

    The slave provides ``name``, ``variables``, ``vr``, ``get_typed`` and ``_call``.
    """

    def set_many(self, values: dict[str, Any]) -> None:
        """Set variables by name, grouped by type.

        Parameters
        ----------
        values : dict of str to object
            Value by variable name, in the variable's unit: a number, a
            boolean or text as the variable's type takes (checked, see
            :func:`value_problem`; a float for a Real is passed as is).

        Raises
        ------
        UnitFailedError
            For an unknown variable, a value its type cannot take, or an FMI error.
        """
        self.set_typed(self.typed_values(values))

    def typed_values(self, values: dict[str, Any]) -> dict[str, tuple[list[int], list[Any]]]:
        """Values by name as value references and checked values, grouped by FMI type.

        Parameters
        ----------
        values : dict of str to object
            Value by variable name, in the variable's unit, as for :meth:`set_many`.

        Returns
        -------
        dict of str to (list of int, list of object)
            For each FMI type (``"Real"``, ``"Integer"``, ...), in the order the
            types first appear: the value references and their values (a Real
            as a float).

        Raises
        ------
        UnitFailedError
            For an unknown variable or a value its type cannot take.
        """
        groups: dict[str, tuple[list[int], list[Any]]] = defaultdict(lambda: ([], []))
        for name, value in values.items():
            var = self.variables.get(name)
            if var is None:
                raise UnitFailedError(f"unit {self.name!r} has no variable {name!r}", self.name)
            refs, vals = groups[var.type]
            refs.append(var.valueReference)
            if type(value) is float and var.type == "Real":  # per step (drivers): the FMU
                vals.append(value)  # itself refuses a value that is not finite
                continue
            problem = value_problem(var, value)
            if problem:
                raise UnitFailedError(
                    f"unit {self.name!r}: {name} = {value!r}: {problem}", self.name
                )
            vals.append(float(value) if var.type == "Real" else value)
        return dict(groups)

    def set_typed(self, groups: dict[str, tuple[Sequence[int], Sequence[Any]]]) -> None:
        """Set values grouped by FMI type, one call per type.

        Parameters
        ----------
        groups : dict of str to (sequence of int, sequence of object)
            For each FMI type, value references and checked values (see
            :meth:`typed_values`), in the variables' units.
        """
        for kind, (refs, vals) in groups.items():
            if refs:
                self._call(f"set{kind}", list(refs), list(vals))

    def get(self, names: Iterable[str]) -> dict[str, Any]:
        """Values of variables by name.

        Parameters
        ----------
        names : iterable of str
            Variables of the FMU.

        Returns
        -------
        dict of str to object
            Each value by name, of the variable's type and in its unit.
        """
        out = {}
        by_type: dict[str, list[str]] = defaultdict(list)
        for name in names:
            by_type[self.variables[name].type].append(name)
        for kind, group in by_type.items():
            values = self.get_typed(kind, [self.vr(n) for n in group])
            out.update(zip(group, values, strict=True))
        return out


_INT32 = (-(2**31), 2**31 - 1)
_KINDS = (
    (bool, "a boolean"),
    (int | float, "a number"),
    (str, "text"),
    (list, "a list"),
    (Mapping, "a table"),
)
"""What a value of a scene file is, as the problems name it (a boolean before the numbers)."""


def _value_kind(value: Any) -> str:
    """What ``value`` is, as a scene file writes it: ``"a list"``, ``"a table"``, ``"text"``.

    Parameters
    ----------
    value : object
        A value as TOML reads it (or as a Python caller passes it).

    Returns
    -------
    str
        ``"a boolean"``, ``"a number"``, ``"text"``, ``"a list"``, ``"a table"``, else the
        type's name.
    """
    for kind, words in _KINDS:
        if isinstance(value, kind):
            return words
    return type(value).__name__


def value_problem(variable, value) -> str | None:
    """What is wrong with ``value`` for an FMI ``variable`` (None if nothing).

    No value is converted silently: a Real takes a finite number, an Integer
    a whole number within 32 bits, a Boolean true or false, a String text.

    Parameters
    ----------
    variable : fmpy.model_description.ScalarVariable
        The variable (its ``type`` and ``causality``).
    value : object
        The value to set.

    Returns
    -------
    str or None
        The problem, e.g. ``"expected a finite number (Real)"``; None if none.
    """
    kind = variable.type
    if kind == "Real":
        if isinstance(value, bool) or not isinstance(value, int | float):
            return f"expected a number (Real), got {_value_kind(value)}"
        if value != value or (variable.causality == "input" and not math.isfinite(value)):
            return "expected a finite number (Real)"
        if isinstance(value, int) and abs(value) > 1.7976931348623157e308:
            return "too large for a Real"
    elif kind in ("Integer", "Enumeration"):
        if isinstance(value, bool) or not isinstance(value, int):
            return f"expected a whole number ({kind}), got {value!r}"
        if not _INT32[0] <= value <= _INT32[1]:
            return f"outside the 32-bit range of an {kind} ({_INT32[0]} to {_INT32[1]})"
    elif kind == "Boolean":
        if not isinstance(value, bool):
            return f"expected true or false (Boolean), got {_value_kind(value)} {value!r}"
    elif kind == "String" and not isinstance(value, str):
        return f"expected text (String), got {_value_kind(value)}"
    return None
