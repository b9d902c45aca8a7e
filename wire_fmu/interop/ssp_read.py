"""Read an SSP package into a scene, so a system made in another tool runs here.

:func:`read_ssp` extracts the package (into a folder keyed by its content,
so reading it again reuses the files), reads ``SystemStructure.ssd`` and
builds the same plain data a scene file holds, then parses it with
:func:`~wire_fmu.master.scene.parse_scene`, so every scene check applies.

* Each ``ssd:Component`` becomes a unit whose ``fmu`` is the path of its FMU
  inside the extracted package.
* Parameter values come from the component's ``ssd:ParameterBinding``\\ s:
  an SSV file (``source``) or an inline ``ssv:ParameterSet``; bindings of the
  system whose names start with ``<component>.`` apply to that component.
  Values are typed by the SSV element (``Real``, ``Integer``, ``Boolean``,
  ``String``; String parameters like a JSON reeving pass through unchanged).
* Each ``ssd:Connection`` is oriented output to input by the FMUs' own
  causalities. Connections carrying our ``org.wire-fmu.bond`` annotation are
  regrouped into power bonds (name, kind, effort/flow/position); all others
  are plain connections.
* Our ``org.wire-fmu.scene`` annotation, when present, restores the run
  settings, drivers, events, outputs, plots and effects exactly, and the
  generated signals component is dropped (its drivers are ours again).
  Without it the stop time comes from ``ssd:DefaultExperiment``, the step
  from the OSP ``FixedStepAlgorithm`` annotation if there is one, and the
  rest of the run settings are our defaults.

Not supported (each is reported as a scene problem): nested systems,
connections to system connectors, signal dictionaries, and connections
with a transformation (``ssc:LinearTransformation`` and the mappings).

A package is untrusted input. It is extracted by
:mod:`wire_fmu.master.archive` (bounded in size and member count, no member
outside the folder, atomic, so a half-extracted folder is never reused);
every file the SSD names (a component's FMU, an SSV parameter file, a table
a driver reads) must be a file inside the package; the XML is parsed
without entities, DTDs or network access; and anything malformed (XML that
is not well formed, a missing required attribute, a value that is not a
number, annotation JSON that does not parse or has the wrong shape) is
reported as a problem naming the element, never as a traceback. Every
problem found is listed in one :class:`~wire_fmu.master.scene.SceneError`.
"""

from __future__ import annotations

import json
import logging
import math
import re
import tempfile
from pathlib import Path
from typing import Any

from fmpy import read_model_description
from lxml import etree

from wire_fmu.master.archive import (
    ArchiveError,
    ArchiveLimits,
    check_member_size,
    extract_archive,
    extract_cached,
)
from wire_fmu.master.files import UnreadableFileError, read_regular
from wire_fmu.master.scene import Scene, SceneError, parse_scene

from .plan import TypedValue
from .ssp import BOND_ANNOTATION, NS, OSP_ANNOTATION, SCENE_ANNOTATION, SSD_NAME

__all__ = ["read_ssp", "extract_ssp", "ssp_scene_data", "MAX_XML_BYTES"]

logger = logging.getLogger(__name__)

_FMU_TYPE = "application/x-fmu-sharedlibrary"
_VALUE_TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")
_ROLES = ("effort", "flow", "position")
_INT32 = (-(2**31), 2**31 - 1)  # an FMI 2.0 Integer
_INT64 = (-(2**63), 2**63 - 1)  # an integer in the scene annotation (as TOML allows)
_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")
_SHOWN = 60  # characters of a value quoted in a message

MAX_XML_BYTES = 64 << 20
"""Largest SSD or SSV file read, bytes (64 MiB; real ones are kilobytes)."""
_MAX_MODEL_DESCRIPTION = 256 << 20  # modelDescription.xml of a component FMU, bytes


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _shown(value: Any) -> str:
    """``value`` quoted for a message, shortened if long."""
    text = repr(value)
    return text if len(text) <= _SHOWN else text[: _SHOWN - 4] + "...'"


def _cache_root() -> Path:
    """Where packages are extracted by default (a folder per package content)."""
    return Path(tempfile.gettempdir()) / "wire_fmu_ssp"


def extract_ssp(
    path: Path, into: Path | None = None, *, limits: ArchiveLimits | None = None
) -> Path:
    """Extract the package ``path`` safely; return the folder holding its SSD.

    See :mod:`wire_fmu.master.archive`: the extraction is bounded, confined
    to the folder and atomic, and a folder is reused only if it holds a
    complete extraction of the same content.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file.
    into : Path, optional
        Target folder (new, empty, or an earlier extraction of ours); default
        a folder under the system's temporary directory named by the
        package's SHA-256, reused when complete.
    limits : ArchiveLimits, optional
        Bounds on the extracted size and member count (default 1 GiB,
        10,000 members).

    Raises
    ------
    SceneError
        Naming the package and what is wrong with it.
    """
    path = Path(path)
    try:
        if into is None:
            folder = extract_cached(path, _cache_root(), what="package", limits=limits)
        else:
            folder = extract_archive(path, Path(into), what="package", limits=limits)
    except ArchiveError as err:
        raise SceneError(err.where, err.problems) from None
    if not (folder / SSD_NAME).is_file():
        raise SceneError(f"package {path}", [f"the package has no {SSD_NAME}"])
    return folder


