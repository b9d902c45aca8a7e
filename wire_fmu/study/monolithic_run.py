"""``wire-fmu run SCENE --monolithic``: a scene's units solved as one ODE, written as a run is.

The same units, parameters, effects, drivers and events as the co-simulated
run, assembled by :class:`~wire_fmu.study.monolithic.MonolithicModel` (the
accuracy study's reference) and solved by SciPy's Radau with event location
to a tolerance, instead of stepping FMUs: no macro step, no held inputs, so
no coupling error. One solver integrates every unit: the units' own solver
parameters do not apply. The results folder has the layout of a normal run:
``timeseries.csv`` (streamed as the run goes), ``metadata.json`` (with
``column_units``, ``"mode": "monolithic"``, the solver, the columns left out
and why, see :mod:`~wire_fmu.study.monolithic_record`, and at the end the
result) and the scene's plots.

Every run ends with a true status, as a co-simulated one
(:data:`~wire_fmu.master.run_result.STATUSES`): ``finished``; ``stopped`` when
the physics or the solver cannot go on (a unit's model error, a failed
integration, non-finite numbers), with the message and the time; ``failed``
when initialisation or something unexpected fails; ``interrupted`` by Ctrl-C
or SIGTERM, after the output interval under way (a second Ctrl-C stops at
once). Every row computed is in the file.

The scene is checked as ``wire-fmu check`` checks its structure, against our
FMUs' model descriptions (built if need be), which also give every column its
unit; the units' own checks of their parameters are those of their core
classes, configured here. No FMU is loaded or stepped. A scene whose units
are not all ours (an FMU given by path) cannot be solved as one ODE: it is
refused before anything runs, naming each such unit.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from wire_fmu.core.errors import ConfigurationError, WireFmuError
from wire_fmu.core.framework.hybrid import SolverSettings, make_solver
from wire_fmu.core.framework.step_limits import IntegrationError
from wire_fmu.core.framework.unit import Unit
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.interrupts import InterruptRequestedError, Interrupts
from wire_fmu.master.observers import Progress
from wire_fmu.master.run import (
    find_scene,
    load_scene_file,
    make_results_folder,
    with_run_settings,
)
from wire_fmu.master.run_result import RunResult
from wire_fmu.master.scene import Scene, SceneError
from wire_fmu.master.validate import validate_scene

from .monolithic import CORE_UNITS, MonolithicModel, _core_class, advance_to
from .monolithic_record import (
    ColumnPlan,
    Recorder,
    plan_columns,
    record_interval,
    run_metadata,
)

__all__ = [
    "METHOD",
    "DEFAULT_RTOL",
    "MonolithicOutcome",
    "monolithic_problems",
    "output_times",
    "run_scene_monolithic",
    "summary_rows",
]

logger = logging.getLogger(__name__)

METHOD = "radau"
"""The solver: SciPy's Radau IIA (implicit, order 5, stiff), with event location."""

DEFAULT_RTOL = 1e-8
"""Relative (and absolute) tolerance by default. On the riser tensioner's first 4 s the
tension is then within 0.01 N of the accuracy study's reference (1e-10), at 0.4 times its
cost; 1e-6 is within 0.7 N, at about half the cost of 1e-8."""

STOPPING = (WireFmuError, IntegrationError, ArithmeticError)
"""What ends a monolithic run ``stopped``: a unit's model cannot go on (a limit), the
integration fails, numbers stop being finite."""


@dataclass
class MonolithicOutcome:
    """What a monolithic run produced.

    Attributes
    ----------
    scene : Scene
        The scene run (with its run settings as overridden).
    result : RunResult
        How it ended; ``steps`` are the solver's accepted steps.
    directory, csv_path : Path
        The results folder and its ``timeseries.csv``.
    plots : list of Path
        The PNG files drawn.
    rtol : float
        The solver's relative and absolute tolerance.
    rhs_calls, events : int
        Right-hand-side evaluations and located guard events.
    omitted : dict of str to str
        Columns a co-simulated run records that this one does not, with the reason.
    """

    scene: Scene
    result: RunResult
    directory: Path
    csv_path: Path
    plots: list[Path] = field(default_factory=list)
    rtol: float = DEFAULT_RTOL
    rhs_calls: int = 0
    events: int = 0
    omitted: dict[str, str] = field(default_factory=dict)


# ----------------------------------------------------------------------- checks
def monolithic_problems(scene: Scene) -> list[str]:
    """Why ``scene``'s units cannot be solved as one ODE; empty if they can.

    Parameters
    ----------
    scene : Scene
        The scene.

    Returns
    -------
    list of str
        One sentence per unit that is not one of our unit types, or whose core
        unit offers no ODE view, naming the unit and why.
    """
    problems = []
    for name, spec in scene.units.items():
        if spec.fmu not in CORE_UNITS:
            problems.append(
                f"unit {name!r}: {spec.fmu!r} is an FMU, not one of our unit types "
                f"({', '.join(CORE_UNITS)}); a monolithic run needs every unit's equations, "
                "which an FMU does not give: run the scene without --monolithic"
            )
        elif _core_class(spec.fmu).ode is Unit.ode:
            problems.append(
                f"unit {name!r}: {spec.fmu} offers no ODE view (its core unit has no ode()), "
                "so it cannot be part of one ODE: run the scene without --monolithic"
            )
    return problems


