"""``wire-fmu info [UNIT] [--effects E1 E2 ...] [--markdown]``: the parameter reference.

:func:`add_info_parser` registers the command with :mod:`wire_fmu.cli`;
:func:`cmd_info` prints a unit's reference (or the list of unit types).
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["add_info_parser", "cmd_info"]

_HELP = "every parameter, effect, port and variable of a unit type"


def add_info_parser(sub: argparse._SubParsersAction) -> None:
    """Add the ``info`` command to the ``wire-fmu`` parser.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The commands of the ``wire-fmu`` parser.
    """
    p = sub.add_parser(
        "info",
        help=_HELP,
        description=f"{_HELP[0].upper()}{_HELP[1:]}: unit, default, valid range, description "
        "and the effects each needs. Without UNIT, the unit types.",
    )
    p.add_argument("unit", nargs="?", help="a unit type, e.g. BlockTrain (as a scene's fmu)")
    p.add_argument(
        "--effects",
        nargs="*",
        metavar="EFFECT",
        help="effects chosen (space or comma separated): marks with '-' what they leave "
        "without influence",
    )
    p.add_argument(
        "--markdown",
        action="store_true",
        help="write Markdown, as docs/units.md (every unit type without UNIT)",
    )
    p.set_defaults(func=cmd_info)


def cmd_info(args: argparse.Namespace) -> int:
    """Print the reference of ``args.unit`` (or of every unit type as Markdown, or the list).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``unit`` (or None), ``effects`` (list or None)
        and ``markdown``.

    Returns
    -------
    int
        Exit status: 0 on success.

    Raises
    ------
    ConfigurationError
        For an unknown unit type or effect, naming the valid ones.
    """
    from wire_fmu.unit_reference.catalogue import chosen_effects, unit_names, unit_reference
    from wire_fmu.unit_reference.markdown import unit_markdown, units_markdown
    from wire_fmu.unit_reference.text import reference_text

    if args.unit is None:
        if args.effects:
            from wire_fmu.core.errors import ConfigurationError

            raise ConfigurationError("wire-fmu info", ["--effects needs a UNIT to apply to"])
        if args.markdown:
            _write(units_markdown())
            return 0
        refs = [unit_reference(n) for n in unit_names()]
        width = max(len(r.name) for r in refs)
        lines = [f"  {r.name:<{width}}  {r.description}" for r in refs]
        _write("\n".join(["unit types (wire-fmu info UNIT for one):", *lines]) + "\n")
        return 0
    ref = unit_reference(args.unit)
    effects = None
    if args.effects is not None:
        names = [n for item in args.effects for n in item.replace(",", " ").split()]
        effects = chosen_effects(ref, names)
    if args.markdown:
        _write(unit_markdown(ref) + "\n")
    else:
        _write(reference_text(ref, effects) + "\n")
    return 0


def _write(text: str) -> None:
    sys.stdout.write(text)
