"""The price list of effects: what leaving each one out saves, and what it changes.

``wire-fmu study effects SCENE`` runs the scene as it is (every effect its
units include: the *baseline*) and then, for each effect of each unit of
ours, once without that effect and without the effects that require it
(``bearing_friction`` needs ``sheave_inertia``, so leaving out the sheaves'
inertia leaves out their friction too). All runs use the scene's own
coupling, macro step and internal solvers, the study's stop time and key
outputs (``[study]`` table, see :mod:`wire_fmu.study.accuracy`).

Per effect it reports the time saved (wall seconds per simulated second,
and as a share of the baseline's) and the change in the key outputs, with
the accuracy study's metric taken against the baseline: the largest
deviation over the run divided by the output's range in the baseline. It
writes ``effects.csv``, ``effects.md`` and ``effects.png`` (time saved and
output change side by side): the price list behind "simulate only the
effects a scene calls for".

Timing is the minimum over ``repeats`` runs of each case (the machine is
shared and only ever slows a run down); a negative saving smaller than the
spread between repeats is noise.
"""

from __future__ import annotations

import logging
import math
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import MappingProxyType
from typing import Any

from wire_fmu.core.framework.effects import EffectCatalogue
from wire_fmu.master.run import with_run_settings
from wire_fmu.master.scene import Scene
from wire_fmu.master.validate import validate_scene
from wire_fmu.registry import BY_NAME, UNIT_TYPES

from .measures import one_line, output_error
from .plan import StudyError, StudyOptions, StudySettings
from .tables import write_tables
from .timing import StudyProgress, TimedRun, fastest_run, pinned

__all__ = [
    "EFFECT_CATALOGUES",
    "EffectCase",
    "EffectRow",
    "EffectsStudy",
    "effect_cases",
    "catalogue",
    "run_effects_study",
    "effects_markdown",
    "summary_text",
    "verdict",
    "without",
]

logger = logging.getLogger(__name__)

EFFECT_CATALOGUES = MappingProxyType({u.name: u.effects for u in UNIT_TYPES if u.effects})
"""Model name -> its :class:`~wire_fmu.core.framework.effects.EffectCatalogue` (module:name),
from :mod:`wire_fmu.registry`."""

QUICK_REPEATS, FULL_REPEATS = 1, 3


def catalogue(fmu: str) -> EffectCatalogue | None:
    """The effect catalogue of one of our models (None for a foreign FMU).

    Parameters
    ----------
    fmu : str
        Model name of a scene's unit, e.g. ``"BlockTrain"``.
    """
    return BY_NAME[fmu].effect_catalogue() if fmu in BY_NAME else None


def _requiring(cat: EffectCatalogue | None, effect: str, present: Sequence[str]) -> list[str]:
    """Effects in ``present`` that need ``effect``, directly or through others."""
    if cat is None:
        return []
    needs = {e.name: set(e.requires) for e in cat.effects}
    gone, changed = {effect}, True
    while changed:
        changed = False
        for name in present:
            if name not in gone and needs.get(name, set()) & gone:
                gone.add(name)
                changed = True
    return [n for n in present if n in gone and n != effect]


@dataclass(frozen=True)
class EffectCase:
    """One effect of one unit left out (with the effects that need it)."""

    unit: str
    effect: str
    also_removed: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """``"rope: sheave_inertia (+ bearing_friction)"``."""
        extra = f" (+ {', '.join(self.also_removed)})" if self.also_removed else ""
        return f"{self.unit}: {self.effect}{extra}"


def effect_cases(scene: Scene) -> list[EffectCase]:
    """Every effect the scene's units include, in scene order.

    Parameters
    ----------
    scene : Scene
        The scene with every effect (the baseline).
    """
    cases = []
    for name, spec in scene.units.items():
        cat = catalogue(spec.fmu)
        for effect in spec.effects:
            cases.append(EffectCase(name, effect, tuple(_requiring(cat, effect, spec.effects))))
    return cases


def without(scene: Scene, case: EffectCase) -> Scene:
    """``scene`` with ``case``'s effects removed from its unit.

    Parameters
    ----------
    scene : Scene
        The baseline scene (not changed).
    case : EffectCase
        The unit and the effects to leave out.
    """
    spec = scene.units[case.unit]
    gone = {case.effect, *case.also_removed}
    units = dict(scene.units)
    units[case.unit] = replace(spec, effects=tuple(e for e in spec.effects if e not in gone))
    return replace(scene, units=units)


