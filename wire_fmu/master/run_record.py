"""What ``metadata.json`` keeps of the scene that ran, so that a results folder explains itself.

A run's plots, its report (:mod:`wire_fmu.master.report`) and a colleague
reading the folder need more than the table: which FMU each unit is, with
which effects and parameter values, what happened when (the scheduled
events), what drove the inputs, and which plots the scene asks for.
:func:`scene_record` gives that as JSON-ready data:

``units``
    ``{unit: {"fmu", "effects", "parameters"}}``; ``parameters`` maps every
    parameter of the unit's FMU to ``{"value", "unit", "given"}``: the value
    the scene gave (``given`` true; a table such as a block train's
    ``reeving`` as the table) or else the FMU's declared start value, in the
    variable's unit (``"1"`` a pure number, ``"text"`` a String, ``""`` a Real
    without a declared unit).
``events``
    ``[{"time", "label", "set"}]``: time in s, the values by ``unit.variable``.
``drivers``
    ``[{"target", "kind", "label"}]``.
``plots``
    ``[{"title", "ylabel", "variables"}]`` as the scene lists them.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from .column_units import variable_unit
from .scene import Scene

__all__ = ["scene_record", "declared_start"]


def scene_record(scene: Scene, descriptions: Mapping[str, Any]) -> dict[str, Any]:
    """The scene as ``metadata.json`` keeps it (see the module docstring).

    Parameters
    ----------
    scene : Scene
        The scene that runs.
    descriptions : mapping of str to fmpy.model_description.ModelDescription
        Each unit's model description, by unit name.

    Returns
    -------
    dict
        ``units``, ``events``, ``drivers`` and ``plots``, JSON-ready.
    """
    return {
        "units": {
            name: {
                "fmu": spec.fmu,
                "effects": list(spec.effects),
                "parameters": _parameters(spec.parameters, descriptions.get(name)),
            }
            for name, spec in scene.units.items()
        },
        "events": [
            {"time": e.time, "label": e.label, "set": {str(k): v for k, v in e.values.items()}}
            for e in scene.events
        ],
        "drivers": [
            {"target": str(d.target), "kind": str(d.spec.get("kind", "")), "label": d.label}
            for d in scene.drivers
        ],
        "plots": [
            {"title": p.title, "ylabel": p.ylabel, "variables": [str(r) for r in p.variables]}
            for p in scene.plots
        ],
    }


def _parameters(given: Mapping[str, Any], model: Any) -> dict[str, dict[str, Any]]:
    """Every parameter of the FMU, with the scene's value where it gives one."""
    out: dict[str, dict[str, Any]] = {}
    variables = {} if model is None else {v.name: v for v in model.modelVariables}
    for name, variable in variables.items():
        if variable.causality == "parameter":
            out[name] = {
                "value": declared_start(variable),
                "unit": variable_unit(variable),
                "given": False,
            }
    for name, value in given.items():
        variable = variables.get(name)
        unit = variable_unit(variable) if variable is not None else ""
        out[name] = {"value": _plain(value), "unit": unit, "given": True}
    return out


def declared_start(variable: Any) -> Any:
    """A variable's declared start value as a number, a flag or text (None if it has none).

    Parameters
    ----------
    variable : fmpy.model_description.ScalarVariable
        The variable.

    Returns
    -------
    float, int, bool, str or None
        The start value by the variable's type.
    """
    start = variable.start
    if start is None:
        return None
    try:
        if variable.type == "Real":
            return float(start)
        if variable.type in ("Integer", "Enumeration"):
            return int(start)
        if variable.type == "Boolean":
            return start if isinstance(start, bool) else str(start).lower() in ("true", "1")
    except (TypeError, ValueError):
        return str(start)
    return str(start)


def _plain(value: Any) -> Any:
    """A scene value as JSON data (tables and lists kept; anything else as text)."""
    try:
        json.dumps(value)
    except (TypeError, ValueError):
        return str(value)
    return value
