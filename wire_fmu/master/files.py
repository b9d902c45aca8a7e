"""Reading a file a user named: only a regular file, never blocking, bounded in size.

A scene, a sweep spec or a table may name any path: a directory, a pipe that
never ends, ``/dev/zero``, a file of many gigabytes. These functions open
without blocking, check the open descriptor (so what is checked is what is
read) and read at most a bound, raising :class:`UnreadableFileError` with a
short reason that does not quote the file.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import BinaryIO

__all__ = ["UnreadableFileError", "open_regular", "read_regular", "file_kind"]

_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a pipe"),
    (stat.S_ISSOCK, "a socket"),
)


class UnreadableFileError(ValueError):
    """A file that cannot be read as asked; the message is the reason, without the path."""


def file_kind(mode: int) -> str:
    """What a file of ``st_mode`` ``mode`` is, in words ("a directory", ...).

    Parameters
    ----------
    mode : int
        ``st_mode`` from :func:`os.stat`.
    """
    for test, kind in _KINDS:
        if test(mode):
            return kind
    return "not a regular file"


def open_regular(path: Path | str) -> BinaryIO:
    """``path`` opened for reading in binary mode, if it is a regular file.

    Parameters
    ----------
    path : Path or str
        The file.

    Returns
    -------
    BinaryIO
        The open file; the caller closes it.

    Raises
    ------
    UnreadableFileError
        When it cannot be opened or is not a regular file.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except (OSError, ValueError) as err:  # ValueError: a NUL character in the name
        reason = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
        raise UnreadableFileError(reason) from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise UnreadableFileError(f"it is {file_kind(mode)}, not a regular file")
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(path: Path | str, limit: int) -> bytes:
    """All bytes of a regular file of at most ``limit`` bytes.

    Parameters
    ----------
    path : Path or str
        The file.
    limit : int
        Largest size read, bytes.

    Raises
    ------
    UnreadableFileError
        When it cannot be read, is not a regular file or is larger than ``limit``.
    """
    with open_regular(path) as handle:
        try:
            data = handle.read(limit + 1)
        except OSError as err:
            raise UnreadableFileError(err.strerror or type(err).__name__) from None
    if len(data) > limit:
        raise UnreadableFileError(f"it is larger than {_size(limit)}")
    return data


def _size(count: int) -> str:
    return f"{count >> 20} MiB" if count >= 2**20 else f"{count} bytes"
