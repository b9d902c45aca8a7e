"""A sweep's output folder: written case by case, read back on resume.

Layout of ``OUT``::

    sweep.json                 manifest: scene, its key, the spec, core version
    records/<case_id>.parquet  one row per case, written when the case ends
    cases/<case_id>/           the case's timeseries.csv, metadata.json, case.json
    summary.parquet            every case of the spec, one row each
    plots/<figure>.png         each key figure against the swept parameters

A case's files are written first and its record last, each record by an
atomic rename, so a record on disk means a complete case: an interrupted
sweep (Ctrl-C, a lost client, a power cut) loses at most the cases that
were still running. ``records/`` is itself a Parquet dataset (one schema);
``summary.parquet`` is rewritten from it at the end of every invocation,
also an interrupted one, with the cases not yet run as ``pending`` rows.

Summary columns: ``case_id``, ``index``, ``status`` (``finished``,
``stopped`` - a unit stopped the run, figures cover what was recorded -,
``failed`` - an error, e.g. a unit refused its parameters -, ``lost`` - the
workers running it kept dying -, ``pending``), one column per axis target
(named by the target), one per key figure, ``error``, ``wall_time`` (s, in
the worker, loading the FMUs included), ``end_time`` (simulated s reached),
``worker``, ``attempts`` and ``finished_at`` (UTC). pyarrow writes and reads
it without pandas; ``pandas.read_parquet`` and polars read it too.
"""

from __future__ import annotations

import datetime as dt
import json
import logging
import os
import shutil
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from wire_fmu.master.plot_units import DisplayUnit, display_unit
from wire_fmu.master.plots import read_results
from wire_fmu.master.results_frame import ResultsError

from .axes import Axis
from .cases import Case
from .spec import SweepError, SweepSpec

__all__ = [
    "CaseOutcome",
    "ResultStore",
    "summary_schema",
    "plot_summary",
    "STATUSES",
    "DONE_STATUSES",
    "TIMESERIES_FILE",
]

logger = logging.getLogger(__name__)

STATUSES = ("finished", "stopped", "failed", "lost", "pending")
DONE_STATUSES = frozenset({"finished", "stopped", "failed"})
"""Statuses a resumed sweep keeps (``lost`` cases run again; ``failed`` and
``stopped`` ones too when asked to rerun failures)."""
TIMESERIES_FILE = "timeseries.csv"
_ARROW_TYPES = MappingProxyType(
    {
        "int": pa.int64(),
        "float": pa.float64(),
        "bool": pa.bool_(),
        "str": pa.string(),
        "json": pa.string(),
    }
)


@dataclass
class CaseOutcome:
    """What running one case produced (returned by a worker, written by the client).

    Attributes
    ----------
    case_id : str
        The case.
    status : str
        ``finished``, ``stopped``, ``failed`` or ``lost``.
    error : str or None
        Why it did not finish.
    wall_time : float
        Seconds the case took in the worker.
    end_time : float or None
        Simulated time reached, s.
    figures : dict
        Key figure name -> value (None when its column has no samples).
    files : dict
        File name -> content of the case's results folder.
    worker : str
        Address of the worker that ran it (``"local"`` when serial).
    attempts : int
        Submissions it took (more than 1 after a lost worker).
    """

    case_id: str
    status: str
    error: str | None = None
    wall_time: float = 0.0
    end_time: float | None = None
    figures: dict[str, float | None] = field(default_factory=dict)
    files: dict[str, bytes] = field(default_factory=dict)
    worker: str = ""
    attempts: int = 1


def summary_schema(spec: SweepSpec) -> pa.Schema:
    """Arrow schema of a record and of the summary table of ``spec``.

    Parameters
    ----------
    spec : SweepSpec
        The sweep: one column per axis target and per key figure.
    """
    fields = [
        pa.field("case_id", pa.string(), nullable=False),
        pa.field("index", pa.int64()),
        pa.field("status", pa.string()),
    ]
    fields += [pa.field(a.target, _ARROW_TYPES[a.kind]) for a in spec.axes]
    fields += [pa.field(f.name, pa.float64()) for f in spec.figures]
    fields += [
        pa.field("error", pa.string()),
        pa.field("wall_time", pa.float64()),
        pa.field("end_time", pa.float64()),
        pa.field("worker", pa.string()),
        pa.field("attempts", pa.int64()),
        pa.field("finished_at", pa.timestamp("ms", tz="UTC")),
    ]
    return pa.schema(fields)


