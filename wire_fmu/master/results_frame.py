"""A run's results as a pandas DataFrame with units.

>>> from wire_fmu.master.run import read_results_frame         # doctest: +SKIP
>>> frame = read_results_frame("results/riser_tensioner")      # doctest: +SKIP
>>> frame.attrs["units"]["rope.path_end.tension"]              # doctest: +SKIP
'N'

The frame is indexed by ``time`` (s) and has one column per recorded column of
``timeseries.csv`` (the unit variables, the bond channels, the ledger sum), each
in the unit ``metadata.json`` gives it (see :mod:`~wire_fmu.master.column_units`).
Its ``attrs`` say where it came from and how the run ended:

``units``
    dict of column (and ``"time"``) to unit string.
``scene``, ``source``
    The scene's name; the results folder.
``status``, ``message``, ``end_time``
    How the run ended (:data:`~wire_fmu.master.run_result.STATUSES`), its
    message, and the time it ended at (s); None when ``metadata.json`` has no
    summary, i.e. the process ended before the run could write one.
``complete``
    Whether the results are all a finished run writes: False if the run did
    not finish, wrote no summary, or the file's last row was cut off (then
    dropped). A warning (:class:`IncompleteResultsWarning`) says which, and
    the number of the line dropped.

:func:`read_table_text` is the part both readers of the table share (this one and
:func:`~wire_fmu.master.plots.read_results`): its header, checked, and its text
without a cut-off last line.

Nothing here imports pandas until a frame is read: the command line imports
this module through :mod:`~wire_fmu.master.run`.
"""

from __future__ import annotations

import io
import json
import logging
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from wire_fmu.core.errors import WireFmuError

from .column_units import TEXT

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "CSV_NAME",
    "METADATA_NAME",
    "ResultsError",
    "IncompleteResultsWarning",
    "read_results_frame",
    "read_table_text",
]

logger = logging.getLogger(__name__)

CSV_NAME = "timeseries.csv"
"""The recorded table in a results folder."""

METADATA_NAME = "metadata.json"
"""Units, descriptions, settings and summary of the run, beside the table."""


class ResultsError(WireFmuError, ValueError):
    """A results folder that cannot be read; the message names the file and what was expected."""


class IncompleteResultsWarning(UserWarning):
    """The results read are less than a finished run writes (a run stopped, or cut off)."""


def read_results_frame(folder: str | Path) -> pd.DataFrame:
    """A run's results as a DataFrame indexed by time, with the unit of every column.

    Parameters
    ----------
    folder : str or Path
        A results folder, as a run writes it: ``timeseries.csv`` and ``metadata.json``.

    Returns
    -------
    pandas.DataFrame
        Indexed by ``time`` (s), one column per recorded column, each in its
        unit: ``attrs["units"]`` maps every column, and ``"time"``, to its unit
        string (``"N"``, ``"m"``, ``"J"``, ``"W"``; ``"1"`` for a pure number,
        a count, state or mode; ``"text"`` for a String variable's column).
        Numbers are read back exactly as written; a String variable's column
        is text. The other ``attrs`` (``scene``, ``source``, ``status``,
        ``message``, ``end_time`` in s, ``complete``) are described in the
        module's docstring.

    Raises
    ------
    ResultsError
        When the folder, the table or the metadata is missing or cannot be
        read, or the metadata gives no unit for a column of the table.

    Warns
    -----
    IncompleteResultsWarning
        When the run did not finish (it stopped, failed or was interrupted),
        wrote no summary, or its last row was cut off: the rows before are read.
    """
    folder = Path(folder)
    csv_path, meta = _files(folder)
    header, text, cut_line = read_table_text(csv_path)
    units = _units(folder / METADATA_NAME, meta, header)
    frame = _table(csv_path, text, units)
    frame.attrs.update(_provenance(folder, meta, units, cut_line is not None))
    _warn_if_incomplete(folder, frame.attrs, cut_line)
    return frame


def read_table_text(csv_path: Path) -> tuple[list[str], str | None, int | None]:
    """The header of a results table, and its text without a cut-off last line.

    A run killed while writing a row leaves that row without its line end: the
    row is cut off, and left out here; the rows before it are whole.

    Parameters
    ----------
    csv_path : Path
        A ``timeseries.csv``.

    Returns
    -------
    header : list of str
        The column names, ``"time"`` first.
    text : str or None
        The table's complete lines when its last line was cut off; None when the
        file ends with a complete line (then read the file itself).
    cut_line : int or None
        The number (from 1) of the cut-off line left out; None if there is none.

    Raises
    ------
    ResultsError
        When the file cannot be read, is empty, is not UTF-8 text, or its first
        line is not a whole header starting with ``time``.
    """
    text, cut_line = _complete_lines(csv_path)
    return _header(csv_path, text), text, cut_line


def _files(folder: Path) -> tuple[Path, dict[str, Any]]:
    """The table's path and the parsed metadata, or a :class:`ResultsError` saying what is amiss."""
    expected = f"a results folder with {CSV_NAME} and {METADATA_NAME}, as a run writes it"
    if not folder.exists():
        raise ResultsError(f"{folder}: no such folder; expected {expected}")
    if not folder.is_dir():
        raise ResultsError(f"{folder}: not a folder; expected {expected}")
    csv_path, meta_path = folder / CSV_NAME, folder / METADATA_NAME
    if not csv_path.is_file():
        raise ResultsError(
            f"{csv_path}: no such file; expected {expected} "
            "(a run that fails in its initialisation records nothing)"
        )
    if not meta_path.is_file():
        raise ResultsError(
            f"{meta_path}: no such file; the units of the columns of {csv_path} are unknown "
            f"without it (expected {expected})"
        )
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise ResultsError(f"{meta_path}: cannot be read as JSON ({err})") from None
    if not isinstance(meta, dict):
        raise ResultsError(f"{meta_path}: expected a JSON object, found {type(meta).__name__}")
    return csv_path, meta


