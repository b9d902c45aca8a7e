"""Bonds written as two ports: ``"cylinder.rod <-> rope.mover_a"``.

Our FMUs declare their power ports in the model description, as
``VendorAnnotations/Tool[@name="wire_fmu"]/Ports/Port`` elements (written by
:mod:`wire_fmu.export.model_description`): a port's kind, which side of the
bond the unit computes (``effort``: it outputs the effort and takes the flow
and position; ``flow``: the reverse) and the names of its effort, flow and
position variables. A scene bond written as two ports is turned here into
the three links of the long form: the effort from the effort side to the
flow side, the flow and (when both ports have one) the position back.

Interface models: when both ports declare one (``interface="true"``), the
bond also offers five links ``effort_unit.{port}.{quantity} ->
flow_unit.{port}.{quantity}``, one per
:data:`~wire_fmu.export.model_description.INTERFACE_QUANTITIES` (stiffness,
damping, effort rate, reference position and velocity), and names the
effort side's ``interface_switch`` parameter that turns their computation
on. Whether the scene wires them is its choice (``run.interface_models``,
or the bond's ``interface_model``; see :mod:`wire_fmu.master.scene.bonds`);
when a side declares no model, :attr:`PortLinks.lacking` says which.

Ramped flows: an effort side that declares a ``flow_ramp`` input takes the flow's
rate of change over the step there; the bond then offers a ramp link from the flow
side's flow, whose value the master works out from the flow's extrapolation (the
slope over the step), and the flow input becomes the value at the step's start.
Whether the scene wires it is ``run.ramped_flows``.

The declarations are read from the FMU file itself, so any FMU that carries
them can be bonded by port; for others the long form is the way.
"""

from __future__ import annotations

import re
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

from wire_fmu.export.model_description import INTERFACE_QUANTITIES, PORTS_TOOL
from wire_fmu.master.archive import check_member_size
from wire_fmu.master.catalog import DEFAULT_FMU_DIR, resolve_fmu

__all__ = [
    "MAX_MODEL_DESCRIPTION_BYTES",
    "PORT_BOND_PATTERN",
    "PortDeclaration",
    "PortLinks",
    "interface_links",
    "parse_port_pair",
    "port_links",
    "read_ports",
    "unit_ports",
]

MAX_MODEL_DESCRIPTION_BYTES = 64 * 2**20
"""The largest ``modelDescription.xml`` read for its ports."""
PORT_BOND_PATTERN = re.compile(
    r"^\s*(?P<a_unit>[A-Za-z_]\w*)\.(?P<a_port>[A-Za-z_]\w*)\s*<->"
    r"\s*(?P<b_unit>[A-Za-z_]\w*)\.(?P<b_port>[A-Za-z_]\w*)\s*$"
)
"""``unit.port <-> unit.port``, unit and port names being identifiers."""
_SIDES = ("effort", "flow")


@dataclass(frozen=True)
class PortDeclaration:
    """A port as an FMU declares it (the attributes of one ``Port`` element).

    Parameters
    ----------
    name, kind, side : str
        The port's name, its kind (``translational``, ``rope``, ``rotational``) and the side
        the unit computes (``effort`` or ``flow``).
    effort, flow : str
        Names of the unit's effort and flow variables at the port.
    position : str or None
        Name of its position variable, if it has one.
    description : str
        What the port is.
    interface : bool
        Whether the port carries the interface model
        (:data:`~wire_fmu.export.model_description.INTERFACE_QUANTITIES` as ``{port}.{quantity}``).
    interface_switch : str or None
        The effort side's Boolean parameter that turns the interface model on.
    flow_ramp : str or None
        The effort side's input that takes the flow's rate of change over the step.
    """

    name: str
    kind: str
    side: str
    effort: str
    flow: str
    position: str | None = None
    description: str = ""
    interface: bool = False
    interface_switch: str | None = None
    flow_ramp: str | None = None