def _cell(axis: Axis, value: Any) -> Any:
    return json.dumps(value) if axis.kind == "json" else value


def _write_atomic(path: Path, write) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    write(tmp)
    os.replace(tmp, path)


class ResultStore:
    """The output folder of one sweep (see the module docstring for the layout).

    Parameters
    ----------
    directory : Path
        The folder (created).
    spec : SweepSpec
        The sweep, for the columns.
    cases : sequence of Case
        Every case of the sweep, for the summary.
    """

    def __init__(self, directory: Path, spec: SweepSpec, cases: Sequence[Case]) -> None:
        self.directory = Path(directory)
        self.spec = spec
        self.cases = list(cases)
        self.schema = summary_schema(spec)
        self.manifest_path = self.directory / "sweep.json"
        self.records_dir = self.directory / "records"
        self.cases_dir = self.directory / "cases"
        self.summary_path = self.directory / "summary.parquet"
        self.plots_dir = self.directory / "plots"

    # -- opening --------------------------------------------------------------------
    def open(self, manifest: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
        """Create the folder or check it holds this scene's sweep; the records on disk.

        Parameters
        ----------
        manifest : mapping
            What the sweep is (scene, its key, spec, core version), written
            as ``sweep.json``.

        Raises
        ------
        SweepError
            The folder holds a sweep of another scene (or another version of it).
        """
        self.records_dir.mkdir(parents=True, exist_ok=True)
        self.cases_dir.mkdir(parents=True, exist_ok=True)
        if self.manifest_path.exists():
            old = json.loads(self.manifest_path.read_text())
            if old.get("scene_key") != manifest["scene_key"]:
                raise SweepError(
                    f"{self.directory} holds a sweep of scene {old.get('scene')!r} as it was "
                    f"then (key {old.get('scene_key')}); this scene {manifest['scene']!r} "
                    f"differs (key {manifest['scene_key']}): choose another output folder or "
                    "delete that one"
                )
            if old.get("core") != manifest.get("core"):
                logger.warning(
                    "the wire_fmu core changed since this sweep started; the cases "
                    "on disk were computed with core %s, new ones with %s",
                    old.get("core"),
                    manifest.get("core"),
                )
        _write_atomic(
            self.manifest_path,
            lambda p: p.write_text(json.dumps(manifest, indent=2, default=str) + "\n"),
        )
        return self.read_records()

    def read_records(self) -> dict[str, dict[str, Any]]:
        """Records on disk by case id (unreadable ones are skipped with a warning)."""
        records = {}
        for path in sorted(self.records_dir.glob("*.parquet")):
            try:
                rows = pq.read_table(path).to_pylist()
            except (OSError, pa.ArrowException) as err:
                logger.warning("record %s cannot be read (%s); the case will run again", path, err)
                continue
            if rows:
                records[rows[0]["case_id"]] = rows[0]
        return records

    # -- writing a case -----------------------------------------------------------------
    def case_dir(self, case_id: str) -> Path:
        """Results folder of one case.

        Parameters
        ----------
        case_id : str
            The case's id.
        """
        return self.cases_dir / case_id

    def write(self, case: Case, outcome: CaseOutcome) -> dict[str, Any]:
        """Write a finished case: its files, then its record; the record row.

        Parameters
        ----------
        case : Case
            The case.
        outcome : CaseOutcome
            Its status, figures and files.
        """
        folder = self.case_dir(case.case_id)
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        for name, content in outcome.files.items():
            (folder / Path(name).name).write_bytes(content)
        (folder / "case.json").write_text(
            json.dumps(
                {"case_id": case.case_id, "index": case.index, "values": case.values},
                indent=2,
                default=str,
            )
            + "\n"
        )
        row = self._row(case, outcome)
        self._write_record(row)
        return row

    def _row(self, case: Case, outcome: CaseOutcome) -> dict[str, Any]:
        row: dict[str, Any] = {
            "case_id": case.case_id,
            "index": case.index,
            "status": outcome.status,
        }
        row |= {a.target: _cell(a, case.values[a.target]) for a in self.spec.axes}
        row |= {f.name: outcome.figures.get(f.name) for f in self.spec.figures}
        row |= {
            "error": outcome.error,
            "wall_time": outcome.wall_time,
            "end_time": outcome.end_time,
            "worker": outcome.worker,
            "attempts": outcome.attempts,
            "finished_at": dt.datetime.now(dt.UTC),
        }
        return row

    def _write_record(self, row: Mapping[str, Any]) -> None:
        table = pa.Table.from_pylist([dict(row)], schema=self.schema)
        _write_atomic(
            self.records_dir / f"{row['case_id']}.parquet", lambda p: pq.write_table(table, p)
        )

    # -- the summary ----------------------------------------------------------------------
    def _pending(self, case: Case) -> dict[str, Any]:
        row: dict[str, Any] = {name: None for name in self.schema.names}
        row |= {"case_id": case.case_id, "index": case.index, "status": "pending"}
        row |= {a.target: _cell(a, case.values[a.target]) for a in self.spec.axes}
        return row

    def _complete(self, case: Case, record: dict[str, Any]) -> dict[str, Any]:
        """The record in the spec's current columns; figures added since are computed.

        A record whose columns or index changed (the spec did) is rewritten, so
        ``records/`` stays one dataset of one schema.
        """
        row = {name: record.get(name) for name in self.schema.names}
        row |= {"index": case.index}
        missing = [f for f in self.spec.figures if f.name not in record]
        csv = self.case_dir(case.case_id) / TIMESERIES_FILE
        if missing and record["status"] in ("finished", "stopped") and csv.exists():
            try:
                columns = read_results(csv)
            except ResultsError as err:  # the other cases' figures stand without this one's
                logger.warning("case %s: key figures left out: %s", case.case_id, err)
                columns = {}
            row |= {f.name: f.evaluate(columns) for f in missing}
        if list(record) != self.schema.names or record["index"] != case.index:
            self._write_record(row)
        return row

    def consolidate(self) -> list[dict[str, Any]]:
        """Write ``summary.parquet``: one row per case of the spec, in case order."""
        records = self.read_records()
        rows = [
            self._complete(c, records[c.case_id]) if c.case_id in records else self._pending(c)
            for c in self.cases
        ]
        table = pa.Table.from_pylist(rows, schema=self.schema)
        _write_atomic(self.summary_path, lambda p: pq.write_table(table, p))
        return rows


# -- plots ------------------------------------------------------------------------------------
def _short(value: Any) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def _order(value: Any) -> tuple:
    number = isinstance(value, int | float) and not isinstance(value, bool)
    return (0, value, "") if number else (1, 0, str(value))


def _numeric(axis: Axis) -> bool:
    return axis.kind in ("int", "float")


def _positions(axis: Axis, values: list[Any], labels: list[str]) -> np.ndarray:
    """Positions of values along an axis (the index of their label when not numeric)."""
    if _numeric(axis):
        return np.asarray(values, dtype=float)
    return np.asarray([labels.index(str(v)) for v in values], dtype=float)


def _group_axis(axes: list[Axis], axis: Axis) -> Axis | None:
    """Another grid axis with few values, to draw one curve per value of."""
    for other in axes:
        if other is not axis and other.is_grid and 2 <= len(other.values) <= 8:
            return other
    return None


def _draw_panel(
    ax,
    axes: list[Axis],
    axis: Axis,
    name: str,
    rows: list[dict],
    shown: tuple[DisplayUnit, DisplayUnit, DisplayUnit | None],
) -> None:
    """The figure ``name`` against ``axis`` (x and y in the units ``shown``; a group's too)."""
    x_unit, y_unit, group_unit = shown
    group = _group_axis(axes, axis)
    connect = axis.is_grid and len(axes) <= (2 if group else 1)
    keys = sorted({r[group.target] for r in rows}, key=_order) if group else [None]
    labels = [] if _numeric(axis) else sorted({str(r[axis.target]) for r in rows})
    for key in keys:
        chosen = [r for r in rows if group is None or r[group.target] == key]
        x = _positions(axis, [r[axis.target] for r in chosen], labels)
        x = x if labels else x_unit.show(x)
        y = y_unit.show(np.asarray([r[name] for r in chosen], dtype=float))
        order = np.argsort(x, kind="stable")
        label = _group_label(group, key, group_unit) if group else None
        ax.plot(x[order], y[order], "o-" if connect else "o", ms=4, label=label)
    if labels:
        ax.set_xticks(range(len(labels)), labels, rotation=30, ha="right", fontsize="small")
    if axis.log_scale:
        ax.set_xscale("log")
    ax.set_xlabel(_with_unit(_axis_name(axis.target), x_unit), fontsize="small")
    ax.grid(True, alpha=0.3)
    if group:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False)