@dataclass
class EffectRow:
    """One row of ``effects.csv``."""

    unit: str
    effect: str
    also_removed: str
    status: str
    wall_per_sim_s: float
    baseline_wall_per_sim_s: float
    saved_per_sim_s: float
    saved_share: float
    time_verdict: str
    output_change: float
    worst_output: str
    spread_per_sim_s: float
    physics_share: float
    message: str = ""

    @property
    def label(self) -> str:
        """Short label for tables and charts."""
        return EffectCase(
            self.unit, self.effect, tuple(self.also_removed.split()) if self.also_removed else ()
        ).label


@dataclass
class EffectsStudy:
    """Everything an effects study produced."""

    scene: str
    settings: StudySettings
    step: float
    repeats: int
    baseline_wall_per_sim_s: float
    baseline_spread: float
    rows: list[EffectRow]
    files: dict[str, Path] = field(default_factory=dict)
    elapsed: float = 0.0


# ------------------------------------------------------------------------- runs
def effects_scene(scene: Scene, settings: StudySettings) -> Scene:
    """The scene at its own step, for the study's stop time, recording the key outputs.

    The output grid is the study's interval rounded up to a multiple of the
    scene's macro step.

    Parameters
    ----------
    scene : Scene
        The scene as given.
    settings : StudySettings
        Key outputs, stop time (s) and output interval (s) of the study.
    """
    step = scene.run.step
    interval = step * max(1, math.ceil(settings.output_interval / step - 1e-9))
    stop = interval * max(1, math.floor(settings.stop_time / interval + 1e-9))
    scene = with_run_settings(scene, stop_time=stop, output_interval=interval)
    return replace(scene, outputs=settings.key_outputs)


def verdict(saved: float, noise: float) -> str:
    """``"saves"``, ``"costs"`` or ``"within noise"`` (``|saved| <= noise``), s per simulated s.

    Parameters
    ----------
    saved : float
        Wall time saved per simulated second, s/s (negative: it costs).
    noise : float
        Spread between repeats, s/s; NaN when a case ran once: the verdict
        then says so.
    """
    if not math.isfinite(saved):
        return "—"
    word = "saves" if saved > 0 else "costs"
    if not math.isfinite(noise):
        return f"{word} (one run: noise unknown)"
    return "within noise" if abs(saved) <= noise else word


def _effect_row(
    case: EffectCase,
    run: TimedRun,
    spread: float,
    baseline: TimedRun,
    baseline_spread: float,
    keys: Sequence[str],
) -> EffectRow:
    base_cost = baseline.timing.per_simulated_second
    also = " ".join(case.also_removed)
    if run.status != "finished":
        return EffectRow(
            case.unit,
            case.effect,
            also,
            run.status,
            math.nan,
            base_cost,
            math.nan,
            math.nan,
            "—",
            math.nan,
            "",
            math.nan,
            math.nan,
            one_line(run.message),
        )
    cost = run.timing.per_simulated_second
    change, worst = output_error(run.columns, baseline.columns, keys)
    noise = max(spread, baseline_spread) if math.isfinite(spread + baseline_spread) else math.nan
    return EffectRow(
        case.unit,
        case.effect,
        also,
        "finished",
        cost,
        base_cost,
        base_cost - cost,
        (base_cost - cost) / base_cost,
        verdict(base_cost - cost, noise),
        change,
        worst,
        spread,
        run.timing.shares()[0],
    )


