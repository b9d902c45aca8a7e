"""PNG plots of a scene's key outputs, from its results file."""

from __future__ import annotations

import csv
import logging
import math
from pathlib import Path

import numpy as np

from .observers import LEDGER_CHANNEL
from .scene import Scene

__all__ = ["read_results", "plot_scene"]

logger = logging.getLogger(__name__)


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


def _figure(title: str, ylabel: str):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 4), dpi=100, layout="constrained")
    ax = fig.add_subplot()
    ax.set_title(title)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    return fig, ax


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


def plot_scene(scene: Scene, csv_path: Path, directory: Path) -> list[Path]:
    """One PNG per scene plot, plus the energy channels; returns the files.

    Parameters
    ----------
    scene : Scene
        The scene that ran (its ``plots``).
    csv_path : Path
        Its results file.
    directory : Path
        Folder the PNG files are written into.

    Returns
    -------
    list of Path
        The PNG files written.
    """
    columns = read_results(csv_path)
    time = columns["time"]
    written = []
    names = _file_names([spec.title for spec in scene.plots], taken={"energy"})
    for spec, name in zip(scene.plots, names, strict=True):
        fig, ax = _figure(spec.title, spec.ylabel)
        for ref in spec.variables:
            ax.plot(time, columns[str(ref)], label=str(ref))
        ax.legend(loc="best", fontsize="small")
        path = Path(directory) / f"{name}.png"
        fig.savefig(path)
        written.append(path)
    energy = [c for c in columns if c.endswith(".energy_residual") or c == LEDGER_CHANNEL]
    if energy:
        fig, ax = _figure(f"{scene.name}: energy bookkeeping", "energy (J)")
        for name in energy:
            ax.plot(time, columns[name], label=name)
        ax.legend(loc="best", fontsize="small")
        path = Path(directory) / "energy.png"
        fig.savefig(path)
        written.append(path)
    logger.info("plots: %s", ", ".join(str(p) for p in written))
    return written