@dataclass(frozen=True)
class PortLinks:
    """The long form of a port bond: links as ``("unit.variable", "unit.variable")`` pairs.

    Parameters
    ----------
    kind : str
        The bond's kind (that of both ports).
    effort, flow : tuple of str
        Source and target of the effort link (effort side to flow side) and of the flow link
        (back).
    position : tuple of str or None
        Source and target of the position link, when both ports have a position.
    interface : tuple of (str, str)
        The interface model's links, effort side to flow side, one per
        :data:`~wire_fmu.export.model_description.INTERFACE_QUANTITIES` in that order; empty
        unless both ports declare the model.
    switch : str or None
        The effort side's ``"unit.parameter"`` that turns its interface model on (None
        without interface links, or when the effort side names none).
    lacking : tuple of str
        The ports that declare no interface model, as ``"unit.port (side side)"``.
    ramp : tuple of str or None
        Source and target of the flow's ramp: the flow side's flow to the effort side's
        ``flow_ramp`` input (None when the effort side takes none).
    """

    kind: str
    effort: tuple[str, str]
    flow: tuple[str, str]
    position: tuple[str, str] | None
    interface: tuple[tuple[str, str], ...] = ()
    switch: str | None = None
    lacking: tuple[str, ...] = ()
    ramp: tuple[str, str] | None = None


def parse_port_pair(text: object) -> tuple[tuple[str, str], tuple[str, str]] | None:
    """``((unit, port), (unit, port))`` of ``"unit.port <-> unit.port"``, else None.

    Parameters
    ----------
    text : object
        What the scene wrote.
    """
    match = PORT_BOND_PATTERN.match(text) if isinstance(text, str) else None
    if match is None:
        return None
    return (match["a_unit"], match["a_port"]), (match["b_unit"], match["b_port"])


def read_ports(path: Path) -> dict[str, PortDeclaration]:
    """The ports an FMU file declares, by name (empty when it declares none).

    Parameters
    ----------
    path : Path
        The FMU file.

    Raises
    ------
    ValueError
        If the FMU cannot be read or its port declarations are malformed (saying why).
    """
    too_big = check_member_size(path, "modelDescription.xml", MAX_MODEL_DESCRIPTION_BYTES)
    if too_big:
        raise ValueError(too_big)
    try:
        with zipfile.ZipFile(path) as archive:
            root = ET.fromstring(archive.read("modelDescription.xml"))
    except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError) as exc:
        raise ValueError(f"cannot read the model description of {path}: {exc}") from exc
    ports: dict[str, PortDeclaration] = {}
    for element in root.findall(f"VendorAnnotations/Tool[@name='{PORTS_TOOL}']/Ports/Port"):
        port = _declaration(element.attrib)
        if port.name in ports:
            raise ValueError(f"port {port.name!r} is declared twice")
        ports[port.name] = port
    return ports


def _declaration(attrs: dict[str, str]) -> PortDeclaration:
    missing = [k for k in ("name", "kind", "side", "effort", "flow") if not attrs.get(k)]
    if missing:
        raise ValueError(f"a port declaration lacks {missing}: {attrs}")
    if attrs["side"] not in _SIDES:
        raise ValueError(f"port {attrs['name']!r}: side {attrs['side']!r} is not one of {_SIDES}")
    return PortDeclaration(
        attrs["name"],
        attrs["kind"],
        attrs["side"],
        attrs["effort"],
        attrs["flow"],
        attrs.get("position") or None,
        attrs.get("description", ""),
        attrs.get("interface") == "true",
        attrs.get("interface_switch") or None,
        attrs.get("flow_ramp") or None,
    )


def unit_ports(
    fmu: str, base_dir: Path, fmu_dir: Path = DEFAULT_FMU_DIR
) -> tuple[dict[str, PortDeclaration] | None, str | None]:
    """The ports of the FMU a scene's unit names: ``(ports, None)`` or ``(None, problem)``.

    Parameters
    ----------
    fmu : str
        The unit's ``fmu`` entry (one of ours, built if needed, or a path to an FMU file).
    base_dir : Path
        Folder relative FMU paths are taken from (the scene's).
    fmu_dir : Path
        Where our FMUs are built.
    """
    path, problem = resolve_fmu(fmu, base_dir, fmu_dir)
    if problem:
        return None, problem
    try:
        return read_ports(path), None
    except ValueError as exc:
        return None, str(exc)


