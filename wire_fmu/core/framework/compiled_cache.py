"""What the compiled-code cache holds, and pruning what other versions of the sources left.

The cache (:func:`~wire_fmu.core.framework.compiled.cache_directory`) keeps one folder
per kernel module and version of its sources (:func:`~wire_fmu.core.framework.compiled.
cache_folder_name`), so that every copy of the same sources shares it. A folder is never
overwritten by another version: each upgrade, or each edit of a kernel's sources, adds
folders, and the old ones stay until pruned. :func:`prune` removes the folders of other
versions than the sources of this copy of ``wire_fmu``; FMUs built from those versions
compile their kernels again at their next run.
"""

from __future__ import annotations

import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from wire_fmu.core.framework.compiled import (
    cache_directory,
    cache_folder_name,
    source_digest,
)

__all__ = ["CacheFolder", "cache_folders", "current_folder_names", "kernel_modules", "prune"]

_KERNEL_FOLDER = re.compile(r"^wire_fmu_\w+-[0-9a-f]{16}$")
"""The name of a kernel module's cache folder: anything else in the cache is left alone."""
_TAKES_DECORATORS = re.compile(r"^[\w, ]+ = kernel_decorators\(__file__\)", re.MULTILINE)
"""The line of a kernel module that takes its decorators (:func:`kernel_decorators`)."""


@dataclass(frozen=True)
class CacheFolder:
    """One kernel module's compiled code for one version of its sources.

    Attributes
    ----------
    path : Path
        The folder.
    size : int
        Bytes in its files.
    current : bool
        Whether it is of the sources of this copy of ``wire_fmu``.
    """

    path: Path
    size: int
    current: bool


def kernel_modules() -> list[Path]:
    """The kernel modules of this copy of ``wire_fmu``: the sources that take their
    decorators from :func:`~wire_fmu.core.framework.compiled.kernel_decorators`."""
    package = Path(__file__).resolve().parents[2]
    return sorted(
        path
        for path in package.rglob("*.py")
        if _TAKES_DECORATORS.search(path.read_text(encoding="utf-8"))
    )


def current_folder_names() -> set[str]:
    """The cache folders the kernel modules of this copy of ``wire_fmu`` use."""
    return {cache_folder_name(str(path), source_digest(str(path))) for path in kernel_modules()}


def cache_folders(directory: Path | None = None) -> list[CacheFolder]:
    """Every kernel module's folder in the cache, by name.

    Parameters
    ----------
    directory : Path, optional
        The cache (default :func:`~wire_fmu.core.framework.compiled.cache_directory`).
    """
    directory = cache_directory() if directory is None else directory
    if not directory.is_dir():
        return []
    current = current_folder_names()
    return [
        CacheFolder(path, _size(path), path.name in current)
        for path in sorted(directory.iterdir())
        if path.is_dir() and _KERNEL_FOLDER.match(path.name)
    ]


def prune(directory: Path | None = None) -> list[CacheFolder]:
    """Remove the folders of other versions than this copy's sources; the ones removed.

    Parameters
    ----------
    directory : Path, optional
        The cache (default :func:`~wire_fmu.core.framework.compiled.cache_directory`).
    """
    removed = [folder for folder in cache_folders(directory) if not folder.current]
    for folder in removed:
        shutil.rmtree(folder.path)
    return removed


def _size(folder: Path) -> int:
    """Bytes in the files of ``folder``."""
    return sum(path.stat().st_size for path in folder.iterdir() if path.is_file())
