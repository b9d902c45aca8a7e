"""Parsers of the scene file's sections: units, bonds, connections, drivers, events,
outputs, plots and run settings; each collects its problems and goes on."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from .checks import MAX_TIME, _check_run, _finite, is_scalar
from .data import (
    EXTRAPOLATIONS,
    Connection,
    DriverSpec,
    EventSpec,
    PlotSpec,
    RunSettings,
    UnitSpec,
    VarRef,
)

_RUN_KEYS = set(RunSettings.__dataclass_fields__)
_UNIT_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")


def _unknown_keys(spec: Mapping, known: set[str], where: str, problems: list[str]) -> None:
    """A problem naming the keys of ``spec`` that are not ``known`` (typos silently ignored
    would change what runs)."""
    unknown = sorted(str(k) for k in set(spec) - known)
    if unknown:
        problems.append(f"{where}: unknown keys {unknown}; known: {', '.join(sorted(known))}")


def _text(value: Any, where: str, key: str, problems: list[str], default: str) -> str:
    """A name, label or title: text, else a problem and ``default``."""
    if isinstance(value, str):
        return value
    problems.append(f"{where}: {key!r} must be text, got {value!r}")
    return default


def _as_list(value: Any, where: str, problems: list[str]) -> list:
    if isinstance(value, list):
        return value
    problems.append(f"{where} must be a list of tables ([[{where}]])")
    return []


def _parse_units(data: Any, problems: list[str]) -> dict[str, UnitSpec]:
    units: dict[str, UnitSpec] = {}
    if not isinstance(data, Mapping) or not data:
        problems.append("the scene needs a [units] table with at least one unit")
        return units
    for name, spec in data.items():
        where = f"unit {name!r}"
        if not _UNIT_NAME.fullmatch(name):
            problems.append(
                f"{where}: a unit name is a letter or '_', then letters, digits or '_' (it "
                "names the unit's variables, 'unit.variable')"
            )
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: must be a table")
            continue
        unknown = set(spec) - {"fmu", "effects", "parameters"}
        if unknown:
            problems.append(
                f"{where}: unknown keys {sorted(unknown)}; known: fmu, effects, parameters"
            )
        fmu = spec.get("fmu")
        if not isinstance(fmu, str) or not fmu:
            problems.append(f"{where}: 'fmu' must name one of our FMUs or give a path to one")
            fmu = ""
        effects = spec.get("effects", [])
        if isinstance(effects, str):
            effects = [e.strip() for e in effects.replace(",", " ").split() if e.strip()]
        if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
            problems.append(f"{where}: 'effects' must be a list of effect names")
            effects = []
        params = spec.get("parameters", {})
        if not isinstance(params, Mapping):
            problems.append(f"{where}: 'parameters' must be a table")
            params = {}
        units[name] = UnitSpec(name, fmu, tuple(effects), dict(params))
    return units


def _parse_link(text: Any, where: str, problems: list[str]) -> tuple[VarRef, VarRef] | None:
    if not isinstance(text, str) or "->" not in text:
        problems.append(f"{where}: must read 'unit.output -> unit.input', got {text!r}")
        return None
    left, _, right = text.partition("->")
    source, target = VarRef.parse(left), VarRef.parse(right)
    if source is None or target is None:
        problems.append(f"{where}: both sides must be 'unit.variable', got {text!r}")
        return None
    return source, target


def _parse_connections(data: Any, problems: list[str]) -> tuple[Connection, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "connections", problems)):
        where = f"connection {i}"
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: must be a table with 'from' and 'to'")
            continue
        _unknown_keys(spec, {"from", "to", "extrapolation"}, where, problems)
        source, target = VarRef.parse(spec.get("from")), VarRef.parse(spec.get("to"))
        if source is None or target is None:
            problems.append(f"{where}: 'from' and 'to' must be 'unit.variable'")
            continue
        extrapolation = spec.get("extrapolation")
        if extrapolation is not None and extrapolation not in EXTRAPOLATIONS:
            problems.append(f"{where}: 'extrapolation' must be one of {EXTRAPOLATIONS}")
        out.append(Connection(source, target, extrapolation=extrapolation))
    return tuple(out)


def _parse_drivers(data: Any, problems: list[str]) -> tuple[DriverSpec, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "drivers", problems)):
        if not isinstance(spec, Mapping):
            problems.append(f"driver {i}: must be a table")
            continue
        target = VarRef.parse(spec.get("target"))
        if target is None:
            problems.append(f"driver {i}: 'target' must be 'unit.input'")
            continue
        rate = spec.get("rate_target")
        rate_ref = VarRef.parse(rate) if rate is not None else None
        if rate is not None and rate_ref is None:
            problems.append(f"driver {i}: 'rate_target' must be 'unit.input'")
        body = {k: v for k, v in spec.items() if k not in ("target", "rate_target", "label")}
        label = _text(spec.get("label", ""), f"driver {i}", "label", problems, "")
        out.append(DriverSpec(target, body, rate_ref, label))
    return tuple(out)


def _parse_events(data: Any, problems: list[str]) -> tuple[EventSpec, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "events", problems)):
        where = f"event {i}"
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: must be a table")
            continue
        _unknown_keys(spec, {"time", "set", "label"}, where, problems)
        time = spec.get("time")
        if not _finite(time) or not 0 <= time <= MAX_TIME:
            problems.append(
                f"{where}: 'time' must be a number of seconds from 0 to {MAX_TIME:g}, got {time!r}"
            )
            continue
        values = {}
        raw = spec.get("set", {})
        if not isinstance(raw, Mapping) or not raw:
            problems.append(f"{where}: 'set' must be a table of 'unit.input' = value")
            continue
        for key, value in raw.items():
            ref = VarRef.parse(key)
            if ref is None:
                problems.append(f"{where}: {key!r} is not 'unit.input'")
            elif not is_scalar(value):
                problems.append(
                    f"{where}: {key} = {value!r}: must be a finite number, true/false or text"
                )
            else:
                values[ref] = value
        label = _text(spec.get("label", f"event {i}"), where, "label", problems, f"event {i}")
        out.append(EventSpec(float(time), values, label))
    return tuple(sorted(out, key=lambda e: e.time))


def _parse_outputs(data: Any, problems: list[str]) -> tuple[VarRef, ...] | None:
    if not isinstance(data, Mapping):
        problems.append("[outputs] must be a table with 'variables'")
        return None
    _unknown_keys(data, {"variables"}, "[outputs]", problems)
    variables = data.get("variables", "all")
    if variables == "all":
        return None
    if not isinstance(variables, list):
        problems.append("outputs.variables must be \"all\" or a list of 'unit.variable'")
        return None
    refs = []
    for text in variables:
        ref = VarRef.parse(text)
        if ref is None:
            problems.append(f"outputs: {text!r} is not 'unit.variable'")
        else:
            refs.append(ref)
    return tuple(refs)


def _parse_plots(data: Any, problems: list[str]) -> tuple[PlotSpec, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "plots", problems)):
        if not isinstance(spec, Mapping) or not isinstance(spec.get("variables"), list):
            problems.append(f"plot {i}: needs 'title' and a list 'variables'")
            continue
        _unknown_keys(spec, {"title", "variables", "ylabel"}, f"plot {i}", problems)
        refs = [VarRef.parse(v) for v in spec["variables"]]
        if not refs or any(r is None for r in refs):
            problems.append(f"plot {i}: 'variables' must list at least one 'unit.variable'")
            continue
        title = _text(spec.get("title", f"plot {i}"), f"plot {i}", "title", problems, "plot")
        if not title.strip() or len(title) > 100:
            problems.append(f"plot {i}: 'title' must be 1 to 100 characters (it names the PNG)")
        ylabel = _text(spec.get("ylabel", ""), f"plot {i}", "ylabel", problems, "")
        out.append(PlotSpec(title, tuple(refs), ylabel))
    return tuple(out)


def _parse_run(data: Any, problems: list[str]) -> RunSettings:
    if not isinstance(data, Mapping):
        problems.append("[run] must be a table")
        return RunSettings()
    unknown = set(data) - _RUN_KEYS
    if unknown:
        problems.append(f"run: unknown keys {sorted(unknown)}; known: {sorted(_RUN_KEYS)}")
    given = {k: v for k, v in data.items() if k in _RUN_KEYS}
    if "order" in given:
        order = given["order"]
        given["order"] = tuple(order) if isinstance(order, list) else order
    settings = RunSettings(**given)
    mine: list[str] = []
    _check_run(settings, mine)
    problems += mine
    if mine:  # go on with the defaults of the settings that are wrong
        defaults = RunSettings()
        valid = {}
        for key, value in given.items():
            trial: list[str] = []
            _check_run(replace(defaults, **{key: value}), trial)
            if not trial:
                valid[key] = value
        settings = replace(defaults, **valid)
    return settings
