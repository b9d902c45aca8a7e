"""Write a scene as an SSP 1.0 package (``.ssp``), for any SSP-aware tool.

Layout of the package (a zip)::

    SystemStructure.ssd           the system: components, connectors, connections
    resources/<unit>.fmu          each unit's FMU, its start values the unit's parameters
    resources/<unit>.ssv          each unit's parameter values (SSV 1.0)

Mapping
-------
* Every unit is an ``ssd:Component`` (``application/x-fmu-sharedlibrary``)
  with a typed ``ssd:Connector`` for every output and parameter of its FMU
  and every input a connection feeds (an input nothing feeds keeps its start
  value and is left out); Reals carry their unit, and ``ssd:Units`` defines every unit
  used by its SI exponents (taken from the FMU's own ``UnitDefinitions``).
* Parameters, including String parameters such as a block train's JSON
  ``reeving`` and the ``effects`` list of our units, are bound through one
  ``ssd:ParameterBinding`` per component to ``resources/<unit>.ssv``; Reals
  are written with ``repr`` so they round-trip bit for bit.
* Each unit's FMU is its own copy configured with the same values as its start
  values (:func:`~wire_fmu.export.start_values.write_configured_fmu`), so a tool
  that applies no parameter binding or cannot set a String (FMPy's
  ``simulate_ssp``) still runs the unit as the scene configured it.
* A power bond's effort, flow and position are ordinary
  ``ssd:Connection`` elements (any tool can run them), each marked with an
  annotation of type ``org.wire-fmu.bond`` naming the bond, its kind
  (``translational``, ``rotational``, ``rope``, ``hydraulic``) and the
  connection's role (``effort``, ``flow``, ``position``). A bond whose
  interface model is wired adds the model's five links (stiffness, damping,
  effort rate, reference position and velocity, effort side to flow side),
  ordinary connections too, with the role ``interface``; the effort unit's
  switch parameter is in its parameter set like any other. A bond whose
  effort side takes a flow ramp names the ramp input on its flow connection's
  annotation (``ramp``): the ramp's value is the master's work, so it is no
  connection, and another tool leaves it at 0 (the held flow).
* Drivers and scheduled events become the generated signals component
  (:mod:`wire_fmu.interop.signals`) and plain connections from it.
* ``ssd:DefaultExperiment`` gives the start and stop time; an annotation of
  type ``com.opensimulationplatform`` gives libcosim the fixed step
  (``osp:FixedStepAlgorithm baseStepSize``); an annotation of type
  ``org.wire-fmu.scene`` on the system keeps, as JSON, what SSP has no
  element for (run settings, drivers, events, outputs, plots), so that
  :mod:`wire_fmu.interop.ssp_read` restores the scene exactly.

libcosim reads SSD files with a parser that matches element names by their
prefix, so the prefixes ``ssd``, ``ssc``, ``ssv`` and ``osp`` are fixed here.
"""

from __future__ import annotations

import json
import logging
import tempfile
import zipfile
from datetime import UTC, datetime
from pathlib import Path

from lxml import etree

import wire_fmu
from wire_fmu.export.start_values import write_configured_fmu
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.scene import Scene

from .plan import ExportPlan, PlannedUnit, plan_export

__all__ = [
    "NS",
    "BOND_ANNOTATION",
    "SCENE_ANNOTATION",
    "OSP_ANNOTATION",
    "SSD_NAME",
    "ssd_tree",
    "ssv_tree",
    "write_ssp",
    "export_ssp",
]

logger = logging.getLogger(__name__)

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations",
    "wf": "https://wire-fmu.org/SSP/annotations/1",
}
"""Namespaces by the prefix every document here uses."""

BOND_ANNOTATION = "org.wire-fmu.bond"
SCENE_ANNOTATION = "org.wire-fmu.scene"
OSP_ANNOTATION = "com.opensimulationplatform"
SSD_NAME = "SystemStructure.ssd"
_KINDS = {
    "input": "input",
    "output": "output",
    "parameter": "parameter",
    "calculatedParameter": "calculatedParameter",
}
_BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _sub(parent: etree._Element, prefix: str, tag: str, **attrs: str) -> etree._Element:
    return etree.SubElement(
        parent, _q(prefix, tag), {k: v for k, v in attrs.items() if v is not None}
    )


def _type_element(parent: etree._Element, var) -> None:
    kind = "Integer" if var.type == "Enumeration" else var.type
    _sub(parent, "ssc", kind, unit=(var.unit or None) if kind == "Real" else None)


