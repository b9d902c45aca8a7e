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
"""

from __future__ import annotations

import hashlib
import json
import logging
import lzma
import os
import shutil
import stat
import struct
import tempfile
import time
import zipfile
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import IO, BinaryIO

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.master.files import UnreadableFileError, open_regular

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

logger = logging.getLogger(__name__)

DEFAULT_MAX_BYTES = 1 << 30
"""Default bound on the total uncompressed size of an archive, bytes (1 GiB)."""
DEFAULT_MAX_FILES = 10_000
"""Default bound on the number of members (files and folders) of an archive."""
COMPLETE_MARKER = ".wire_fmu_extracted"
"""File written last into an extracted folder: the archive's SHA-256 and sizes (JSON)."""

_CHUNK = 1 << 20  # bytes copied at a time
_CD_BYTES_PER_MEMBER = 1024  # central directory bytes allowed per permitted member
_MAX_DEPTH = 100  # folders a member may be nested in
_STALE_SECONDS = 24 * 3600.0  # a partial folder this old belongs to a dead process
_PARTIAL, _STALE = ".partial-", ".stale-"
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


# ------------------------------------------------------------------ opening


@contextmanager
def _open_regular(path: Path, where: str) -> Iterator[BinaryIO]:
    """Open ``path`` for reading, refusing anything but a regular file."""
    try:
        handle = open_regular(path)
    except UnreadableFileError as err:
        raise ArchiveError(
            where, [f"cannot read the file: {err} (a zip archive was expected)"]
        ) from None
    with handle:
        yield handle


def _reason(err: BaseException) -> str:
    """The short reason of an OS error (no traceback, no path repeated)."""
    if isinstance(err, OSError) and err.strerror:
        return err.strerror
    return str(err) or type(err).__name__


def _digest(handle: IO[bytes]) -> str:
    """SHA-256 of an open file, read in chunks; leaves it at the start."""
    handle.seek(0)
    sha = hashlib.sha256()
    while chunk := handle.read(_CHUNK):
        sha.update(chunk)
    handle.seek(0)
    return sha.hexdigest()


def archive_digest(path: Path, *, what: str = "archive") -> str:
    """SHA-256 (hex) of the archive file ``path``, read in chunks.

    Raises
    ------
    ArchiveError
        If ``path`` is not a readable regular file.
    """
    path = Path(path)
    with _open_regular(path, f"{what} {path}") as handle:
        return _digest(handle)


def _end_record(handle: IO[bytes]) -> tuple[int, int] | None:
    """(member count, central directory size) from the end record, before parsing it all.

    ``zipfile`` reads the whole central directory into memory when it opens
    an archive; this reads only the end record, so an archive that claims
    millions of members is refused first. None if the record is unreadable
    (``zipfile`` then reports the archive as broken).
    """
    # private to zipfile, but in every CPython since 2.x; without it zipfile's checks remain
    end_record = getattr(zipfile, "_EndRecData", None)
    entries, size = getattr(zipfile, "_ECD_ENTRIES_TOTAL", 4), getattr(zipfile, "_ECD_SIZE", 5)
    if end_record is None:  # pragma: no cover
        return None
    try:
        record = end_record(handle)
        return (int(record[entries]), int(record[size])) if record else None
    except (OSError, ValueError, EOFError, IndexError, TypeError, struct.error):
        return None
    finally:
        handle.seek(0)


def _open_zip(handle: IO[bytes], limits: ArchiveLimits, where: str) -> zipfile.ZipFile:
    """The archive in ``handle``, after the cheap checks of its end record."""
    end = _end_record(handle)
    if end is not None:
        count, directory = end
        if count > limits.max_files:
            raise ArchiveError(
                where, [f"holds {count} members, more than the limit of {limits.max_files}"]
            )
        if directory > limits.max_files * _CD_BYTES_PER_MEMBER:
            raise ArchiveError(
                where,
                [
                    f"its central directory is {_size(directory)}, too large for at most "
                    f"{limits.max_files} members"
                ],
            )
    try:
        return zipfile.ZipFile(handle)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, *_READ_ERRORS) as err:
        raise ArchiveError(where, [f"not a valid zip archive ({_reason(err)})"]) from None


# ------------------------------------------------------------------ checking


