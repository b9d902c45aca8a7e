"""Small helpers shared by the block-train tests: make a unit, run it."""

from __future__ import annotations

import json
from collections.abc import Callable

import numpy as np

from wire_fmu.core.units.block_train.unit import BlockTrainUnit


def make_unit(reeving: dict, effects: str = "", **params) -> BlockTrainUnit:
    """A configured, initialised block-train unit."""
    unit = BlockTrainUnit("test")
    unit.values["reeving"] = json.dumps(reeving)
    unit.values["effects"] = effects
    for name, value in params.items():
        unit.values[name] = value
    unit.configure()
    unit.initialize(0.0)
    return unit


def run(
    unit: BlockTrainUnit,
    duration: float,
    step: float,
    drive: Callable[[float, BlockTrainUnit], None] | None = None,
    record: tuple[str, ...] = ("block_a.position",),
) -> dict[str, np.ndarray]:
    """Step ``unit`` for ``duration`` seconds; ``drive(t, unit)`` sets inputs.

    Payout inputs are advanced with their rates so that position and rate
    stay consistent, as a master connecting a winch would do.
    """
    n = int(round(duration / step))
    out = {name: np.empty(n + 1) for name in ("time", *record)}
    out["time"][0] = 0.0
    for name in record:
        out[name][0] = unit.values[name]
    t = 0.0
    for i in range(n):
        if drive is not None:
            drive(t, unit)
        result = unit.advance(t, step)
        assert result.success, result.message
        for port in ("line_a", "line_b"):
            unit.values[f"{port}.payout"] += unit.values[f"{port}.payout_rate"] * step
        for port in ("mover_a", "mover_b"):
            unit.values[f"{port}.position"] += unit.values[f"{port}.velocity"] * step
        t = (i + 1) * step
        out["time"][i + 1] = t
        for name in record:
            out[name][i + 1] = unit.values[name]
    return out


FALL_MASS, FALL_LENGTH, FALL_EA, FALL_PRETENSION = 1000.0, 10.0, 1.0e7, 5000.0
"""The released fall of the study tests: kg, m, N, N."""


def fall_scene(**extra):
    """A mass released on a taut single fall (``extra`` adds or replaces scene sections)."""
    from pathlib import Path

    from wire_fmu.core.units.block_train.reevings import single_fall
    from wire_fmu.master.scene import parse_scene

    data = {
        "name": "fall",
        "run": {"stop_time": 1.0, "step": 0.01},
        "units": {
            "rope": {
                "fmu": "BlockTrain",
                "parameters": {
                    "reeving": single_fall(
                        mass=FALL_MASS, length=FALL_LENGTH, axial_stiffness=FALL_EA
                    ),
                    "initial_equilibrium": False,
                    "pretension": FALL_PRETENSION,
                },
            }
        },
    }
    data.update(extra)
    return parse_scene(data, base_dir=Path("."))


def long_form_rope_data(bond: dict | None = None, **extra) -> dict:
    """A winch ``w`` and a block train ``r`` on one rope bond written out long-hand (no
    interface model offered), as plain scene data.

    Parameters
    ----------
    bond : dict, optional
        More keys of the bond (e.g. ``ramp``).
    **extra
        More top-level keys of the scene (``run``, ``study``, ...).
    """
    return {
        "units": {"w": {"fmu": "Winch"}, "r": {"fmu": "BlockTrain"}},
        "bonds": [
            {
                "name": "rope",
                "kind": "rope",
                "effort": "r.line_a.tension -> w.rope.tension",
                "flow": "w.rope.payout_rate -> r.line_a.payout_rate",
                "position": "w.rope.payout -> r.line_a.payout",
                **(bond or {}),
            }
        ],
        **extra,
    }