def port_links(
    a: tuple[str, PortDeclaration], b: tuple[str, PortDeclaration]
) -> tuple[PortLinks | None, list[str]]:
    """The links of a bond between two ports, or the problems that prevent it.

    Parameters
    ----------
    a, b : tuple of (str, PortDeclaration)
        Each port's unit name and declaration, in the order the scene wrote them.

    Returns
    -------
    PortLinks or None
        The long form (None when there are problems).
    list of str
        Why the two ports cannot be bonded: different kinds, not one effort side and one
        flow side, or a position the effort side takes and the flow side does not give.
    """
    (a_unit, a_port), (b_unit, b_port) = a, b
    named = f"{a_unit}.{a_port.name} ({a_port.kind}, {a_port.side} side) and "
    named += f"{b_unit}.{b_port.name} ({b_port.kind}, {b_port.side} side)"
    problems = []
    if a_port.kind != b_port.kind:
        problems.append(f"ports {named} are of different kinds")
    if a_port.side == b_port.side:
        problems.append(
            f"ports {named} both compute the {a_port.side}: a bond joins an effort side "
            "to a flow side"
        )
    if problems:
        return None, problems
    (e_unit, e_port), (f_unit, f_port) = (a, b) if a_port.side == "effort" else (b, a)
    if e_port.position and not f_port.position:
        return None, [
            f"port {e_unit}.{e_port.name} takes a position ({e_port.position}) that port "
            f"{f_unit}.{f_port.name} does not give: write the bond's links out (effort, flow, "
            "position) with the position from another output"
        ]
    position = None
    if e_port.position:
        position = (f"{f_unit}.{f_port.position}", f"{e_unit}.{e_port.position}")
    interface, switch, lacking = interface_links((e_unit, e_port), (f_unit, f_port))
    ramp = None
    if e_port.flow_ramp:
        ramp = (f"{f_unit}.{f_port.flow}", f"{e_unit}.{e_port.flow_ramp}")
    return PortLinks(
        a_port.kind,
        (f"{e_unit}.{e_port.effort}", f"{f_unit}.{f_port.effort}"),
        (f"{f_unit}.{f_port.flow}", f"{e_unit}.{e_port.flow}"),
        position,
        interface,
        switch,
        lacking,
        ramp,
    ), []


def interface_links(
    effort: tuple[str, PortDeclaration], flow: tuple[str, PortDeclaration]
) -> tuple[tuple[tuple[str, str], ...], str | None, tuple[str, ...]]:
    """The interface model's links across a bond, its switch, and the ports that lack one.

    Parameters
    ----------
    effort, flow : tuple of (str, PortDeclaration)
        The effort side's and the flow side's unit name and port declaration.

    Returns
    -------
    links : tuple of (str, str)
        ``("effort_unit.{port}.{quantity}", "flow_unit.{port}.{quantity}")`` for each of
        :data:`~wire_fmu.export.model_description.INTERFACE_QUANTITIES`, in that order; empty
        unless both ports declare the model.
    switch : str or None
        ``"effort_unit.parameter"``: the effort side's interface switch, with the links.
    lacking : tuple of str
        Each port without the model, ``"unit.port (effort side)"`` or ``"(flow side)"``.
    """
    lacking = tuple(
        f"{unit}.{port.name} ({port.side} side)"
        for unit, port in (effort, flow)
        if not port.interface
    )
    if lacking:
        return (), None, lacking
    (e_unit, e_port), (f_unit, f_port) = effort, flow
    links = tuple(
        (f"{e_unit}.{e_port.name}.{q}", f"{f_unit}.{f_port.name}.{q}") for q in INTERFACE_QUANTITIES
    )
    switch = f"{e_unit}.{e_port.interface_switch}" if e_port.interface_switch else None
    return links, switch, ()
