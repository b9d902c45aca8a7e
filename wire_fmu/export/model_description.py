"""Finish pythonfmu's ``modelDescription.xml`` from a unit's declarations.

pythonfmu 0.7 writes no units, no ``min``/``max``/``nominal``, outputs
without ``dependencies`` (which FMI 2.0 reads as "depends on every input")
and no ``InitialUnknowns``. :func:`patch_model_description` adds:

* a ``UnitDefinitions`` section with the SI ``BaseUnit`` of every unit used
  (table in :mod:`wire_fmu.export.units`) and ``unit``/``min``/``max``/
  ``nominal`` on every Real;
* a description on every variable and start values printed to round-trip;
* ``ModelStructure/Outputs`` with ``dependencies`` from ``depends_on``
  (``dependencies=""``: no direct feedthrough);
* ``ModelStructure/InitialUnknowns``: every output (all have
  ``initial="calculated"``) in index order, depending on the knowns of
  initialisation mode -- parameters (``initial="exact"``) and inputs;
* ``canGetAndSetFMUstate``/``canSerializeFMUstate`` true;
* the unit's power ports as ``VendorAnnotations/Tool[@name="wire_fmu"]/Ports``
  (:func:`vendor_annotations`), which a scene's bond shorthand reads;
* the local Real ``physics_seconds`` (the facade's timing variable) with its unit.

Initial unknowns depend on every parameter (the declarations do not say
which) and on every input, unless the unit class narrows the inputs with an
optional ``INITIAL_DEPENDS_ON`` mapping (output name -> input names), e.g.
an inertia whose initial position comes from parameters only.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from xml.etree import ElementTree as ET

from wire_fmu.core.errors import ConfigurationError

# re-exported: a Port element's interface="true" promises {port}.{quantity} variables of
# these quantities, in these units by kind, which is the declaration a master reads
from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES, INTERFACE_UNITS, Port
from wire_fmu.core.framework.unit import Causality, Unit, Variable
from wire_fmu.export.facade import PHYSICS_SECONDS
from wire_fmu.export.units import UNITS

__all__ = [
    "CAPABILITIES",
    "INTERFACE_QUANTITIES",
    "INTERFACE_UNITS",
    "PORTS_TOOL",
    "check_units",
    "patch_model_description",
    "vendor_annotations",
]

PORTS_TOOL = "wire_fmu"
"""``Tool`` name of the vendor annotation that declares a unit's ports."""

CAPABILITIES = {
    "needsExecutionTool": "true",  # a Python interpreter with numpy/scipy
    "canHandleVariableCommunicationStepSize": "true",
    "canInterpolateInputs": "false",
    "canBeInstantiatedOnlyOncePerProcess": "false",
    "canGetAndSetFMUstate": "true",
    "canSerializeFMUstate": "true",
    "providesDirectionalDerivative": "false",
}
"""``CoSimulation`` attributes every FMU of this project declares."""

_INITIAL = {Causality.parameter: "exact", Causality.output: "calculated"}
_TIMING_DESCRIPTION = "wall-clock time spent in the unit's physics since instantiation"


def check_units(unit_class: type[Unit]) -> list[str]:
    """Problems with the units of ``unit_class``'s Reals (empty when all known).

    Parameters
    ----------
    unit_class : type of Unit
        The unit class whose Real variables are checked.
    """
    return [
        f"{unit_class.NAME}.{v.name}: unit {v.unit!r} is not defined in "
        "wire_fmu.export.units.UNITS; use a listed unit or add it to the table"
        for v in unit_class.variables()
        if v.type is float and v.unit not in UNITS
    ]


def _indices(names: Iterable[str], index_of: Mapping[str, int]) -> list[int]:
    return sorted(index_of[n] for n in names)


def _dependency_attrs(indices: list[int], with_kind: bool) -> dict[str, str]:
    # An absent dependenciesKind means "dependent" for every entry.
    attrs = {"dependencies": " ".join(map(str, indices))}
    if indices and with_kind:
        attrs["dependenciesKind"] = " ".join(["dependent"] * len(indices))
    return attrs


def _unit_definitions(units: Iterable[str]) -> ET.Element:
    section = ET.Element("UnitDefinitions")
    for name in sorted(set(units)):
        definition = UNITS[name]
        unit = ET.SubElement(section, "Unit", name=name)
        ET.SubElement(unit, "BaseUnit", definition.base_unit_attributes())
        for display in definition.display:
            attrs = {"name": display.name, "factor": repr(display.factor)}
            if display.offset:
                attrs["offset"] = repr(display.offset)
            ET.SubElement(unit, "DisplayUnit", attrs)
    return section


def _format_start(var: Variable) -> str:
    if var.type is float:
        return repr(float(var.start))  # shortest text that round-trips
    if var.type is bool:
        return "true" if var.start else "false"
    return str(var.start) if var.type is str else str(int(var.start))


def _patch_variable(node: ET.Element, var: Variable) -> None:
    node.set("description", var.description)
    initial = _INITIAL.get(var.causality)
    if initial is None:
        node.attrib.pop("initial", None)
    else:
        node.set("initial", initial)
    typed = node[0]
    typed.attrib.clear()
    if var.causality is not Causality.output:
        typed.set("start", _format_start(var))
    if var.type is float:
        typed.set("unit", var.unit)
    if var.type in (float, int):
        for attr in ("min", "max", "nominal"):
            value = getattr(var, attr)
            if value is not None and not (attr == "nominal" and var.type is int):
                typed.set(attr, repr(var.type(value)))


