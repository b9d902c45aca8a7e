"""Which ``wire_fmu`` files an FMU bundles, and their fingerprint (stdlib only).

Every FMU ships a copy of the ``wire_fmu`` package in its resources. The
builder records the fingerprint of that copy; at instantiation the facade
compares it with the fingerprint of the ``wire_fmu`` package the process
actually imported (all FMUs in one process share one interpreter, so the
first ``wire_fmu`` imported serves them all). Build and runtime must select
the same files, so the selection lives here, in one place.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

__all__ = ["BUNDLED_TOP_LEVEL", "bundled_files", "fingerprint", "package_dir"]

BUNDLED_TOP_LEVEL = frozenset({"__init__.py", "_fingerprint.py", "core", "export"})
"""What runs inside an FMU: the physics core and the facade layer. The rest
of the package (master, command line, studies) uses fmpy and stays out."""

_EXCLUDED_DIRS = frozenset({"__pycache__"})
_EXCLUDED_SUFFIXES = (".pyc", ".pyo", ".swp", ".swo", ".orig", ".rej", "~")


def package_dir() -> Path:
    """Directory of the ``wire_fmu`` package this module belongs to."""
    return Path(__file__).resolve().parent


def _is_bundled(relative: Path) -> bool:
    parts = relative.parts
    if parts[0] not in BUNDLED_TOP_LEVEL:
        return False
    if any(part in _EXCLUDED_DIRS or part.startswith(".") for part in parts):
        return False
    return not relative.name.endswith(_EXCLUDED_SUFFIXES)


def bundled_files(root: Path) -> list[Path]:
    """Files of the package at ``root`` that an FMU bundles.

    Parameters
    ----------
    root : Path
        The ``wire_fmu`` package directory.

    Returns
    -------
    list of Path
        Paths relative to ``root``, sorted by their POSIX form.
    """
    files = (p.relative_to(root) for p in root.rglob("*") if p.is_file())
    return sorted((p for p in files if _is_bundled(p)), key=lambda p: p.as_posix())


def fingerprint(root: Path) -> str:
    """SHA-256 over the bundled files' relative paths and contents.

    Parameters
    ----------
    root : Path
        The ``wire_fmu`` package directory.

    Returns
    -------
    str
        64 hexadecimal digits; equal for byte-identical sources.
    """
    digest = hashlib.sha256()
    for relative in bundled_files(root):
        digest.update(relative.as_posix().encode("utf-8") + b"\0")
        digest.update((root / relative).read_bytes() + b"\0")
    return digest.hexdigest()
