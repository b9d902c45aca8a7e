"""Writing an archive's members into a folder: bounded, confined and atomic, with a
marker written last; reusing, replacing and tidying extracted folders."""

from __future__ import annotations

import json
import logging
import os
import shutil
import stat
import tempfile
import time
import zipfile
from pathlib import Path

from .inspection import _digest, _open_regular, _open_zip, _plan, archive_digest
from .limits import (
    _CHUNK,
    _READ_ERRORS,
    COMPLETE_MARKER,
    ArchiveError,
    ArchiveLimits,
    _reason,
    _RefusedError,
    _shown,
    _size,
)

__all__ = ["extract_archive", "extract_cached", "extract_temporary", "remove_extracted"]

logger = logging.getLogger(__name__)

_STALE_SECONDS = 24 * 3600.0  # a partial folder this old belongs to a dead process
_PARTIAL, _STALE = ".partial-", ".stale-"


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
    """Remove a folder made by :func:`extract_temporary` (nothing if None or gone).

    Parameters
    ----------
    folder : Path or str or None
        The folder :func:`extract_temporary` returned.
    """
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
