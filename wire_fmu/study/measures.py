"""What one run of a study measured: its error against a reference, and its table row.

The error metric is the accuracy study's (:mod:`wire_fmu.study.accuracy`,
"Error metric"); a :class:`RunRow` is one row of ``accuracy.csv``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from wire_fmu.master.scene import VarRef

from .monolithic import MonolithicResult
from .plan import Configuration
from .timing import TimedRun

__all__ = ["MONOLITHIC_RADAU", "output_error", "RunRow", "one_line"]

MONOLITHIC_RADAU = "monolithic / radau"
"""Family of the monolithic model at looser Radau tolerances."""

_RANGE_FLOOR = 1e-6
_DIVERGED = 1.0  # an error above the output's whole range: the run blew up


# ---------------------------------------------------------------------- error
def _scale(reference: np.ndarray) -> float:
    span = float(np.ptp(reference)) if reference.size else 0.0
    return max(span, _RANGE_FLOOR * float(np.max(np.abs(reference), initial=0.0)), 1e-300)


def output_error(
    values: Mapping[str, np.ndarray],
    reference: Mapping[str, np.ndarray],
    keys: Sequence[VarRef | str],
) -> tuple[float, str]:
    """The study's error metric (module docstring) and the key output that sets it.

    Returns ``(nan, reason)`` if the run does not cover the reference grid.

    Parameters
    ----------
    values : mapping of str to ndarray
        The run's recorded columns by name (``"unit.variable"``).
    reference : mapping of str to ndarray
        The reference's columns on the same grid.
    keys : sequence of VarRef or str
        The key outputs compared.
    """
    worst, which = 0.0, ""
    for key in map(str, keys):
        ref = np.asarray(reference[key], dtype=float)
        got = np.asarray(values.get(key, ()), dtype=float)
        if got.shape != ref.shape:
            return math.nan, f"{key}: {got.size} samples, the reference has {ref.size}"
        error = float(np.max(np.abs(got - ref))) / _scale(ref)
        if not math.isfinite(error):
            return math.inf, key
        if error >= worst:
            worst, which = error, key
    return worst, which


# ---------------------------------------------------------------------- rows
@dataclass
class RunRow:
    """One row of ``accuracy.csv``."""

    family: str
    algorithm: str
    extrapolation: str
    solver: str
    step: float
    status: str
    error: float
    worst_output: str
    wall_time_s: float
    simulated_s: float
    wall_per_sim_s: float
    macro_steps: int
    rejected: int
    fmu_calls: int
    do_step_calls: int
    physics_share: float
    fmi_overhead_share: float
    master_share: float
    message: str = ""

    @property
    def usable(self) -> bool:
        """Finished with a finite error no larger than the outputs' range."""
        return self.status == "finished" and math.isfinite(self.error) and self.error <= _DIVERGED


def _row(config: Configuration, run: TimedRun, error: float, worst: str) -> RunRow:
    t = run.timing
    physics, overhead, master = t.shares()
    status = run.status
    if status == "finished" and not (math.isfinite(error) and error <= _DIVERGED):
        status = "diverged"
    return RunRow(
        config.family,
        config.algorithm,
        config.extrapolation,
        config.solver.label,
        config.step,
        status,
        error,
        worst,
        t.wall,
        t.simulated,
        t.per_simulated_second,
        run.steps,
        run.rejected,
        t.calls,
        t.do_steps,
        physics,
        overhead,
        master,
        one_line(run.message),
    )


def one_line(message: str, limit: int = 300) -> str:
    """A message on one line (a unit's list of problems joined), at most ``limit`` characters.

    Parameters
    ----------
    message : str
        Any text.
    limit : int
        Most characters kept (the cut ends in ``...``).
    """
    text = " ".join(message.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _skipped(config: Configuration, reason: str) -> RunRow:
    return RunRow(
        config.family,
        config.algorithm,
        config.extrapolation,
        config.solver.label,
        config.step,
        "skipped",
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
        reason,
    )


def _monolithic_row(
    family: str, label: str, result: MonolithicResult, error: float, worst: str, stop: float
) -> RunRow:
    status = "finished" if math.isfinite(error) and error <= _DIVERGED else "diverged"
    return RunRow(
        family,
        "monolithic",
        "-",
        label,
        math.nan,
        status,
        error,
        worst,
        result.wall_time,
        stop,
        result.wall_time / stop,
        result.steps,
        0,
        0,
        0,
        1.0,
        0.0,
        0.0,
        f"{result.rhs_calls} right-hand side calls",
    )
