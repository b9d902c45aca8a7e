"""The ``[[bonds]]`` section: power bonds written out link by link, or as two ports.

Long form: ``kind`` and the ``effort``, ``flow`` (and ``position``) links. Short
form: ``ports = "winch.rope <-> rope.line_a"`` in a bond table, or the text
alone as an item of ``bonds = [...]``; the links and the kind come from the
ports the two units' FMUs declare (:mod:`wire_fmu.master.ports`), so the
short form is the one place where reading a scene opens its units' FMUs
(ours are built if needed). A short-form bond is named after its first port
unless ``name`` says otherwise.

Interface models: when both ports of a short-form bond declare one, the bond
also offers the model's five links (``effort_unit.{port}.{quantity} ->
flow_unit.{port}.{quantity}``: stiffness, damping, effort rate, reference
position and velocity) and the effort side's switch parameter. The scene
wires them with ``interface_models = true`` in ``[run]``, or per bond with
``interface_model = true`` (``false`` keeps the bond's three links whatever
the run says); see :mod:`.data` for what wiring does. A bond that is asked
for the model by its own key and whose ports cannot give it is a problem; asked
by the run setting, it keeps its three links and ``wire-fmu check`` warns
(:func:`.checks.interface_warnings`). A long-form bond lists the model's links
itself, ``interface = ["rope.mover_a.stiffness -> cylinder.rod.stiffness",
...]``, effort side to flow side, and its scene sets the effort unit's switch.

Ramped flows: when the effort port of a short-form bond declares a ``flow_ramp``
input, the bond offers a ramp link from the flow side's flow to it, wired by
``ramped_flows = true`` in ``[run]`` (:class:`.data.Bond`); a long-form bond
offers one when it names it, ``ramp = "winch.rope.payout_rate ->
rope.line_a.payout_acceleration"`` (from the flow's source).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from ..ports import PortDeclaration, PortLinks, parse_port_pair, port_links
from .data import (
    BOND_KINDS,
    EXTRAPOLATIONS,
    HELD,
    INTERFACE_ROLE,
    RAMP_ROLE,
    Bond,
    Connection,
    VarRef,
)
from .sections import _as_list, _parse_link, _text, _unknown_keys

__all__ = ["PortsOf", "parse_bonds"]

PortsOf = Callable[[str], tuple[dict[str, PortDeclaration] | None, str | None]]
"""A unit's name -> ``(its ports, None)`` or ``(None, why they cannot be read)``."""
_LONG_KEYS = {
    "name",
    "kind",
    "effort",
    "flow",
    "position",
    "extrapolation",
    "interface",
    "interface_model",
    "ramp",
}
_SHORT_KEYS = {"name", "kind", "ports", "extrapolation", "interface_model"}


def parse_bonds(
    data: Any, problems: list[str], units: set[str], ports_of: PortsOf
) -> tuple[Bond, ...]:
    """The scene's bonds; every problem appended to ``problems``.

    Parameters
    ----------
    data : Any
        The ``bonds`` entry of the scene (a list of tables or port texts).
    problems : list of str
        Where problems are collected.
    units : set of str
        The scene's unit names.
    ports_of : PortsOf
        Reads a unit's declared ports (called only for short-form bonds).
    """
    bonds = []
    names: set[str] = set()
    for i, spec in enumerate(_as_list(data, "bonds", problems)):
        if isinstance(spec, str):
            spec = {"ports": spec}
        if not isinstance(spec, Mapping):
            problems.append(f"bond {i}: must be a table or 'unit.port <-> unit.port'")
            continue
        if "ports" in spec:
            bond = _short_bond(spec, i, names, units, ports_of, problems)
        else:
            bond = _long_bond(spec, i, names, units, problems)
        if bond is not None:
            bonds.append(bond)
    return tuple(bonds)


def _name(spec: Mapping, i: int, default: str, names: set[str], problems: list[str]) -> str:
    name = _text(spec.get("name", default), f"bond {i}", "name", problems, default)
    if name in names:
        problems.append(f"bond {name!r}: defined twice")
    names.add(name)
    return name


