"""One self-contained HTML page of a run, to read or to send: ``wire-fmu report RESULTS_DIR``.

:func:`write_report` reads a results folder (``metadata.json``,
``timeseries.csv``, the plots) and writes ``report.html`` into it: the scene's
description, units, events and drivers; how the run ended; the warnings it
gave; the energy books (each bond's residual against what it carried, each
unit's ledger); the plots; the reeving drawings; the settings and every
parameter; the columns with their units. Images are embedded as ``data:``
URIs and the style sheet is inline, so the one file is all: it loads nothing
and links only inside itself. ``wire-fmu run`` writes it at the end of a run.
"""

from __future__ import annotations

import json
import logging
import math
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import wire_fmu
from wire_fmu.core.errors import WireFmuError
from wire_fmu.master.observers import LEDGER_TERMS
from wire_fmu.master.plot_units import display_unit
from wire_fmu.master.plots import plot_requests, plot_results, read_metadata, read_results
from wire_fmu.master.results_frame import CSV_NAME, METADATA_NAME, ResultsError

from .report_html import Raw, details, esc, image, page, table

__all__ = ["REPORT_NAME", "ReportError", "write_report"]

logger = logging.getLogger(__name__)

REPORT_NAME = "report.html"
"""File name of the report in a results folder."""

_RUN_UNITS = {
    "stop_time": "s",
    "step": "s",
    "output_interval": "s",
    "min_step": "s",
    "max_step": "s",
    "energy_tolerance": "J",
}
"""Units of the run settings that have one (the others are pure numbers, names or flags)."""


class ReportError(WireFmuError, ValueError):
    """The report cannot be written where asked; the message names the file and why."""


def write_report(
    folder: str | Path, output: str | Path | None = None, *, plots: list[Path] | None = None
) -> Path:
    """Write the HTML report of a results folder.

    Parameters
    ----------
    folder : str or Path
        A results folder as a run writes it.
    output : str or Path, optional
        The HTML file, or an existing folder to write ``report.html`` into
        (default ``<folder>/report.html``).
    plots : list of Path, optional
        The run's plot files; default those of the folder, drawn again if
        missing.

    Returns
    -------
    Path
        The report written.

    Raises
    ------
    ResultsError
        When the folder has no readable ``metadata.json``, or its
        ``timeseries.csv`` cannot be read as a table (see
        :func:`~wire_fmu.master.plots.read_results`).
    ReportError
        When the report cannot be written where ``output`` says.
    """
    folder = Path(folder)
    meta = read_metadata(folder)
    if not meta:
        raise ResultsError(
            f"{folder / METADATA_NAME}: missing or unreadable; expected a results folder "
            f"as a run writes it ({METADATA_NAME} and {CSV_NAME})"
        )
    target = _target(folder, output)
    data = read_results(folder / CSV_NAME) if (folder / CSV_NAME).is_file() else {}
    notes: list[str] = []
    figures = _plots(folder, meta, data, plots, notes)
    drawings = _drawings(folder, meta, notes)
    page = _page(folder, meta, data, figures, drawings, notes)
    try:
        target.write_text(page, encoding="utf-8")
    except OSError as err:
        raise ReportError(f"{target}: the report cannot be written: {_reason(err)}") from None
    logger.info("report: %s", target)
    return target


def _target(folder: Path, output: str | Path | None) -> Path:
    """The report's file: ``output``, or :data:`REPORT_NAME` in it if it is a folder.

    Raises
    ------
    ReportError
        When the file's folder does not exist (said before anything is drawn).
    """
    if output is None:
        return folder / REPORT_NAME
    target = Path(output)
    if target.is_dir():
        return target / REPORT_NAME
    if not target.parent.is_dir():
        raise ReportError(
            f"{target}: the report cannot be written: no folder {target.parent}; expected "
            "an HTML file in an existing folder, or an existing folder for report.html"
        )
    return target


