"""What accuracy costs in time: work-precision study of a scene (SPEC section 16).

``wire-fmu study accuracy SCENE`` runs the scene with the master over a grid
of configurations,

    coupling algorithm (jacobi, gauss_seidel)
    x extrapolation (constant, linear, quadratic)
    x macro step (a geometric series H_max / 2^k)
    x internal solver of the units (its method, tolerance or internal step),

compares each run's key outputs with the monolithic reference (the same core
units as one ODE, Radau at rtol 1e-10, :mod:`wire_fmu.study.monolithic`),
and writes

``accuracy.csv``
    one row per run: error, wall time per simulated second, FMU calls and
    the share of the wall time spent in the physics (inside the core units'
    ``advance``), in the FMI layers around it, and in the master itself;
``accuracy.md``
    the observed convergence order of every family next to the theory, the
    equal-error comparison and the table;
``accuracy.json``
    the same figures for programs;
``work_precision.png``
    error against wall time per simulated second, log-log, one curve per
    family along its macro-step series, the monolithic solver's own curve
    and the reference's cost as a horizontal line (the speed floor);
``convergence.png``
    error against macro step with slope-1 and slope-2 guides.

Error metric
------------
Outputs are compared on a common grid of spacing ``output_interval`` (a
multiple of every macro step, so each recorded row is a step end). For each
key output ``k``::

    e_k = max_t |y_k(t) - y_ref_k(t)| / range_k,
    range_k = max(max_t y_ref_k - min_t y_ref_k, 1e-6 max_t |y_ref_k|)

over the samples of the study's window (from 0 s to the stop time; a quick
study's window may start later, :mod:`~wire_fmu.study.window`), and the
run's error is ``max_k e_k`` (the key output that sets it is recorded). A
run that stops early (a refused step, a unit failure, a blow-up to
non-finite numbers) has no error: it is recorded with its status and
message and left out of the fits and plots.

A study that cannot say anything refuses (:mod:`~wire_fmu.study.key_outputs`):
a key output that is not a physical quantity (a count, a flag, a state), or
key outputs none of which moves in the window of the reference; a key output
that does not move while others do is left out of the errors, with a
warning in the summary.

Families, orders, equal error
-----------------------------
A *family* is one (algorithm, extrapolation, solver); its runs differ only
in the macro step. The observed order is the least-squares slope of
``log e`` against ``log H`` over the family's runs in the asymptotic range
(:mod:`~wire_fmu.study.orders`): the longest stretch of consecutive steps
whose errors are at most :data:`ASYMPTOTIC_LIMIT`, above :data:`DOMINANCE`
times the solver's floor (the monolithic model solved with that solver: its
own integration error) and the reference's own error, and decrease at every
step; with fewer than three such runs no order is fitted. Theory (SPEC section 15): a held effort or
signal converges at order 1 held constant and at order 2 held at the
midpoint of a linear (or the step average of a quadratic) extrapolant; a
flow that a unit integrates into a position handed over exactly at each
step start (a bond's ``position`` link) is second order even held
constant. Configurations are compared at equal achieved error, never at
equal tolerance: for each target error the cost of every family is
interpolated (log-log, between the two runs that bracket the target) and
the cheapest configuration named.

Timing
------
Wall time is measured from the end of initialisation to the end of the
run. Physics time is the time spent inside the units' ``advance``, as each
FMU of ours counts it in its local variable ``physics_seconds``, read
through FMI at the end of the run (unknown for a run that failed); FMI time
is the time the master spends in FMI calls (:attr:`Slave.seconds`); FMI
overhead is FMI time minus physics; the master is the rest. The machine
is shared: repeat a study before trusting a 20 % difference in cost.

The study's pieces
------------------
:mod:`~wire_fmu.study.plan` (settings, grid, run options),
:mod:`~wire_fmu.study.solvers` (the units' solver choices),
:mod:`~wire_fmu.study.timing` (timed runs), :mod:`~wire_fmu.study.measures`
(the error metric and the rows), :mod:`~wire_fmu.study.orders` (orders and
equal error), :mod:`~wire_fmu.study.window` (the compared window),
:mod:`~wire_fmu.study.key_outputs` (physical, moving key outputs),
:mod:`~wire_fmu.study.accuracy_report` (the files); this module runs the
study.
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, TextIO

from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.hybrid import SOLVERS as HYBRID_SOLVERS
from wire_fmu.core.framework.hybrid import IntegrationError
from wire_fmu.master.scene import Scene, SceneError
from wire_fmu.master.validate import Structure, validate_scene

from .accuracy_report import AccuracyStudy, observed_text, write_accuracy_files
from .key_outputs import check_physical, moving_key_outputs, still_tolerance
from .measures import (
    MONOLITHIC_RADAU,
    Comparison,
    RunRow,
    _monolithic_row,
    _row,
    _skipped,
    one_line,
)
from .monolithic import MonolithicResult, run_monolithic
from .orders import default_targets, equal_error, observed_orders
from .plan import (
    GRIDS,
    Configuration,
    StudyError,
    StudyOptions,
    StudySettings,
    build_grid,
    configured_scene,
    parse_couplings,
    solver_choices,
    study_scene,
)
from .solvers import SolverChoice
from .timing import StudyProgress, fastest_run, pinned
from .window import first_sample

__all__ = ["REFERENCE_MARGIN", "reference_run", "run_accuracy_study", "summary_text"]

REFERENCE_MARGIN = 100.0
"""Errors below this many times the reference's tolerance are the reference's own."""


# ------------------------------------------------------------------ reference
def reference_run(
    scene: Scene, settings: StudySettings, rtol: float | None = None
) -> MonolithicResult:
    """The monolithic model of a study scene on the study's output grid.

    Parameters
    ----------
    scene : Scene
        A study scene (see :func:`~wire_fmu.study.plan.study_scene`), every
        unit one of ours.
    settings : StudySettings
        The plan: its output interval (s) and reference tolerance.
    rtol : float, optional
        Relative and absolute tolerance of Radau instead of the plan's
        ``reference_rtol``.

    Raises
    ------
    StudyError
        If the scene cannot be assembled into one ODE (a foreign FMU, a unit
        without an ODE view), saying which, or if its integration fails.
    """
    tol = settings.reference_rtol if rtol is None else rtol
    try:
        return run_monolithic(scene, rtol=tol, atol=tol, output_interval=settings.output_interval)
    except NotImplementedError as exc:
        raise StudyError(
            f"scene {scene.name!r}: no monolithic reference: {exc} (its core "
            "unit offers no ode() view yet)"
        ) from None
    except SceneError as exc:
        raise StudyError(f"scene {scene.name!r}: no monolithic reference: {exc}") from None
    except (IntegrationError, ModelError, FloatingPointError, ValueError) as exc:
        raise StudyError(
            f"scene {scene.name!r}: the monolithic reference (Radau, rtol "
            f"{tol:g}) failed: {type(exc).__name__}: {exc}"
        ) from None


def _describe(row: RunRow) -> str:
    where = f"{row.family} H={row.step:g}" if math.isfinite(row.step) else row.family
    if row.status == "finished":
        return f"{where}: error {row.error:.2e}, {row.wall_per_sim_s:.3g} s/s"
    return f"{where}: {row.status} {row.message[:80]}"


def _run_grid(
    scene: Scene,
    structure: Structure,
    grid: Sequence[Configuration],
    comparison: Comparison,
    settings: StudySettings,
    workdir: Path,
    progress: StudyProgress,
) -> list[RunRow]:
    rows: list[RunRow] = []
    over_budget: dict[str, float] = {}
    for config in grid:
        if config.family in over_budget:
            row = _skipped(
                config,
                f"skipped: the run at a larger step took "
                f"{over_budget[config.family]:.1f} s (budget "
                f"{settings.run_budget:g} s)",
            )
        else:
            run, _ = fastest_run(
                configured_scene(scene, config, structure),
                structure,
                workdir,
                settings.repeats,
            )
            error, worst = (
                comparison.error(run.columns) if run.status == "finished" else (math.nan, "")
            )
            row = _row(config, run, error, worst)
            if 2.0 * row.wall_time_s > settings.run_budget:
                over_budget[config.family] = row.wall_time_s
        rows.append(row)
        progress.advance(_describe(row))
    return rows


def _monolithic_attempt(
    scene: Scene,
    settings: StudySettings,
    comparison: Comparison,
    family: str,
    label: str,
    **solver,
) -> RunRow:
    try:
        result = run_monolithic(scene, output_interval=settings.output_interval, **solver)
    except Exception as exc:  # noqa: BLE001 - a loose tolerance may fail; record it
        return RunRow(
            family,
            "monolithic",
            "-",
            label,
            math.nan,
            "failed",
            math.nan,
            "",
            math.nan,
            0.0,
            math.nan,
            0,
            0,
            0,
            0,
            math.nan,
            math.nan,
            math.nan,
            one_line(f"{type(exc).__name__}: {exc}"),
        )
    error, worst = comparison.error(result.values)
    return _monolithic_row(family, label, result, error, worst, settings.stop_time)


def _monolithic_solver(choice: SolverChoice) -> dict[str, Any] | None:
    """The monolithic solver arguments matching a unit solver choice (None if there is none)."""
    params = choice.complete
    if choice.only is not None or params["solver"] not in HYBRID_SOLVERS:
        return None
    return {
        "method": params["solver"],
        "rtol": float(params["solver_rtol"]),
        "atol": float(params["solver_atol"]),
        "max_step": float(params["solver_max_step"]),
    }


def _monolithic_rows(
    scene: Scene, settings: StudySettings, comparison: Comparison, progress: StudyProgress
) -> list[RunRow]:
    """The monolithic model at looser Radau tolerances, and with each unit solver."""
    rows = []
    for rtol in settings.monolithic_rtols:
        rows.append(
            _monolithic_attempt(
                scene,
                settings,
                comparison,
                MONOLITHIC_RADAU,
                f"radau rtol={rtol:g}",
                method="radau",
                rtol=rtol,
                atol=rtol,
            )
        )
        progress.advance(_describe(rows[-1]))
    for choice in solver_choices(scene, settings) if settings.solver_floors else ():
        solver = _monolithic_solver(choice)
        if solver is not None:
            rows.append(
                _monolithic_attempt(
                    scene,
                    settings,
                    comparison,
                    f"monolithic / {choice.label}",
                    choice.label,
                    **solver,
                )
            )
            progress.advance(_describe(rows[-1]))
    return rows


def _monolithic_runs(scene: Scene, settings: StudySettings) -> int:
    floors = (
        sum(1 for c in solver_choices(scene, settings) if _monolithic_solver(c) is not None)
        if settings.solver_floors
        else 0
    )
    return len(settings.monolithic_rtols) + floors


def run_accuracy_study(
    scene: Scene | str | Path,
    output_dir: Path,
    *,
    grid: str | None = None,
    couplings: Sequence[str] | None = None,
    **options: Any,
) -> AccuracyStudy:
    """Run the accuracy study of ``scene`` and write its files into ``output_dir``.

    Parameters
    ----------
    scene : Scene, str or Path
        A parsed scene, a shipped scene's name or a scene file.
    output_dir : Path
        Folder for ``accuracy.csv``, ``accuracy.md``, ``accuracy.json``,
        ``work_precision.png`` and ``convergence.png`` (created).
    grid : str, optional
        ``"slices"`` or ``"product"`` (see :func:`~wire_fmu.study.plan.build_grid`),
        instead of the plan's.
    couplings : sequence of str, optional
        Keys of :data:`~wire_fmu.study.plan.COUPLINGS` to compare besides the scene's
        own, instead of the plan's (:data:`~wire_fmu.study.plan.DEFAULT_COUPLINGS`);
        those the scene's bonds cannot take are left out.
    **options
        How the study runs, the fields of
        :class:`~wire_fmu.study.plan.StudyOptions`: ``quick`` (the reduced
        plan of :func:`~wire_fmu.study.plan.study_settings`), ``settings``
        (a plan of one's own), ``repeats`` (runs per configuration, the
        fastest counts; default the plan's), ``stop_time``, ``fmu_dir``,
        ``progress``, ``stream``.

    Raises
    ------
    SceneError
        The scene or its ``[study]`` table has problems.
    StudyError
        No monolithic reference can be built for the scene; a key output is
        not a physical quantity; no key output moves in the study's window.
    """
    started = time.perf_counter()
    opts = StudyOptions(**options)
    scene, settings = opts.prepare(scene)
    settings = replace(
        settings, repeats=opts.repeats or settings.repeats, grid=grid or settings.grid
    )
    if settings.grid not in GRIDS:
        raise ValueError(f"grid must be one of {GRIDS}, got {settings.grid!r}")
    if couplings is not None:
        settings = replace(settings, couplings=parse_couplings(",".join(couplings)))
    base = study_scene(scene, settings)
    with tempfile.TemporaryDirectory(prefix="wire_fmu_study_") as tmp:
        structure = pinned(validate_scene(base, opts.fmu_dir), Path(tmp))
        check_physical(scene.name, settings.key_outputs, structure.variable)
        study = _study(
            scene.name, base, structure, settings, Path(tmp) / "run", opts.progress, opts.stream
        )
    study.elapsed = time.perf_counter() - started
    study.files = write_accuracy_files(study, Path(output_dir))
    return study


def _study(
    name: str,
    base: Scene,
    structure: Structure,
    settings: StudySettings,
    workdir: Path,
    progress: bool,
    stream: TextIO | None,
) -> AccuracyStudy:
    grid = build_grid(base, settings)
    report = StudyProgress(len(grid) + _monolithic_runs(base, settings), stream, progress)
    report.note(
        f"study of {name!r}: {len(grid)} runs of {settings.stop_time:g} s, "
        f"reference: monolithic Radau rtol {settings.reference_rtol:g}"
    )
    reference = reference_run(base, settings)
    report.note(
        f"reference: {reference.wall_time:.2f} s wall, {reference.rhs_calls} "
        f"right-hand side calls, {reference.events} events"
    )
    settings, notes, comparison = _compared(name, settings, reference)
    rows = _run_grid(base, structure, grid, comparison, settings, workdir, report)
    rows += _monolithic_rows(base, settings, comparison, report)
    orders = observed_orders(rows, base, REFERENCE_MARGIN * settings.reference_rtol)
    at_equal_error = equal_error(rows, default_targets(rows))
    study = AccuracyStudy(
        name, settings, reference.wall_time / settings.stop_time, rows, orders, at_equal_error
    )
    study.notes = notes
    return study


def _compared(
    name: str, settings: StudySettings, reference: MonolithicResult
) -> tuple[StudySettings, list[str], Comparison]:
    """The plan with the key outputs that move in the window, the warnings, the comparison."""
    first = first_sample(reference.time, settings.window_start)
    moving, notes = moving_key_outputs(
        name,
        reference.values,
        settings.key_outputs,
        settings.window,
        first,
        still_tolerance(settings.reference_rtol),
    )
    settings = replace(settings, key_outputs=moving)
    return settings, notes, Comparison(reference.values, tuple(map(str, moving)), first)


def summary_text(study: AccuracyStudy) -> str:
    """Orders and the equal-error comparison as plain text (for the command line).

    Parameters
    ----------
    study : AccuracyStudy
        What :func:`run_accuracy_study` produced.
    """
    lines = [f"warning: {note}" for note in study.notes]
    start, stop = study.settings.window
    lines.append(
        f"observed convergence orders ({study.scene}, errors over [{start:g}, {stop:g}] s):"
    )
    width = max((len(o.family) for o in study.orders), default=10)
    for o in study.orders:
        theory = "-" if o.theory is None else str(o.theory)
        lines.append(f"  {o.family:<{width}}  theory {theory}  observed {observed_text(o)}")
        if math.isfinite(o.observed):
            lines[-1] += f"  ({o.points} runs)"
    lines.append(f"monolithic reference: {study.reference_wall_per_sim_s:.3g} s per simulated s")
    for c in study.comparison:
        if c.cheapest:
            lines.append(
                f"  at error {c.target:.0e}: cheapest {c.cheapest} "
                f"({c.cheapest_cost:.3g} s/s, {c.reached()}/{len(c.costs)} reach it)"
            )
    return "\n".join(lines)
