"""PNG plots of a run, from its results folder: the scene's plots and the energy channels.

Each plot is drawn by :func:`~wire_fmu.master.plot_figure.plot_figure` in
engineering units, with the reference lines the run's parameters give, the
discrete states on axes of their own and fast oscillations as envelopes.
What it needs besides the table comes from ``metadata.json`` (the unit and
description of every column, the parameters, the events, the plots the scene
lists), so a results folder can be plotted again on its own
(:func:`plot_results`).
"""

from __future__ import annotations

import csv
import io
import json
import logging
import math
from pathlib import Path
from typing import Any

import numpy as np

from .observers import LEDGER_CHANNEL
from .plot_figure import PlotContext, PlotRequest, plot_figure
from .results_frame import ResultsError, read_table_text
from .scene import Scene

__all__ = ["read_results", "plot_scene", "plot_results", "plot_requests", "plot_context"]

logger = logging.getLogger(__name__)

ENERGY_PLOT = "energy"
"""File name (without ``.png``) of the energy-channel plot."""


def read_results(csv_path: Path) -> dict[str, np.ndarray]:
    """Columns of a results file as float arrays, by name (a text cell reads as NaN).

    A last line cut off (a run killed while writing it) is left out, with a
    warning naming the file and the line; the rows before it are read.

    Parameters
    ----------
    csv_path : Path
        A ``timeseries.csv`` written by :class:`~wire_fmu.master.observers.CsvRecorder`.

    Returns
    -------
    dict of str to ndarray
        Each column by its header (``"time"`` in s, ``"unit.variable"`` in the
        variable's unit), shape (rows,).

    Raises
    ------
    ResultsError
        When the file cannot be read, is empty, has no header line starting with
        ``time``, or has a row (other than a cut-off last one) of another number
        of cells than the header; the message names the file and the lines.
    """
    csv_path = Path(csv_path)
    header, text, cut_line = read_table_text(csv_path)
    rows = _rows(csv_path, text, len(header))
    if cut_line is not None:
        logger.warning(
            "%s: line %d, the last, was cut off (the run ended while writing it) and is "
            "dropped; the %d rows before it are read",
            csv_path,
            cut_line,
            len(rows),
        )
    data = np.array(rows, dtype=float) if rows else np.zeros((0, len(header)))
    return {name: data[:, i] for i, name in enumerate(header)}


def _rows(csv_path: Path, text: str | None, width: int) -> list[list[float]]:
    """The rows after the header as numbers (the file's, or ``text`` if given).

    Every row must have ``width`` cells; those that do not are named all at once.
    """
    rows, wrong = [], []
    try:
        with (
            csv_path.open(encoding="utf-8", newline="")
            if text is None
            else io.StringIO(text, newline="")
        ) as f:
            reader = csv.reader(f)
            next(reader, None)  # the header, read and checked already
            for row in reader:
                if len(row) == width:
                    rows.append([_number(c) for c in row])
                elif row:  # a blank line is no row
                    wrong.append(f"{reader.line_num} ({len(row)} cell{'s' * (len(row) != 1)})")
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise ResultsError(f"{csv_path}: cannot be read ({err})") from None
    if wrong:
        shown = ", ".join(wrong[:5]) + (f" and {len(wrong) - 5} more" if len(wrong) > 5 else "")
        raise ResultsError(
            f"{csv_path}: expected {width} cells in every line, as in the header; "
            f"line {shown} {'differs' if len(wrong) == 1 else 'differ'} "
            "(not a table as a run writes it)"
        )
    return rows


def _number(cell: str) -> float:
    """A recorded cell as a number; a String or Boolean output's text is no number: NaN."""
    try:
        return float(cell)
    except ValueError:
        return math.nan


def _slug(text: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in text.lower()).strip("_")


def _file_names(titles: list[str], taken: set[str]) -> list[str]:
    """One file name per plot title, none twice and none in ``taken`` (``_2``, ``_3`` ...)."""
    names = []
    used = set(taken)
    for title in titles:
        base = _slug(title) or "plot"
        name, n = base, 1
        while name in used:
            n += 1
            name = f"{base}_{n}"
        used.add(name)
        names.append(name)
    return names


def read_metadata(folder: Path) -> dict[str, Any]:
    """A results folder's ``metadata.json`` (empty if it has none or it cannot be read).

    Parameters
    ----------
    folder : Path
        The results folder.
    """
    path = Path(folder) / "metadata.json"
    try:
        meta = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return {}
    return meta if isinstance(meta, dict) else {}