def _extrapolation(spec: Mapping, where: str, problems: list[str]) -> str | None:
    extrapolation = spec.get("extrapolation")
    if extrapolation is not None and extrapolation not in EXTRAPOLATIONS:
        problems.append(f"{where}: 'extrapolation' must be one of {EXTRAPOLATIONS}")
        return None
    return extrapolation


def _interface_model(spec: Mapping, where: str, problems: list[str]) -> bool | None:
    """The bond's ``interface_model`` (None when it leaves the choice to the run)."""
    choice = spec.get("interface_model")
    if choice is not None and not isinstance(choice, bool):
        problems.append(f"{where}: 'interface_model' must be true or false, got {choice!r}")
        return None
    return choice


def _interface_links(
    spec: Mapping, name: str, where: str, problems: list[str]
) -> tuple[Connection, ...]:
    """A long-form bond's ``interface`` links (role ``interface``, held over the step)."""
    texts = spec.get("interface", [])
    if not isinstance(texts, list):
        problems.append(
            f"{where}: 'interface' must be a list of 'unit.output -> unit.input' links, "
            f"got {texts!r}"
        )
        return ()
    links = []
    for k, text in enumerate(texts):
        link = _parse_link(text, f"{where} interface link {k}", problems)
        if link:
            links.append(Connection(*link, role=INTERFACE_ROLE, bond=name, extrapolation=HELD))
    return tuple(links)


def _crossed_interface(
    effort: Connection, interface: tuple[Connection, ...], where: str, problems: list[str]
) -> None:
    """A problem for each interface link that does not go the effort's way."""
    for c in interface:
        if (c.source.unit, c.target.unit) != (effort.source.unit, effort.target.unit):
            problems.append(
                f"{where}: interface link {c.source} -> {c.target} must go the effort's way, "
                f"from unit {effort.source.unit!r} to unit {effort.target.unit!r}"
            )


def _long_bond(
    spec: Mapping, i: int, names: set[str], units: set[str], problems: list[str]
) -> Bond | None:
    name = _name(spec, i, f"bond{i}", names, problems)
    where = f"bond {name!r}"
    kind = spec.get("kind")
    if kind not in BOND_KINDS:
        problems.append(f"{where}: 'kind' must be one of {sorted(BOND_KINDS)}, got {kind!r}")
    extrapolation = _extrapolation(spec, where, problems)
    choice = _interface_model(spec, where, problems)
    interface = _interface_links(spec, name, where, problems)
    if choice is True and not interface and "interface" not in spec:
        problems.append(
            f"{where}: 'interface_model' = true needs the bond's 'interface' links (or write "
            "the bond as 'ports' whose FMUs declare the model)"
        )
    links = {}
    for role in ("effort", "flow", "position", RAMP_ROLE):
        if role not in spec:
            if role in ("effort", "flow"):
                problems.append(f"{where}: '{role}' is required (or write the bond as 'ports')")
            continue
        link = _parse_link(spec[role], f"{where} {role}", problems)
        if link:
            links[role] = Connection(*link, role=role, bond=name, extrapolation=extrapolation)
    _unknown_keys(spec, _LONG_KEYS, where, problems)
    if "effort" not in links or "flow" not in links:
        return None
    e, f = links["effort"], links["flow"]
    named = {e.source.unit, e.target.unit, f.source.unit, f.target.unit}
    crossed = e.source.unit != f.target.unit or e.target.unit != f.source.unit
    if named <= units and crossed:
        problems.append(
            f"{where}: the effort must go from the unit the flow goes to "
            f"(effort {e.source.unit} -> {e.target.unit}, flow "
            f"{f.source.unit} -> {f.target.unit})"
        )
    _crossed_interface(e, interface, where, problems)
    ramp = links.get(RAMP_ROLE)
    if ramp is not None and (ramp.source != f.source or ramp.target.unit != f.target.unit):
        problems.append(
            f"{where}: the ramp must go from the flow's source {f.source} to an input of "
            f"unit {f.target.unit!r}, got {ramp.source} -> {ramp.target}"
        )
    return Bond(
        name,
        str(kind),
        e,
        f,
        links.get("position"),
        interface=interface,
        interface_model=choice,
        extrapolation=extrapolation,
        ramp=ramp if ramp is not None and not problems else None,
    )


