"""Write a scene as an Open Simulation Platform configuration (libcosim, OSP tools).

Layout of the output folder::

    OspSystemStructure.xml               simulators, initial values, connections
    <Model>.fmu                          each distinct FMU once
    <Model>_OspModelDescription.xml      units and variable groups of that model

libcosim finds ``<modelName>_OspModelDescription.xml`` beside the FMU (or
the configuration), so every FMU gets one when it takes part in a bond.

Mapping
-------
* ``OspSystemStructure`` (format 0.1): ``StartTime``, ``EndTime``,
  ``BaseStepSize`` = the scene's step, ``Algorithm`` = ``fixedStep``; one
  ``Simulator`` per unit with every parameter (String ones such as the JSON
  ``reeving`` and ``effects`` included) as an ``InitialValue``.
* A power bond becomes a ``VariableGroupConnection`` with
  ``powerBond="<bond name>"`` between two port groups, each side's port
  holding its effort and flow variable (OSP-IS 1.0.1):

  =================  ========================  ===========================
  bond kind          port group                effort / flow groups
  =================  ========================  ===========================
  ``translational``  ``LinearMechanicalPort``  ``Force`` / ``LinearVelocity``
  ``rope``           ``LinearMechanicalPort``  ``Force`` / ``LinearVelocity``
  ``rotational``     ``AngularMechanicalPort`` ``Torque`` / ``AngularVelocity``
  ``hydraulic``      ``HydraulicPort``         ``Pressure`` / ``VolumeFlowRate``
  =================  ========================  ===========================

  The bond's position (our ports also pass the integral of the flow)
  becomes a second ``VariableGroupConnection`` of ``LinearDisplacement``,
  ``AngularDisplacement`` or ``Volume`` groups. libcosim pairs the nested
  groups by position and connects each pair output to input, so effort
  goes one way and flow the other, as in the scene.
* A bond whose interface model is wired adds the model's five links
  (stiffness, damping, effort rate, reference position and velocity, effort
  side to flow side) as ``VariableConnection`` elements after its groups:
  OSP-IS has no variable group for them. The effort unit's switch parameter
  is an ``InitialValue`` like any other.
* Plain connections (and the generated signals unit's) are
  ``VariableConnection`` elements.
* ``UnitDefinitions`` of each model description give every unit its SI
  exponents (from the FMU's own unit definitions); each grouped variable
  names its unit.
"""

from __future__ import annotations

import logging
import shutil
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.scene import INTERFACE_ROLE, Bond, Scene, VarRef

from .plan import ExportPlan, archive_names, plan_export

__all__ = [
    "OSP_NS",
    "OSP_MD_NS",
    "PORTS",
    "Port",
    "model_ports",
    "system_structure_tree",
    "model_description_tree",
    "write_osp",
    "export_osp",
]

logger = logging.getLogger(__name__)

OSP_NS = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"
OSP_MD_NS = "https://open-simulation-platform.com/OspModelDescription/1.0.1"
SYSTEM_STRUCTURE = "OspSystemStructure.xml"

PORTS = {
    # bond kind: (port group, effort group, flow group, position group)
    "translational": ("LinearMechanicalPort", "Force", "LinearVelocity", "LinearDisplacement"),
    "rope": ("LinearMechanicalPort", "Force", "LinearVelocity", "LinearDisplacement"),
    "rotational": ("AngularMechanicalPort", "Torque", "AngularVelocity", "AngularDisplacement"),
    "hydraulic": ("HydraulicPort", "Pressure", "VolumeFlowRate", "Volume"),
}
_GROUP_ORDER = (
    "Generic",
    "Force",
    "Torque",
    "Voltage",
    "Pressure",
    "LinearVelocity",
    "AngularVelocity",
    "Current",
    "VolumeFlowRate",
    "LinearDisplacement",
    "AngularDisplacement",
    "Charge",
    "Volume",
    "LinearAcceleration",
    "AngularAcceleration",
    "LinearMechanicalPort",
    "AngularMechanicalPort",
    "ElectromagneticPort",
    "HydraulicPort",
)
"""The order OspModelDescription 1.0.1 requires for top-level groups."""
_BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


@dataclass(frozen=True)
class Port:
    """A variable group of one model: a power port, or a position group.

    Attributes
    ----------
    name : str
        Group name, unique within the model description.
    group : str
        OSP-IS element name (``LinearMechanicalPort``, ``LinearDisplacement``...).
    members : tuple of (str, str)
        ``(element, variable)``: for a port its effort and flow groups
        (``("Force", "force")``...), for a position group ``("", variable)``.
    """

    name: str
    group: str
    members: tuple[tuple[str, str], ...]

    def nested_name(self, element: str) -> str:
        """Name of a port's nested effort or flow group.

        Parameters
        ----------
        element : str
            The nested group's element, e.g. ``"Force"`` or ``"LinearVelocity"``.
        """
        return f"{self.name}.{element}"


