"""Cost of one doStep of a 10-line block train, per effect set, and its FMI overhead.

Run ``python -m wire_fmu.bench.block_train [--steps N] [--out FILE]``. Each
effect set steps the same drawworks manoeuvre (lower at 0.5 m/s for 1 s,
then the drum stops) in the core and through the built FMU; see
:mod:`wire_fmu.bench.common` for what is timed.
"""

from __future__ import annotations

import json
import logging

from wire_fmu.bench.common import Case, unit_benchmark
from wire_fmu.core.units.block_train.model import BLOCK_TRAIN_EFFECTS
from wire_fmu.core.units.block_train.reevings import drilling_block_train
from wire_fmu.core.units.block_train.unit import BlockTrainUnit

logger = logging.getLogger(__name__)

STEP = 0.01  # s, communication step
SPEED = 0.5  # m/s, fast line while lowering
OUTPUTS = (
    "line_a.tension",
    "block_a.position",
    "block_a.velocity",
    "stored_energy",
    "energy_balance",
)


def effect_sets() -> list[str]:
    """None, each effect alone (with what it needs), and all planar effects together."""
    alone = [e for e in BLOCK_TRAIN_EFFECTS.effects if e.name != "spatial_geometry"]
    sets = [""] + [",".join((*e.requires, e.name)) for e in alone]
    sets.append(",".join(e.name for e in alone))
    return sets


def lowering(i: int) -> dict[str, float]:
    """Fast line paid out at SPEED for 100 steps, then held.

    Parameters
    ----------
    i : int
        Step number, from 0.

    Returns
    -------
    dict of str to float
        ``line_a.payout`` (m) and ``line_a.payout_rate`` (m/s).
    """
    moving = min(i, 100)
    return {"line_a.payout": SPEED * STEP * moving, "line_a.payout_rate": SPEED if i < 100 else 0.0}


def cases() -> list[Case]:
    """One case per effect set."""
    reeving = json.dumps(drilling_block_train(10))
    return [
        Case(
            effects or "(none)",
            BlockTrainUnit,
            {"reeving": reeving, "effects": effects},
            inputs=lowering,
            outputs=OUTPUTS,
            step=STEP,
        )
        for effects in effect_sets()
    ]


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    title = f"10-line block train, ros2, max internal step 1 ms, communication step {STEP:g} s"
    unit_benchmark(__doc__.splitlines()[0], "BlockTrain", cases(), title, argv)


if __name__ == "__main__":
    main()
