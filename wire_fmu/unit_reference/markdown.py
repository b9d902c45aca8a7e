"""The parameter reference of every unit type as Markdown: ``docs/units.md``.

Written from the units' declarations by :func:`units_markdown`;
``python -m wire_fmu.unit_reference`` writes the file, and a test fails
when the checked-in copy is not what the declarations give.
"""

from __future__ import annotations

from collections.abc import Sequence

from wire_fmu.unit_reference.catalogue import (
    Entry,
    UnitReference,
    condition_text,
    port_quantities,
    unit_names,
    unit_reference,
)

__all__ = ["units_markdown", "unit_markdown"]

_HEADER = """# Unit reference

Every parameter, effect, port and variable of each unit type, with unit,
default, valid range and description, as the units declare them. Generated
by `python -m wire_fmu.unit_reference` (also `wire-fmu info UNIT`; with
`--effects E1 E2` it marks what those effects leave without influence); do
not edit by hand.

A scene sets parameters under `[units.NAME.parameters]`, chooses effects with
`effects = [...]` and bonds ports with `ports = "a.port <-> b.port"`
(docs/architecture.md). Units are FMI symbols (`N.m` is newton metre, `m3`
cubic metre). A range `> 0` excludes zero; `[0, 1]` includes both ends.
"Acts only with" names the effects without which a parameter has no
influence: `wire-fmu check` warns when a scene sets it without them.
"""


def units_markdown(names: Sequence[str] | None = None) -> str:
    """The reference of the unit types ``names`` (default: all) as one Markdown page.

    Parameters
    ----------
    names : sequence of str, optional
        Model names; None for every unit type, in the registry's order.

    Returns
    -------
    str
        The page, ending in a newline.
    """
    refs = [unit_reference(n) for n in (names or unit_names())]
    toc = [f"- [{r.name}](#{r.name.lower()}): {r.description}" for r in refs]
    body = [unit_markdown(r) for r in refs]
    return "\n".join([_HEADER, *toc, "", *body]).rstrip() + "\n"


def unit_markdown(ref: UnitReference) -> str:
    """One unit type's section.

    Parameters
    ----------
    ref : UnitReference
        The unit.

    Returns
    -------
    str
        Its section: effects, ports, parameters, fields, inputs and outputs.
    """
    parts = [f"## {ref.name}", "", f"{ref.description}.", ""]
    parts += _effects(ref)
    parts += _ports(ref)
    parts += _entries("Parameters", ref.parameters, ref, with_default=True)
    for param, fields in ref.fields.items():
        title = f"Fields of `{param}`"
        note = "`<name>` stands for any entry of a table, `[i]` for any node of a list."
        parts += _entries(title, fields, ref, with_default=True, note=note)
    parts += _entries("Inputs", ref.inputs, ref, with_default=True)
    parts += _entries("Outputs", ref.outputs, ref, with_default=False)
    return "\n".join(parts)


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _code(text: str) -> str:
    return f"`{text}`" if text else ""


def _effects(ref: UnitReference) -> list[str]:
    if not ref.effects:
        return ["No optional effects.", ""]
    rows = ["### Effects", "", "| effect | absent | present | needs |", "|---|---|---|---|"]
    for e in ref.effects:
        needs = ", ".join(_code(n) for n in e.requires)
        rows.append(f"| `{e.name}` | {_cell(e.absent)} | {_cell(e.present)} | {needs} |")
    return rows + [""]


def _ports(ref: UnitReference) -> list[str]:
    if not ref.ports:
        return []
    rows = [
        "### Ports",
        "",
        "| port | kind | side | outputs | inputs | description |",
        "|---|---|---|---|---|---|",
    ]
    for p in ref.ports:
        gives, takes = port_quantities(p)
        rows.append(
            f"| `{p.name}` | {p.kind} | {p.side.value} | {_cell(gives)} | {_cell(takes)} "
            f"| {_cell(p.description)} |"
        )
    return rows + [""]


def _entries(
    title: str,
    entries: Sequence[Entry],
    ref: UnitReference,
    *,
    with_default: bool,
    note: str = "",
) -> list[str]:
    if not entries:
        return []
    head = ["name", "type", "unit"] + (["default", "range"] if with_default else [])
    head += ["description"]
    rows = [f"### {title}", ""] + ([note, ""] if note else [])
    rows += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for item in entries:
        text = item.description.rstrip(".")
        condition = condition_text(ref.effects, item.acts_with, item.acts_without, item.acts_when)
        if condition:
            text += f". *{condition[0].upper()}{condition[1:]}.*"
        default = item.default or ("required" if item.required else "")
        cells = [f"`{item.name}`", item.type, _code(item.unit)]
        if with_default:
            cells += [_code(default) if item.default else default, _cell(item.range)]
        cells.append(_cell(text))
        rows.append("| " + " | ".join(cells) + " |")
    return rows + [""]