# ------------------------------------------------------------------ files and XML


def _inside(
    folder: Path, source: Any, owner: str, problems: list[str], key: str = "source"
) -> Path | None:
    """The file ``source`` (a reference in the SSD) names inside ``folder``, or a problem."""
    if not isinstance(source, str) or not source.strip():
        problems.append(f"{owner}: '{key}' is required (a file in the package)")
        return None
    text = source[len("file:") :] if source.startswith("file:") else source
    if "\x00" in text:
        problems.append(f"{owner}: {key} {_shown(source)} has a NUL character")
        return None
    if _SCHEME.match(text) or text.startswith(("/", "\\")) or "\\" in text:
        problems.append(
            f"{owner}: {key} {_shown(source)} is outside the package (expected a relative "
            "path to a file in the package)"
        )
        return None
    base = folder.resolve()
    target = (base / text).resolve()
    if not target.is_relative_to(base) or target == base:
        problems.append(
            f"{owner}: {key} {_shown(source)} is outside the package (expected a relative "
            "path to a file in the package)"
        )
        return None
    if not target.is_file():
        problems.append(f"{owner}: {key} {_shown(source)} is not a file in the package")
        return None
    return target


def _parser() -> etree.XMLParser:
    """An XML parser that resolves no entities and loads no DTD or network resource."""
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
    )


def _read_xml(path: Path, label: str, problems: list[str]) -> etree._Element | None:
    """The root element of the XML file ``path`` (bounded in size), or a problem."""
    try:
        data = read_regular(path, MAX_XML_BYTES)
    except UnreadableFileError as err:
        problems.append(f"{label}: cannot be read ({err})")
        return None
    try:
        return etree.fromstring(data, _parser())
    except etree.XMLSyntaxError as err:
        problems.append(f"{label}: not well-formed XML ({err.msg})")
    except (etree.LxmlError, ValueError) as err:  # UnicodeDecodeError is a ValueError
        problems.append(f"{label}: not readable XML ({type(err).__name__}: {err})")
    return None


def _annotation(element: etree._Element, kind: str) -> etree._Element | None:
    for note in element.findall(f"{_q('ssd', 'Annotations')}/{_q('ssc', 'Annotation')}"):
        if note.get("type") == kind and len(note):
            return note[0]
    return None


# ------------------------------------------------------------------ the scene annotation


def _json_int(text: str) -> int:
    """A JSON integer as TOML would hold it (64 bits), so later float() calls cannot overflow."""
    value = int(text)
    if not _INT64[0] <= value <= _INT64[1]:
        raise ValueError(f"integer {text[:20]}{'...' if len(text) > 20 else ''} out of range")
    return value


def _scene_metadata(system: etree._Element, problems: list[str]) -> dict[str, Any] | None:
    note = _annotation(system, SCENE_ANNOTATION)
    if note is None or not (note.text or "").strip():
        return None
    where = f"scene annotation ({SCENE_ANNOTATION})"
    try:
        meta = json.loads(note.text, parse_int=_json_int)
    except (ValueError, RecursionError) as err:
        problems.append(f"{where}: not valid JSON ({err})")
        return None
    if not isinstance(meta, dict):
        problems.append(f"{where}: must be a JSON object, got a {type(meta).__name__}")
        return None
    if meta.get("format") != "wire_fmu.scene/1":
        return None  # someone else's annotation of the same type: read the SSD alone
    signals = meta.get("signals")
    if signals is not None and not isinstance(signals, str):
        problems.append(
            f"{where}: 'signals' must name the signals component, got {_shown(signals)}"
        )
        meta["signals"] = None
    for key, kind in (("drivers", list), ("events", list), ("plots", list), ("effects", dict)):
        if key in meta and not isinstance(meta[key], kind):
            problems.append(f"{where}: '{key}' must be a JSON {_JSON_KIND[kind]}")
            meta[key] = kind()
    return meta


_JSON_KIND = {list: "array", dict: "object"}


