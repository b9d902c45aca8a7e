"""How the cost of one block-train step grows with the number of lines, per kernel.

Run ``python -m wire_fmu.bench.block_train_scaling [--lines 2 4 8 16 32] [--steps N]
[--out FILE]``. A drilling block train
(:func:`~wire_fmu.core.units.block_train.reevings.drilling_block_train`) with
``n`` lines between crown and travelling block steps the lowering of
:mod:`wire_fmu.bench.block_train` (fast line paid out at 0.5 m/s, ``ros2`` with
a 1 ms internal step, 10 ms communication step) in the core, once with the
Python kernel and once with the compiled one (``WIRE_FMU_KERNEL``); each figure
is the median wall time of one ``advance`` (ms) as
:func:`~wire_fmu.bench.common.time_core` measures it.

Two row sets: every planar effect (the block train's state grows with the
sheaves: a rim and a rope coordinate per sheave), and only the effects the
compiled kernel covers, so that its cost exponent shows where it applies. A
``kernel`` column says which kernel the "compiled" run really used (a block
train outside the compiled kernel's cover runs the Python kernel). Under the
table, the fitted cost exponent of each kernel and row set: the slope of the
least-squares line through ``log(ms)`` against ``log(lines)`` over the whole
range, and the compiled kernel's slope between the two largest block trains
(where fixed costs per step no longer flatten it).

The Python kernel at many lines with every effect takes a large fraction of a
second per step, so it is timed over fewer steps there (see
:func:`python_steps`).
"""

from __future__ import annotations

import argparse
import json
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wire_fmu.bench.block_train import OUTPUTS, STEP, lowering
from wire_fmu.bench.common import WARM_UP, Case, time_core
from wire_fmu.core.units.block_train.model import BLOCK_TRAIN_EFFECTS
from wire_fmu.core.units.block_train.reevings import drilling_block_train
from wire_fmu.core.units.block_train.unit import BlockTrainUnit

__all__ = [
    "LINES",
    "ScalingRow",
    "compiled_effects",
    "exponent",
    "main",
    "measure_set",
    "planar_effects",
    "python_steps",
    "table",
]

logger = logging.getLogger(__name__)

LINES = (2, 4, 8, 16, 32)
"""Default numbers of lines between crown and travelling block."""
MIN_TIMED = 10
"""Fewest timed steps (after the warm-up) of any measurement."""


@dataclass(frozen=True)
class ScalingRow:
    """Figures of one block train (one number of lines, one effect set).

    Attributes
    ----------
    effects : str
        The effect set.
    lines : int
        Lines between crown and travelling block.
    states : int
        Length of the continuous state vector.
    python_ms : float
        Median ms per 10 ms communication step, Python kernel.
    compiled_ms : float
        Median ms per communication step with ``WIRE_FMU_KERNEL=compiled``.
    compiled : bool
        Whether that run really used the compiled kernel.
    """

    effects: str
    lines: int
    states: int
    python_ms: float
    compiled_ms: float
    compiled: bool

    @property
    def ratio(self) -> float:
        """How many times faster the compiled run steps than the Python one."""
        return self.python_ms / self.compiled_ms


def planar_effects() -> list[str]:
    """Every effect of :data:`BLOCK_TRAIN_EFFECTS` but ``spatial_geometry``, in catalogue order."""
    return [e.name for e in BLOCK_TRAIN_EFFECTS.effects if e.name != "spatial_geometry"]


def _unit(lines: int, effects: str) -> BlockTrainUnit:
    """A configured, initialised block-train unit (whatever ``WIRE_FMU_KERNEL`` says)."""
    unit = BlockTrainUnit("bench")
    unit.values.update({"reeving": json.dumps(drilling_block_train(lines)), "effects": effects})
    unit.configure()
    unit.initialize(0.0)
    return unit


def compiled_effects() -> list[str]:
    """The planar effects the compiled kernel covers, each alone with what it needs.

    Asks the model (``kernel_applies``) of a 2-line block train, so that the row set
    follows the kernel as its cover grows.
    """
    covered = []
    for effect in BLOCK_TRAIN_EFFECTS.effects:
        if effect.name == "spatial_geometry":
            continue
        model = _unit(2, ",".join((*effect.requires, effect.name))).model
        if model.kernel_applies():
            covered.append(effect.name)
    return covered


