"""Reference lines for plotted outputs, read from the parameters of the run.

What an engineer holds a curve against is usually a parameter of the unit
that computes it. :func:`references` finds, for one recorded column:

========================================  =========================================
column                                    references
========================================  =========================================
a rope tension (``<unit>.<end>.tension``,  the rope's breaking load (``reeving``:
``<unit>.tension_max``)                    ``rope.breaking_load``); the set tension
                                          (``pretension``) when the rope does not
                                          start from block equilibrium
a block's position (``<unit>.<port>.      the floor it lands on (``reeving``: the
position``)                               body on that port, ``floor.position``)
a cylinder's rod extension                0 and the ``stroke`` (the end stops)
(``<unit>.rod.position``)
``<unit>.stroke_used``                    0 and 1
========================================  =========================================

Parameters are given as ``metadata.json`` keeps them
(:mod:`~wire_fmu.master.run_record`): by unit, by name, ``{"value", "unit",
"given"}``. A parameter the run does not have gives no line.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["Reference", "references"]

Parameters = Mapping[str, Mapping[str, Mapping[str, Any]]]
"""Parameters by unit and name, each ``{"value", "unit", "given"}``."""


@dataclass(frozen=True)
class Reference:
    """A horizontal reference line.

    Attributes
    ----------
    label : str
        What it is (``"breaking load"``).
    value : float
        Where, in the column's unit.
    source : str
        The parameter it comes from (``"rope.reeving: rope.breaking_load"``).
    kind : str
        ``"limit"`` (a bound: stroke ends, breaking load, a floor) or
        ``"set"`` (a set point).
    """

    label: str
    value: float
    source: str
    kind: str = "limit"


def references(column: str, parameters: Parameters) -> list[Reference]:
    """The reference lines of a recorded column.

    Parameters
    ----------
    column : str
        ``unit.variable`` as recorded.
    parameters : mapping
        The run's parameters by unit and name (see the module docstring).

    Returns
    -------
    list of Reference
        In the column's unit; empty when none applies.
    """
    unit, _, variable = column.partition(".")
    own = parameters.get(unit) or {}
    found: list[Reference] = []
    reeving = _table(_value(own, "reeving"))
    if variable.endswith(".tension") or variable == "tension_max":
        found += _tension(unit, own, reeving)
    if variable.endswith(".position") and reeving:
        found += _floor(unit, variable.removesuffix(".position"), reeving)
    if variable == "rod.position":
        stroke = _number(_value(own, "stroke"))
        if stroke is not None:
            found += [
                Reference("fully retracted", 0.0, f"{unit}.stroke"),
                Reference("full stroke", stroke, f"{unit}.stroke"),
            ]
    if variable == "stroke_used":
        found += [
            Reference("fully retracted", 0.0, f"{unit}.stroke"),
            Reference("full stroke", 1.0, f"{unit}.stroke"),
        ]
    return found


def _tension(unit: str, own: Mapping[str, Any], reeving: dict[str, Any]) -> list[Reference]:
    found = []
    rope = reeving.get("rope") if isinstance(reeving.get("rope"), dict) else {}
    breaking = _number(rope.get("breaking_load"))
    if breaking is not None:
        found.append(Reference("breaking load", breaking, f"{unit}.reeving: rope.breaking_load"))
    pretension = _number(_value(own, "pretension"))
    if pretension is not None and _value(own, "initial_equilibrium") is False:
        found.append(Reference("set tension", pretension, f"{unit}.pretension", "set"))
    return found


def _floor(unit: str, port: str, reeving: dict[str, Any]) -> list[Reference]:
    bodies = reeving.get("bodies") if isinstance(reeving.get("bodies"), dict) else {}
    for name, body in bodies.items():
        if isinstance(body, dict) and body.get("port") == port:
            floor = body.get("floor") if isinstance(body.get("floor"), dict) else {}
            level = _number(floor.get("position"))
            if level is not None:
                source = f"{unit}.reeving: bodies.{name}.floor.position"
                return [Reference("floor (the block lands)", level, source)]
    return []


def _value(own: Mapping[str, Any], name: str) -> Any:
    entry = own.get(name)
    return entry.get("value") if isinstance(entry, Mapping) else None


def _table(value: Any) -> dict[str, Any]:
    """A table parameter (a reeving): as given, or parsed from its JSON text."""
    if isinstance(value, str):
        try:
            value = json.loads(value)
        except ValueError:
            return {}
    return value if isinstance(value, dict) else {}


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None
