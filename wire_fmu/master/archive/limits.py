"""Bounds on what an archive may expand to, the errors that refuse one, and how
messages show sizes and member names."""

from __future__ import annotations

import lzma
import zipfile
import zlib
from dataclasses import dataclass

from wire_fmu.core.errors import ConfigurationError

__all__ = [
    "ArchiveError",
    "ArchiveLimits",
    "COMPLETE_MARKER",
    "DEFAULT_MAX_BYTES",
    "DEFAULT_MAX_FILES",
]

DEFAULT_MAX_BYTES = 1 << 30
"""Default bound on the total uncompressed size of an archive, bytes (1 GiB)."""
DEFAULT_MAX_FILES = 10_000
"""Default bound on the number of members (files and folders) of an archive."""
COMPLETE_MARKER = ".wire_fmu_extracted"
"""File written last into an extracted folder: the archive's SHA-256 and sizes (JSON)."""

_CHUNK = 1 << 20  # bytes copied at a time
_MAX_NAME_SHOWN = 80  # characters of a member name quoted in a message
# what a corrupt member, an unsupported method or a wrong password raise while reading
_READ_ERRORS = (
    zipfile.BadZipFile,
    zlib.error,
    lzma.LZMAError,
    EOFError,
    NotImplementedError,
    RuntimeError,
    ValueError,
)


class ArchiveError(ConfigurationError):
    """An archive that cannot be extracted safely (names the archive and every problem)."""


class _RefusedError(Exception):
    """Internal: stop extracting; the message is the problem."""


@dataclass(frozen=True)
class ArchiveLimits:
    """Bounds on what an archive may expand to.

    Parameters
    ----------
    max_bytes : int
        Total uncompressed size of all members, bytes.
    max_files : int
        Number of members (files and folders).
    """

    max_bytes: int = DEFAULT_MAX_BYTES
    max_files: int = DEFAULT_MAX_FILES

    def __post_init__(self) -> None:
        """Check both bounds are positive integers."""
        for name in ("max_bytes", "max_files"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"ArchiveLimits.{name} must be an integer >= 1, got {value!r}")


def _size(n: int) -> str:
    """Bytes as a short human-readable size (binary units)."""
    for unit, scale in (("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n} bytes"


def _shown(name: str) -> str:
    """A member name quoted for a message, shortened if long."""
    if len(name) > _MAX_NAME_SHOWN:
        name = name[: _MAX_NAME_SHOWN - 3] + "..."
    return repr(name)


def _reason(err: BaseException) -> str:
    """The short reason of an OS error (no traceback, no path repeated)."""
    if isinstance(err, OSError) and err.strerror:
        return err.strerror
    return str(err) or type(err).__name__