def _member_parts(info: zipfile.ZipInfo) -> tuple[str, ...] | str:
    """The path parts a member is written to, or the problem with its name."""
    name = info.filename
    shown = _shown(name)
    if "\x00" in name:
        return f"member {shown} has a NUL byte in its name"
    if "\\" in name:
        return f"member {shown} has a backslash in its name (zip paths use '/')"
    if name.startswith("/"):
        return f"member {shown} would be written outside the folder (an absolute path)"
    if ":" in name:
        return f"member {shown} has ':' in its name (a drive or device on Windows)"
    parts = tuple(p for p in PurePosixPath(name).parts if p not in ("", "."))
    if ".." in parts:
        return f"member {shown} would be written outside the folder ('..' in its path)"
    if len(parts) > _MAX_DEPTH:
        return f"member {shown} is nested more than {_MAX_DEPTH} folders deep"
    mode = info.external_attr >> 16
    kind = stat.S_IFMT(mode)
    if stat.S_ISLNK(mode):
        return f"member {shown} is a symbolic link (only files and folders are extracted)"
    if kind and kind not in (stat.S_IFREG, stat.S_IFDIR):
        return f"member {shown} is a special file (only files and folders are extracted)"
    if not parts and not info.is_dir():
        return f"member {shown} has no file name"
    if parts == (COMPLETE_MARKER,):
        return f"member {shown} has a name reserved for the extraction marker"
    return parts


def _plan(
    archive: zipfile.ZipFile, limits: ArchiveLimits, where: str
) -> list[tuple[zipfile.ZipInfo, tuple[str, ...]]]:
    """Every member with its path parts; raise listing every problem found."""
    infos = archive.infolist()
    problems: list[str] = []
    if len(infos) > limits.max_files:
        problems.append(f"holds {len(infos)} members, more than the limit of {limits.max_files}")
    declared = sum(info.file_size for info in infos)
    if declared > limits.max_bytes:
        problems.append(
            f"expands to more than {_size(limits.max_bytes)} (its members declare "
            f"{_size(declared)} uncompressed)"
        )
    if problems:  # refuse a bomb before looking at each of its members
        raise ArchiveError(where, problems)
    plan, files, folders = [], {}, set()
    for info in infos:
        parts = _member_parts(info)
        if isinstance(parts, str):
            problems.append(parts)
            continue
        key = "/".join(parts)
        if not info.is_dir():
            if key in files or key in folders:
                problems.append(f"member {_shown(info.filename)} appears twice")
                continue
            files[key] = info.filename
        else:
            folders.add(key)
        folders.update("/".join(parts[:i]) for i in range(1, len(parts)))
        plan.append((info, parts))
    for key in sorted(set(files) & folders):
        problems.append(f"member {_shown(files[key])} is both a file and a folder")
    if len(problems) > 20:
        problems = [*problems[:20], f"and {len(problems) - 20} more problems with members"]
    if problems:
        raise ArchiveError(where, problems)
    return plan


# ------------------------------------------------------------------ writing


def _write_members(
    archive: zipfile.ZipFile,
    plan: list[tuple[zipfile.ZipInfo, tuple[str, ...]]],
    folder: Path,
    limits: ArchiveLimits,
) -> int:
    """Write every member under ``folder``, counting bytes; return the total written."""
    written = 0
    for info, parts in plan:
        target = folder.joinpath(*parts)
        shown = _shown(info.filename)
        try:
            if info.is_dir():
                target.mkdir(parents=True, exist_ok=True)
                continue
            target.parent.mkdir(parents=True, exist_ok=True)
            with archive.open(info) as source, open(target, "xb") as out:
                own = 0
                while chunk := source.read(_CHUNK):
                    own += len(chunk)
                    written += len(chunk)
                    if written > limits.max_bytes:
                        raise _RefusedError(
                            f"expands to more than {_size(limits.max_bytes)} (member {shown} "
                            "holds more than it declares)"
                        )
                    if own > info.file_size:
                        raise _RefusedError(f"member {shown} holds more than the size it declares")
                    out.write(chunk)
        except _RefusedError:
            raise
        except OSError as err:  # writing, or reading a bzip2 member
            raise _RefusedError(f"cannot extract member {shown}: {_reason(err)}") from None
        except _READ_ERRORS as err:
            raise _RefusedError(f"member {shown} cannot be read ({_reason(err)})") from None
    return written


def _remove(folder: Path) -> None:
    """Remove a folder tree we made (errors logged, not raised: we are cleaning up)."""
    try:
        if folder.is_symlink():
            folder.unlink(missing_ok=True)
        elif folder.exists():
            shutil.rmtree(folder, ignore_errors=True)
    except OSError as err:
        logger.debug("could not remove %s: %s", folder, err)
    if folder.exists():
        logger.debug("could not remove all of %s", folder)


def remove_extracted(folder: Path | str | None) -> None:
    """Remove a folder made by :func:`extract_temporary` (nothing if None or gone)."""
    if folder is not None:
        _remove(Path(folder))


