"""Opening an archive and checking it before anything is written: its digest, its end
record, every member's path, the sizes it declares."""

from __future__ import annotations

import hashlib
import stat
import struct
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path, PurePosixPath
from typing import IO, BinaryIO

from wire_fmu.master.files import UnreadableFileError, open_regular

from .limits import (
    _CHUNK,
    _READ_ERRORS,
    COMPLETE_MARKER,
    ArchiveError,
    ArchiveLimits,
    _reason,
    _shown,
    _size,
)

__all__ = ["archive_digest", "check_member_size"]

_CD_BYTES_PER_MEMBER = 1024  # central directory bytes allowed per permitted member
_MAX_DEPTH = 100  # folders a member may be nested in


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

    Parameters
    ----------
    path : Path
        The archive.
    what : str
        What the archive is, for messages: "FMU", "package".

    Returns
    -------
    str
        64 hexadecimal digits.

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


def check_member_size(path: Path, member: str, max_bytes: int, *, what: str = "archive") -> str:
    """Problem with ``member`` of the archive ``path`` being too large to read ('' if none).

    For readers that load one member into memory (``modelDescription.xml``
    of an FMU): its declared size must not exceed ``max_bytes``. A member
    that is missing or an archive that cannot be opened is not reported
    here (the reader says what is wrong).

    Parameters
    ----------
    path : Path
        The archive.
    member : str
        The member's name in the archive, e.g. ``"modelDescription.xml"``.
    max_bytes : int
        Largest uncompressed size allowed, bytes.
    what : str
        What the archive is, for messages: "FMU", "package".

    Returns
    -------
    str
        The problem, e.g. ``"its modelDescription.xml expands to 300 MiB, more
        than the 256 MiB allowed"``; empty if none.
    """
    try:
        with _open_regular(Path(path), f"{what} {path}") as handle, zipfile.ZipFile(handle) as z:
            size = z.getinfo(member).file_size
    except (ArchiveError, KeyError, OSError, *_READ_ERRORS, zipfile.LargeZipFile):
        return ""
    if size > max_bytes:
        return f"its {member} expands to {_size(size)}, more than the {_size(max_bytes)} allowed"
    return ""