def output_times(stop: float, interval: float) -> Iterator[float]:
    """The record times after 0: every multiple of ``interval`` up to ``stop``, then ``stop``.

    Times are whole nanoseconds, as the master counts them, so that a row of a
    monolithic run and of a co-simulated one have the same ``time``.

    Parameters
    ----------
    stop : float
        Stop time, s (> 0).
    interval : float
        Record spacing, s (> 0).

    Yields
    ------
    float
        Record times, s, increasing, the last ``stop``.
    """
    stop_ns = round(stop * 1e9)
    count = math.floor(stop / interval * (1 + 1e-12))
    last = 0
    for k in range(1, count + 1):
        last = min(round(k * interval * 1e9), stop_ns)
        yield last / 1e9
    if last < stop_ns:
        yield stop_ns / 1e9


def _scene(scene: str | Path | Scene, stop_time: float | None) -> Scene:
    if not isinstance(scene, Scene):
        scene = load_scene_file(find_scene(scene))
    return with_run_settings(scene, stop_time=stop_time) if stop_time is not None else scene


def _model(scene: Scene) -> MonolithicModel:
    """The scene as one ODE, each unit configured (a unit's own check names it)."""
    try:
        return MonolithicModel(scene)
    except WireFmuError:
        raise
    except (ValueError, TypeError, KeyError) as exc:
        raise SceneError(
            f"scene {scene.name!r} (monolithic)",
            [f"the units could not be configured: {type(exc).__name__}: {exc}"],
        ) from None


# --------------------------------------------------------------------------- the run
@dataclass
class _Clock:
    """What :class:`~wire_fmu.master.observers.Progress` reads of a run."""

    scene: Scene
    run_settings: Any
    time: float = 0.0


@dataclass
class _Solve:
    """One monolithic run under way: the model, its solver, its recorder and clock."""

    model: MonolithicModel
    plan: ColumnPlan
    recorder: Recorder
    clock: _Clock
    progress: Progress | None
    rtol: float
    events: int = 0
    solver: Any = None

    def run(self) -> RunResult:
        """Initialise and solve to the stop time, recording every output time; never raises."""
        result = RunResult("finished")
        wall = time.perf_counter()
        with Interrupts() as interrupts:
            try:
                self._loop(interrupts)
            except (KeyboardInterrupt, InterruptRequestedError):
                result.status = "interrupted"
                result.message = f"interrupted at t = {self.clock.time:.6g} s"
            except _InitialisationError as exc:
                result.status, result.message = "failed", str(exc)
            except STOPPING as exc:
                result.status = "stopped"
                result.message = f"after t = {self.clock.time:.6g} s: {_said(exc)}"
            except Exception as exc:  # noqa: BLE001 - a run ends with a status, never a traceback
                logger.debug("unexpected failure after t = %g s", self.clock.time, exc_info=True)
                result.status = "failed"
                result.message = (
                    f"after t = {self.clock.time:.6g} s: unexpected {_said(exc)} "
                    "(run with --verbose for the traceback)"
                )
            finally:
                self._finish(result, wall)
        return result

    def _loop(self, interrupts: Interrupts) -> None:
        settings = SolverSettings(method=METHOD, max_step=math.inf, rtol=self.rtol, atol=self.rtol)
        self.solver = make_solver(settings)
        try:
            x = self.model.initialize(0.0)
            first = self.plan.row(self.model, 0.0, x)
        except Exception as exc:  # noqa: BLE001 - said as the run's failure, nothing recorded
            logger.debug("initialisation failed", exc_info=True)
            raise _InitialisationError(f"initialisation failed: {_said(exc)}") from None
        self.recorder.open()
        self.recorder.add(first)
        if self.progress is not None:
            self.progress.on_start(self.clock)
        t = 0.0
        for t_next in output_times(
            self.clock.run_settings.stop_time, record_interval(self.clock.scene)
        ):
            if interrupts.requested:
                raise InterruptRequestedError
            x, events = advance_to(self.model, self.solver, t, x, t_next)
            self.events += events
            t = self.clock.time = t_next
            self.recorder.add(self.plan.row(self.model, t, x))
            if self.progress is not None:
                self.progress.on_step(self.clock)

    def _finish(self, result: RunResult, wall: float) -> None:
        result.end_time, result.wall_time = self.clock.time, time.perf_counter() - wall
        result.steps = self.solver.steps if self.solver is not None else 0
        try:
            self.recorder.close()
        finally:
            self.recorder.write_metadata(result, rhs_calls=self.rhs_calls, events=self.events)
            if self.progress is not None:
                self.progress.on_end(self.clock, result)

    @property
    def rhs_calls(self) -> int:
        """Right-hand-side evaluations so far."""
        return self.solver.rhs_calls if self.solver is not None else 0


