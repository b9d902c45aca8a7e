"""Safe extraction of the zip archives we are handed: FMUs and SSP packages.

Every archive the master opens goes through here, because a zip file from
elsewhere can be hostile:

* **Bounded.** The total uncompressed size and the number of members are
  limited (defaults :data:`DEFAULT_MAX_BYTES`, 1 GiB, and
  :data:`DEFAULT_MAX_FILES`, 10,000: generous for real FMUs and packages).
  The sizes the archive declares are checked before anything is written,
  and the bytes actually written are counted as they are written, so an
  archive whose declared sizes lie is stopped too: a zip bomb is refused
  at once, never after writing gigabytes.
* **Confined.** A member whose path would land outside the target folder
  (absolute, a drive letter, ``..``, a backslash) is refused, as are
  symbolic links and other special files, names that hold NUL bytes and
  names that collide with each other.
* **Atomic.** Files are extracted into a fresh temporary sibling of the
  target folder and renamed into place only when complete, with a marker
  file (:data:`COMPLETE_MARKER`, holding the archive's SHA-256) written
  last. A folder is reused only if its marker names the same content, so a
  half-written folder (a process killed while extracting) is never taken
  for a complete one.
* **Tidy.** The temporary folder is removed when extraction fails; a stale
  partial folder left by a killed process is removed once it is a day old.

Problems raise :class:`ArchiveError` naming the archive and what is wrong
with it, e.g. ``package x.ssp: expands to more than 1 GiB``.

Three entry points:

:func:`extract_archive`
    Into a given folder (reused when it already holds this archive).
:func:`extract_cached`
    Into a cache folder named by the archive's content digest.
:func:`extract_temporary`
    Into a fresh private temporary folder (one FMU instance); remove it
    with :func:`remove_extracted` when done.

Modules: :mod:`.limits` (bounds, errors), :mod:`.inspection` (opening and
checking an archive before anything is written) and :mod:`.extraction`
(writing the members, reusing and tidying folders).
"""

from __future__ import annotations

from .extraction import extract_archive, extract_cached, extract_temporary, remove_extracted
from .inspection import archive_digest, check_member_size
from .limits import (
    COMPLETE_MARKER,
    DEFAULT_MAX_BYTES,
    DEFAULT_MAX_FILES,
    ArchiveError,
    ArchiveLimits,
)

__all__ = [
    "ArchiveError",
    "ArchiveLimits",
    "COMPLETE_MARKER",
    "DEFAULT_MAX_BYTES",
    "DEFAULT_MAX_FILES",
    "archive_digest",
    "check_member_size",
    "extract_archive",
    "extract_cached",
    "extract_temporary",
    "remove_extracted",
]
