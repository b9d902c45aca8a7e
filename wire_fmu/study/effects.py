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
deviation over the study's window divided by the output's range in the
baseline (a quick study's window is the scene's ``quick_window``, see
:mod:`wire_fmu.study.window`). It writes ``effects.csv``, ``effects.md``
and ``effects.png`` (time saved and output change side by side): the price
list behind "simulate only the effects a scene calls for"
(:mod:`wire_fmu.study.effects_report`).

A change is only ever relative to something that moves: a key output that
is not a physical quantity is refused, and one that does not move in the
baseline's window (swing zero or not above :func:`~wire_fmu.study.key_outputs.still_tolerance`
of its magnitude, or not finite) is left out with a warning; if none
moves, the study refuses (:mod:`wire_fmu.study.key_outputs`). A run
without an effect whose key outputs are not finite numbers is
``diverged``, with no change.

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

import numpy as np

from wire_fmu.core.framework.effects import EffectCatalogue
from wire_fmu.master.run import with_run_settings
from wire_fmu.master.scene import Scene
from wire_fmu.master.validate import validate_scene
from wire_fmu.registry import BY_NAME, UNIT_TYPES

from .effects_report import (
    change_text,
    effects_markdown,
    plot_effects,
    summary_text,
    write_effects_files,
)
from .key_outputs import check_physical, moving_key_outputs, still_tolerance
from .measures import Comparison, one_line
from .plan import StudyError, StudyOptions, StudySettings
from .timing import StudyProgress, TimedRun, fastest_run, pinned
from .window import first_sample

__all__ = [
    "EFFECT_CATALOGUES",
    "EffectCase",
    "EffectRow",
    "EffectsStudy",
    "effect_cases",
    "catalogue",
    "run_effects_study",
    "change_text",
    "effects_markdown",
    "plot_effects",
    "write_effects_files",
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
    window: tuple[float, float] = (0.0, 0.0)
    """The compared window, s (runs start at 0 s and end at its end)."""
    notes: list[str] = field(default_factory=list)
    """Warnings about what the changes leave out (key outputs still in the baseline)."""


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


def _failed_row(case: EffectCase, status: str, base_cost: float, message: str) -> EffectRow:
    return EffectRow(
        case.unit,
        case.effect,
        " ".join(case.also_removed),
        status,
        math.nan,
        base_cost,
        math.nan,
        math.nan,
        "—",
        math.nan,
        "",
        math.nan,
        math.nan,
        one_line(message),
    )


def _effect_row(
    case: EffectCase,
    run: TimedRun,
    spread: float,
    baseline: TimedRun,
    baseline_spread: float,
    comparison: Comparison,
) -> EffectRow:
    base_cost = baseline.timing.per_simulated_second
    if run.status != "finished":
        return _failed_row(case, run.status, base_cost, run.message)
    change, worst = comparison.error(run.columns)
    if math.isnan(change):
        return _failed_row(case, "failed", base_cost, f"no change to report: {worst}")
    if not math.isfinite(change):
        return _failed_row(
            case,
            "diverged",
            base_cost,
            f"without it, {worst} is not a finite number in the window: no change to report",
        )
    cost = run.timing.per_simulated_second
    noise = max(spread, baseline_spread) if math.isfinite(spread + baseline_spread) else math.nan
    saved = base_cost - cost
    return EffectRow(
        case.unit,
        case.effect,
        " ".join(case.also_removed),
        "finished",
        cost,
        base_cost,
        saved,
        saved / base_cost if base_cost > 0.0 else math.nan,
        verdict(saved, noise),
        change,
        worst,
        spread,
        run.timing.shares()[0],
    )


def _baseline_comparison(
    name: str, baseline: TimedRun, settings: StudySettings, stop: float
) -> tuple[Comparison, list[str]]:
    """What the runs without an effect are compared with: the baseline's moving key outputs."""
    if baseline.status != "finished":
        raise StudyError(
            f"scene {name!r}: the run with all its effects did not "
            f"finish ({baseline.status}): {baseline.message}"
        )
    window = (settings.window_start, stop)
    first = first_sample(baseline.columns.get("time", np.zeros(0)), settings.window_start)
    moving, notes = moving_key_outputs(
        name,
        baseline.columns,
        settings.key_outputs,
        window,
        first,
        still_tolerance(settings.reference_rtol),
        source="run with every effect",
    )
    return Comparison(baseline.columns, tuple(map(str, moving)), first), notes


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
        If a key output is not a physical quantity, if the run with every
        effect does not finish, or if no key output moves in its window.
    """
    started = time.perf_counter()
    opts = StudyOptions(**options)
    scene, settings = opts.prepare(scene)
    repeats = opts.repeats or (QUICK_REPEATS if settings.quick else FULL_REPEATS)
    base = effects_scene(scene, settings)
    cases = effect_cases(base)
    report = StudyProgress(len(cases) + 1, opts.stream, opts.progress)
    window = (settings.window_start, base.run.stop_time)
    report.note(
        f"effects of {scene.name!r}: {len(cases)} effects, {repeats} run(s) each of "
        f"{base.run.stop_time:g} s at H = {base.run.step:g} s, changes over "
        f"[{window[0]:g}, {window[1]:g}] s"
    )
    rows = []
    with tempfile.TemporaryDirectory(prefix="wire_fmu_effects_") as tmp:
        structure = pinned(validate_scene(base, opts.fmu_dir), Path(tmp))
        check_physical(scene.name, settings.key_outputs, structure.variable)
        baseline, spread = fastest_run(base, structure, Path(tmp) / "run", repeats)
        report.advance(
            f"all effects: {baseline.status}, {baseline.timing.per_simulated_second:.3g} s/s"
        )
        comparison, notes = _baseline_comparison(scene.name, baseline, settings, window[1])
        for case in cases:
            run, case_spread = fastest_run(
                without(base, case), structure, Path(tmp) / "run", repeats
            )
            rows.append(_effect_row(case, run, case_spread, baseline, spread, comparison))
            report.advance(_describe(rows[-1]))
    moving = tuple(k for k in settings.key_outputs if str(k) in comparison.keys)
    study = EffectsStudy(
        scene.name,
        replace(settings, key_outputs=moving),
        base.run.step,
        repeats,
        baseline.timing.per_simulated_second,
        spread,
        rows,
        window=window,
        notes=notes,
    )
    study.elapsed = time.perf_counter() - started
    study.files = write_effects_files(study, Path(output_dir))
    return study


def _describe(row: EffectRow) -> str:
    if row.status != "finished":
        return f"without {row.label}: {row.status} {row.message[:80]}"
    return (
        f"without {row.label}: {row.wall_per_sim_s:.3g} s/s (saves "
        f"{100 * row.saved_share:.0f} %), outputs change {change_text(row)}"
    )
