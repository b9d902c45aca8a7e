"""SSD elements as scene data: components and their parameter bindings, connections
(regrouped into bonds where our annotation marks them, an interface model's links
among them) and run settings."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fmpy import read_model_description
from lxml import etree

from wire_fmu.master.archive import check_member_size

from .plan import TypedValue
from .ssp import BOND_ANNOTATION, NS, OSP_ANNOTATION
from .ssp_read_annotation import _meta_run
from .ssp_read_files import _annotation, _inside, _q, _read_xml, _shown

_FMU_TYPE = "application/x-fmu-sharedlibrary"
_VALUE_TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")
_ROLES = ("effort", "flow", "position", "interface")
_MANY = "interface"
"""The role a bond has several connections of (its interface model's links)."""
_INT32 = (-(2**31), 2**31 - 1)  # an FMI 2.0 Integer
_MAX_MODEL_DESCRIPTION = 256 << 20  # modelDescription.xml of a component FMU, bytes


def _parameter_values(
    parameter_set: etree._Element, owner: str, problems: list[str]
) -> dict[str, Any]:
    out = {}
    path = f"{_q('ssv', 'Parameters')}/{_q('ssv', 'Parameter')}"
    for i, parameter in enumerate(parameter_set.iterfind(path)):
        name = parameter.get("name")
        if not name:
            problems.append(f"{owner}: parameter {i} has no 'name'")
            continue
        for kind in _VALUE_TYPES:
            value = parameter.find(_q("ssv", kind))
            if value is not None:
                parsed = _typed(kind, value.get("value"), f"{owner}: parameter {name!r}", problems)
                if parsed is not None:
                    out[name] = parsed
                break
        else:
            problems.append(
                f"{owner}: parameter {name!r} has no value (expected one of "
                f"{', '.join(_VALUE_TYPES)})"
            )
    return out


def _typed(kind: str, text: str | None, where: str, problems: list[str]) -> Any:
    """The SSV ``value`` attribute of a ``kind`` element, or None after a problem."""
    if text is None:
        problems.append(f"{where}: the {kind} element has no 'value'")
        return None
    expected = {
        "Real": "a number",
        "Integer": "an integer",
        "Enumeration": "an integer",
        "Boolean": "true or false",
    }.get(kind)
    try:
        value = TypedValue.parse(kind, text).value
    except (ValueError, OverflowError):
        problems.append(f"{where}: {kind} value {_shown(text)} is not {expected}")
        return None
    if kind in ("Integer", "Enumeration") and not _INT32[0] <= value <= _INT32[1]:
        problems.append(f"{where}: {kind} value {_shown(text)} is out of the 32-bit range")
        return None
    if kind == "Boolean" and text.strip().lower() not in ("true", "false", "1", "0"):
        problems.append(f"{where}: Boolean value {_shown(text)} is not {expected}")
        return None
    return value


def _bindings(
    element: etree._Element, folder: Path, owner: str, problems: list[str]
) -> dict[str, Any]:
    out: dict[str, Any] = {}
    path = f"{_q('ssd', 'ParameterBindings')}/{_q('ssd', 'ParameterBinding')}"
    for binding in element.iterfind(path):
        prefix = binding.get("prefix", "")
        source = binding.get("source")
        if source is not None:
            where = f"{owner}: parameter binding {_shown(source)}"
            file = _inside(folder, source, f"{owner}: parameter binding", problems)
            root = _read_xml(file, where, problems) if file is not None else None
            if root is None:
                continue
            if root.tag != _q("ssv", "ParameterSet"):
                problems.append(
                    f"{where}: not an SSV parameter set (root element "
                    f"{_shown(etree.QName(root).localname)})"
                )
                continue
            sets = [root]
        else:
            sets = binding.findall(f"{_q('ssd', 'ParameterValues')}/{_q('ssv', 'ParameterSet')}")
        for parameter_set in sets:
            for name, value in _parameter_values(parameter_set, owner, problems).items():
                out[name[len(prefix) :] if prefix and name.startswith(prefix) else name] = value
    return out


def _components(
    system: etree._Element, folder: Path, problems: list[str]
) -> dict[str, dict[str, Any]]:
    units: dict[str, dict[str, Any]] = {}
    elements = system.find(_q("ssd", "Elements"))
    for i, element in enumerate(elements if elements is not None else ()):
        if not isinstance(element.tag, str):
            continue
        name = element.get("name")
        if not name:
            problems.append(f"element {i} of the system has no 'name'")
            continue
        if element.tag != _q("ssd", "Component"):
            problems.append(
                f"element {name!r}: only FMU components are supported "
                f"(found {etree.QName(element).localname})"
            )
            continue
        owner = f"component {name!r}"
        if element.get("type", _FMU_TYPE) != _FMU_TYPE:
            problems.append(f"{owner}: type {_shown(element.get('type'))} is not an FMU")
            continue
        if name in units:
            problems.append(f"{owner}: defined twice")
            continue
        fmu = _inside(folder, element.get("source"), owner, problems)
        if fmu is not None:
            too_big = check_member_size(
                fmu, "modelDescription.xml", _MAX_MODEL_DESCRIPTION, what="FMU"
            )
            if too_big:
                problems.append(f"{owner}: {too_big}")
                fmu = None
        units[name] = {
            "fmu": str(fmu) if fmu is not None else "",
            "parameters": _bindings(element, folder, owner, problems),
        }
    system_name = f"system {system.get('name')!r}" if system.get("name") else "the system"
    for key, value in _bindings(system, folder, system_name, problems).items():
        unit, _, variable = key.partition(".")
        if unit in units and variable:
            units[unit]["parameters"][variable] = value
        else:
            problems.append(f"system parameter {key!r} names no component")
    return units


def _causalities(units: dict[str, dict[str, Any]]) -> dict[str, dict[str, str]]:
    out = {}
    for name, unit in units.items():
        if not unit["fmu"]:
            continue
        try:
            md = read_model_description(unit["fmu"])
        except Exception:  # noqa: BLE001 - reported by the scene checks with the path
            continue
        out[name] = {v.name: v.causality for v in md.modelVariables}
    return out


def _link(
    connection: etree._Element, causality: dict[str, dict[str, str]]
) -> tuple[str, str] | None:
    start = (connection.get("startElement"), connection.get("startConnector"))
    end = (connection.get("endElement"), connection.get("endConnector"))
    if start[0] is None or end[0] is None:
        return None
    if causality.get(start[0], {}).get(start[1]) == "input" and causality.get(end[0], {}).get(
        end[1]
    ) in ("output", "calculatedParameter"):
        start, end = end, start
    return f"{start[0]}.{start[1]}", f"{end[0]}.{end[1]}"


def _connections(
    system: etree._Element, units: dict[str, dict[str, Any]], skip: str | None, problems: list[str]
) -> tuple[list[dict], list[dict]]:
    causality = _causalities(units)
    plain, bonds = [], {}
    path = f"{_q('ssd', 'Connections')}/{_q('ssd', 'Connection')}"
    for i, connection in enumerate(system.iterfind(path)):
        if skip is not None and skip in (
            connection.get("startElement"),
            connection.get("endElement"),
        ):
            continue
        where = f"connection {i} ({connection.get('startElement')}."
        where += f"{connection.get('startConnector')} -> {connection.get('endElement')}."
        where += f"{connection.get('endConnector')})"
        missing = [a for a in ("startConnector", "endConnector") if not connection.get(a)]
        if missing:
            verb = "is" if len(missing) == 1 else "are"
            problems.append(f"{where}: {' and '.join(repr(a) for a in missing)} {verb} required")
            continue
        link = _link(connection, causality)
        if link is None:
            problems.append(f"{where}: connections to system connectors are not supported")
            continue
        if any(
            child.tag.startswith(f"{{{NS['ssc']}}}")
            for child in connection
            if isinstance(child.tag, str)
        ):
            problems.append(f"{where}: transformations on connections are not supported")
            continue
        mark = _annotation(connection, BOND_ANNOTATION)
        if mark is None:
            plain.append({"from": link[0], "to": link[1]})
            continue
        name, kind, role = mark.get("name"), mark.get("kind"), mark.get("role")
        if not name or not kind or role not in _ROLES:
            problems.append(
                f"{where}: the bond annotation needs 'name', 'kind' and a 'role' of "
                f"{', '.join(_ROLES)} (got name={_shown(name)}, kind={_shown(kind)}, "
                f"role={_shown(role)})"
            )
            continue
        bond = bonds.setdefault(name, {"name": name, "kind": kind})
        if role == _MANY:
            bond.setdefault(role, []).append(f"{link[0]} -> {link[1]}")
            continue
        if role in bond:
            problems.append(f"{where}: bond {name!r} has a second {role} connection")
            continue
        bond[role] = f"{link[0]} -> {link[1]}"
        if role == "flow" and mark.get("ramp"):  # the flow's ramp input, set by the master
            bond["ramp"] = f"{link[0]} -> {link[1].split('.', 1)[0]}.{mark.get('ramp')}"
    return plain, list(bonds.values())


def _wire_interface_models(bonds: list[dict], run: dict[str, Any]) -> None:
    """Bonds that came with interface links ask for their model, unless the run already does.

    Parameters
    ----------
    bonds : list of dict
        The bonds as scene data (long form).
    run : dict
        The run settings as scene data.
    """
    if run.get("interface_models") is True:
        return
    for bond in bonds:
        if bond.get(_MANY):
            bond["interface_model"] = True


def _number(
    element: etree._Element, attribute: str, where: str, problems: list[str]
) -> float | None:
    """A number attribute (None if absent or after a problem)."""
    text = element.get(attribute)
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        problems.append(f"{where}: {attribute} {_shown(text)} is not a number")
        return None


def _run_settings(
    root: etree._Element, meta: dict[str, Any] | None, problems: list[str]
) -> dict[str, Any]:
    if meta is not None:
        return _meta_run(meta, problems)
    run: dict[str, Any] = {}
    experiment = root.find(_q("ssd", "DefaultExperiment"))
    if experiment is not None:
        where = "DefaultExperiment"
        start = _number(experiment, "startTime", where, problems)
        stop = _number(experiment, "stopTime", where, problems)
        if stop is not None:
            run["stop_time"] = stop - (start or 0.0)
        algorithm = _annotation(experiment, OSP_ANNOTATION)
        fixed = algorithm.find(_q("osp", "FixedStepAlgorithm")) if algorithm is not None else None
        if fixed is not None:
            step = _number(fixed, "baseStepSize", f"{where} FixedStepAlgorithm", problems)
            if step is not None:
                run["step"] = step
    return run
