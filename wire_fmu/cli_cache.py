"""``wire-fmu cache``: what the compiled-code cache holds, and pruning other versions'."""

from __future__ import annotations

import argparse

from wire_fmu.cli_commands import _print, plural
from wire_fmu.core.framework.compiled import cache_directory
from wire_fmu.core.framework.compiled_cache import CacheFolder, cache_folders, prune

__all__ = ["add_cache_parser", "cmd_cache"]


def add_cache_parser(sub: argparse._SubParsersAction) -> None:
    """Add the ``cache`` command to the command line's subcommands.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of ``wire-fmu``.
    """
    p = sub.add_parser(
        "cache",
        help="what the compiled-code cache holds; --prune removes other versions' code",
    )
    p.add_argument(
        "--prune",
        action="store_true",
        help="remove the compiled code of other versions of the sources (FMUs built from "
        "those versions compile again at their next run)",
    )
    p.set_defaults(func=cmd_cache)


def cmd_cache(args: argparse.Namespace) -> int:
    """Say what the compiled-code cache holds; with ``--prune``, remove other versions' code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``prune``.

    Returns
    -------
    int
        Exit status: 0; 1 if the cache could not be read or a folder removed (named).
    """
    directory = cache_directory()
    try:
        folders = cache_folders(directory)
    except OSError as err:
        _print(f"error: cannot read the cache {err.filename or directory}: {err.strerror or err}")
        return 1
    current = [f for f in folders if f.current]
    others = [f for f in folders if not f.current]
    _print(f"compiled-code cache: {directory}")
    _print(f"  these sources: {_amount(current)}")
    if not args.prune:
        hint = " (wire-fmu cache --prune removes them)" if others else ""
        _print(f"  other versions: {_amount(others)}{hint}")
        return 0
    try:
        removed = prune(directory)
    except OSError as err:
        _print(f"error: cannot remove {err.filename}: {err.strerror or err}")
        return 1
    _print(f"  removed, of other versions: {_amount(removed)}")
    return 0


def _amount(folders: list[CacheFolder]) -> str:
    """``"13 folders, 34.2 MB"``."""
    return f"{plural(len(folders), 'folder')}, {sum(f.size for f in folders) / 1e6:.1f} MB"