def _meta_run(meta: dict[str, Any], problems: list[str]) -> dict[str, Any]:
    where = f"scene annotation ({SCENE_ANNOTATION})"
    run = meta.get("run")
    if not isinstance(run, dict):
        got = "missing" if run is None else f"a {type(run).__name__}"
        problems.append(f"{where}: 'run' must be an object of run settings ({got})")
        return {}
    order = run.get("order")
    if order is not None and not (
        isinstance(order, list) and all(isinstance(u, str) for u in order)
    ):
        problems.append(f"{where}: run 'order' must be a list of unit names, got {_shown(order)}")
        run = {k: v for k, v in run.items() if k != "order"}
    # infinity travels as "inf" (strict JSON has none): energy_guard = inf, off
    return {k: math.inf if v == "inf" else v for k, v in run.items() if v is not None}


def _restore(data: dict[str, Any], meta: dict[str, Any], folder: Path, problems: list[str]) -> None:
    """Put back what SSP has no element for, from our annotation."""
    where = f"scene annotation ({SCENE_ANNOTATION})"
    data["description"] = meta.get("description", "")
    data["drivers"] = []
    for i, d in enumerate(meta.get("drivers", [])):
        spec = d.get("spec") if isinstance(d, dict) else None
        if not isinstance(spec, dict):
            problems.append(f"{where}: driver {i} must be an object with a 'spec' object")
            continue
        if spec.get("kind") == "table" and "file" in spec:  # a file it reads: in the package
            _inside(folder, spec["file"], f"{where}: driver {i}", problems, key="file")
        data["drivers"].append(
            {
                "target": d.get("target"),
                **({"rate_target": d["rate_target"]} if d.get("rate_target") else {}),
                **({"label": d["label"]} if d.get("label") else {}),
                **spec,
            }
        )
    data["events"] = []
    for i, e in enumerate(meta.get("events", [])):
        if not isinstance(e, dict):
            problems.append(f"{where}: event {i} must be an object")
            continue
        event = {"time": e.get("time"), "set": e.get("set")}
        if e.get("label") is not None:
            event["label"] = e["label"]
        data["events"].append(event)
    data["outputs"] = {"variables": meta["outputs"] if meta.get("outputs") is not None else "all"}
    data["plots"] = []
    for i, p in enumerate(meta.get("plots", [])):
        if not isinstance(p, dict):
            problems.append(f"{where}: plot {i} must be an object")
            continue
        data["plots"].append({k: p[k] for k in ("title", "ylabel", "variables") if k in p})
    for name, effects in meta.get("effects", {}).items():
        if name in data["units"]:
            data["units"][name]["effects"] = effects
            data["units"][name]["parameters"].pop("effects", None)


# ------------------------------------------------------------------ SSD elements


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
        if role in bond:
            problems.append(f"{where}: bond {name!r} has a second {role} connection")
            continue
        bond[role] = f"{link[0]} -> {link[1]}"
    return plain, list(bonds.values())


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


# ------------------------------------------------------------------ the scene


def ssp_scene_data(folder: Path) -> tuple[dict[str, Any], list[str]]:
    """Scene data (as a scene file holds it) from an extracted package, and problems."""
    folder = Path(folder)
    problems: list[str] = []
    root = _read_xml(folder / SSD_NAME, SSD_NAME, problems)
    if root is None:
        return {}, problems
    system = root.find(_q("ssd", "System"))
    if root.tag != _q("ssd", "SystemStructureDescription") or system is None:
        return {}, [f"{SSD_NAME} is not an SSP 1.0 system structure description"]
    meta = _scene_metadata(system, problems)
    skip = meta.get("signals") if meta else None
    units = _components(system, folder, problems)
    units.pop(skip, None)
    plain, bonds = _connections(system, units, skip, problems)
    data: dict[str, Any] = {
        "name": root.get("name") or system.get("name") or "ssp",
        "description": system.get("description", ""),
        "run": _run_settings(root, meta, problems),
        "units": units,
        "connections": plain,
        "bonds": bonds,
    }
    if meta is not None:
        data["name"] = meta.get("name", data["name"])
        _restore(data, meta, folder, problems)
    return data, problems


def read_ssp(
    path: Path, *, extract_to: Path | None = None, limits: ArchiveLimits | None = None
) -> Scene:
    """The scene an SSP package describes.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file.
    extract_to : Path, optional
        Where to extract it (see :func:`extract_ssp`).
    limits : ArchiveLimits, optional
        Bounds on the extracted size and member count (see :func:`extract_ssp`).

    Raises
    ------
    SceneError
        Listing every problem (unsupported SSP features included).
    """
    path = Path(path)
    folder = extract_ssp(path, extract_to, limits=limits)
    data, problems = ssp_scene_data(folder)
    if problems:
        raise SceneError(f"package {path}", problems)
    logger.info(
        "read %s: %d units, %d bonds, %d connections",
        path.name,
        len(data["units"]),
        len(data["bonds"]),
        len(data["connections"]),
    )
    return parse_scene(data, base_dir=folder, source=path)
