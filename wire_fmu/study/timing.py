"""Timed master runs: where a run's wall time went, the fastest of repeats, progress lines.

Shared by the accuracy study (:mod:`wire_fmu.study.accuracy`) and the
effects study (:mod:`wire_fmu.study.effects`); see the accuracy study's
"Timing" section for what is measured.
"""

from __future__ import annotations

import logging
import math
import shutil
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.plots import read_results
from wire_fmu.master.scene import Scene
from wire_fmu.master.simulation import Simulation
from wire_fmu.master.validate import Structure

from .monolithic import CORE_UNITS
from .solvers import _import

__all__ = [
    "Timing",
    "PhysicsTimer",
    "core_classes",
    "TimedRun",
    "timed_run",
    "fastest_run",
    "pinned",
    "StudyProgress",
]

logger = logging.getLogger(__name__)


@dataclass
class Timing:
    """Where the wall time of one run went (seconds over the stepping phase)."""

    wall: float = 0.0
    simulated: float = 0.0
    physics: float = 0.0
    fmi: float = 0.0
    calls: int = 0
    do_steps: int = 0

    @property
    def per_simulated_second(self) -> float:
        """Wall seconds per simulated second."""
        return self.wall / self.simulated if self.simulated > 0 else math.nan

    def shares(self) -> tuple[float, float, float]:
        """Shares of the wall time: physics, FMI overhead (FMI minus physics), master."""
        if self.wall <= 0:
            return math.nan, math.nan, math.nan
        physics = min(self.physics, self.fmi)
        return (
            physics / self.wall,
            (self.fmi - physics) / self.wall,
            (self.wall - self.fmi) / self.wall,
        )


class PhysicsTimer:
    """Accumulates the time spent in ``advance`` of some core unit classes (wraps them).

    Parameters
    ----------
    classes : iterable of type
        Core unit classes whose ``advance`` is timed while the timer is entered.
    """

    def __init__(self, classes: Iterable[type]) -> None:
        self.classes = list(dict.fromkeys(classes))
        self.elapsed = 0.0
        self._originals: dict[type, Any] = {}

    def __enter__(self) -> PhysicsTimer:
        for cls in self.classes:
            self._originals[cls] = cls.__dict__.get("advance")
            cls.advance = self._timed(cls.advance)
        return self

    def __exit__(self, *exc) -> None:
        for cls, original in self._originals.items():
            if original is None:
                del cls.advance
            else:
                cls.advance = original
        self._originals.clear()

    def _timed(self, original):
        timer = self

        def advance(unit, time_, step):
            start = time.perf_counter()
            try:
                return original(unit, time_, step)
            finally:
                timer.elapsed += time.perf_counter() - start

        return advance


def core_classes(scene: Scene) -> list[type]:
    """Core unit classes of the scene's units of ours (those that cannot be imported skipped)."""
    out = []
    for fmu in sorted({u.fmu for u in scene.units.values() if u.fmu in CORE_UNITS}):
        try:
            out.append(_import(CORE_UNITS[fmu]))
        except (ImportError, AttributeError) as exc:
            logger.warning("cannot time the physics of %s: %s", fmu, exc)
    return out


class _TimingObserver:
    """Stamps the stepping phase: wall, physics and FMI time, call counts."""

    def __init__(self, timer: PhysicsTimer) -> None:
        self.timer = timer
        self.timing = Timing()
        self._start = (0.0, 0.0, 0.0, 0, 0)

    @staticmethod
    def _fmi(sim: Simulation) -> tuple[float, int, int]:
        seconds = sum(sum(s.seconds.values()) for s in sim.slaves.values())
        calls = sum(sum(s.calls.values()) for s in sim.slaves.values())
        steps = sum(s.calls.get("doStep", 0) for s in sim.slaves.values())
        return seconds, calls, steps

    def on_start(self, sim: Simulation) -> None:
        """Stamp the start of stepping (:class:`~wire_fmu.master.observers.Observer`).

        Parameters
        ----------
        sim : Simulation
            The running simulation.
        """
        self._start = (time.perf_counter(), self.timer.elapsed, *self._fmi(sim))

    def on_step(self, sim: Simulation) -> None:
        """Nothing per step (:class:`~wire_fmu.master.observers.Observer`).

        Parameters
        ----------
        sim : Simulation
            The running simulation.
        """

    def on_end(self, sim: Simulation, result) -> None:
        """Stamp the end (:class:`~wire_fmu.master.observers.Observer`).

        Parameters
        ----------
        sim : Simulation
            The simulation at its end.
        result : RunResult
            How it ended (not used).
        """
        wall0, physics0, fmi0, calls0, steps0 = self._start
        if wall0 == 0.0:
            return
        fmi, calls, steps = self._fmi(sim)
        self.timing = Timing(
            time.perf_counter() - wall0,
            sim.time,
            self.timer.elapsed - physics0,
            fmi - fmi0,
            calls - calls0,
            steps - steps0,
        )


