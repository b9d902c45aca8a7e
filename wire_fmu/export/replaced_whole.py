"""A file replaced in one step: written beside its target, then moved onto it.

The FMU binary, a built FMU and a rewritten FMU archive are each replaced this
way, so that a process reading one while another writes it (two runs started
together on a fresh checkout, parallel test workers) reads the old file or the
new one, never part of either, and a failed write leaves the old one as it was.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["replaced_whole"]


@contextmanager
def replaced_whole(target: Path) -> Iterator[Path]:
    """A path to write ``target`` at; it becomes ``target`` when the block ends without error.

    The path lies in a temporary folder of its own beside ``target`` (the same file
    system, so the move is one ``os.replace``); the folder, and whatever is left in it
    after an error, is removed.

    Parameters
    ----------
    target : Path
        The file to replace (its folder must exist).

    Yields
    ------
    Path
        Where to write it, under ``target``'s own name.
    """
    with tempfile.TemporaryDirectory(prefix=f".{target.name}.", dir=target.parent) as own:
        partial = Path(own) / target.name
        yield partial
        os.replace(partial, target)