def _complete(folder: Path, digest: str) -> bool:
    """Whether ``folder`` is a complete extraction of the archive with SHA-256 ``digest``."""
    marker = folder / COMPLETE_MARKER
    try:
        if folder.is_symlink() or not folder.is_dir() or not marker.is_file():
            return False
        if marker.stat().st_size > 4096:
            return False
        return json.loads(marker.read_text(encoding="utf-8")).get("sha256") == digest
    except (OSError, ValueError, AttributeError):
        return False


def _ours(folder: Path) -> bool:
    """Whether ``folder`` carries our extraction marker (so we may replace it)."""
    return (folder / COMPLETE_MARKER).is_file() and not folder.is_symlink()


def _sweep(parent: Path, name: str) -> None:
    """Remove partial or stale siblings of ``parent / name`` left a day ago or earlier."""
    now = time.time()
    try:
        siblings = list(parent.glob(f".{name}{_PARTIAL}*")) + list(parent.glob(f".{name}{_STALE}*"))
    except OSError:
        return
    for sibling in siblings:
        try:
            old = now - sibling.lstat().st_mtime > _STALE_SECONDS
        except OSError:
            continue
        if old:
            logger.info("removing %s, left by an extraction that did not finish", sibling)
            _remove(sibling)


def _set_aside(folder: Path) -> None:
    """Rename ``folder`` out of the way, then remove it."""
    aside = Path(tempfile.mkdtemp(prefix=f".{folder.name}{_STALE}", dir=folder.parent))
    try:
        os.replace(folder, aside / "old")
    except FileNotFoundError:  # another process moved it first
        pass
    _remove(aside)


def extract_archive(
    path: Path,
    into: Path,
    *,
    what: str = "archive",
    limits: ArchiveLimits | None = None,
    replace: bool = False,
    digest: str | None = None,
) -> Path:
    """Extract ``path`` into the folder ``into``, atomically; reuse it if already done.

    The members are written into a fresh temporary sibling of ``into``, a
    marker (:data:`COMPLETE_MARKER`) with the archive's SHA-256 is written
    last, and the sibling is renamed to ``into``. If ``into`` already holds
    a complete extraction of the same content it is returned as it is.

    Parameters
    ----------
    path : Path
        The archive (a zip file: ``.fmu``, ``.ssp``).
    into : Path
        The folder to extract into. If it exists it must be empty, hold an
        earlier extraction of ours (replaced) or, with ``replace``, anything.
    what : str
        What the archive is, for messages: "FMU", "package".
    limits : ArchiveLimits, optional
        Size and member-count bounds (default 1 GiB, 10,000 members).
    replace : bool
        Replace whatever ``into`` holds if it is not a complete extraction of
        this archive (for folders we own, such as a cache).
    digest : str, optional
        The archive's SHA-256 if already known (see :func:`archive_digest`).

    Returns
    -------
    Path
        ``into``.

    Raises
    ------
    ArchiveError
        Naming the archive and each problem: not a zip file, too large, too
        many members, an unsafe member path, a corrupt member, a folder in the
        way, or a write that failed.
    """
    path, into = Path(path), Path(into)
    limits = limits or ArchiveLimits()
    where = f"{what} {path}"
    with _open_regular(path, where) as handle:
        digest = digest or _digest(handle)
        if _complete(into, digest):
            logger.debug("%s: reusing %s", where, into)
            return into
        if into.is_symlink() or (into.exists() and not into.is_dir()):
            raise ArchiveError(where, [f"cannot extract into {into}: it is not a folder"])
        if into.is_dir() and not (replace or _ours(into) or not any(into.iterdir())):
            raise ArchiveError(
                where,
                [
                    f"cannot extract into {into}: the folder holds other files (give a new or "
                    "empty folder)"
                ],
            )
        with _open_zip(handle, limits, where) as archive:
            plan = _plan(archive, limits, where)
            try:
                into.parent.mkdir(parents=True, exist_ok=True)
                _sweep(into.parent, into.name)
                partial = Path(tempfile.mkdtemp(prefix=f".{into.name}{_PARTIAL}", dir=into.parent))
            except OSError as err:
                raise ArchiveError(where, [f"cannot create {into}: {_reason(err)}"]) from None
            try:
                written = _write_members(archive, plan, partial, limits)
                marker = {
                    "sha256": digest,
                    "archive": str(path),
                    "bytes": written,
                    "members": len(plan),
                }
                (partial / COMPLETE_MARKER).write_text(json.dumps(marker), encoding="utf-8")
                _move_into_place(partial, into, digest)
            except _RefusedError as refused:
                raise ArchiveError(where, [str(refused)]) from None
            except OSError as err:
                raise ArchiveError(where, [f"cannot extract into {into}: {_reason(err)}"]) from None
            finally:
                _remove(partial)  # gone already after a successful rename
    logger.debug("%s: extracted %d members (%s) into %s", where, len(plan), _size(written), into)
    return into


