"""What every unit benchmark shares: timing the core and the built FMU per step.

A benchmark describes one manoeuvre as a :class:`Case`: the unit class, its
facade script, string and real parameters, and a function giving the real
inputs at step ``i``. :func:`measure` steps it in the core with the Python
kernel and with the compiled one (``WIRE_FMU_KERNEL``), and through the FMU
(fmpy, in this process, compiled kernel), and returns a :class:`Row`.

The FMU runs in this process and uses the ``wire_fmu`` already imported
here, so the time spent inside the unit's ``advance`` during the FMU run is
measured too; the FMI overhead is the rest of the FMU's time (our FMU
binary, pythonfmu's slave class, the facade, fmpy's ctypes calls). Times are medians
over the steps (wall clock, ``time.perf_counter``) after a warm-up.
"""

from __future__ import annotations

import argparse
import logging
import os
import statistics
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from wire_fmu.core.framework.compiled import KERNEL_ENV
from wire_fmu.core.framework.unit import Unit

from .tables import markdown_table

__all__ = ["Case", "Row", "measure", "table", "ROOT", "run_cases", "command_line"]

logger = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parents[2]
WARM_UP = 5


@dataclass(frozen=True)
class Case:
    """One benchmark manoeuvre.

    Parameters
    ----------
    label : str
        Row label (usually the effect set).
    unit_class : type of Unit
        The core unit.
    strings, reals, booleans : mapping
        Parameters to set before initialisation.
    inputs : callable
        ``inputs(i)`` -> mapping of real input name to value at step ``i``.
    outputs : sequence of str
        Outputs a master would read every step.
    step : float
        Communication step, s.
    """

    label: str
    unit_class: type[Unit]
    strings: Mapping[str, str] = field(default_factory=dict)
    reals: Mapping[str, float] = field(default_factory=dict)
    booleans: Mapping[str, bool] = field(default_factory=dict)
    inputs: Callable[[int], Mapping[str, float]] = lambda i: {}
    outputs: tuple[str, ...] = ()
    step: float = 0.01


@dataclass(frozen=True)
class Row:
    """Benchmark figures of one case, ms per communication step."""

    label: str
    states: int
    python_ms: float
    core_ms: float
    fmu_ms: float
    overhead_ms: float

    @property
    def kernel_ratio(self) -> float:
        """How many times faster the compiled kernel steps the core than the Python one."""
        return self.python_ms / self.core_ms

    @property
    def overhead_share(self) -> float:
        """Share of the FMU step spent outside the physics."""
        return self.overhead_ms / self.fmu_ms


def _core_unit(case: Case) -> Unit:
    unit = case.unit_class("bench")
    unit.values.update(case.strings)
    unit.values.update(case.reals)
    unit.values.update(case.booleans)
    unit.configure()
    unit.initialize(0.0)
    return unit


def time_core(case: Case, steps: int, kernel: str = "compiled") -> tuple[float, int]:
    """Median ms per step of the core unit, and the size of its state.

    Parameters
    ----------
    case : Case
        The manoeuvre.
    steps : int
        Steps timed (the first ``WARM_UP`` do not count).
    kernel : str
        ``WIRE_FMU_KERNEL`` while the unit is built: ``"compiled"`` or ``"python"``.

    Returns
    -------
    ms_per_step : float
        Median wall time of one ``advance``, ms.
    states : int
        Length of the unit's continuous state vector.
    """
    before = os.environ.get(KERNEL_ENV)
    os.environ[KERNEL_ENV] = kernel
    try:
        unit = _core_unit(case)
    finally:
        if before is None:
            del os.environ[KERNEL_ENV]
        else:
            os.environ[KERNEL_ENV] = before
    samples = []
    for i in range(steps):
        unit.values.update(case.inputs(i))
        start = time.perf_counter()
        unit.advance(i * case.step, case.step)
        samples.append(time.perf_counter() - start)
    state = unit.get_state().get("x", [])
    return statistics.median(samples[WARM_UP:]) * 1e3, len(state)


class _AdvanceTimer:
    """Accumulates the time spent in ``unit_class.advance`` (wraps it)."""

    def __init__(self, unit_class: type[Unit]) -> None:
        self.unit_class = unit_class
        self.elapsed = 0.0
        self._original = unit_class.advance

    def __enter__(self) -> _AdvanceTimer:
        original, timer = self._original, self

        def timed(unit, time_, step):
            """The unit's ``advance``, timed.

            Parameters
            ----------
            unit : Unit
                The unit stepped.
            time_ : float
                Start of the step, s.
            step : float
                Communication step, s.
            """
            start = time.perf_counter()
            try:
                return original(unit, time_, step)
            finally:
                timer.elapsed += time.perf_counter() - start

        self.unit_class.advance = timed
        return self

    def __exit__(self, *exc) -> None:
        self.unit_class.advance = self._original