@dataclass
class TimedRun:
    """One master run: its status, recorded columns and timing (zero if it could not start)."""

    status: str
    message: str
    columns: dict[str, np.ndarray]
    timing: Timing
    steps: int = 0
    rejected: int = 0


def timed_run(scene: Scene, structure: Structure, workdir: Path, timer: PhysicsTimer) -> TimedRun:
    """Run ``scene`` with the master, recording its outputs and timing the stepping.

    The scene was validated once (``structure``); each run builds a
    :class:`~wire_fmu.master.simulation.Simulation` as
    :func:`~wire_fmu.master.run.run_scene` does, without validating again
    (which would instantiate every unit once more, and rebuild FMUs if the
    core changed on disk during a study). A failure of any kind is a result.

    Parameters
    ----------
    scene : Scene
        The scene of one configuration.
    structure : Structure
        The validated (pinned) FMUs.
    workdir : Path
        Folder for the run's recorded CSV (overwritten by each run).
    timer : PhysicsTimer
        The entered timer of the core classes.
    """
    timing = _TimingObserver(timer)
    recorder = CsvRecorder(workdir, scene.run.output_interval)
    try:
        sim = Simulation(scene, structure, [timing, recorder])
        result = sim.run()
        if result.status == "interrupted":  # Ctrl-C ends the study, not just this run
            raise KeyboardInterrupt
    except Exception as exc:  # noqa: BLE001 - one configuration failing must not end a study
        logger.debug("run failed: %s", exc, exc_info=True)
        return TimedRun("failed", f"{type(exc).__name__}: {exc}", {}, Timing())
    columns = read_results(recorder.csv_path) if recorder.csv_path.exists() else {}
    return TimedRun(
        result.status, result.message, columns, timing.timing, result.steps, result.rejected
    )


def fastest_run(
    scene: Scene, structure: Structure, workdir: Path, timer: PhysicsTimer, repeats: int = 1
) -> tuple[TimedRun, float]:
    """The fastest of ``repeats`` runs, and the spread of their costs (s per simulated s;
    NaN with fewer than two finished runs).

    A shared machine only ever slows a run down, so the minimum is the
    best estimate of its cost; outputs do not depend on the repeat.

    Parameters
    ----------
    scene, structure, workdir, timer
        As for :func:`timed_run`.
    repeats : int
        Runs made (at least one).
    """
    runs = [timed_run(scene, structure, workdir, timer) for _ in range(max(1, repeats))]
    finished = [r for r in runs if r.status == "finished"]
    if not finished:
        return runs[-1], math.nan
    costs = [r.timing.per_simulated_second for r in finished]
    spread = max(costs) - min(costs) if len(costs) > 1 else math.nan
    return min(finished, key=lambda r: r.timing.per_simulated_second), spread


def pinned(structure: Structure, directory: Path) -> Structure:
    """The validated FMUs copied into ``directory``.

    A study keeps running the FMUs it validated, even if ours are rebuilt
    meanwhile because another process changed the core on disk (their
    guard would refuse an FMU whose core differs from the one imported here).

    Parameters
    ----------
    structure : Structure
        The validated scene.
    directory : Path
        Where the copies go (an existing folder that outlives the study).
    """
    copies: dict[Path, Path] = {}
    for path in structure.paths.values():
        if path not in copies:
            copies[path] = directory / f"{len(copies)}_{path.name}"
            shutil.copy2(path, copies[path])
    return Structure({n: copies[p] for n, p in structure.paths.items()}, structure.descriptions)


class StudyProgress:
    """One line per run on a stream (stderr by default), with elapsed time and an estimate.

    Parameters
    ----------
    total : int
        Runs planned.
    stream : text stream, optional
        Where to write (default ``sys.stderr``); None with ``enabled=False``.
    enabled : bool
        Write nothing when False.
    """

    def __init__(self, total: int, stream: TextIO | None = None, enabled: bool = True) -> None:
        self.total = total
        self.done = 0
        self.stream = stream
        self.enabled = enabled
        self._start = time.perf_counter()

    def note(self, text: str) -> None:
        """A line that is not a run.

        Parameters
        ----------
        text : str
            The line (without its newline).
        """
        if self.enabled:
            (self.stream or sys.stderr).write(text + "\n")
            (self.stream or sys.stderr).flush()

    def advance(self, text: str) -> None:
        """One run done.

        Parameters
        ----------
        text : str
            What the run gave, after the bar, the count and the time.
        """
        self.done += 1
        elapsed = time.perf_counter() - self._start
        left = elapsed / self.done * (self.total - self.done)
        width = 20
        filled = int(width * self.done / max(self.total, 1))
        bar = "#" * filled + "." * (width - filled)
        self.note(
            f"[{bar}] {self.done:>3}/{self.total} {elapsed:6.0f} s (~{left:.0f} s left) {text}"
        )
