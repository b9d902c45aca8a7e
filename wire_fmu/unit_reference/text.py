"""A unit's reference as plain text for the terminal (``wire-fmu info UNIT``)."""

from __future__ import annotations

import textwrap
from collections.abc import Iterable, Sequence

from wire_fmu.core.framework.ports import Port
from wire_fmu.unit_reference.catalogue import (
    Entry,
    UnitReference,
    condition_text,
    port_quantities,
)

__all__ = ["reference_text"]

_WIDTH = 96
_INDENT = "      "


def reference_text(ref: UnitReference, effects: frozenset[str] | None = None) -> str:
    """The reference of one unit as text.

    Parameters
    ----------
    ref : UnitReference
        The unit.
    effects : frozenset of str or None
        The effects chosen (checked): what they leave without influence is
        marked. None lists when each item acts instead.

    Returns
    -------
    str
        Sections: effects, ports, parameters (with the fields of structured
        parameters), inputs and outputs.
    """
    lines = [f"{ref.name}: {ref.description}"]
    if effects is not None:
        chosen = ", ".join(sorted(effects)) or "none (the simplest model)"
        lines.append(f"effects chosen: {chosen}; '-' marks what they leave without influence")
    lines += _effects(ref, effects)
    lines += _ports(ref.ports)
    lines += _entries("Parameters", ref.parameters, ref, effects)
    for param, fields in ref.fields.items():
        title = f"Fields of parameter '{param}' (<name>: any entry; [i]: any node)"
        lines += _entries(title, fields, ref, effects)
    lines += _entries("Inputs", ref.inputs, ref, effects)
    lines += _entries("Outputs", ref.outputs, ref, effects)
    return "\n".join(lines)


def _effects(ref: UnitReference, chosen: frozenset[str] | None) -> list[str]:
    if not ref.effects:
        return ["", "Effects: none (nothing optional)"]
    width = max(len(e.name) for e in ref.effects)
    out = ["", "Effects"]
    for e in ref.effects:
        mark = "" if chosen is None else ("on " if e.name in chosen else "off")
        needs = f"; needs {', '.join(e.requires)}" if e.requires else ""
        text = f"absent: {e.absent}; present: {e.present}{needs}"
        head = f"  {e.name:<{width}}  {mark}{' ' if mark else ''}"
        out += _wrapped(head, text)
    return out


def _ports(ports: Sequence[Port]) -> list[str]:
    if not ports:
        return ["", "Ports: none"]
    out = ["", "Ports (power bonds: 'unit.port <-> unit.port' in a scene's [[bonds]])"]
    for p in ports:
        gives, takes = port_quantities(p)
        about = f" ({p.description})" if p.description else ""
        text = f"{p.kind}, {p.side.value} side{about}: outputs {gives}; inputs {takes}"
        out += _wrapped(f"  {p.name}  ", text)
    return out


def _entries(
    title: str,
    entries: Sequence[Entry],
    ref: UnitReference,
    chosen: frozenset[str] | None,
) -> list[str]:
    if not entries:
        return []
    out = ["", title]
    for item in entries:
        facts = [f"[{item.unit}]" if item.unit else "", item.type]
        if item.default:
            facts.append(f"default {item.default}")
        elif item.required:
            facts.append("required")
        if item.range:
            facts.append(f"range {item.range}")
        if item.tunable:
            facts.append("tunable")
        head = f"  {item.name}  " + "  ".join(f for f in facts if f)
        silent = chosen is not None and not item.acts(chosen)
        out.append(("- " if silent else "  ") + head[2:])
        out += _wrapped(_INDENT, item.description)
        condition = condition_text(ref.effects, item.acts_with, item.acts_without, item.acts_when)
        if condition:
            note = "no influence with these effects: " if silent else ""
            out += _wrapped(_INDENT, f"{note}{condition}")
    return out


def _wrapped(head: str, text: str) -> Iterable[str]:
    indent = " " * len(head) if len(head) <= 32 else _INDENT
    return textwrap.wrap(
        text, _WIDTH, initial_indent=head, subsequent_indent=indent, break_on_hyphens=False
    ) or [head.rstrip()]