def _model_structure(unit_class: type[Unit], index_of: Mapping[str, int]) -> ET.Element:
    variables = unit_class.variables()
    outputs = [v for v in variables if v.causality is Causality.output]
    inputs = [v.name for v in variables if v.causality is Causality.input]
    parameters = [v.name for v in variables if v.causality is Causality.parameter]
    narrowed: Mapping[str, Iterable[str]] = getattr(unit_class, "INITIAL_DEPENDS_ON", {})
    structure = ET.Element("ModelStructure")
    section = ET.SubElement(structure, "Outputs") if outputs else None
    for var in outputs:
        attrs = _dependency_attrs(_indices(var.depends_on, index_of), with_kind=True)
        ET.SubElement(section, "Unknown", index=str(index_of[var.name]), **attrs)
    section = ET.SubElement(structure, "InitialUnknowns") if outputs else None
    for var in outputs:  # declaration order is index order
        knowns = parameters + list(narrowed.get(var.name, inputs))
        attrs = _dependency_attrs(_indices(knowns, index_of), with_kind=False)
        ET.SubElement(section, "Unknown", index=str(index_of[var.name]), **attrs)
    return structure


def _check_variables(root: ET.Element, unit_class: type[Unit]) -> list[ET.Element]:
    """The nodes of the declared variables (the facade's timing variable follows them)."""
    nodes = list(root.find("ModelVariables"))
    names = [n.get("name") for n in nodes]
    declared = [v.name for v in unit_class.variables()] + [PHYSICS_SECONDS]
    if names != declared:
        raise ConfigurationError(
            f"{unit_class.NAME} modelDescription.xml",
            [f"variables {names} do not match the declarations {declared}"],
        )
    _patch_timing(nodes[-1])
    return nodes[:-1]


def _patch_timing(node: ET.Element) -> None:
    node.set("description", _TIMING_DESCRIPTION)
    node[0].attrib.clear()
    node[0].set("unit", "s")


def vendor_annotations(ports: Iterable[Port]) -> ET.Element:
    """``VendorAnnotations`` declaring a unit's power ports (read by the master).

    Parameters
    ----------
    ports : iterable of Port
        The unit's ports.

    Returns
    -------
    xml.etree.ElementTree.Element
        ``<VendorAnnotations><Tool name="wire_fmu"><Ports><Port .../>...``, one ``Port``
        element per port with the attributes ``name``, ``kind``, ``side``, ``effort``,
        ``flow``, ``description``, (when the port has one) ``position`` and (when it
        carries the interface model) ``interface="true"`` and its ``interface_switch``, and
        (on an effort side that takes one) the ``flow_ramp`` input.
    """
    annotations = ET.Element("VendorAnnotations")
    tool = ET.SubElement(annotations, "Tool", name=PORTS_TOOL)
    section = ET.SubElement(tool, "Ports")
    for port in ports:
        attrs = {
            "name": port.name,
            "kind": port.kind,
            "side": port.side.value,
            "effort": port.effort,
            "flow": port.flow,
        }
        if port.position:
            attrs["position"] = port.position
        attrs["description"] = port.description
        if port.interface:
            attrs["interface"] = "true"
        if port.interface_switch:
            attrs["interface_switch"] = port.interface_switch
        if port.flow_ramp:
            attrs["flow_ramp"] = port.flow_ramp
        ET.SubElement(section, "Port", attrs)
    return annotations


def _insert_before(root: ET.Element, element: ET.Element, successors: tuple[str, ...]) -> None:
    for position, child in enumerate(root):
        if child.tag in successors:
            root.insert(position, element)
            return
    root.append(element)


def patch_model_description(xml: bytes, unit_class: type[Unit], generation_tool: str) -> bytes:
    """Complete pythonfmu's model description for ``unit_class``.

    Parameters
    ----------
    xml : bytes
        ``modelDescription.xml`` as written by pythonfmu.
    unit_class : type of Unit
        The unit the FMU exposes; its declarations are the source of truth.
    generation_tool : str
        Value of the ``generationTool`` attribute.

    Returns
    -------
    bytes
        The completed, indented XML document (UTF-8).

    Raises
    ------
    ConfigurationError
        If a unit is not in the table (naming every such variable) or the
        XML's variables do not match the declarations.
    """
    problems = check_units(unit_class)
    if problems:
        raise ConfigurationError(f"{unit_class.NAME} units", problems)
    root = ET.fromstring(xml)
    root.set("generationTool", generation_tool)
    if unit_class.DESCRIPTION:
        root.set("description", unit_class.DESCRIPTION)
    cosim = root.find("CoSimulation")
    for key, value in CAPABILITIES.items():
        cosim.set(key, value)
    for node, var in zip(_check_variables(root, unit_class), unit_class.variables(), strict=True):
        _patch_variable(node, var)
    for tag in ("UnitDefinitions", "ModelStructure"):
        for old in root.findall(tag):
            root.remove(old)
    successors = ("TypeDefinitions", "LogCategories", "DefaultExperiment", "ModelVariables")
    used = [v.unit for v in unit_class.variables() if v.type is float] + ["s"]  # s: the timing
    _insert_before(root, _unit_definitions(used), successors)
    for old in root.findall("VendorAnnotations"):
        root.remove(old)
    if unit_class.PORTS:
        _insert_before(root, vendor_annotations(unit_class.PORTS), ("ModelVariables",))
    index_of = {v.name: i + 1 for i, v in enumerate(unit_class.variables())}
    root.append(_model_structure(unit_class, index_of))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True) + b"\n"