def _port_name(variables: list[str]) -> str:
    """The dotted prefix the variables share, else their names joined."""
    parts = [v.split(".") for v in variables]
    common = []
    for pieces in zip(*[p[:-1] for p in parts], strict=False):
        if len(set(pieces)) != 1:
            break
        common.append(pieces[0])
    return ".".join(common) if common else "|".join(variables)


def _bond_ends(bond: Bond) -> dict[str, tuple[str, str, str | None]]:
    """For each unit of ``bond``: (effort variable, flow variable, position variable)."""
    e, f, p = bond.effort, bond.flow, bond.position
    effort_side = (e.source.variable, f.target.variable, p.target.variable if p else None)
    flow_side = (e.target.variable, f.source.variable, p.source.variable if p else None)
    return {e.source.unit: effort_side, e.target.unit: flow_side}


def model_ports(plan: ExportPlan) -> tuple[dict[str, list[Port]], dict[tuple[str, str], Port]]:
    """Variable groups per model name, and the group of each (unit, bond role).

    Parameters
    ----------
    plan : ExportPlan
        The scene planned for export (its units and bonds).

    Returns
    -------
    by_model : dict
        Model name -> its ports and position groups (deduplicated).
    by_end : dict
        ``(unit, "<bond>")`` -> port; ``(unit, "<bond>.position")`` -> position group.
    """
    by_model: dict[str, dict[tuple, Port]] = defaultdict(dict)
    by_end: dict[tuple[str, str], Port] = {}
    for bond in plan.bonds:
        group, effort_el, flow_el, position_el = PORTS.get(bond.kind, PORTS["translational"])
        for unit, (effort, flow, position) in _bond_ends(bond).items():
            model = plan.unit(unit).model.modelName
            members = ((effort_el, effort), (flow_el, flow))
            by_end[(unit, bond.name)] = _add(
                by_model[model], group, members, _port_name([effort, flow])
            )
            if position is not None:
                by_end[(unit, f"{bond.name}.position")] = _add(
                    by_model[model], position_el, (("", position),), position
                )
    return {m: list(ports.values()) for m, ports in by_model.items()}, by_end


def _add(ports: dict[tuple, Port], group: str, members: tuple, base: str) -> Port:
    key = (group, members)
    if key in ports:
        return ports[key]
    taken = {p.name for p in ports.values()}
    name, i = base, 1
    while name in taken:
        i += 1
        name = f"{base}#{i}"
    ports[key] = Port(name, group, members)
    return ports[key]


def _el(parent: etree._Element | None, ns: str, tag: str, **attrs: str | None) -> etree._Element:
    clean = {k: v for k, v in attrs.items() if v is not None}
    if parent is None:
        return etree.Element(f"{{{ns}}}{tag}", clean, nsmap={None: ns})
    return etree.SubElement(parent, f"{{{ns}}}{tag}", clean)


def _text(parent: etree._Element, tag: str, value: str) -> None:
    _el(parent, OSP_NS, tag).text = value


def _simulators(root: etree._Element, plan: ExportPlan, names: dict[Path, str]) -> None:
    simulators = _el(root, OSP_NS, "Simulators")
    for unit in plan.units:
        simulator = _el(
            simulators, OSP_NS, "Simulator", name=unit.name, source=names[unit.fmu.resolve()]
        )
        if not unit.start_values:
            continue
        values = _el(simulator, OSP_NS, "InitialValues")
        for name, typed in unit.start_values.items():
            initial = _el(values, OSP_NS, "InitialValue", variable=name)
            _el(initial, OSP_NS, typed.type, value=typed.text())


def _endpoint(parent: etree._Element, tag: str, ref: VarRef) -> None:
    _el(parent, OSP_NS, tag, simulator=ref.unit, name=ref.variable)


def _connections(root: etree._Element, plan: ExportPlan) -> None:
    connections = _el(root, OSP_NS, "Connections")
    for c in plan.connections:
        element = _el(connections, OSP_NS, "VariableConnection")
        _endpoint(element, "Variable", c.source)
        _endpoint(element, "Variable", c.target)
    _, by_end = model_ports(plan)
    for bond in plan.bonds:
        a, b = bond.effort.source.unit, bond.effort.target.unit
        connections.append(
            etree.Comment(
                f" power bond {bond.name!r} ({bond.kind}): effort {bond.effort.source} -> "
                f"{bond.effort.target}, flow {bond.flow.source} -> {bond.flow.target} "
            )
        )
        for key in (bond.name, f"{bond.name}.position"):
            if (a, key) in by_end:
                element = _el(connections, OSP_NS, "VariableGroupConnection")
                for unit in (a, b):
                    _endpoint(element, "VariableGroup", VarRef(unit, by_end[(unit, key)].name))
        _interface_connections(connections, bond)