def _reason(err: OSError) -> str:
    return err.strerror or type(err).__name__


# ----------------------------------------------------------------------------- images
def _plots(folder: Path, meta, data, given: list[Path] | None, notes: list[str]) -> list:
    """(file, caption) of each plot: the given files, else the folder's, drawn if missing."""
    requests = plot_requests(meta, list(data))
    if given is None:
        given = [folder / f"{name}.png" for name, _ in requests]
        if data and not all(p.is_file() for p in given):
            try:
                given = plot_results(folder, data=data)
            except Exception as exc:  # noqa: BLE001 - the report stands without its plots
                notes.append(f"the plots could not be drawn: {exc}")
                given = [p for p in given if p.is_file()]
    captions = {
        f"{name}.png": f"{request.title}: {', '.join(request.columns)}"
        for name, request in requests
    }
    return [(p, captions.get(p.name, p.stem.replace("_", " "))) for p in given if p.is_file()]


def _drawings(folder: Path, meta: dict[str, Any], notes: list[str]) -> list:
    """(file, caption) of each unit's reeving drawing, drawn into the folder."""
    from .draw import draw_reeving

    out = []
    for unit, spec in (meta.get("units") or {}).items():
        reeving = ((spec or {}).get("parameters") or {}).get("reeving", {}).get("value")
        if isinstance(reeving, str):
            try:
                reeving = json.loads(reeving)
            except ValueError:
                notes.append(f"unit {unit!r}: its reeving is not JSON; not drawn")
                continue
        if not isinstance(reeving, dict):
            continue
        path = folder / f"{unit}_reeving.png"
        try:
            draw_reeving(reeving, path, title=f"{meta.get('scene', '')}: {unit}")
        except (WireFmuError, ValueError, ArithmeticError) as exc:
            notes.append(f"unit {unit!r}: the reeving could not be drawn: {exc}")
            continue
        out.append((path, f"Reeving of unit {unit!r}: {reeving.get('name', '')}".rstrip(": ")))
    return out


# ------------------------------------------------------------------------------ page
def _page(folder: Path, meta, data, figures, drawings, notes: list[str]) -> str:
    result = meta.get("result") if isinstance(meta.get("result"), dict) else {}
    status = str(result.get("status") or "unknown")
    scene = str(meta.get("scene", folder.name))
    written = datetime.fromtimestamp((folder / METADATA_NAME).stat().st_mtime, UTC)
    header = (
        f'<h1>{esc(scene)} <span class="status {esc(status)}">{esc(status)}</span></h1>'
        f'<p class="meta">Results folder <code>{esc(folder.resolve())}</code>, '
        f"written {written:%Y-%m-%d %H:%M} UTC"
        + (" (monolithic reference run)" if meta.get("mode") == "monolithic" else "")
        + "</p>"
    )
    sections = [
        ("scene", "Scene", _scene(meta)),
        ("summary", "Summary", _summary(meta, result)),
        ("warnings", "Warnings", _warnings(meta, result, notes)),
        ("energy", "Energy books", _energy(meta, result, data)),
        ("plots", "Plots", "".join(image(p, c) for p, c in figures) or _none("no plots")),
        (
            "reeving",
            "Reeving",
            "".join(image(p, c) for p, c in drawings) or _none("no unit has a reeving"),
        ),
        ("settings", "Settings", _settings(meta)),
        ("columns", "Columns", _columns(meta)),
    ]
    footer = f"wire_fmu {wire_fmu.__version__}: report of {scene}"
    return page(f"{scene}: run report", header, sections, footer)


def _none(text: str) -> str:
    return f'<p class="none">{esc(text)}</p>'


