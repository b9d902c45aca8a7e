"""What a scene sets that its chosen effects, or its units' parameters, leave without influence.

A scene may set a parameter, a key of a structured parameter (a sheave's
``efficiency`` in a reeving) or an input (by an event, a driver or a
connection) that acts only with an effect the unit does not include, or only
with a setting of another parameter (the scissor jack's handle torque acts only
with ``handle_drive = "torque"``): the value is then silently ignored. A value
equal to the declared default is not reported: the scene asks for nothing the
unit does not do. :func:`inactive_settings` finds each one from
the units' declarations (``acts_with``/``acts_without``/``acts_when`` on
:class:`~wire_fmu.core.framework.variables.Variable`, ``acts_with``/``acts_without``
on :class:`~wire_fmu.core.framework.data_fields.DataField`), naming the unit, the
setting and the effect or parameter setting that would make it act. Only our unit
types declare this; units given as FMU files are passed over.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

from wire_fmu.master.scene import Scene
from wire_fmu.registry import BY_NAME
from wire_fmu.unit_reference.catalogue import (
    Entry,
    UnitReference,
    condition_text,
    settings_text,
    unit_reference,
)

__all__ = ["inactive_settings", "scene_file_warnings"]

_SHOWN = 4
"""Places of one key named in a warning; more are counted."""


def inactive_settings(scene: Scene) -> list[str]:
    """Every setting of ``scene`` that its units' effects leave without influence.

    Parameters
    ----------
    scene : Scene
        The scene (parsed; it need not be valid as a whole).

    Returns
    -------
    list of str
        One warning per unit and setting (a structured parameter's key once,
        with the places it is set), each naming the unit, what is set, the
        effects chosen and the effect that would make it act.
    """
    warnings: list[str] = []
    for name, spec in scene.units.items():
        if spec.fmu not in BY_NAME:
            continue
        ref = unit_reference(spec.fmu)
        effects = frozenset(spec.effects)
        settings = {**{p.name: p.value for p in ref.parameters}, **spec.parameters}
        for key, value in spec.parameters.items():
            entry = ref.entry(key)
            if entry is not None and not entry.is_default(value):
                what = f"parameter {key!r}"
                warnings += _silenced(name, ref, effects, settings, what, entry)
            for field, places in _fields_set(ref.fields.get(key, ()), value):
                if not field.acts(effects):
                    where = _places([p for p in places if p])
                    what = f"{key} key {field.name!r}" + (f" ({where})" if where else "")
                    warnings.append(_warning(name, ref, effects, what, field))
        warnings += _inputs_set(scene, name, ref, effects, settings)
    return warnings


def _silenced(
    unit: str,
    ref: UnitReference,
    effects: frozenset[str],
    settings: Mapping[str, Any],
    what: str,
    entry: Entry,
) -> list[str]:
    """The warning that ``what`` has no influence with the unit's effects or with its
    parameters (``settings``, by name), or none."""
    if not entry.acts(effects):
        return [_warning(unit, ref, effects, what, entry)]
    if not entry.acts_with_parameters(settings):
        return [_settings_warning(unit, settings, what, entry)]
    return []


def _warning(unit: str, ref: UnitReference, effects: frozenset[str], what: str, entry) -> str:
    chosen = ", ".join(sorted(effects)) or "none"
    condition = condition_text(ref.effects, entry.acts_with, entry.acts_without)
    return (
        f"unit {unit!r}: {what} has no influence with its effects ({chosen}): it {condition}; "
        "change the effects or leave it out"
    )


def _settings_warning(unit: str, settings: Mapping[str, Any], what: str, entry: Entry) -> str:
    """``what`` has no influence with the unit's parameters so set (``settings``, by name)."""
    unmet = tuple((p, (settings[p],)) for p, values in entry.acts_when if settings[p] not in values)
    names = " and ".join(p for p, _ in unmet)
    return (
        f"unit {unit!r}: {what} has no influence with {settings_text(unmet)}: it acts only "
        f"with {settings_text(entry.acts_when)}; change {names} or leave it out"
    )


def _places(places: list[str]) -> str:
    shown = ", ".join(places[:_SHOWN])
    more = len(places) - _SHOWN
    return shown + (f" and {more} more" if more > 0 else "")


def _inputs_set(
    scene: Scene,
    unit: str,
    ref: UnitReference,
    effects: frozenset[str],
    settings: Mapping[str, Any],
) -> list[str]:
    """Inputs of ``unit`` that events, drivers or connections set without influence (with
    its effects, or with its parameters: ``settings``, by name)."""
    setters: dict[str, list[str]] = {}
    for event in scene.events:
        for target in event.values:
            setters.setdefault(str(target), []).append(f"event {event.label!r}")
    for driver in scene.drivers:
        for target in (driver.target, driver.rate_target):
            if target is not None:
                setters.setdefault(str(target), []).append(f"driver {driver.label!r}")
    for connection in scene.all_connections:
        setters.setdefault(str(connection.target), []).append(
            f"connection from {connection.source}"
        )
    out = []
    for item in ref.inputs:
        who = setters.get(f"{unit}.{item.name}")
        if who:
            what = f"input {item.name!r} (set by {', '.join(dict.fromkeys(who))})"
            out += _silenced(unit, ref, effects, settings, what, item)
    return out


def _fields_set(fields: Iterable[Entry], value: Any) -> Iterator[tuple[Entry, list[str]]]:
    """Each declared field that ``value`` (a table, or its JSON text) sets to other than its
    default, with where."""
    data = _table(value)
    if data is None:
        return
    for field in fields:
        places = [
            where
            for where, value in _where(data, field.name.split("."), [])
            if not field.is_default(value)
        ]
        if places:
            yield field, places


def _table(value: Any) -> Mapping | None:
    if isinstance(value, str):
        try:
            value = json.loads(value)
        except ValueError:
            return None  # not JSON: the unit's own check says so
    return value if isinstance(value, Mapping) else None


def _where(data: Any, parts: list[str], at: list[str]) -> Iterator[tuple[str, Any]]:
    """Where in ``data`` the dotted ``parts`` are set, and to what: the entries (``crown_0``)
    and nodes (``path[3]``) standing for ``<name>`` and ``[i]``, empty for a fixed key."""
    if not parts:
        yield "/".join(at), data
        return
    head, rest = parts[0], parts[1:]
    if not isinstance(data, Mapping):
        return
    if head == "<name>":
        for key, item in data.items():
            yield from _where(item, rest, at + [str(key)])
    elif head.endswith("[i]"):
        items = data.get(head[:-3])
        if isinstance(items, list):
            for i, item in enumerate(items):
                yield from _where(item, rest, at + [f"{head[:-3]}[{i}]"])
    elif head in data:
        yield from _where(data[head], rest, at)


def scene_file_warnings(name_or_path: str) -> list[str]:
    """:func:`inactive_settings` of a shipped scene, a scene file or an SSP package.

    Parameters
    ----------
    name_or_path : str
        What ``wire-fmu run`` takes.

    Returns
    -------
    list of str
        The warnings; none when the scene cannot be read (the run then says why).
    """
    from wire_fmu.core.errors import WireFmuError
    from wire_fmu.master.run import find_scene, load_scene_file

    try:
        scene = load_scene_file(find_scene(name_or_path))
    except WireFmuError:
        return []
    return inactive_settings(scene)