def _short_bond(
    spec: Mapping,
    i: int,
    names: set[str],
    units: set[str],
    ports_of: PortsOf,
    problems: list[str],
) -> Bond | None:
    pair = parse_port_pair(spec["ports"])
    default = pair[0][1] if pair else f"bond{i}"
    name = _name(spec, i, default, names, problems)
    where = f"bond {name!r}"
    extrapolation = _extrapolation(spec, where, problems)
    choice = _interface_model(spec, where, problems)
    _unknown_keys(spec, _SHORT_KEYS, where, problems)
    if pair is None:
        problems.append(
            f"{where}: 'ports' must read 'unit.port <-> unit.port', got {spec['ports']!r}"
        )
        return None
    declared = [_declared(unit, port, units, ports_of, where, problems) for unit, port in pair]
    if None in declared:
        return None
    links, why = port_links(*declared)
    problems += [f"{where}: {w}" for w in why]
    if links is None:
        return None
    kind = spec.get("kind", links.kind)
    if kind != links.kind:
        problems.append(f"{where}: 'kind' {kind!r} differs from the ports' kind {links.kind!r}")
        return None
    if choice is True and links.lacking:
        problems.append(
            f"{where}: 'interface_model' = true, but {' and '.join(links.lacking)} declares "
            "no interface model; leave the key out or set it false to keep the bond's effort, "
            "flow and position links"
        )
    return _bond_of_links(name, links, extrapolation, choice)


def _bond_of_links(
    name: str, links: PortLinks, extrapolation: str | None, choice: bool | None
) -> Bond:
    """The bond of a port pair's links (see :func:`~wire_fmu.master.ports.port_links`)."""

    def connection(pair: tuple[str, str], role: str, scheme: str | None) -> Connection:
        """The bond's link of ``role``.

        Parameters
        ----------
        pair : (str, str)
            Source and target, ``"unit.variable"`` each.
        role : str
            ``"effort"``, ``"flow"``, ``"position"``, ``"interface"`` or ``"ramp"``.
        scheme : str or None
            Its extrapolation (None: the run's).
        """
        source, target = (VarRef.parse(side) for side in pair)
        return Connection(source, target, role=role, bond=name, extrapolation=scheme)

    position = links.position and connection(links.position, "position", extrapolation)
    return Bond(
        name,
        links.kind,
        connection(links.effort, "effort", extrapolation),
        connection(links.flow, "flow", extrapolation),
        position or None,
        interface=tuple(connection(p, INTERFACE_ROLE, HELD) for p in links.interface),
        interface_switch=VarRef.parse(links.switch) if links.switch else None,
        interface_model=choice,
        interface_lacking=links.lacking,
        extrapolation=extrapolation,
        ramp=connection(links.ramp, RAMP_ROLE, extrapolation) if links.ramp else None,
    )


def _declared(
    unit: str, port: str, units: set[str], ports_of: PortsOf, where: str, problems: list[str]
) -> tuple[str, PortDeclaration] | None:
    """``(unit, its port's declaration)``, or None with the problem appended."""
    if unit not in units:
        problems.append(f"{where}: names unit {unit!r}, which is no unit of the scene")
        return None
    ports, why = ports_of(unit)
    if ports is None:
        problems.append(f"{where}: cannot read the ports of unit {unit!r}: {why}")
        return None
    if port not in ports:
        known = ", ".join(sorted(ports)) or "none (write the bond's links out)"
        problems.append(f"{where}: unit {unit!r} has no port {port!r}; its ports: {known}")
        return None
    return unit, ports[port]