def _scene(meta: dict[str, Any]) -> str:
    parts = [f'<p class="description">{esc(str(meta.get("description", "")).strip())}</p>']
    units = meta.get("units") or {}
    if units:
        rows = [
            (name, spec.get("fmu", ""), ", ".join(spec.get("effects", [])) or "none")
            for name, spec in units.items()
        ]
        parts += ["<h3>Units</h3>", table(("unit", "FMU", "effects"), rows)]
    events = meta.get("events") or []
    if events:
        rows = [
            (f"{e['time']:g}", e.get("label", ""), _assignments(e.get("set", {}), meta))
            for e in events
        ]
        parts += ["<h3>Scheduled events</h3>", table(("time (s)", "what", "sets"), rows, (0,))]
    drivers = meta.get("drivers") or []
    if drivers:
        rows = [(d.get("target", ""), d.get("kind", ""), d.get("label", "")) for d in drivers]
        parts += ["<h3>Drivers</h3>", table(("input", "signal", "label"), rows)]
    return "".join(parts)


def _assignments(values: dict[str, Any], meta: dict[str, Any]) -> str:
    variables = meta.get("variables") or {}
    return "; ".join(
        f"{k} = {_quantity(v, (variables.get(k) or {}).get('unit', ''))}" for k, v in values.items()
    )


def _summary(meta: dict[str, Any], result: dict[str, Any]) -> str:
    if not result:
        return _none("no summary: the process ended before the run could write one")
    rtf = result.get("real_time_factor")
    rows = [
        ("status", result.get("status", "")),
        ("message", result.get("message") or "-"),
        (
            "simulated",
            f"{_g(result.get('end_time'))} s of {_g((meta.get('run') or {}).get('stop_time'))} s",
        ),
        ("wall time", f"{_g(result.get('wall_time'))} s"),
        ("real-time factor", _g(rtf) if rtf is not None else "-"),
        ("steps", _steps(result)),
    ]
    parts = [table(None, rows)]
    units = result.get("units") or {}
    if units:
        per_unit = [
            (
                name,
                u.get("calls", {}).get("doStep", 0),
                sum(u.get("calls", {}).values()),
                f"{sum(u.get('seconds', {}).values()):.3g}",
            )
            for name, u in units.items()
        ]
        parts += [
            "<h3>Units through FMI</h3>",
            table(("unit", "doStep", "FMI calls", "time in FMI (s)"), per_unit, (1, 2, 3)),
        ]
    return "".join(parts)


def _steps(result: dict[str, Any]) -> str:
    text = f"{result.get('steps', 0)} accepted"
    for key, word in (
        ("rejected_steps", "rejected"),
        ("synchronised_steps", "synchronised"),
        ("sweeps", "sweeps"),
        ("rhs_calls", "right-hand-side calls"),
        ("events", "events"),
    ):
        if key in result:
            text += f", {result[key]} {word}"
    return text


def _warnings(meta: dict[str, Any], result: dict[str, Any], notes: list[str]) -> str:
    items = []
    status = result.get("status")
    if status and status != "finished":
        items.append(("error", f"the run {status}: {result.get('message', '')}"))
    for w in meta.get("warnings") or []:
        items.append((w.get("level", "warning"), f"{w.get('message', '')} ({w.get('source', '')})"))
    items += [("warning", note) for note in notes]
    if not items:
        return _none("none: the run gave no warning")
    lines = "".join(f'<li class="{esc(level)}">{esc(text)}</li>' for level, text in items)
    return f'<ul class="warnings">{lines}</ul>'