def _connectors(component: etree._Element, unit: PlannedUnit, connected: set[str]) -> None:
    """A typed connector for every output and parameter and for each input a connection feeds.

    An input nothing feeds keeps its start value (from the unit's parameter
    set) and gets no connector: a tool that sets every declared input from
    its connection would find none to set it from (FMPy's ``simulate_ssp``
    fails then, see ``docs/interop.md``).
    """
    connectors = _sub(component, "ssd", "Connectors")
    for var in unit.model.modelVariables:
        kind = _KINDS.get(var.causality)
        if kind is None or (kind == "input" and var.name not in connected):
            continue
        connector = _sub(
            connectors,
            "ssd",
            "Connector",
            name=var.name,
            kind=kind,
            description=var.description or None,
        )
        _type_element(connector, var)


def _component(
    elements: etree._Element, unit: PlannedUnit, fmu_name: str, connected: set[str]
) -> None:
    component = _sub(
        elements,
        "ssd",
        "Component",
        name=unit.name,
        type="application/x-fmu-sharedlibrary",
        source=f"resources/{fmu_name}",
        description=unit.model.description or None,
    )
    _connectors(component, unit, connected)
    if unit.start_values:
        bindings = _sub(component, "ssd", "ParameterBindings")
        _sub(
            bindings,
            "ssd",
            "ParameterBinding",
            type="application/x-ssp-parameter-set",
            source=f"resources/{unit.name}.ssv",
        )


def _annotation(parent: etree._Element, kind: str) -> etree._Element:
    annotations = _sub(parent, "ssd", "Annotations")
    return _sub(annotations, "ssc", "Annotation", type=kind)


def _connections(system: etree._Element, plan: ExportPlan) -> None:
    """``ssd:Connections``, left out when there are none (the schema wants at least one)."""
    if not plan.all_connections:
        return
    connections = _sub(system, "ssd", "Connections")
    roles = {id(c): b for b in plan.bonds for c in b.connections}
    for c in plan.all_connections:
        element = _sub(
            connections,
            "ssd",
            "Connection",
            startElement=c.source.unit,
            startConnector=c.source.variable,
            endElement=c.target.unit,
            endConnector=c.target.variable,
        )
        bond = roles.get(id(c))
        if bond is not None:
            note = _annotation(element, BOND_ANNOTATION)
            marks = {"name": bond.name, "kind": bond.kind, "role": c.role}
            if c.role == "flow" and bond.ramp is not None:  # the master's, not a connection
                marks["ramp"] = bond.ramp.target.variable
            _sub(note, "wf", "Bond", **marks)


def _units(parent: etree._Element, prefix: str, used: set[str], models) -> None:
    """``<prefix>:Units`` defining each unit in ``used`` by its SI exponents."""
    if not used:
        return
    definitions = {}
    for model in models:
        for definition in model.unitDefinitions:
            definitions.setdefault(definition.name, definition)
    units = _sub(parent, prefix, "Units")
    for name in sorted(used):
        element = _sub(units, "ssc", "Unit", name=name)
        base = definitions.get(name)
        attrs = {}
        if base is not None and base.baseUnit is not None:
            b = base.baseUnit
            attrs = {k: str(getattr(b, k)) for k in _BASE if getattr(b, k)}
            if b.factor != 1.0:
                attrs["factor"] = repr(b.factor)
            if b.offset != 0.0:
                attrs["offset"] = repr(b.offset)
        _sub(element, "ssc", "BaseUnit", **attrs)


def _default_experiment(root: etree._Element, plan: ExportPlan) -> None:
    experiment = _sub(
        root,
        "ssd",
        "DefaultExperiment",
        startTime="0.0",
        stopTime=repr(float(plan.scene.run.stop_time)),
    )
    note = _annotation(experiment, OSP_ANNOTATION)
    algorithm = _sub(note, "osp", "Algorithm")
    _sub(algorithm, "osp", "FixedStepAlgorithm", baseStepSize=repr(float(plan.scene.run.step)))


def component_files(plan: ExportPlan) -> dict[str, str]:
    """File name in the package's ``resources/`` of each unit's FMU, by unit name.

    Parameters
    ----------
    plan : ExportPlan
        What to write.
    """
    return {unit.name: f"{unit.name}.fmu" for unit in plan.units}


