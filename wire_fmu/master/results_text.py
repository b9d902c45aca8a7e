"""The results' numbers as text.

:func:`number_lines` writes rows of numbers as CSV lines: each float as the
shortest text that reads back to the same bits, at about a fifth of the cost of
``repr`` (see ``docs/architecture.md``, *Results as CSV*).
"""

from __future__ import annotations

from numbers import Integral
from typing import Any

import numpy as np
import orjson

__all__ = ["number_lines"]

_OPTIONS = orjson.OPT_SERIALIZE_NUMPY


def number_lines(rows: list[list[float | int]] | np.ndarray) -> str:
    """CSV lines of rows of numbers, each line ended by CRLF as the csv module ends it.

    A float is written as the shortest text that reads back to the same number
    (``0.1``, ``2.5e-7``, ``1e+20``), an integer as its digits. orjson writes the
    numbers (the Ryu algorithm, about 0.1 µs a float against 0.46 µs for ``repr``,
    which runs the bignum dtoa; a quarter of that from a float array, which it
    reads without looking at each number's type); JSON has no text for nan and
    infinity, so a row holding one is written with ``repr`` (``nan``, ``inf``,
    ``-inf``).

    Parameters
    ----------
    rows : list of list of float or int, or numpy.ndarray
        The rows, each a list of numbers (Python or numpy scalars; any other
        number, such as a Fraction or a 0-d array, is written as its ``float``),
        or a 2-D array with a row per line.

    Returns
    -------
    str
        One line per row (none for no rows).
    """
    if len(rows) == 0:
        return ""
    if isinstance(rows, np.ndarray):
        rows = np.ascontiguousarray(rows, dtype=float)  # orjson takes C-ordered arrays only
    text = orjson.dumps(rows, default=float, option=_OPTIONS)  # b"[[1.0,2],[...]]"
    if b"null" not in text:
        return text[2:-2].replace(b"],[", b"\r\n").decode("ascii") + "\r\n"
    if isinstance(rows, np.ndarray):
        rows = rows.tolist()
    lines = []
    for row in rows:
        line = orjson.dumps(row, default=float, option=_OPTIONS)[1:-1].decode("ascii")
        if "null" in line:  # a non-finite number: repr spells it as float() reads it
            line = ",".join(map(_repr, row))
        lines.append(line + "\r\n")
    return "".join(lines)


def _repr(value: Any) -> str:
    """A number's text as ``repr`` writes it: an integer's digits, else its float's."""
    return str(int(value)) if isinstance(value, Integral) else repr(float(value))