class _InitialisationError(RuntimeError):
    """The units could not be initialised as one ODE; the message says why."""


def _said(exc: BaseException) -> str:
    """An exception in one line: the message of ours, the type and message of any other."""
    if isinstance(exc, ConfigurationError):
        return f"{exc.where}: {'; '.join(exc.problems)}"
    text = " ".join(str(exc).split())
    if isinstance(exc, WireFmuError):
        return text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def run_scene_monolithic(
    scene: str | Path | Scene,
    results: Path | None = None,
    *,
    progress: bool = False,
    plots: bool = True,
    fmu_dir: str | Path = DEFAULT_FMU_DIR,
    stop_time: float | None = None,
    rtol: float = DEFAULT_RTOL,
) -> MonolithicOutcome:
    """Solve a scene's units as one ODE; write results (and plots) as a run does.

    Parameters
    ----------
    scene, results, progress, plots
        As :func:`~wire_fmu.master.run.run_scene` takes them: the scene (name, file or
        parsed), the results folder, a progress bar on stderr, the scene's plots.
    fmu_dir : str or Path
        Where our FMUs are built and cached (their model descriptions check the
        scene and give the columns' units).
    stop_time : float, optional
        Stop time instead of the scene's, s.
    rtol : float
        Relative and absolute tolerance of the solver (> 0).

    Returns
    -------
    MonolithicOutcome
        The scene, the result, the files, the solver's counts.

    Raises
    ------
    SceneError
        When a unit is not one of ours or the scene has problems (every one listed).
    ConfigurationError
        When ``rtol`` is not a finite number > 0, or a unit refuses its parameters.
    """
    if not (0.0 < rtol < math.inf):
        raise ConfigurationError("monolithic run", [f"rtol must be a number > 0, got {rtol}"])
    scene = _scene(scene, stop_time)
    problems = monolithic_problems(scene)
    if problems:
        raise SceneError(f"scene {scene.name!r} cannot run monolithically", problems)
    directory = make_results_folder(Path(results) if results else Path("results") / scene.name)
    structure = validate_scene(scene, Path(fmu_dir), through_fmi=False)
    model = _model(scene)
    plan = plan_columns(scene, structure, model)
    meta = run_metadata(
        scene, structure, model, plan, {"method": METHOD, "rtol": rtol, "atol": rtol}
    )
    recorder = Recorder(directory, plan, meta)
    recorder.write_metadata()
    clock = _Clock(scene, scene.run)
    solve = _Solve(model, plan, recorder, clock, Progress() if progress else None, rtol)
    result = solve.run()
    outcome = MonolithicOutcome(
        scene,
        result,
        directory,
        recorder.csv_path,
        rtol=rtol,
        rhs_calls=solve.rhs_calls,
        events=solve.events,
        omitted=plan.omitted,
    )
    if plots and scene.plots:
        outcome.plots = _plots(scene, plan, recorder.csv_path, directory)
    return outcome


def _plots(scene: Scene, plan: ColumnPlan, csv_path: Path, directory: Path) -> list[Path]:
    """The scene's plots of what was recorded (a left-out column is left out of its plot)."""
    if not csv_path.is_file():
        logger.info("no plots: nothing was recorded (the run ended in its initialisation)")
        return []
    from wire_fmu.master.plots import plot_scene

    shown = []
    for spec in scene.plots:
        variables = tuple(v for v in spec.variables if str(v) in plan.units)
        if variables:
            shown.append(replace(spec, variables=variables))
    try:
        return plot_scene(replace(scene, plots=tuple(shown)), csv_path, directory)
    except Exception as exc:  # noqa: BLE001 - the run's results stand without their plots
        logger.warning("the plots could not be drawn: %s", exc)
        logger.debug("plot failure", exc_info=True)
        return []


def summary_rows(outcome: MonolithicOutcome) -> list[tuple[str, str]]:
    """Key figures of a monolithic run, for a summary table.

    Parameters
    ----------
    outcome : MonolithicOutcome
        The run.

    Returns
    -------
    list of (str, str)
        Label and text of each figure: status, times, the solver's work, the
        columns left out.
    """
    result = outcome.result
    rows = [
        ("status", result.status),
        ("mode", f"monolithic: one ODE, {METHOD} at rtol = atol = {outcome.rtol:g}"),
        ("simulated", f"{result.end_time:.6g} s"),
        ("wall time", f"{result.wall_time:.3g} s"),
        (
            "real-time factor",
            f"{result.end_time / result.wall_time:.3g}" if result.wall_time else "-",
        ),
        (
            "solver",
            f"{result.steps} steps, {outcome.rhs_calls} right-hand sides, {outcome.events} events",
        ),
    ]
    if outcome.omitted:
        rows.append(
            ("columns left out", f"{', '.join(outcome.omitted)} (why: metadata.json)"),
        )
    return rows