def python_steps(lines: int, steps: int) -> int:
    """Steps to time the Python kernel over: ``steps`` up to 4 lines, fewer beyond.

    Parameters
    ----------
    lines : int
        Lines between crown and travelling block.
    steps : int
        Steps asked for (warm-up included).

    Returns
    -------
    int
        ``steps * 4 / lines``, at least ``WARM_UP + MIN_TIMED`` and at most ``steps``.
    """
    return min(steps, max(WARM_UP + MIN_TIMED, steps * 4 // max(lines, 1)))


def case(lines: int, effects: str) -> Case:
    """The lowering of ``lines`` lines with ``effects``.

    Parameters
    ----------
    lines : int
        Lines between crown and travelling block (even).
    effects : str
        Comma-separated effect names.
    """
    reeving = json.dumps(drilling_block_train(lines))
    return Case(
        effects or "(none)",
        BlockTrainUnit,
        {"reeving": reeving, "effects": effects},
        inputs=lowering,
        outputs=OUTPUTS,
        step=STEP,
    )


def _runs_compiled(lines: int, effects: str) -> bool:
    """Whether the block train runs the compiled kernel when ``WIRE_FMU_KERNEL=compiled``."""
    from wire_fmu.core.framework.compiled import use_compiled

    return _unit(lines, effects).model.kernel_applies() and use_compiled("block train")


def measure_set(effects: str, lines: Sequence[int], steps: int) -> list[ScalingRow]:
    """Time one effect set at every number of lines, with both kernels.

    Parameters
    ----------
    effects : str
        Comma-separated effect names.
    lines : sequence of int
        Numbers of lines.
    steps : int
        Steps per compiled measurement (warm-up included); the Python kernel takes
        :func:`python_steps`.

    Returns
    -------
    list of ScalingRow
        One per number of lines.
    """
    rows = []
    for n in lines:
        c = case(n, effects)
        python_ms, states = time_core(c, python_steps(n, steps), "python")
        compiled_ms, _ = time_core(c, steps, "compiled")
        row = ScalingRow(effects, n, states, python_ms, compiled_ms, _runs_compiled(n, effects))
        logger.info(
            "%d lines, %s: %.3f ms Python, %.3f ms compiled (%s kernel)",
            n,
            c.label,
            python_ms,
            compiled_ms,
            "compiled" if row.compiled else "Python",
        )
        rows.append(row)
    return rows


def exponent(lines: Sequence[int], ms: Sequence[float]) -> float:
    """Least-squares slope of ``log(ms)`` against ``log(lines)``: cost ~ lines^exponent.

    Parameters
    ----------
    lines : sequence of int
        Numbers of lines (at least two different ones).
    ms : sequence of float
        Cost per step at each, ms.

    Returns
    -------
    float
        The exponent, 1; NaN with fewer than two different numbers of lines.
    """
    if len(set(lines)) < 2:
        return math.nan
    slope, _ = np.polyfit(np.log(np.asarray(lines, float)), np.log(np.asarray(ms, float)), 1)
    return float(slope)


def table(sets: Sequence[list[ScalingRow]]) -> str:
    """Markdown table of the figures, and each set's fitted exponents under it.

    Parameters
    ----------
    sets : sequence of list of ScalingRow
        One list per effect set.
    """
    lines = [
        "| effects | lines | states | Python ms/step | compiled ms/step | ratio | kernel |",
        "|---|---:|---:|---:|---:|---:|---|",
    ]
    for rows in sets:
        for r in rows:
            lines.append(
                f"| {r.effects or '(none)'} | {r.lines} | {r.states} | {r.python_ms:.3f} | "
                f"{r.compiled_ms:.3f} | {r.ratio:.1f} | {'compiled' if r.compiled else 'Python'} |"
            )
    lines.append("")
    lines.append(
        "| effects | lines | Python exponent | compiled exponent | compiled, largest two |"
    )
    lines.append("|---|---|---:|---:|---:|")
    for rows in sets:
        n = [r.lines for r in rows]
        python = exponent(n, [r.python_ms for r in rows])
        fitted = exponent(n, [r.compiled_ms for r in rows])
        last = exponent(n[-2:], [r.compiled_ms for r in rows[-2:]])
        span = f"{min(n)}-{max(n)}"
        lines.append(
            f"| {rows[0].effects or '(none)'} | {span} | {python:.2f} | {fitted:.2f} | {last:.2f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lines", type=int, nargs="+", default=list(LINES), help="even numbers")
    parser.add_argument("--steps", type=int, default=100, help="steps per compiled measurement")
    parser.add_argument("--out", type=Path, help="also write the table (Markdown) here")
    args = parser.parse_args(argv)
    if args.steps < WARM_UP + MIN_TIMED:
        parser.error(f"--steps must be at least {WARM_UP + MIN_TIMED}, got {args.steps}")
    if any(n < 2 or n % 2 for n in args.lines):
        parser.error(f"--lines must be even numbers >= 2, got {args.lines}")
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    every = ",".join(planar_effects())
    covered = ",".join(compiled_effects())
    sets = [measure_set(every, args.lines, args.steps)]
    if covered != every:
        sets.append(measure_set(covered, args.lines, args.steps))
    text = table(sets)
    title = (
        f"drilling block train lowering, ros2, max internal step 1 ms, "
        f"communication step {STEP:g} s"
    )
    logger.info("\n%s:\n%s", title, text)
    if args.out:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