def _interface_connections(connections: etree._Element, bond: Bond) -> None:
    """The bond's wired interface model: one ``VariableConnection`` per link, after a note."""
    links = [c for c in bond.connections if c.role == INTERFACE_ROLE]
    if not links:
        return
    connections.append(
        etree.Comment(f" interface model of bond {bond.name!r}: held over each step ")
    )
    for c in links:
        element = _el(connections, OSP_NS, "VariableConnection")
        _endpoint(element, "Variable", c.source)
        _endpoint(element, "Variable", c.target)


def system_structure_tree(
    plan: ExportPlan, fmu_names: dict[Path, str] | None = None
) -> etree._Element:
    """The ``OspSystemStructure.xml`` document of ``plan``.

    Parameters
    ----------
    plan : ExportPlan
        The scene planned for export.
    fmu_names : dict of Path to str, optional
        The file name each FMU gets beside the document (default
        :func:`~.plan.archive_names`).
    """
    names = fmu_names or archive_names(plan.units)
    root = _el(None, OSP_NS, "OspSystemStructure", version="0.1")
    _text(root, "StartTime", "0.0")
    _text(root, "EndTime", repr(float(plan.scene.run.stop_time)))
    _text(root, "BaseStepSize", repr(float(plan.scene.run.step)))
    _text(root, "Algorithm", "fixedStep")
    _simulators(root, plan, names)
    _connections(root, plan)
    return root


def _unit_definitions(root: etree._Element, model, used: set[str]) -> None:
    if not used:
        return
    definitions = {d.name: d for d in model.unitDefinitions}
    container = _el(root, OSP_MD_NS, "UnitDefinitions")
    for name in sorted(used):
        unit = _el(container, OSP_MD_NS, "Unit", name=name)
        base = definitions.get(name)
        attrs = {}
        if base is not None and base.baseUnit is not None:
            b = base.baseUnit
            attrs = {k: str(getattr(b, k)) for k in _BASE if getattr(b, k)}
            attrs.update(factor=repr(float(b.factor)), offset=repr(float(b.offset)))
        _el(unit, OSP_MD_NS, "BaseUnit", **attrs)


def model_description_tree(model, ports: list[Port]) -> etree._Element:
    """The ``<Model>_OspModelDescription.xml`` of ``model`` with its ``ports``.

    Parameters
    ----------
    model : fmpy.model_description.ModelDescription
        The model's description (its variables and unit definitions).
    ports : list of Port
        Its variable groups (see :func:`model_ports`).
    """
    units = {v.name: v.unit for v in model.modelVariables if v.unit}
    root = _el(None, OSP_MD_NS, "OspModelDescription", version="1.0")
    used = {units[v] for p in ports for _, v in p.members if v in units}
    _unit_definitions(root, model, used)
    groups = _el(root, OSP_MD_NS, "VariableGroups")
    for port in sorted(ports, key=lambda p: (_GROUP_ORDER.index(p.group), p.name)):
        element = _el(groups, OSP_MD_NS, port.group, name=port.name)
        for nested, variable in port.members:
            parent = (
                element
                if not nested
                else _el(element, OSP_MD_NS, nested, name=port.nested_name(nested))
            )
            _el(parent, OSP_MD_NS, "Variable", ref=variable, unit=units.get(variable))
    return root


def _xml(root: etree._Element) -> bytes:
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)


def write_osp(plan: ExportPlan, folder: Path) -> Path:
    """Write ``plan`` as an OSP configuration in ``folder``.

    Parameters
    ----------
    plan : ExportPlan
        The scene planned for export.
    folder : Path
        Output folder (created); the FMUs are copied into it.

    Returns
    -------
    Path
        The ``OspSystemStructure.xml`` file.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    names = archive_names(plan.units)
    for source, name in names.items():
        if source.resolve() != (folder / name).resolve():  # the signals FMU is built here
            shutil.copyfile(source, folder / name)
    by_model, _ = model_ports(plan)
    models = {u.model.modelName: u.model for u in plan.units}
    for model_name, ports in by_model.items():
        path = folder / f"{model_name}_OspModelDescription.xml"
        path.write_bytes(_xml(model_description_tree(models[model_name], ports)))
    target = folder / SYSTEM_STRUCTURE
    target.write_bytes(_xml(system_structure_tree(plan, names)))
    logger.info("wrote %s (%d simulators)", target, len(plan.units))
    return target


def export_osp(scene: Scene, out: Path, *, fmu_dir: Path = DEFAULT_FMU_DIR) -> Path:
    """Plan and write ``scene`` as an OSP configuration folder ``out``.

    Parameters
    ----------
    scene : Scene
        A validated scene.
    out : Path
        Output folder (created).
    fmu_dir : Path
        Where our FMUs are built and cached. The signals FMU of a scene with
        drivers or events is built into ``out`` itself, never into ``fmu_dir``
        (it belongs to this scene alone).

    Returns
    -------
    Path
        The ``OspSystemStructure.xml`` file.
    """
    out = Path(out)
    return write_osp(plan_export(scene, fmu_dir=fmu_dir, build_dir=out), out)