def _energy(meta: dict[str, Any], result: dict[str, Any], data) -> str:
    parts = []
    carried = result.get("bond_energy_carried") or {}
    if carried:
        rows = []
        for bond, total in carried.items():
            net = (result.get("bond_energy_residual") or {}).get(bond, math.nan)
            error = (result.get("bond_energy_error") or {}).get(bond, math.nan)
            share = f"{100 * error / total:.3g} %" if total else "-"
            rows.append((bond, _joules(total), _joules(net), _joules(error), share))
        parts += [
            "<h3>Bonds</h3>",
            "<p>Energy each power bond carried, and the energy its coupling created or "
            "destroyed (net, and summed without sign) against it.</p>",
            table(
                ("bond", "carried", "net residual", "created or destroyed", "share"),
                rows,
                (1, 2, 3, 4),
            ),
        ]
    rows = _ledgers(meta, data)
    if rows:
        parts += [
            "<h3>Units' ledgers at the end</h3>",
            "<p>Each unit's own books: stored change + dissipated − external work = "
            "residual (zero for exact bookkeeping).</p>",
            table(("unit", *(t.replace("_", " ") for t in LEDGER_TERMS)), rows, (1, 2, 3, 4)),
        ]
    return "".join(parts) or _none("no energy channels were recorded")


def _ledgers(meta: dict[str, Any], data) -> list[tuple]:
    if not data or not len(data.get("time", [])):
        return []
    rows = []
    for unit in meta.get("units") or {}:
        cells = []
        for term in LEDGER_TERMS:
            column = data.get(f"{unit}.{term}")
            cells.append(_joules(float(column[-1])) if column is not None else "-")
        if any(c != "-" for c in cells):
            rows.append((unit, *cells))
    return rows


def _settings(meta: dict[str, Any]) -> str:
    run = meta.get("run") or {}
    rows = [(k, _quantity(v, _RUN_UNITS.get(k, "1"))) for k, v in run.items()]
    parts = [table(("setting", "value"), rows)]
    for unit, spec in (meta.get("units") or {}).items():
        parameters = spec.get("parameters") or {}
        given = [
            (k, _quantity(p.get("value"), p.get("unit", "")))
            for k, p in parameters.items()
            if p.get("given")
        ]
        default = [
            (k, _quantity(p.get("value"), p.get("unit", "")))
            for k, p in parameters.items()
            if not p.get("given")
        ]
        parts.append(f"<h3>Unit {esc(unit)} ({esc(spec.get('fmu', ''))})</h3>")
        parts.append(
            table(("parameter set by the scene", "value"), given)
            if given
            else _none("the scene sets no parameter")
        )
        if default:
            parts.append(
                f"<details><summary>{len(default)} more parameters at their defaults</summary>"
                + table(("parameter", "default"), default)
                + "</details>"
            )
    return "".join(parts)


def _columns(meta: dict[str, Any]) -> str:
    units = meta.get("column_units") or {}
    variables = meta.get("variables") or {}
    rows = [
        (c, units.get(c, "?"), (variables.get(c) or {}).get("description", ""))
        for c in meta.get("columns") or units
    ]
    return (
        f"<details><summary>{len(rows)} columns of {CSV_NAME} with their units</summary>"
        + table(("column", "unit", "description"), rows)
        + "</details>"
    )


# ----------------------------------------------------------------------------- numbers
def _g(value: Any) -> str:
    return f"{value:.6g}" if isinstance(value, int | float) else str(value)


def _joules(value: float) -> str:
    return _quantity(value, "J")


def _quantity(value: Any, unit: str) -> str | Raw:
    """A value with its unit in the engineering multiple (``4.674 MJ``); text as it is."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return _plain(value)
    if not math.isfinite(value):
        return f"{value} {unit}".rstrip() if unit not in ("1", "") else str(value)
    shown = display_unit(unit, abs(value))
    return f"{shown.show(value):.4g} {shown.label}".rstrip() if shown.label else f"{value:.6g}"


def _plain(value: Any) -> str | Raw:
    """A value as text; a table (a reeving, a drive train) folded, in full."""
    if isinstance(value, dict | list):
        text = json.dumps(value, indent=1)
        if len(text) <= 80:
            return json.dumps(value)
        name = value.get("name") if isinstance(value, dict) else None
        shown = f"{name!r}: table" if name else "table"
        return details(f"{shown} ({len(text.splitlines())} lines)", f"<pre>{esc(text)}</pre>")
    return str(value)
