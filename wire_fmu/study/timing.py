"""Timed master runs: where a run's wall time went, the fastest of repeats, progress lines.

Shared by the accuracy study (:mod:`wire_fmu.study.accuracy`) and the
effects study (:mod:`wire_fmu.study.effects`); see the accuracy study's
"Timing" section for what is measured. The physics time is read through
FMI, like any variable: every FMU of ours counts the wall-clock time its
unit spends in its physics in the local variable :data:`PHYSICS_SECONDS`.
"""

from __future__ import annotations

import logging
import math
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

import numpy as np

from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.plots import read_results
from wire_fmu.master.scene import Scene
from wire_fmu.master.simulation import Simulation
from wire_fmu.master.slave import UnitFailedError
from wire_fmu.master.validate import Structure

__all__ = [
    "PHYSICS_SECONDS",
    "Timing",
    "physics_seconds",
    "TimedRun",
    "timed_run",
    "fastest_run",
    "pinned",
    "StudyProgress",
]

logger = logging.getLogger(__name__)

PHYSICS_SECONDS = "physics_seconds"
"""Local Real of every FMU of ours: wall-clock time spent in its unit's physics (its
``advance``) since instantiation, s."""


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


def physics_seconds(sim: Simulation) -> float:
    """Wall-clock time the units' physics took so far, read through FMI, s.

    The sum of :data:`PHYSICS_SECONDS` over the units that have it (ours;
    a foreign FMU's physics counts as FMI time); NaN if a unit cannot be
    asked (it failed).

    Parameters
    ----------
    sim : Simulation
        A simulation whose units are instantiated.
    """
    total = 0.0
    for slave in sim.slaves.values():
        if PHYSICS_SECONDS in slave.variables:
            try:
                total += float(slave.get([PHYSICS_SECONDS])[PHYSICS_SECONDS])
            except UnitFailedError as exc:
                logger.debug("physics time of %s unknown: %s", slave.name, exc)
                return math.nan
    return total


class _TimingObserver:
    """Stamps the stepping phase: wall and FMI time, call counts; at the end, the physics."""

    def __init__(self) -> None:
        self.timing = Timing()
        self._start = (0.0, 0.0, 0, 0)

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
        self._start = (time.perf_counter(), *self._fmi(sim))

    def on_step(self, sim: Simulation) -> None:
        """Nothing per step (:class:`~wire_fmu.master.observers.Observer`).

        Parameters
        ----------
        sim : Simulation
            The running simulation.
        """

    def on_end(self, sim: Simulation, result) -> None:
        """Stamp the end (:class:`~wire_fmu.master.observers.Observer`).

        The physics time is read from the units after the stamps (the calls
        that read it are not counted); it covers the stepping phase, since
        the units step in no other. After a failure it is unknown (NaN): a
        unit that failed may not be asked anything more.

        Parameters
        ----------
        sim : Simulation
            The simulation at its end, its units not yet freed.
        result : RunResult
            How it ended.
        """
        wall0, fmi0, calls0, steps0 = self._start
        if wall0 == 0.0:
            return
        fmi, calls, steps = self._fmi(sim)
        wall = time.perf_counter() - wall0
        self.timing = Timing(
            wall,
            sim.time,
            physics_seconds(sim) if result.status != "failed" else math.nan,
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


def timed_run(scene: Scene, structure: Structure, workdir: Path) -> TimedRun:
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
    """
    timing = _TimingObserver()
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
    scene: Scene, structure: Structure, workdir: Path, repeats: int = 1
) -> tuple[TimedRun, float]:
    """The fastest of ``repeats`` runs, and the spread of their costs (s per simulated s;
    NaN with fewer than two finished runs).

    A shared machine only ever slows a run down, so the minimum is the
    best estimate of its cost; outputs do not depend on the repeat.

    Parameters
    ----------
    scene, structure, workdir
        As for :func:`timed_run`.
    repeats : int
        Runs made (at least one).
    """
    runs = [timed_run(scene, structure, workdir) for _ in range(max(1, repeats))]
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