def plot_context(meta: dict[str, Any], scene: Scene | None = None) -> PlotContext:
    """What the plots need besides the table, from the metadata (and the scene, if at hand).

    Parameters
    ----------
    meta : dict
        The run's ``metadata.json``.
    scene : Scene, optional
        The scene that ran: its parameters and events where the metadata has none.

    Returns
    -------
    PlotContext
    """
    variables = meta.get("variables") if isinstance(meta.get("variables"), dict) else {}
    parameters = _parameters(meta.get("units"))
    if not parameters and scene is not None:
        parameters = {
            name: {k: {"value": v, "given": True} for k, v in spec.parameters.items()}
            for name, spec in scene.units.items()
        }
    events = [
        (float(e["time"]), str(e.get("label", "")))
        for e in meta.get("events", []) or []
        if isinstance(e, dict) and isinstance(e.get("time"), int | float)
    ]
    if not events and scene is not None:
        events = [(e.time, e.label) for e in scene.events]
    return PlotContext(
        units=dict(meta.get("column_units") or {}),
        descriptions={
            k: str(v.get("description", "")) for k, v in variables.items() if isinstance(v, dict)
        },
        parameters=parameters,
        events=tuple(events),
    )


def _parameters(units: Any) -> dict[str, dict[str, Any]]:
    if not isinstance(units, dict):
        return {}
    return {
        name: spec["parameters"]
        for name, spec in units.items()
        if isinstance(spec, dict) and isinstance(spec.get("parameters"), dict)
    }


def plot_requests(meta: dict[str, Any], columns: list[str], scene: Scene | None = None):
    """The plots of a run: the scene's (from the scene, else the metadata), then the energy.

    Parameters
    ----------
    meta : dict
        The run's ``metadata.json``.
    columns : list of str
        The recorded columns.
    scene : Scene, optional
        The scene that ran (its ``plots`` win over the metadata's).

    Returns
    -------
    list of (str, PlotRequest)
        File name (without ``.png``) and plot, in order.
    """
    if scene is not None:
        listed = [PlotRequest(p.title, tuple(map(str, p.variables)), p.ylabel) for p in scene.plots]
        name = scene.name
    else:
        listed = [
            PlotRequest(str(p["title"]), tuple(p["variables"]), str(p.get("ylabel", "")))
            for p in meta.get("plots", []) or []
            if isinstance(p, dict) and "title" in p and isinstance(p.get("variables"), list)
        ]
        name = str(meta.get("scene", "run"))
    names = _file_names([p.title for p in listed], taken={ENERGY_PLOT})
    requests = list(zip(names, listed, strict=True))
    energy = [c for c in columns if c.endswith(".energy_residual") or c == LEDGER_CHANNEL]
    if energy:
        title = f"{name}: energy bookkeeping"
        requests.append((ENERGY_PLOT, PlotRequest(title, tuple(energy), "energy (J)")))
    return requests


def plot_scene(scene: Scene, csv_path: Path, directory: Path) -> list[Path]:
    """One PNG per scene plot, plus the energy channels; returns the files.

    Parameters
    ----------
    scene : Scene
        The scene that ran (its ``plots``).
    csv_path : Path
        Its results file; ``metadata.json`` beside it gives units, descriptions,
        parameters and events.
    directory : Path
        Folder the PNG files are written into.

    Returns
    -------
    list of Path
        The PNG files written.
    """
    meta = read_metadata(Path(csv_path).parent)
    return _write(read_results(csv_path), meta, Path(directory), scene)


def plot_results(
    folder: str | Path,
    directory: str | Path | None = None,
    *,
    data: dict[str, np.ndarray] | None = None,
) -> list[Path]:
    """Draw the plots of a results folder again, from its files alone.

    Parameters
    ----------
    folder : str or Path
        A results folder (``timeseries.csv`` and ``metadata.json``).
    directory : str or Path, optional
        Where to write the PNG files (default: ``folder``).
    data : dict of str to ndarray, optional
        Its ``timeseries.csv`` as :func:`read_results` reads it, if read already.

    Returns
    -------
    list of Path
        The PNG files written.
    """
    folder = Path(folder)
    meta = read_metadata(folder)
    if data is None:
        data = read_results(folder / "timeseries.csv")
    return _write(data, meta, Path(directory or folder), None)


def _write(
    data: dict[str, np.ndarray], meta: dict[str, Any], directory: Path, scene: Scene | None
) -> list[Path]:
    context = plot_context(meta, scene)
    written = []
    for name, request in plot_requests(meta, list(data), scene):
        fig = plot_figure(request, data, context)
        path = directory / f"{name}.png"
        fig.savefig(path)
        written.append(path)
    logger.info("plots: %s", ", ".join(str(p) for p in written))
    return written