def time_fmu(fmu_path: Path, case: Case, steps: int) -> tuple[float, float]:
    """Median ms per FMU step (set inputs, doStep, get outputs), and of it outside ``advance``.

    Parameters
    ----------
    fmu_path : Path
        The built FMU of ``case``'s unit.
    case : Case
        The manoeuvre.
    steps : int
        Steps timed (the first ``WARM_UP`` do not count).

    Returns
    -------
    fmu_ms : float
        Median wall time of one FMU step, ms.
    overhead_ms : float
        Median of its part outside the unit's ``advance``, ms.
    """
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu_path))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(
        guid=md.guid,
        unzipDirectory=extract(str(fmu_path)),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="bench",
    )
    fmu.instantiate()
    for setter, values in (
        (fmu.setString, case.strings),
        (fmu.setReal, case.reals),
        (fmu.setBoolean, case.booleans),
    ):
        if values:
            setter([refs[k] for k in values], list(values.values()))
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    outputs = [refs[n] for n in case.outputs]
    samples, outside = [], []
    with _AdvanceTimer(case.unit_class) as timer:
        for i in range(steps):
            values = case.inputs(i)
            refs_in, vals_in = [refs[k] for k in values], list(values.values())
            inside = timer.elapsed
            start = time.perf_counter()
            if refs_in:
                fmu.setReal(refs_in, vals_in)
            fmu.doStep(currentCommunicationPoint=i * case.step, communicationStepSize=case.step)
            fmu.getReal(outputs)
            total = time.perf_counter() - start
            samples.append(total)
            outside.append(total - (timer.elapsed - inside))
    fmu.terminate()
    fmu.freeInstance()
    return statistics.median(samples[WARM_UP:]) * 1e3, statistics.median(outside[WARM_UP:]) * 1e3


def measure(fmu_path: Path, case: Case, steps: int) -> Row:
    """Time ``case`` in the core and through the FMU at ``fmu_path``.

    Parameters
    ----------
    fmu_path : Path
        The built FMU of ``case``'s unit.
    case : Case
        The manoeuvre.
    steps : int
        Steps timed in each (the first ``WARM_UP`` do not count).

    Returns
    -------
    Row
    """
    python_ms, states = time_core(case, steps, "python")
    core_ms, _ = time_core(case, steps, "compiled")
    fmu_ms, overhead_ms = time_fmu(fmu_path, case, steps)
    return Row(case.label, states, python_ms, core_ms, fmu_ms, overhead_ms)


def table(rows: list[Row]) -> str:
    """Markdown table of the figures, a row per case.

    Parameters
    ----------
    rows : list of Row
        The cases' figures.
    """
    return markdown_table(
        "effects | states | Python kernel ms/step | compiled ms/step | ratio | FMU ms/step "
        "| FMI overhead ms | share",
        (
            f"{r.label} | {r.states} | {r.python_ms:.3f} | {r.core_ms:.3f} | "
            f"{r.kernel_ratio:.1f} | {r.fmu_ms:.3f} | {r.overhead_ms:.3f} | "
            f"{100 * r.overhead_share:.1f} %"
            for r in rows
        ),
    )


def command_line(description: str, argv: list[str] | None) -> argparse.Namespace:
    """Parse the options every unit benchmark takes and set up logging.

    Parameters
    ----------
    description : str
        The benchmark's description for ``--help``.
    argv : list of str or None
        The arguments; None reads the command line.

    Returns
    -------
    argparse.Namespace
        ``steps`` (int) and ``out`` (Path or None).
    """
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--steps", type=int, default=200, help="steps per measurement")
    parser.add_argument("--out", type=Path, help="also write the table (Markdown) here")
    args = parser.parse_args(argv)
    if args.steps <= WARM_UP:
        parser.error(f"--steps must be more than the {WARM_UP} warm-up steps, got {args.steps}")
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    return args


def run_cases(unit: str, cases: Sequence[Case], steps: int, title: str) -> str:
    """Build our unit type ``unit`` (:mod:`wire_fmu.registry`) into a temporary folder, measure
    every case, log the table.

    Parameters
    ----------
    unit : str
        Name of our unit type, e.g. ``"Winch"``.
    cases : sequence of Case
        The manoeuvres.
    steps : int
        Steps timed per case.
    title : str
        Heading of the logged table.

    Returns
    -------
    str
        The Markdown table.
    """
    from wire_fmu.export.builder import build_fmu
    from wire_fmu.registry import unit_type

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_fmu(unit_type(unit).facade_path, Path(tmp))
        for case in cases:
            rows.append(measure(fmu, case, steps))
            row = rows[-1]
            logger.info(
                "%s: %.3f ms Python, %.3f ms compiled, %.3f ms FMU",
                case.label,
                row.python_ms,
                row.core_ms,
                row.fmu_ms,
            )
    text = table(rows)
    logger.info("\n%s:\n%s", title, text)
    return text


def unit_benchmark(
    description: str, unit: str, cases: Sequence[Case], title: str, argv: list[str] | None
) -> None:
    """Run a unit benchmark from its command line: measure, log, and write ``--out``.

    Parameters
    ----------
    description : str
        The benchmark's description for ``--help``.
    unit : str
        Name of our unit type, e.g. ``"Hydraulics"``.
    cases : sequence of Case
        The manoeuvres.
    title : str
        Heading of the table.
    argv : list of str or None
        The arguments; None reads the command line.
    """
    args = command_line(description, argv)
    text = run_cases(unit, cases, args.steps, title)
    if args.out:
        args.out.write_text(text + "\n")
