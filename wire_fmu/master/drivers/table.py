"""The ``table`` driver: linear interpolation in two columns of a CSV file."""

from __future__ import annotations

import csv
import io
import logging
import math
import os
import re
import stat
from pathlib import Path

import numpy as np

from .protocol import Driver
from .simple import PiecewiseLinearDriver
from .spec_reading import _close_hint, _Context, _finite_slopes, _increasing, _Reader, _show

__all__ = ["MAX_TABLE_BYTES"]

logger = logging.getLogger(__name__)

_MAX_REPORTED_ROWS = 5  # bad CSV rows reported one by one, the rest counted
_MAX_CELL_SHOWN = 20  # a bad CSV cell longer than this is described, not quoted
_MAX_HEADER_SHOWN = (2, 50, 32)  # column names listed: min and max count, max length
_COLUMN_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_ .()\[\]/%-]*")  # a name we may quote
MAX_TABLE_BYTES = 64 << 20
"""Largest CSV file a ``table`` driver reads, bytes (64 MiB, about two million rows)."""


_EXPECTED_TABLE = "a CSV text file with a header row naming the columns, then rows of numbers"


def _shown_path(path: Path) -> str:
    """The table file's path for a problem (shortened if absurdly long)."""
    text = str(path)
    return text if len(text) <= 200 else f"{text[:100]}...{text[-60:]}"


def _file_kind(mode: int) -> str:
    # this package is also bundled into the signals FMU: stdlib and numpy only
    for test, kind in (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISFIFO, "a pipe"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return kind
    return "not a regular file"


def _read_table_bytes(path: Path, shown: str, r: _Reader) -> bytes | None:
    """The bytes of a regular file of at most :data:`MAX_TABLE_BYTES` (None after a problem).

    Opened without blocking (a pipe does not hang the read) and checked on
    the open descriptor, so what is checked is what is read.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        r.add(f"cannot read table file '{shown}': {reason}")
        return None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            r.add(f"table file '{shown}' is {_file_kind(info.st_mode)}; expected {_EXPECTED_TABLE}")
            return None
        if info.st_size > MAX_TABLE_BYTES:
            r.add(
                f"table file '{shown}' is {info.st_size / 2**20:.0f} MiB, more than the "
                f"{MAX_TABLE_BYTES >> 20} MiB a table may have"
            )
            return None
        with os.fdopen(os.dup(fd), "rb") as handle:
            data = handle.read(MAX_TABLE_BYTES + 1)
    except OSError as exc:
        r.add(f"cannot read table file '{shown}': {exc.strerror or type(exc).__name__}")
        return None
    finally:
        os.close(fd)
    if len(data) > MAX_TABLE_BYTES:  # it grew while we looked
        r.add(f"table file '{shown}' is more than the {MAX_TABLE_BYTES >> 20} MiB a table may have")
        return None
    return data


def _csv_rows(path: Path, r: _Reader) -> list[list[str]] | None:
    """Non-empty, non-comment rows of a CSV file (None after a problem).

    No problem quotes the file: it may not be a table at all.
    """
    shown = _shown_path(path)
    data = _read_table_bytes(path, shown, r)
    if data is None:
        return None
    try:
        if b"\0" in data:
            raise UnicodeError("NUL byte")
        text = data.decode("utf-8-sig")
    except UnicodeError:
        r.add(
            f"table file '{shown}' is not UTF-8 text (a binary file?); expected {_EXPECTED_TABLE}"
        )
        return None
    try:
        rows = [
            row for row in csv.reader(io.StringIO(text, newline="")) if any(c.strip() for c in row)
        ]
    except csv.Error as exc:
        r.add(f"table file '{shown}' is not a CSV table ({exc}); expected {_EXPECTED_TABLE}")
        return None
    rows = [row for row in rows if not row[0].lstrip().startswith("#")]
    if len(rows) < 3:
        r.add(f"table file '{shown}' needs a header row and at least two data rows")
        return None
    return rows


def _numeric_table(rows: list[list[str]]) -> bool:
    """Whether the rows under the header are all numbers, as many as the header names.

    Only then is the first row taken for column names that may be quoted in
    a problem: the first line of any other file may be a secret.
    """
    header = rows[0]
    least, most, longest = _MAX_HEADER_SHOWN
    if not least <= len(header) <= most or any(
        len(c) > longest or not _COLUMN_NAME.fullmatch(c) for c in header
    ):
        return False
    for row in rows[1:]:
        if len(row) != len(header):
            return False
        for cell in row:
            try:
                float(cell)
            except ValueError:
                return False
    return True


def _csv_column(rows: list[list[str]], index: int, name: str, path: Path, r: _Reader):
    """Floats of one column (None after a problem); reports the first bad rows."""
    values, bad = [], []
    for line, row in enumerate(rows[1:], start=2):
        try:
            x = float(row[index])
            if not math.isfinite(x):
                raise ValueError
            values.append(x)
        except (IndexError, ValueError):
            if index >= len(row):
                cell = "missing"
            elif len(row[index]) > _MAX_CELL_SHOWN:
                cell = f"a {len(row[index])}-character value"
            else:
                cell = repr(row[index])
            bad.append(f"data row {line - 1} ({cell})")
    if bad:
        more = f" and {len(bad) - _MAX_REPORTED_ROWS} more" if len(bad) > _MAX_REPORTED_ROWS else ""
        shown = "; ".join(bad[:_MAX_REPORTED_ROWS])
        r.add(
            f"table file '{_shown_path(path)}': column {name!r} is not a finite number in "
            f"{shown}{more}"
        )
        return None
    return np.array(values)


def _build_table(r: _Reader, ctx: _Context) -> Driver | None:
    file = r.text("file")
    time_name = r.text("time_column", "time")
    value_name = r.text("value_column", "value")
    if not (file and time_name and value_name):
        return None
    path = Path(file) if Path(file).is_absolute() else ctx.base_dir / file
    rows = _csv_rows(path, r)
    if rows is None:
        return None
    header = [c.strip() for c in rows[0]]
    shown = _shown_path(path)
    missing = [name for name in (time_name, value_name) if name not in header]
    if missing:
        listed = _numeric_table([header, *rows[1:]])
        for name in missing:
            if listed:
                r.add(
                    f"table file '{shown}' has no column {_show(name)}{_close_hint(name, header)}; "
                    f"columns: {', '.join(header)}"
                )
            else:
                r.add(
                    f"table file '{shown}' has no column {_show(name)} (its first row is not "
                    f"quoted: the file does not look like a numeric table); expected "
                    f"{_EXPECTED_TABLE}"
                )
        return None
    columns = [
        _csv_column(rows, header.index(name), name, path, r) for name in (time_name, value_name)
    ]
    if any(c is None for c in columns):
        return None
    label = f"table file '{shown}' column {time_name!r}"
    if not (
        _increasing(columns[0], label, r)
        and _finite_slopes(columns[0], columns[1], f"table file '{shown}'", r)
    ):
        return None
    logger.debug("table driver: %d rows from %s", len(columns[0]), path)
    return PiecewiseLinearDriver(columns[0], columns[1], source=str(path))
