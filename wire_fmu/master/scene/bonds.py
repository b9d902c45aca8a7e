"""The ``[[bonds]]`` section: power bonds written out link by link, or as two ports.

Long form: ``kind`` and the ``effort``, ``flow`` (and ``position``) links. Short
form: ``ports = "winch.rope <-> rope.line_a"`` in a bond table, or the text
alone as an item of ``bonds = [...]``; the links and the kind come from the
ports the two units' FMUs declare (:mod:`wire_fmu.master.ports`), so the
short form is the one place where reading a scene opens its units' FMUs
(ours are built if needed). A short-form bond is named after its first port
unless ``name`` says otherwise.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from ..ports import PortDeclaration, parse_port_pair, port_links
from .data import BOND_KINDS, EXTRAPOLATIONS, Bond, Connection, VarRef
from .sections import _as_list, _parse_link, _text, _unknown_keys

__all__ = ["PortsOf", "parse_bonds"]

PortsOf = Callable[[str], tuple[dict[str, PortDeclaration] | None, str | None]]
"""A unit's name -> ``(its ports, None)`` or ``(None, why they cannot be read)``."""
_LONG_KEYS = {"name", "kind", "effort", "flow", "position", "extrapolation"}
_SHORT_KEYS = {"name", "kind", "ports", "extrapolation"}


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


def _long_bond(
    spec: Mapping, i: int, names: set[str], units: set[str], problems: list[str]
) -> Bond | None:
    name = _name(spec, i, f"bond{i}", names, problems)
    where = f"bond {name!r}"
    kind = spec.get("kind")
    if kind not in BOND_KINDS:
        problems.append(f"{where}: 'kind' must be one of {sorted(BOND_KINDS)}, got {kind!r}")
    extrapolation = _extrapolation(spec, where, problems)
    links = {}
    for role in ("effort", "flow", "position"):
        if role not in spec:
            if role != "position":
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
    return Bond(name, str(kind), e, f, links.get("position"))


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

    def connection(pair: tuple[str, str], role: str) -> Connection:
        """The bond's link of ``role``.

        Parameters
        ----------
        pair : (str, str)
            Source and target, ``"unit.variable"`` each.
        role : str
            ``"effort"``, ``"flow"`` or ``"position"``.
        """
        source, target = (VarRef.parse(side) for side in pair)
        return Connection(source, target, role=role, bond=name, extrapolation=extrapolation)

    position = connection(links.position, "position") if links.position else None
    return Bond(
        name,
        links.kind,
        connection(links.effort, "effort"),
        connection(links.flow, "flow"),
        position,
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