def _complete_lines(csv_path: Path) -> tuple[str | None, int | None]:
    """The table's text up to its last complete line if its last line was cut off.

    Returns
    -------
    text : str or None
        The complete lines when the last one is cut off; None when the file ends
        with a complete line (then it is read from the file itself).
    cut_line : int or None
        The number (from 1) of the cut-off last line dropped; None if none was.
    """
    try:
        with csv_path.open("rb") as f:
            size = f.seek(0, io.SEEK_END)
            if size == 0:
                raise ResultsError(f"{csv_path}: empty; expected at least the header line")
            f.seek(size - 1)
            if f.read(1) == b"\n":
                return None, None
            f.seek(0)
            data = f.read()
    except OSError as err:
        raise ResultsError(f"{csv_path}: cannot be read ({err.strerror or err})") from None
    end = data.rfind(b"\n")
    if end < 0:
        raise ResultsError(f"{csv_path}: its header line is cut off; expected a complete header")
    complete = data[: end + 1]
    return _decode(csv_path, complete), complete.count(b"\n") + 1


def _decode(csv_path: Path, data: bytes) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise ResultsError(f"{csv_path}: not UTF-8 text ({err})") from None


def _header(csv_path: Path, text: str | None) -> list[str]:
    """The column names of the table's header line."""
    import csv

    if text is None:
        try:
            with csv_path.open(encoding="utf-8", newline="") as f:
                line = f.readline()
        except (OSError, UnicodeDecodeError) as err:
            raise ResultsError(f"{csv_path}: cannot be read ({err})") from None
    else:
        line = text.split("\n", 1)[0]
    header = next(csv.reader([line]), [])
    if not header or header[0] != "time":
        raise ResultsError(
            f"{csv_path}: expected a header line starting with 'time', found {line.strip()[:80]!r}"
        )
    return header


def _units(meta_path: Path, meta: dict[str, Any], header: list[str]) -> dict[str, str]:
    """The unit of every column of ``header``, from the metadata's ``column_units``."""
    units = meta.get("column_units")
    if not isinstance(units, dict):
        raise ResultsError(
            f"{meta_path}: has no 'column_units' (written before the units of the columns "
            "were recorded); run the scene again to read its results with units"
        )
    missing = [c for c in header if not isinstance(units.get(c), str)]
    if missing:
        shown = ", ".join(missing[:5]) + (
            f" and {len(missing) - 5} more" if len(missing) > 5 else ""
        )
        raise ResultsError(
            f"{meta_path}: gives no unit for column(s) {shown} of {CSV_NAME}; "
            "the two files are not of the same run"
        )
    return {c: units[c] for c in header}


def _table(csv_path: Path, text: str | None, units: dict[str, str]) -> pd.DataFrame:
    """The table read with pandas: numbers exactly as written, text columns as text."""
    import pandas as pd

    text_columns = {c: str for c, unit in units.items() if unit == TEXT}
    numbers = [c for c in units if c not in text_columns]
    source = csv_path if text is None else io.StringIO(text)
    try:
        frame = pd.read_csv(
            source,
            dtype=text_columns or None,
            keep_default_na=False,  # a text cell is never taken for a missing value
            na_values={c: ["nan", "NaN", "-nan"] for c in numbers},  # as Python writes NaN
            encoding="utf-8",
            **_exact_floats(pd),
        )
    except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as err:
        raise ResultsError(f"{csv_path}: not a table as a run writes it ({err})") from None
    if frame.empty:  # the header alone: no cell tells the columns' types
        frame = frame.astype(dict.fromkeys(numbers, float))
    for column in numbers:
        if not pd.api.types.is_numeric_dtype(frame[column]):
            raise ResultsError(
                f"{csv_path}: column {column!r} holds cells that are not numbers, "
                f"though its unit is {units[column]!r}"
            )
    return frame.set_index("time")


def _exact_floats(pd: Any) -> dict[str, str]:
    """The ``read_csv`` option that reads back every float exactly (pandas 3 does by default)."""
    major = int(pd.__version__.split(".", 1)[0])
    return {"float_precision": "round_trip"} if major < 3 else {}


def _provenance(
    folder: Path, meta: dict[str, Any], units: dict[str, str], cut: bool
) -> dict[str, Any]:
    """The frame's ``attrs``: units, scene, source, how the run ended, whether it is complete."""
    result = meta.get("result") if isinstance(meta.get("result"), dict) else {}
    status = result.get("status")
    return {
        "units": units,
        "scene": meta.get("scene"),
        "source": str(folder),
        "status": status,
        "message": result.get("message"),
        "end_time": result.get("end_time"),
        "complete": status == "finished" and not cut,
    }


def _warn_if_incomplete(folder: Path, attrs: dict[str, Any], cut_line: int | None) -> None:
    """Say why the frame holds less than a finished run writes, if it does."""
    reasons = []
    if cut_line is not None:
        reasons.append(f"{CSV_NAME} line {cut_line}, the last, was cut off and is dropped")
    if attrs["status"] is None:
        reasons.append(f"{METADATA_NAME} has no summary: the process ended before the run did")
    elif attrs["status"] != "finished":
        message = f": {attrs['message']}" if attrs["message"] else ""
        reasons.append(f"the run {attrs['status']} at t = {attrs['end_time']} s{message}")
    if reasons:
        warnings.warn(
            f"{folder}: results incomplete; " + "; ".join(reasons),
            IncompleteResultsWarning,
            stacklevel=3,
        )