def _move_into_place(partial: Path, into: Path, digest: str) -> None:
    """Rename the complete ``partial`` folder to ``into`` (someone else's complete copy wins)."""
    if into.exists() and not _complete(into, digest):
        _set_aside(into)  # checked by the caller: empty, ours, or ours to replace
    try:
        os.rename(partial, into)
    except OSError:
        if _complete(into, digest):  # another process finished the same extraction first
            return
        raise


def extract_cached(
    path: Path,
    cache: Path,
    *,
    what: str = "archive",
    limits: ArchiveLimits | None = None,
) -> Path:
    """Extract ``path`` into ``cache / <first 16 hex digits of its SHA-256>``; reuse it.

    The cache folder must be ours: a real folder owned by this user that no
    one else may write to (it usually lives in the shared temporary
    directory). If it is not, the archive is extracted into a fresh private
    temporary folder instead (not reused).

    Parameters
    ----------
    path : Path
        The archive.
    cache : Path
        The cache folder (made if missing, readable by this user only).
    what : str
        What the archive is, for messages.
    limits : ArchiveLimits, optional
        Size and member-count bounds.

    Returns
    -------
    Path
        The folder holding the extracted archive.

    Raises
    ------
    ArchiveError
        See :func:`extract_archive`.
    """
    path, cache = Path(path), Path(cache)
    digest = archive_digest(path, what=what)
    if not _private_folder(cache):
        logger.warning(
            "%s is not a private folder of this user; extracting %s without a cache", cache, path
        )
        cache = Path(tempfile.mkdtemp(prefix=f"{cache.name}_"))
    return extract_archive(
        path, cache / digest[:16], what=what, limits=limits, replace=True, digest=digest
    )


def _private_folder(folder: Path) -> bool:
    """Make ``folder`` if missing; whether it is a real folder only this user can write."""
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        info = os.lstat(folder)
    except OSError:
        return False
    if not stat.S_ISDIR(info.st_mode):
        return False
    if hasattr(os, "getuid") and info.st_uid != os.getuid():
        return False
    return not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def extract_temporary(
    path: Path,
    *,
    what: str = "archive",
    prefix: str = "wire_fmu_",
    limits: ArchiveLimits | None = None,
) -> Path:
    """Extract ``path`` into a fresh private temporary folder and return it.

    The folder is new and only this process knows it, so nothing else can
    take it for complete while it is written; it is removed if extraction
    fails. Remove it with :func:`remove_extracted` when done.

    Parameters
    ----------
    path : Path
        The archive.
    what : str
        What the archive is, for messages.
    prefix : str
        Start of the folder's name (in the system's temporary directory).
    limits : ArchiveLimits, optional
        Size and member-count bounds.

    Raises
    ------
    ArchiveError
        See :func:`extract_archive`.
    """
    path = Path(path)
    limits = limits or ArchiveLimits()
    where = f"{what} {path}"
    with _open_regular(path, where) as handle, _open_zip(handle, limits, where) as archive:
        plan = _plan(archive, limits, where)
        folder = Path(tempfile.mkdtemp(prefix=prefix))
        try:
            written = _write_members(archive, plan, folder, limits)
        except BaseException as exc:
            _remove(folder)
            if isinstance(exc, _RefusedError):
                raise ArchiveError(where, [str(exc)]) from None
            raise
    logger.debug("%s: extracted %d members (%s) into %s", where, len(plan), _size(written), folder)
    return folder


def check_member_size(path: Path, member: str, max_bytes: int, *, what: str = "archive") -> str:
    """Problem with ``member`` of the archive ``path`` being too large to read ('' if none).

    For readers that load one member into memory (``modelDescription.xml``
    of an FMU): its declared size must not exceed ``max_bytes``. A member
    that is missing or an archive that cannot be opened is not reported
    here (the reader says what is wrong).
    """
    try:
        with _open_regular(Path(path), f"{what} {path}") as handle, zipfile.ZipFile(handle) as z:
            size = z.getinfo(member).file_size
    except (ArchiveError, KeyError, OSError, *_READ_ERRORS, zipfile.LargeZipFile):
        return ""
    if size > max_bytes:
        return f"its {member} expands to {_size(size)}, more than the {_size(max_bytes)} allowed"
    return ""
