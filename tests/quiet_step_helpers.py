"""Helpers of the quiet-step tests: a unit made to step the general way, a record of which
steps a unit took the quiet way, two units stepped side by side, a shipped scene's rope."""

from __future__ import annotations

import json
import tomllib

from wire_fmu.core.framework.unit import Unit
from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.master.run import find_scene


def general_way(unit: Unit) -> Unit:
    """``unit`` made to take every step the general way."""
    unit._take_quiet_step = lambda time, step: False
    return unit


def counted(unit: Unit) -> list[bool]:
    """Whether each step of ``unit`` from now on was taken the quiet way."""
    taken: list[bool] = []
    quiet = unit._take_quiet_step

    def counting(time, step):
        taken.append(quiet(time, step))
        return taken[-1]

    unit._take_quiet_step = counting
    return taken


def step_both(quiet, general, inputs, steps: int, h: float) -> None:
    """Step both units with ``inputs(t)`` set before each step; their outputs must agree
    to the last bit after every step."""
    for k in range(steps):
        t = k * h
        for unit in (quiet, general):
            unit.values.update(inputs(t))
            result = unit.advance(t, h)
            assert result.success, result.message
        assert quiet.values == general.values, f"outputs differ after the step from t = {t}"


def scene_rope(scene: str, **values) -> BlockTrainUnit:
    """The block train of a shipped scene, with its parameters and ``values``, initialised."""
    spec = tomllib.loads(find_scene(scene).read_text())["units"]["rope"]
    unit = BlockTrainUnit("rope")
    unit.values["reeving"] = json.dumps(spec["parameters"]["reeving"])
    unit.values["effects"] = ",".join(spec["effects"])
    for name, value in spec["parameters"].items():
        if name != "reeving":
            unit.values[name] = value
    unit.values.update(values)
    unit.configure()
    unit.initialize(0.0)
    return unit