def _axis_name(target: str) -> str:
    """An axis target as a short name: ``units.cylinder.parameters.x`` -> ``cylinder.x``."""
    parts = target.split(".")
    if parts[0] == "units" and len(parts) >= 4 and parts[2] == "parameters":
        return ".".join([parts[1], *parts[3:]])
    return target


def _with_unit(text: str, shown: DisplayUnit) -> str:
    return f"{text} ({shown.label})" if shown.label else text


def _group_label(group: Axis, key: Any, shown: DisplayUnit | None) -> str:
    name = group.target.rsplit(".", 1)[-1]
    if shown is not None and shown.label and isinstance(key, int | float):
        return f"{name} = {_short(shown.show(key))} {shown.label}"
    return f"{name} = {_short(key)}"


def _display(unit: str, values: list[Any]) -> DisplayUnit:
    numbers = [abs(v) for v in values if isinstance(v, int | float) and not isinstance(v, bool)]
    return display_unit(unit, max(numbers, default=float("nan")))


def plot_summary(
    rows: list[dict[str, Any]],
    spec: SweepSpec,
    directory: Path,
    units: Mapping[str, str] | None = None,
) -> list[Path]:
    """One PNG per key figure: the figure against each swept parameter.

    Only finished cases are drawn (the title says how many others there are);
    axes of a single value get no panel. With another grid axis of at most 8
    values, each of its values gets its own colour (and a curve when the
    sweep varies just those two).

    Parameters
    ----------
    rows : list of dict
        Summary rows (see :meth:`ResultStore.consolidate`).
    spec : SweepSpec
        The sweep.
    directory : Path
        Where the PNG files go (created).
    units : mapping of str to str, optional
        Unit of each axis target and figure column
        (:func:`~wire_fmu.sweep.units.sweep_units`); values are shown in
        engineering multiples of them (kN, MPa) and every axis names its unit.

    Returns
    -------
    list of Path
        The files written.
    """
    from matplotlib.figure import Figure

    units = units or {}

    directory.mkdir(parents=True, exist_ok=True)
    axes = [a for a in spec.axes if not a.is_grid or len(a.values) > 1] or list(spec.axes)
    written = []
    for figure in spec.figures:
        done = [r for r in rows if r["status"] == "finished" and r[figure.name] is not None]
        width = min(len(axes), 3)
        height = -(-len(axes) // width)
        grouped = any(_group_axis(axes, a) for a in axes)  # legends beside the panels
        panel_width = 6.2 if grouped else 4.5
        fig = Figure(figsize=(panel_width * width, 3.6 * height), dpi=100, layout="constrained")
        others = len(rows) - len(done)
        note = f" ({others} of {len(rows)} cases not finished, not shown)" if others else ""
        fig.suptitle(f"{figure.name} = {figure.expression}{note}")
        y_unit = _display(units.get(figure.column, ""), [r[figure.name] for r in done])
        for i, axis in enumerate(axes):
            ax = fig.add_subplot(height, width, i + 1)
            ax.set_ylabel(_with_unit(figure.name, y_unit))
            x_unit = _display(units.get(axis.target, ""), [r[axis.target] for r in done])
            group = _group_axis(axes, axis)
            group_unit = (
                _display(units.get(group.target, ""), [r[group.target] for r in done])
                if group
                else None
            )
            if done:
                _draw_panel(ax, axes, axis, figure.name, done, (x_unit, y_unit, group_unit))
        path = directory / f"{figure.name}.png"
        fig.savefig(path)
        written.append(path)
    logger.info("sweep plots: %s", ", ".join(str(p) for p in written))
    return written
