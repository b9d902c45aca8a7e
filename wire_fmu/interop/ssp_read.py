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
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import tempfile
import zipfile
from pathlib import Path
from typing import Any

from fmpy import read_model_description
from lxml import etree

from wire_fmu.master.scene import Scene, SceneError, parse_scene

from .plan import TypedValue
from .ssp import BOND_ANNOTATION, NS, OSP_ANNOTATION, SCENE_ANNOTATION, SSD_NAME

__all__ = ["read_ssp", "extract_ssp", "ssp_scene_data"]

logger = logging.getLogger(__name__)

_FMU_TYPE = "application/x-fmu-sharedlibrary"
_VALUE_TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def extract_ssp(path: Path, into: Path | None = None) -> Path:
    """Extract the package ``path``; return the folder holding its SSD.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file.
    into : Path, optional
        Target folder; default a folder under the system's temporary
        directory named by the package's SHA-256, reused when it exists.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        raise SceneError(str(path), [f"cannot read the SSP package: {err}"]) from None
    if into is None:
        digest = hashlib.sha256(data).hexdigest()[:16]
        into = Path(tempfile.gettempdir()) / "wire_fmu_ssp" / digest
    into = Path(into)
    if not (into / SSD_NAME).exists():
        try:
            with zipfile.ZipFile(path) as archive:
                _check_members(path, archive.namelist())
                archive.extractall(into)
        except zipfile.BadZipFile:
            raise SceneError(str(path), ["not an SSP package (not a zip file)"]) from None
    if not (into / SSD_NAME).exists():
        raise SceneError(str(path), [f"the package has no {SSD_NAME}"])
    return into


def _check_members(path: Path, names: list[str]) -> None:
    bad = [n for n in names if n.startswith("/") or ".." in Path(n).parts]
    if bad:
        raise SceneError(str(path), [f"unsafe file names in the package: {bad}"])


def _annotation(element: etree._Element, kind: str) -> etree._Element | None:
    for note in element.findall(f"{_q('ssd', 'Annotations')}/{_q('ssc', 'Annotation')}"):
        if note.get("type") == kind and len(note):
            return note[0]
    return None


def _scene_metadata(system: etree._Element) -> dict[str, Any] | None:
    note = _annotation(system, SCENE_ANNOTATION)
    if note is None or not (note.text or "").strip():
        return None
    meta = json.loads(note.text)
    return meta if meta.get("format") == "wire_fmu.scene/1" else None


def _parameter_values(parameter_set: etree._Element) -> dict[str, Any]:
    out = {}
    for parameter in parameter_set.iterfind(f"{_q('ssv', 'Parameters')}/{_q('ssv', 'Parameter')}"):
        for kind in _VALUE_TYPES:
            value = parameter.find(_q("ssv", kind))
            if value is not None:
                out[parameter.get("name")] = TypedValue.parse(kind, value.get("value", "")).value
                break
    return out


def _bindings(element: etree._Element, folder: Path, problems: list[str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    path = f"{_q('ssd', 'ParameterBindings')}/{_q('ssd', 'ParameterBinding')}"
    for binding in element.iterfind(path):
        prefix = binding.get("prefix", "")
        source = binding.get("source")
        if source:
            try:
                tree = etree.parse(str(folder / source))
            except (OSError, etree.XMLSyntaxError) as err:
                problems.append(f"parameter binding {source!r}: {err}")
                continue
            sets = [tree.getroot()]
        else:
            sets = binding.findall(f"{_q('ssd', 'ParameterValues')}/{_q('ssv', 'ParameterSet')}")
        for parameter_set in sets:
            for name, value in _parameter_values(parameter_set).items():
                out[name[len(prefix) :] if prefix and name.startswith(prefix) else name] = value
    return out


def _components(
    system: etree._Element, folder: Path, problems: list[str]
) -> dict[str, dict[str, Any]]:
    units: dict[str, dict[str, Any]] = {}
    elements = system.find(_q("ssd", "Elements"))
    for element in elements if elements is not None else ():
        if not isinstance(element.tag, str):
            continue
        name = element.get("name")
        if element.tag != _q("ssd", "Component"):
            problems.append(
                f"element {name!r}: only FMU components are supported "
                f"(found {etree.QName(element).localname})"
            )
            continue
        if element.get("type", _FMU_TYPE) != _FMU_TYPE:
            problems.append(f"component {name!r}: type {element.get('type')!r} is not an FMU")
            continue
        source = element.get("source", "")
        source = source[len("file:") :] if source.startswith("file:") else source
        units[name] = {
            "fmu": str((folder / source).resolve()),
            "parameters": _bindings(element, folder, problems),
        }
    for key, value in _bindings(system, folder, problems).items():
        unit, _, variable = key.partition(".")
        if unit in units and variable:
            units[unit]["parameters"][variable] = value
        else:
            problems.append(f"system parameter {key!r} names no component")
    return units


def _causalities(units: dict[str, dict[str, Any]]) -> dict[str, dict[str, str]]:
    out = {}
    for name, unit in units.items():
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
    for connection in system.iterfind(path):
        if skip is not None and skip in (
            connection.get("startElement"),
            connection.get("endElement"),
        ):
            continue
        link = _link(connection, causality)
        where = f"connection {connection.get('startElement')}.{connection.get('startConnector')}"
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
        bond = bonds.setdefault(
            mark.get("name"), {"name": mark.get("name"), "kind": mark.get("kind")}
        )
        bond[mark.get("role")] = f"{link[0]} -> {link[1]}"
    return plain, list(bonds.values())


def _run_settings(root: etree._Element, meta: dict[str, Any] | None) -> dict[str, Any]:
    if meta is not None:
        # infinity travels as "inf" (strict JSON has none): energy_guard = inf, off
        return {k: math.inf if v == "inf" else v for k, v in meta["run"].items() if v is not None}
    run: dict[str, Any] = {}
    experiment = root.find(_q("ssd", "DefaultExperiment"))
    if experiment is not None:
        if experiment.get("stopTime") is not None:
            start = float(experiment.get("startTime", 0.0))
            run["stop_time"] = float(experiment.get("stopTime")) - start
        algorithm = _annotation(experiment, OSP_ANNOTATION)
        fixed = algorithm.find(_q("osp", "FixedStepAlgorithm")) if algorithm is not None else None
        if fixed is not None and fixed.get("baseStepSize"):
            run["step"] = float(fixed.get("baseStepSize"))
    return run


def _restore(data: dict[str, Any], meta: dict[str, Any]) -> None:
    """Put back what SSP has no element for, from our annotation."""
    data["description"] = meta.get("description", "")
    data["drivers"] = [
        {
            "target": d["target"],
            **({"rate_target": d["rate_target"]} if d["rate_target"] else {}),
            **({"label": d["label"]} if d["label"] else {}),
            **d["spec"],
        }
        for d in meta.get("drivers", [])
    ]
    data["events"] = [
        {"time": e["time"], "label": e["label"], "set": e["set"]} for e in meta.get("events", [])
    ]
    data["outputs"] = {"variables": meta["outputs"] if meta.get("outputs") is not None else "all"}
    data["plots"] = [
        {"title": p["title"], "ylabel": p["ylabel"], "variables": p["variables"]}
        for p in meta.get("plots", [])
    ]
    for name, effects in meta.get("effects", {}).items():
        if name in data["units"]:
            data["units"][name]["effects"] = effects
            data["units"][name]["parameters"].pop("effects", None)


def ssp_scene_data(folder: Path) -> tuple[dict[str, Any], list[str]]:
    """Scene data (as a scene file holds it) from an extracted package, and problems."""
    problems: list[str] = []
    try:
        root = etree.parse(str(folder / SSD_NAME)).getroot()
    except (OSError, etree.XMLSyntaxError) as err:
        return {}, [f"cannot read {SSD_NAME}: {err}"]
    system = root.find(_q("ssd", "System"))
    if root.tag != _q("ssd", "SystemStructureDescription") or system is None:
        return {}, [f"{SSD_NAME} is not an SSP 1.0 system structure description"]
    meta = _scene_metadata(system)
    skip = meta.get("signals") if meta else None
    units = _components(system, folder, problems)
    units.pop(skip, None)
    plain, bonds = _connections(system, units, skip, problems)
    data: dict[str, Any] = {
        "name": root.get("name") or system.get("name") or "ssp",
        "description": system.get("description", ""),
        "run": _run_settings(root, meta),
        "units": units,
        "connections": plain,
        "bonds": bonds,
    }
    if meta is not None:
        data["name"] = meta.get("name", data["name"])
        _restore(data, meta)
    return data, problems


def read_ssp(path: Path, *, extract_to: Path | None = None) -> Scene:
    """The scene an SSP package describes.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file.
    extract_to : Path, optional
        Where to extract it (see :func:`extract_ssp`).

    Raises
    ------
    SceneError
        Listing every problem (unsupported SSP features included).
    """
    path = Path(path)
    folder = extract_ssp(path, extract_to)
    data, problems = ssp_scene_data(folder)
    if problems:
        raise SceneError(str(path), problems)
    logger.info(
        "read %s: %d units, %d bonds, %d connections",
        path.name,
        len(data["units"]),
        len(data["bonds"]),
        len(data["connections"]),
    )
    return parse_scene(data, base_dir=folder, source=path)
