"""Cost of one doStep of a 10-line block train, per effect set, and its FMI overhead.

Run ``python -m wire_fmu.bench.block_train [--steps N] [--out FILE]``. For
each effect set the same drawworks manoeuvre (lower at 0.5 m/s, then hold)
is stepped

* in the core, calling :meth:`BlockTrainUnit.advance` directly, and
* through the built FMU with fmpy (set two inputs, ``fmi2DoStep``, get
  five outputs), as a master would.

The FMU runs in this process and uses the ``wire_fmu`` already imported
here, so the time spent inside ``advance`` during the FMU run is measured
too; the FMI overhead is the rest of the FMU's time (pythonfmu's C++ and
Python layers, the facade, fmpy's ctypes calls), as a share. Times are
medians over the steps (wall clock, ``time.perf_counter``) after a warm-up.
"""

from __future__ import annotations

import argparse
import json
import logging
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from wire_fmu.core.block_train import BLOCK_TRAIN_EFFECTS
from wire_fmu.core.block_train_unit import BlockTrainUnit
from wire_fmu.core.reevings import drilling_block_train

logger = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parents[2]
STEP = 0.01  # s, communication step
OUTPUTS = ["line_a.tension", "block_a.position", "block_a.velocity", "stored_energy",
           "energy_balance"]


@dataclass(frozen=True)
class Row:
    """Benchmark figures of one effect set."""

    effects: str
    states: int
    core_ms: float
    fmu_ms: float
    overhead_ms: float

    @property
    def overhead_share(self) -> float:
        """Share of the FMU step spent outside the physics (FMI, pythonfmu, fmpy)."""
        return self.overhead_ms / self.fmu_ms


def effect_sets() -> list[str]:
    """None, each effect alone, and all together."""
    alone = [e for e in BLOCK_TRAIN_EFFECTS.names if e != "spatial_geometry"]
    sets = [""]
    for name in alone:
        needs = [r for e in BLOCK_TRAIN_EFFECTS.effects if e.name == name for r in e.requires]
        sets.append(",".join(needs + [name]))
    sets.append(",".join(alone))
    return sets


def rate(i: int) -> float:
    """Fast-line speed of the manoeuvre, m/s."""
    return 0.5 if i < 100 else 0.0


def time_core(effects: str, steps: int) -> tuple[float, int]:
    unit = BlockTrainUnit("bench")
    unit.values["reeving"] = json.dumps(drilling_block_train(10))
    unit.values["effects"] = effects
    unit.configure()
    unit.initialize(0.0)
    payout, samples = 0.0, []
    for i in range(steps):
        unit.values["line_a.payout"], unit.values["line_a.payout_rate"] = payout, rate(i)
        start = time.perf_counter()
        unit.advance(i * STEP, STEP)
        samples.append(time.perf_counter() - start)
        payout += rate(i) * STEP
    return statistics.median(samples[5:]) * 1e3, unit.model.state.size


class _AdvanceTimer:
    """Accumulates the time spent in ``BlockTrainUnit.advance`` (wraps it)."""

    def __init__(self) -> None:
        self.elapsed = 0.0
        self._original = BlockTrainUnit.advance

    def __enter__(self):
        original, timer = self._original, self

        def timed(unit, time_, step):
            start = time.perf_counter()
            try:
                return original(unit, time_, step)
            finally:
                timer.elapsed += time.perf_counter() - start

        BlockTrainUnit.advance = timed
        return self

    def __exit__(self, *exc) -> None:
        BlockTrainUnit.advance = self._original


def time_fmu(fmu_path: Path, effects: str, steps: int) -> tuple[float, float]:
    """Median ms per FMU step and median ms outside ``advance``."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu_path))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu_path)),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bench")
    fmu.instantiate()
    fmu.setString([refs["reeving"], refs["effects"]],
                  [json.dumps(drilling_block_train(10)), effects])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    inputs = [refs["line_a.payout"], refs["line_a.payout_rate"]]
    outputs = [refs[n] for n in OUTPUTS]
    payout, samples, outside = 0.0, [], []
    with _AdvanceTimer() as timer:
        for i in range(steps):
            inside = timer.elapsed
            start = time.perf_counter()
            fmu.setReal(inputs, [payout, rate(i)])
            fmu.doStep(currentCommunicationPoint=i * STEP, communicationStepSize=STEP)
            fmu.getReal(outputs)
            total = time.perf_counter() - start
            samples.append(total)
            outside.append(total - (timer.elapsed - inside))
            payout += rate(i) * STEP
    fmu.terminate()
    fmu.freeInstance()
    return statistics.median(samples[5:]) * 1e3, statistics.median(outside[5:]) * 1e3


def run(steps: int) -> list[Row]:
    """Measure every effect set; build the FMU into a temporary folder first."""
    from wire_fmu.export.builder import build_fmu

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        fmu_path = build_fmu(ROOT / "models" / "block_train.py", Path(tmp))
        for effects in effect_sets():
            core_ms, states = time_core(effects, steps)
            fmu_ms, overhead_ms = time_fmu(fmu_path, effects, steps)
            rows.append(Row(effects or "(none)", states, core_ms, fmu_ms, overhead_ms))
            logger.info("%-70s %6.3f ms core, %6.3f ms FMU (%.3f ms FMI)", effects or "(none)",
                        core_ms, fmu_ms, overhead_ms)
    return rows


def table(rows: list[Row]) -> str:
    """Markdown table of the figures."""
    lines = [
        "| effects | states | core ms/step | FMU ms/step | FMI overhead ms | share |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(f"| {r.effects} | {r.states} | {r.core_ms:.3f} | {r.fmu_ms:.3f} | "
                     f"{r.overhead_ms:.3f} | {100 * r.overhead_share:.1f} % |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200, help="steps per measurement")
    parser.add_argument("--out", type=Path, help="also write the table (Markdown) here")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    text = table(run(args.steps))
    logger.info("\n10-line block train, ros2 solver, max internal step 1 ms, "
                "communication step %g s:\n%s", STEP, text)
    if args.out:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()
