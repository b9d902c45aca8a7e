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

__all__ = ["MONOLITHIC_RADAU", "output_error", "Comparison", "RunRow", "one_line"]

MONOLITHIC_RADAU = "monolithic / radau"
"""Family of the monolithic model at looser Radau tolerances."""

_RANGE_FLOOR = 1e-6
_DIVERGED = 1.0  # an error above the output's whole range: the run blew up


# ---------------------------------------------------------------------- error
def _scale(reference: np.ndarray) -> float:
    """The output's swing, at least :data:`_RANGE_FLOOR` of its magnitude; 0 if neither."""
    span = float(np.ptp(reference)) if reference.size else 0.0
    return max(span, _RANGE_FLOOR * float(np.max(np.abs(reference), initial=0.0)))


def output_error(
    values: Mapping[str, np.ndarray],
    reference: Mapping[str, np.ndarray],
    keys: Sequence[VarRef | str],
    first: int = 0,
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
    first : int
        Index of the first compared sample (the study window's start);
        earlier samples are not compared.

    Raises
    ------
    ValueError
        If a key output is zero throughout the window of the reference: no
        deviation can be scaled by its swing (the studies leave such outputs
        out first, :mod:`wire_fmu.study.key_outputs`).
    """
    worst, which = 0.0, ""
    for key in map(str, keys):
        ref = np.asarray(reference[key], dtype=float)
        got = np.asarray(values.get(key, ()), dtype=float)
        if got.shape != ref.shape:
            return math.nan, f"{key}: {got.size} samples, the reference has {ref.size}"
        scale = _scale(ref[first:])
        if not (scale > 0.0 and math.isfinite(scale)):
            raise ValueError(
                f"{key} is {scale:g} in the reference's window: no error can be scaled by its swing"
            )
        error = float(np.max(np.abs(got[first:] - ref[first:]), initial=0.0)) / scale
        if not math.isfinite(error):
            return math.inf, key
        if error >= worst:
            worst, which = error, key
    return worst, which


@dataclass(frozen=True)
class Comparison:
    """What every run of a study is compared with: reference columns, key outputs, window.

    Attributes
    ----------
    reference : mapping of str to ndarray
        The reference's columns by name, on the study's output grid from 0 s.
    keys : tuple of str
        The key outputs measured (those that move in the window).
    first : int
        Index of the window's first sample.
    """

    reference: Mapping[str, np.ndarray]
    keys: tuple[str, ...]
    first: int = 0

    def error(self, values: Mapping[str, np.ndarray]) -> tuple[float, str]:
        """The run's error and the key output that sets it (see :func:`output_error`).

        Parameters
        ----------
        values : mapping of str to ndarray
            The run's columns by name, on the same grid.
        """
        return output_error(values, self.reference, self.keys, self.first)


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
    coupling: str = "held"

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
        config.coupling,
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
        config.coupling,
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
