"""What an accuracy study produced, and its files: table, summary, JSON, two diagrams."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .log_ticks import log_ticks
from .measures import MONOLITHIC_RADAU, RunRow
from .orders import (
    ASYMPTOTIC_LIMIT,
    DOMINANCE,
    MIN_ASYMPTOTIC_RUNS,
    EqualErrorRow,
    OrderRow,
    _families,
    not_fitted,
)
from .plan import StudySettings
from .tables import write_tables

__all__ = [
    "AccuracyStudy",
    "observed_text",
    "accuracy_markdown",
    "plot_work_precision",
    "plot_convergence",
    "write_accuracy_files",
]


@dataclass
class AccuracyStudy:
    """Everything a study produced."""

    scene: str
    settings: StudySettings
    reference_wall_per_sim_s: float
    rows: list[RunRow]
    orders: list[OrderRow]
    comparison: list[EqualErrorRow]
    files: dict[str, Path] = field(default_factory=dict)
    elapsed: float = 0.0
    notes: list[str] = field(default_factory=list)
    """Warnings about what the errors leave out (key outputs still in the window)."""


# -------------------------------------------------------------------- reports
def _fmt(value: float, spec: str = ".3g") -> str:
    return "—" if not math.isfinite(value) else format(value, spec)


def _pct(value: float) -> str:
    return "—" if not math.isfinite(value) else f"{100 * value:.0f} %"


def observed_text(order: OrderRow) -> str:
    """The observed order (``"1.98"``), or ``"not fitted (n runs in the asymptotic range)"``.

    Parameters
    ----------
    order : OrderRow
        One family's order.
    """
    if math.isfinite(order.observed):
        return f"{order.observed:.2f}"
    return not_fitted(order.points)


def _window_text(study: AccuracyStudy) -> str:
    start, stop = study.settings.window
    if start <= 0.0:
        return f"{stop:g} s simulated"
    return (
        f"{stop:g} s simulated from 0 s, errors compared over the window [{start:g}, {stop:g}] s "
        "(the lead-in is the scene's history: no unit starts mid-scene)"
    )


def _plan_lines(study: AccuracyStudy) -> list[str]:
    s = study.settings
    steps = ", ".join(f"{h:g}" for h in s.steps)
    return (
        [
            f"# Accuracy study: {study.scene}" + (" (quick)" if s.quick else ""),
            "",
            f"{sum(r.algorithm != 'monolithic' for r in study.rows)} co-simulation runs of "
            f"{_window_text(study)}; macro steps {steps} s; errors on a grid of "
            f"{s.output_interval:g} s; key outputs {', '.join(map(str, s.key_outputs))}.",
            f"Reference: the monolithic model, Radau at rtol = atol = {s.reference_rtol:g}: "
            f"**{study.reference_wall_per_sim_s:.3g} s per simulated second** (the dash-dotted "
            "line in the diagram; the monolithic model at looser tolerances is the real floor). "
            "The study took "
            f"{study.elapsed:.0f} s.",
            "",
            "Error: for each key output, the largest deviation from the reference over the "
            "compared window divided by that output's range there in the reference; the run's "
            "error is the largest "
            "of these. Cost: wall seconds per simulated second of the stepping phase.",
            "",
        ]
        + [f"**Warning:** {note}." for note in study.notes]
        + ([""] if study.notes else [])
    )


def _order_lines(study: AccuracyStudy) -> list[str]:
    lines = [
        "## Observed convergence orders",
        "",
        "Slope of log error against log macro step over the runs in the asymptotic range: "
        f"the longest stretch of consecutive steps with errors below {ASYMPTOTIC_LIMIT:g}, "
        f"above {DOMINANCE:g} times the solver's own error and the reference's, decreasing "
        f"at every step; fitted on at least {MIN_ASYMPTOTIC_RUNS} runs.",
        "",
        "| family | theory | observed | runs used | steps used (s) |",
        "|---|---:|---:|---:|---|",
    ]
    for o in study.orders:
        theory = "—" if o.theory is None else str(o.theory)
        used = ", ".join(f"{h:g}" for h in o.steps_used) or "—"
        lines.append(f"| {o.family} | {theory} | {observed_text(o)} | {o.points} | {used} |")
    notes = [f"- {o.family}: {o.note}." for o in study.orders if o.note]
    return lines + ([""] + notes if notes else []) + [""]


def _comparison_lines(study: AccuracyStudy) -> list[str]:
    if not study.comparison:
        return ["## Equal-error comparison", "", "No run finished with a usable error.", ""]
    targets = [c.target for c in study.comparison]
    lines = [
        "## Equal-error comparison",
        "",
        "Wall seconds per simulated second each family needs to reach a target error "
        "(interpolated log-log between its runs; — : not reached on this grid).",
        "",
        "| family | " + " | ".join(f"error {t:.0e}" for t in targets) + " |",
        "|---|" + "---:|" * len(targets),
    ]
    for family in study.comparison[0].costs:
        cells = [_fmt(c.costs[family]) for c in study.comparison]
        lines.append(f"| {family} | " + " | ".join(cells) + " |")
    lines += [
        "| **cheapest** | "
        + " | ".join(
            f"{c.cheapest} ({_fmt(c.cheapest_cost)})" if c.cheapest else "—"
            for c in study.comparison
        )
        + " |",
        "",
    ]
    for c in study.comparison:
        if c.cheapest:
            ratio = c.cheapest_cost / study.reference_wall_per_sim_s
            lines.append(
                f"- error {c.target:.0e}: cheapest **{c.cheapest}**, "
                f"{c.cheapest_cost:.3g} s/s ({ratio:.2g} x the monolithic reference's "
                f"cost); {c.reached()} of {len(c.costs)} families reach it."
            )
    return lines + [""]


def _run_lines(study: AccuracyStudy) -> list[str]:
    lines = [
        "## Runs",
        "",
        "| family | H (s) | status | error | worst output | s/s | doStep | FMU calls | "
        "physics | FMI overhead | master |",
        "|---|---:|---|---:|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in study.rows:
        lines.append(
            f"| {r.family} | {_fmt(r.step, 'g')} | {r.status} | {_fmt(r.error, '.2e')} "
            f"| {r.worst_output} | {_fmt(r.wall_per_sim_s)} | {r.do_step_calls} | "
            f"{r.fmu_calls} | {_pct(r.physics_share)} | {_pct(r.fmi_overhead_share)} | "
            f"{_pct(r.master_share)} |"
        )
    failed = [r for r in study.rows if r.status not in ("finished", "skipped")]
    if failed:
        lines += ["", "### Runs that did not finish or blew up", ""]
        lines += [
            f"- {r.family}, H = {r.step:g} s: {r.status}: {r.message or '(no message)'}"
            for r in failed
        ]
    return lines + [""]


def accuracy_markdown(study: AccuracyStudy) -> str:
    """The summary ``accuracy.md``.

    Parameters
    ----------
    study : AccuracyStudy
        The study to summarise.
    """
    files = [
        "",
        "Files: `accuracy.csv` (the table), `accuracy.json`, `work_precision.png`, "
        "`convergence.png`.",
        "",
    ]
    return "\n".join(
        _plan_lines(study)
        + _order_lines(study)
        + _comparison_lines(study)
        + _run_lines(study)
        + files
    )


_DASHES = {"constant": ":", "linear": "-", "quadratic": "--"}
_MARKERS = {"gauss_seidel": "o", "jacobi": "s"}


def _colour_key(row: RunRow) -> str:
    """What a curve's colour tells: the units' solver and, unless held, the coupling."""
    return row.solver if row.coupling == "held" else f"{row.solver} / {row.coupling}"


def _style(study_rows: Sequence[RunRow]):
    keys = list(dict.fromkeys(_colour_key(r) for r in study_rows if r.algorithm != "monolithic"))
    colours = {s: f"C{i % 10}" for i, s in enumerate(keys)}
    return colours, dict(_DASHES), dict(_MARKERS)


def _drawn(rows: Sequence[RunRow]) -> dict[str, set[str]]:
    """What the diagrams draw of ``rows``: solvers, extrapolations, algorithms, monolithic kinds."""
    coupled = [r for r in rows if r.usable and r.algorithm != "monolithic"]
    single = [r for r in rows if r.usable and r.algorithm == "monolithic"]
    return {
        "solver": {_colour_key(r) for r in coupled},
        "extrapolation": {r.extrapolation for r in coupled},
        "algorithm": {r.algorithm for r in coupled},
        "monolithic": {"radau" if r.family == MONOLITHIC_RADAU else "solver" for r in single},
    }


def _legend(ax, colours, dashes, markers, work_precision: bool, rows: Sequence[RunRow]) -> None:
    """The legend of what was run and drawn: no entry for a family the study did not run."""
    from matplotlib.lines import Line2D

    drawn = _drawn(rows)
    handles = [
        Line2D([], [], color=c, lw=2, label=s) for s, c in colours.items() if s in drawn["solver"]
    ]
    handles += [
        Line2D([], [], color="0.3", ls=d, label=e)
        for e, d in dashes.items()
        if e in drawn["extrapolation"]
    ]
    handles += [
        Line2D([], [], color="0.3", ls="", marker=m, label=a)
        for a, m in markers.items()
        if a in drawn["algorithm"]
    ]
    if work_precision:
        if "radau" in drawn["monolithic"]:
            handles.append(
                Line2D([], [], color="k", marker="D", ms=4, label="monolithic, Radau rtol")
            )
        if "solver" in drawn["monolithic"]:
            handles.append(
                Line2D(
                    [],
                    [],
                    color="w",
                    ls="",
                    marker="*",
                    ms=11,
                    mec="k",
                    label="monolithic, unit solver",
                )
            )
        handles.append(Line2D([], [], color="k", ls="-.", lw=1, label="monolithic reference"))
    elif "solver" in drawn["monolithic"]:
        handles.append(
            Line2D(
                [],
                [],
                color="0.3",
                ls=(0, (1, 3)),
                label="solver's own error\n(monolithic, same solver)",
            )
        )
    ax.legend(
        handles=handles,
        loc="center left",
        bbox_to_anchor=(1.01, 0.5),
        fontsize="small",
        frameon=False,
    )


def _figure(title: str, xlabel: str, ylabel: str):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 6), dpi=110, layout="constrained")
    ax = fig.add_subplot()
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.25)
    return fig, ax


def _plot_families(ax, study: AccuracyStudy, x_of, y_of, work_precision: bool) -> None:
    colours, dashes, markers = _style(study.rows)
    labelled = False
    for runs in _families(study.rows).values():
        ok = [r for r in runs if r.usable]
        if not ok:
            continue
        first = ok[0]
        if first.family == MONOLITHIC_RADAU:
            ax.plot([x_of(r) for r in ok], [y_of(r) for r in ok], color="k", marker="D", ms=4)
            continue
        if first.algorithm == "monolithic":
            ax.plot(
                [x_of(first)],
                [y_of(first)],
                ls="",
                marker="*",
                ms=11,
                mec="k",
                color=colours.get(first.solver, "k"),
            )
            continue
        ax.plot(
            [x_of(r) for r in ok],
            [y_of(r) for r in ok],
            color=colours[_colour_key(first)],
            ls=dashes[first.extrapolation],
            marker=markers[first.algorithm],
            ms=4,
            lw=1.2,
        )
        if work_precision and not labelled:
            for r in ok:
                ax.annotate(
                    f"H={r.step:g}",
                    (x_of(r), y_of(r)),
                    fontsize="x-small",
                    textcoords="offset points",
                    xytext=(4, 4),
                )
            labelled = True
    _legend(ax, colours, dashes, markers, work_precision, study.rows)


def plot_work_precision(study: AccuracyStudy, path: Path) -> Path:
    """The work-precision diagram: error (x) against wall s per simulated s (y), log-log.

    Parameters
    ----------
    study : AccuracyStudy
        The study to draw.
    path : Path
        PNG file to write (its folder must exist).
    """
    fig, ax = _figure(
        f"{study.scene}: what accuracy costs",
        "error (max over key outputs of max |y - y_ref| / range of y_ref)",
        "wall time per simulated second (s/s)",
    )
    _plot_families(ax, study, lambda r: r.error, lambda r: r.wall_per_sim_s, work_precision=True)
    floor = study.reference_wall_per_sim_s
    ax.axhline(floor, color="k", ls="-.", lw=1)
    ax.annotate(
        f"monolithic reference, Radau rtol {study.settings.reference_rtol:g}: {floor:.3g} s/s",
        (0.01, floor),
        xycoords=("axes fraction", "data"),
        fontsize="small",
        textcoords="offset points",
        xytext=(0, 4),
    )
    log_ticks(ax)
    fig.savefig(path)
    return path


def plot_convergence(study: AccuracyStudy, path: Path) -> Path:
    """Error against macro step for every family, with slope-1 and slope-2 guides.

    Parameters
    ----------
    study : AccuracyStudy
        The study to draw.
    path : Path
        PNG file to write (its folder must exist).
    """
    fig, ax = _figure(f"{study.scene}: convergence in the macro step", "macro step H (s)", "error")
    rows = [r for r in study.rows if r.algorithm != "monolithic"]
    _plot_families(
        ax, replace(study, rows=rows), lambda r: r.step, lambda r: r.error, work_precision=False
    )
    colours = _style(study.rows)[0]
    for r in study.rows:
        if r.algorithm == "monolithic" and r.family != MONOLITHIC_RADAU and r.usable:
            ax.axhline(r.error, color=colours.get(r.solver, "k"), ls=(0, (1, 3)), lw=1)
    usable = [r for r in rows if r.usable]
    if usable:
        h = np.array(sorted({r.step for r in usable}))
        anchor = max(r.error for r in usable if r.step == h[-1])
        for order, ls in ((1, (0, (6, 3))), (2, (0, (2, 2)))):
            ax.plot(h, anchor * (h / h[-1]) ** order, color="0.5", ls=ls, lw=1)
            ax.annotate(
                f"order {order}",
                (h[0], anchor * (h[0] / h[-1]) ** order),
                fontsize="small",
                color="0.4",
            )
    log_ticks(ax)
    fig.savefig(path)
    return path


def write_accuracy_files(study: AccuracyStudy, directory: Path) -> dict[str, Path]:
    """Write the table, the summary, the JSON and both diagrams; return their paths.

    Parameters
    ----------
    study : AccuracyStudy
        The study to write.
    directory : Path
        Folder for the files (created).
    """
    data = {
        "scene": study.scene,
        "settings": study.settings,
        "elapsed_s": study.elapsed,
        "reference_wall_per_sim_s": study.reference_wall_per_sim_s,
        "window_s": study.settings.window,
        "notes": study.notes,
        "orders": study.orders,
        "equal_error": study.comparison,
        "runs": study.rows,
    }
    files = write_tables(directory, "accuracy", study.rows, accuracy_markdown(study), data)
    files["work_precision"] = plot_work_precision(study, directory / "work_precision.png")
    files["convergence"] = plot_convergence(study, directory / "convergence.png")
    return files
