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
import json
import logging
import math
from pathlib import Path
from typing import Any

import numpy as np

from .observers import LEDGER_CHANNEL
from .plot_figure import PlotContext, PlotRequest, plot_figure
from .scene import Scene

__all__ = ["read_results", "plot_scene", "plot_results", "plot_requests", "plot_context"]

logger = logging.getLogger(__name__)

ENERGY_PLOT = "energy"
"""File name (without ``.png``) of the energy-channel plot."""


def read_results(csv_path: Path) -> dict[str, np.ndarray]:
    """Columns of a results file as float arrays, by name (a text cell reads as NaN).

    Parameters
    ----------
    csv_path : Path
        A ``timeseries.csv`` written by :class:`~wire_fmu.master.observers.CsvRecorder`.

    Returns
    -------
    dict of str to ndarray
        Each column by its header (``"time"`` in s, ``"unit.variable"`` in the
        variable's unit), shape (rows,).
    """
    with Path(csv_path).open(newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    data = (
        np.array([[_number(c) for c in row] for row in body])
        if body
        else np.zeros((0, len(header)))
    )
    return {name: data[:, i] for i, name in enumerate(header)}


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


def plot_results(folder: str | Path, directory: str | Path | None = None) -> list[Path]:
    """Draw the plots of a results folder again, from its files alone.

    Parameters
    ----------
    folder : str or Path
        A results folder (``timeseries.csv`` and ``metadata.json``).
    directory : str or Path, optional
        Where to write the PNG files (default: ``folder``).

    Returns
    -------
    list of Path
        The PNG files written.
    """
    folder = Path(folder)
    meta = read_metadata(folder)
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