def run_effects_study(scene: Scene | str | Path, output_dir: Path, **options: Any) -> EffectsStudy:
    """Run the effects study of ``scene`` and write its files into ``output_dir``.

    Parameters
    ----------
    scene : Scene, str or Path
        A parsed scene, a shipped scene's name or a scene file.
    output_dir : Path
        Folder for ``effects.csv``, ``effects.md`` and ``effects.png``.
    **options
        How the study runs, the fields of
        :class:`~wire_fmu.study.plan.StudyOptions`: ``quick`` (short stop
        time and one run per case), ``settings`` (key outputs and stop time
        of one's own), ``repeats`` (runs per case, the fastest counts;
        default 1 quick, 3 full), ``stop_time``, ``fmu_dir``, ``progress``,
        ``stream``.

    Raises
    ------
    StudyError
        If the run with every effect does not finish.
    """
    started = time.perf_counter()
    opts = StudyOptions(**options)
    scene, settings = opts.prepare(scene)
    repeats = opts.repeats or (QUICK_REPEATS if settings.quick else FULL_REPEATS)
    base = effects_scene(scene, settings)
    cases = effect_cases(base)
    report = StudyProgress(len(cases) + 1, opts.stream, opts.progress)
    report.note(
        f"effects of {scene.name!r}: {len(cases)} effects, {repeats} run(s) each of "
        f"{base.run.stop_time:g} s at H = {base.run.step:g} s"
    )
    rows = []
    keys = [str(k) for k in settings.key_outputs]
    with tempfile.TemporaryDirectory(prefix="wire_fmu_effects_") as tmp:
        structure = pinned(validate_scene(base, opts.fmu_dir), Path(tmp))
        baseline, spread = fastest_run(base, structure, Path(tmp) / "run", repeats)
        report.advance(
            f"all effects: {baseline.status}, {baseline.timing.per_simulated_second:.3g} s/s"
        )
        if baseline.status != "finished":
            raise StudyError(
                f"scene {scene.name!r}: the run with all its effects did not "
                f"finish ({baseline.status}): {baseline.message}"
            )
        for case in cases:
            run, case_spread = fastest_run(
                without(base, case), structure, Path(tmp) / "run", repeats
            )
            rows.append(_effect_row(case, run, case_spread, baseline, spread, keys))
            report.advance(_describe(rows[-1]))
    study = EffectsStudy(
        scene.name,
        settings,
        base.run.step,
        repeats,
        baseline.timing.per_simulated_second,
        spread,
        rows,
    )
    study.elapsed = time.perf_counter() - started
    study.files = write_effects_files(study, Path(output_dir))
    return study


def _describe(row: EffectRow) -> str:
    if row.status != "finished":
        return f"without {row.label}: {row.status} {row.message[:80]}"
    return (
        f"without {row.label}: {row.wall_per_sim_s:.3g} s/s (saves "
        f"{100 * row.saved_share:.0f} %), outputs change {row.output_change:.2e}"
    )


# ---------------------------------------------------------------------- reports
def _fmt(value: float, spec: str = ".3g") -> str:
    return "—" if not math.isfinite(value) else format(value, spec)


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
        f"coupling and step H = {study.step:g} s, {s.stop_time:g} s simulated, fastest of "
        f"{study.repeats} run(s). With every effect: **{study.baseline_wall_per_sim_s:.3g} s "
        f"per simulated second** (spread {_fmt(study.baseline_spread)} s/s).",
        "",
        "Output change: the largest deviation of a key output from the run with every "
        f"effect, over its range there ({', '.join(map(str, s.key_outputs))}).",
        "",
        "| left out | s/s without | saved s/s | saved | time | output change | worst output | "
        "spread s/s | status |",
        "|---|---:|---:|---:|---|---:|---|---:|---|",
    ]
    for r in study.rows:
        lines.append(
            f"| {r.label} | {_fmt(r.wall_per_sim_s)} | {_fmt(r.saved_per_sim_s)} | "
            f"{_fmt(100 * r.saved_share, '.0f')} % | {r.time_verdict} | "
            f"{_fmt(r.output_change, '.2e')} | {r.worst_output} | "
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
    right.barh(list(y), [max(r.output_change, 1e-16) for r in rows], color="C3")
    right.set_xscale("log")
    right.set_xlabel("change in key outputs (max |dy| / range)")
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
    lines = [
        f"effects of {study.scene!r}: all effects {study.baseline_wall_per_sim_s:.3g} s "
        "per simulated s"
    ]
    width = max((len(r.label) for r in study.rows), default=10)
    for r in study.rows:
        lines.append(
            f"  without {r.label:<{width}}  saves {_fmt(r.saved_per_sim_s):>6} s/s "
            f"({_fmt(100 * r.saved_share, '.0f'):>3} %, {r.time_verdict})  outputs "
            f"change {_fmt(r.output_change, '.2e')}  [{r.status}]"
        )
    if not study.rows:
        lines.append("  the scene's units include no effect")
    return "\n".join(lines)
