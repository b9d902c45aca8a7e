"""The effects study's files: table, summary, JSON and chart, and its text for the command line.

See :mod:`wire_fmu.study.effects` for what the study measures.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from .log_ticks import log_ticks
from .tables import write_tables

if TYPE_CHECKING:
    from .effects import EffectRow, EffectsStudy

__all__ = [
    "change_text",
    "effects_markdown",
    "plot_effects",
    "write_effects_files",
    "summary_text",
]


def _fmt(value: float, spec: str = ".3g") -> str:
    return "—" if not math.isfinite(value) else format(value, spec)


def change_text(row: EffectRow) -> str:
    """The output change (``"2.70e-02"``), or why there is none.

    Parameters
    ----------
    row : EffectRow
        One effect left out.
    """
    if math.isfinite(row.output_change):
        return f"{row.output_change:.2e}"
    return f"none ({row.status})"


def _window_text(study: EffectsStudy) -> str:
    start, stop = study.window
    if start <= 0.0:
        return f"{stop:g} s simulated"
    return f"{stop:g} s simulated from 0 s, changes over the window [{start:g}, {stop:g}] s"


def effects_markdown(study: EffectsStudy) -> str:
    """The summary ``effects.md``.

    Parameters
    ----------
    study : EffectsStudy
        The study to summarise.
    """
    s = study.settings
    lines = [
        f"# Effects study: {study.scene}" + (" (quick)" if s.quick else ""),
        "",
        f"Each effect left out in turn (with the effects that need it), at the scene's own "
        f"coupling and step H = {study.step:g} s, {_window_text(study)}, fastest of "
        f"{study.repeats} run(s). With every effect: **{study.baseline_wall_per_sim_s:.3g} s "
        f"per simulated second** (spread {_fmt(study.baseline_spread)} s/s).",
        "",
        "Output change: the largest deviation of a key output from the run with every "
        f"effect, over its range there ({', '.join(map(str, s.key_outputs))}).",
        "",
        *(f"**Warning:** {note}." for note in study.notes),
        *([""] if study.notes else []),
        "| left out | s/s without | saved s/s | saved | time | output change | worst output | "
        "spread s/s | status |",
        "|---|---:|---:|---:|---|---:|---|---:|---|",
    ]
    for r in study.rows:
        lines.append(
            f"| {r.label} | {_fmt(r.wall_per_sim_s)} | {_fmt(r.saved_per_sim_s)} | "
            f"{_fmt(100 * r.saved_share, '.0f')} % | {r.time_verdict} | "
            f"{change_text(r)} | {r.worst_output} | "
            f"{_fmt(r.spread_per_sim_s)} | {r.status} |"
        )
    if not study.rows:
        lines.append("| (the scene's units include no effect) | | | | | | | | |")
    lines += [
        "",
        "Time: *within noise* when the saving is no larger than the spread between "
        "repeats (of this case or of the run with every effect).",
    ]
    lines += ["", f"The study took {study.elapsed:.0f} s. Files: `effects.csv`, `effects.png`.", ""]
    return "\n".join(lines)


def plot_effects(study: EffectsStudy, path: Path) -> Path:
    """Bar chart: time saved (share of the baseline) and output change, per effect.

    Parameters
    ----------
    study : EffectsStudy
        The study to draw.
    path : Path
        PNG file to write (its folder must exist).
    """
    from matplotlib.figure import Figure

    rows = [r for r in study.rows if r.status == "finished"]
    fig = Figure(figsize=(10, 1.2 + 0.45 * max(len(rows), 1)), dpi=110, layout="constrained")
    left, right = fig.subplots(1, 2, sharey=True)
    labels = [r.label for r in rows]
    y = range(len(rows))
    left.barh(list(y), [100 * r.saved_share for r in rows], color="C0")
    left.set_xlabel("time saved (% of wall time per simulated second)")
    left.axvline(0.0, color="k", lw=0.8)
    changed = [(i, r.output_change) for i, r in enumerate(rows) if r.output_change > 0.0]
    right.barh([i for i, _ in changed], [c for _, c in changed], color="C3")
    right.set_xscale("log")
    if not changed:
        right.set_xlim(1e-16, 1.0)
    right.set_xlabel("change in key outputs (max |dy| / range)")
    log_ticks(right, y=False, most=6)
    for i, r in enumerate(rows):
        if not r.output_change > 0.0:  # none at all: no bar on a log axis, say so
            right.annotate("no change", (0.02, i), xycoords=("axes fraction", "data"), va="center")
    left.set_yticks(list(y), labels)
    left.invert_yaxis()
    for ax in (left, right):
        ax.grid(True, axis="x", alpha=0.3)
    fig.suptitle(
        f"{study.scene}: leaving effects out (all effects: {study.baseline_wall_per_sim_s:.3g} s/s)"
    )
    fig.savefig(path)
    return path


def write_effects_files(study: EffectsStudy, directory: Path) -> dict[str, Path]:
    """Write the table, the summary, the JSON and the chart; return their paths.

    Parameters
    ----------
    study : EffectsStudy
        The study to write.
    directory : Path
        Folder for the files (created).
    """
    files = write_tables(directory, "effects", study.rows, effects_markdown(study), study)
    files["png"] = plot_effects(study, directory / "effects.png")
    return files


def summary_text(study: EffectsStudy) -> str:
    """The price list as plain text (for the command line).

    Parameters
    ----------
    study : EffectsStudy
        What :func:`run_effects_study` produced.
    """
    start, stop = study.window
    lines = [f"warning: {note}" for note in study.notes]
    lines.append(
        f"effects of {study.scene!r}: all effects {study.baseline_wall_per_sim_s:.3g} s "
        f"per simulated s; output changes over [{start:g}, {stop:g}] s"
    )
    width = max((len(r.label) for r in study.rows), default=10)
    for r in study.rows:
        lines.append(
            f"  without {r.label:<{width}}  saves {_fmt(r.saved_per_sim_s):>6} s/s "
            f"({_fmt(100 * r.saved_share, '.0f'):>3} %, {r.time_verdict})  outputs "
            f"change {change_text(r)}  [{r.status}]"
        )
    if not study.rows:
        lines.append("  the scene's units include no effect")
    return "\n".join(lines)