def ssd_tree(plan: ExportPlan) -> etree._Element:
    """The ``SystemStructure.ssd`` document of ``plan``.

    Parameters
    ----------
    plan : ExportPlan
        What to write.
    """
    names = component_files(plan)
    scene = plan.scene
    root = etree.Element(
        _q("ssd", "SystemStructureDescription"),
        {
            "version": "1.0",
            "name": scene.name,
            "generationTool": f"wire_fmu {wire_fmu.__version__}",
            "generationDateAndTime": _now(),
        },
        nsmap={k: NS[k] for k in ("ssd", "ssc", "osp", "wf")},
    )
    system = _sub(
        root, "ssd", "System", name=scene.name, description=scene.description.strip() or None
    )
    elements = _sub(system, "ssd", "Elements")
    fed = {(c.target.unit, c.target.variable) for c in plan.all_connections}
    for unit in plan.units:
        connected = {variable for name, variable in fed if name == unit.name}
        _component(elements, unit, names[unit.name], connected)
    _connections(system, plan)
    note = _annotation(system, SCENE_ANNOTATION)
    meta = dict(plan.metadata, signals=plan.signals)
    _sub(note, "wf", "Scene").text = json.dumps(meta, indent=1, sort_keys=True)
    used = {v.unit for u in plan.units for v in u.model.modelVariables if v.unit}
    _units(root, "ssd", used, [u.model for u in plan.units])
    _default_experiment(root, plan)
    return root


def ssv_tree(unit: PlannedUnit) -> etree._Element:
    """The SSV 1.0 parameter set of ``unit`` (Reals with their units).

    Parameters
    ----------
    unit : PlannedUnit
        A unit planned for export (its typed start values).
    """
    root = etree.Element(
        _q("ssv", "ParameterSet"),
        {"version": "1.0", "name": unit.name, "generationTool": f"wire_fmu {wire_fmu.__version__}"},
        nsmap={k: NS[k] for k in ("ssv", "ssc")},
    )
    parameters = _sub(root, "ssv", "Parameters")
    used = set()
    for name, typed in unit.start_values.items():
        parameter = _sub(parameters, "ssv", "Parameter", name=name)
        var_unit = unit.variable(name).unit if typed.type == "Real" else None
        _sub(parameter, "ssv", typed.type, value=typed.text(), unit=var_unit or None)
        used |= {var_unit} if var_unit else set()
    _units(root, "ssv", used, [unit.model])
    return root


def _now() -> str:
    return datetime.now(UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")


def _xml(root: etree._Element) -> bytes:
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)


def write_ssp(plan: ExportPlan, path: Path) -> Path:
    """Write ``plan`` as the SSP package ``path`` (a ``.ssp`` zip).

    Parameters
    ----------
    plan : ExportPlan
        The scene planned for export.
    path : Path
        The package file (its folder is created; an existing file replaced).

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    names = component_files(plan)
    with (
        tempfile.TemporaryDirectory(prefix="wire_fmu_ssp_") as tmp,
        zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive,
    ):
        archive.writestr(SSD_NAME, _xml(ssd_tree(plan)))
        for unit in plan.units:
            configured = Path(tmp) / names[unit.name]
            write_configured_fmu(unit.fmu, unit.start_values, configured)
            archive.write(configured, f"resources/{names[unit.name]}")
            if unit.start_values:
                archive.writestr(f"resources/{unit.name}.ssv", _xml(ssv_tree(unit)))
    logger.info(
        "wrote %s (%d components, %d connections)", path, len(plan.units), len(plan.all_connections)
    )
    return path


def export_ssp(scene: Scene, out: Path, *, fmu_dir: Path = DEFAULT_FMU_DIR) -> Path:
    """Plan and write ``scene`` as an SSP package.

    Parameters
    ----------
    scene : Scene
        The parsed scene.
    out : Path
        A ``.ssp`` file, or a folder to write ``<scene name>.ssp`` into.
    fmu_dir : Path
        Where our FMUs are built and cached. The signals FMU of a scene with
        drivers or events (``Signals_<scene>.fmu``) is built beside the
        package, never into ``fmu_dir``: it belongs to this scene alone, and
        the package holds a copy.

    Returns
    -------
    Path
        The package written.
    """
    out = Path(out)
    target = out if out.suffix == ".ssp" else out / f"{scene.name}.ssp"
    plan = plan_export(scene, fmu_dir=fmu_dir, build_dir=target.parent)
    return write_ssp(plan, target)
