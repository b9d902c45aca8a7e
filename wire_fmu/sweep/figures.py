"""Key figures of a sweep: one function of one recorded column, one number per case.

The functions and the ``[figures]`` syntax are described in
:mod:`wire_fmu.sweep.spec`.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

__all__ = ["FUNCTIONS", "RESERVED_COLUMNS", "Figure", "well_formed_figures"]


def _peak(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.max(values))


def _low(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.min(values))


def _absmax(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.max(np.abs(values)))


def _range(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.max(values) - np.min(values))


def _final(time: np.ndarray, values: np.ndarray) -> float:
    return float(values[-1])


def _mean(time: np.ndarray, values: np.ndarray) -> float:
    span = float(time[-1] - time[0])
    if len(values) < 2 or span <= 0.0:
        return float(values[-1])
    area = np.sum(0.5 * (values[1:] + values[:-1]) * np.diff(time))
    return float(area / span)


FUNCTIONS: Mapping[str, Callable[[np.ndarray, np.ndarray], float]] = MappingProxyType(
    {
        "max": _peak,
        "min": _low,
        "absmax": _absmax,
        "range": _range,
        "final": _final,
        "mean": _mean,
    }
)
"""Key figure functions: ``f(time, values) -> float`` over the recorded samples."""

RESERVED_COLUMNS = frozenset(
    {
        "case_id",
        "index",
        "status",
        "error",
        "wall_time",
        "end_time",
        "worker",
        "attempts",
        "finished_at",
    }
)
"""Columns every summary row has; a key figure may not take one of these names."""

_FIGURE_RE = re.compile(r"""^\s*([A-Za-z_]+)\s*\(\s*(["']?)([^"'()\s]+)\2\s*\)\s*$""")


@dataclass(frozen=True)
class Figure:
    """A key figure: one function of one recorded column, one number per case.

    Attributes
    ----------
    name : str
        Summary column name (an identifier).
    function : str
        One of :data:`FUNCTIONS`.
    column : str
        The recorded column, e.g. ``"rope.path_end.tension"``.
    """

    name: str
    function: str
    column: str

    @property
    def expression(self) -> str:
        """``function(column)``, as written in a spec."""
        return f"{self.function}({self.column})"

    def evaluate(self, columns: Mapping[str, np.ndarray]) -> float | None:
        """The figure from recorded columns; None when the column has no samples.

        Parameters
        ----------
        columns : mapping of str to ndarray
            Recorded columns by name, with ``"time"`` (s).
        """
        values = columns.get(self.column)
        if values is None or len(values) == 0:
            return None
        return FUNCTIONS[self.function](np.asarray(columns["time"]), np.asarray(values))


# -- key figures ----------------------------------------------------------------------
def _parse_figure(name: str, text: Any, problems: list[str]) -> Figure | None:
    where = f"figure {name!r}"
    if not name.isidentifier():
        problems.append(f"{where}: a figure name must be an identifier (letters, digits, _)")
    elif name in RESERVED_COLUMNS:
        problems.append(
            f"{where}: the name is a summary column already; reserved: "
            f"{', '.join(sorted(RESERVED_COLUMNS))}"
        )
    match = _FIGURE_RE.match(text) if isinstance(text, str) else None
    if match is None:
        problems.append(
            f"{where}: must read 'function(unit.variable)', e.g. "
            f"'max(rope.path_end.tension)', got {text!r}"
        )
        return None
    function, _, column = match.groups()
    if function not in FUNCTIONS:
        problems.append(f"{where}: unknown function {function!r}; known: {', '.join(FUNCTIONS)}")
        return None
    if "." not in column:
        problems.append(f"{where}: the column must be 'unit.variable', got {column!r}")
        return None
    return Figure(name, function, column)


def well_formed_figures(data: Any) -> list[Figure]:
    """The ``[figures]`` entries that read ``function(unit.variable)``, whatever else is
    amiss (an unknown function, a reserved name): their columns can still be checked.

    Parameters
    ----------
    data : Any
        The spec's ``figures``, as read.
    """
    if not isinstance(data, Mapping):
        return []
    figures = []
    for name, text in data.items():
        match = _FIGURE_RE.match(text) if isinstance(text, str) else None
        if match is not None and "." in match.group(3):
            figures.append(Figure(str(name), match.group(1), match.group(3)))
    return figures


def _parse_figures(data: Any, problems: list[str]) -> list[Figure]:
    if not isinstance(data, Mapping):
        problems.append('[figures] must be a table of name = "function(unit.variable)"')
        return []
    figures = [_parse_figure(str(name), text, problems) for name, text in data.items()]
    return [f for f in figures if f is not None]
