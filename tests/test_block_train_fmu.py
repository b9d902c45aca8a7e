"""The block train's ports, causality and feedthrough, and its facade, without building."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wire_fmu.core.framework.unit import Causality
from wire_fmu.core.units.block_train.reevings import drilling_block_train
from wire_fmu.core.units.block_train.unit import BlockTrainUnit

from .block_train_helpers import make_unit
from .facade_checks import (
    assert_maps_every_declared_variable,
    load_facade_class,
    started_facade,
)

INPUTS = [
    v.name for v in BlockTrainUnit.VARIABLES if v.causality is Causality.input and v.type is float
]


def tensioner_like() -> dict:
    """A rope from a line end over a sheave on a driven rod to an anchor on a block."""
    return {
        "rope": {"axial_stiffness": 1e7, "damping": 1e4},
        "bodies": {
            "rod": {"kind": "driven", "direction": [1, 0, 0], "port": "mover_a"},
            "riser": {"kind": "block", "mass": 500.0, "direction": [0, 1, 0], "port": "block_a"},
        },
        "sheaves": {"moving": {"body": "rod", "centre": [2, 5, 0], "radius": 0.5}},
        "anchors": {"ring": {"body": "riser", "point": [2.5, 0, 0]}},
        "path": [
            {"line_end": "line_a", "point": [-3, 5.5, 0]},
            {"sheave": "moving", "wrap": "cw"},
            {"anchor": "ring"},
        ],
    }


def test_declarations_are_sound():
    assert BlockTrainUnit.check_declarations() == []
    for var in BlockTrainUnit.VARIABLES:
        assert var.description
        if var.type is float:
            assert var.unit


def test_state_outputs_have_no_direct_feedthrough():
    """Block motion is a state: it depends on no input within a step."""
    for name in ("block_a.position", "block_a.velocity", "dissipated_energy", "external_work"):
        assert BlockTrainUnit.variable(name).depends_on == ()


def perturbed_outputs(unit, name, delta):
    before = dict(unit.values)
    unit.values[name] += delta
    unit.evaluate_outputs()
    after = dict(unit.values)
    unit.values[name] -= delta
    unit.evaluate_outputs()
    return before, after


@pytest.mark.parametrize("effects", ["", "rope_damping"])
def test_declared_feedthrough_matches_the_numbers(effects):
    """An output declared without dependencies never moves when an input does;
    the rope forces move with the kinematic inputs of their ports."""
    unit = make_unit(tensioner_like(), effects)
    outputs = [v for v in BlockTrainUnit.VARIABLES if v.causality is Causality.output]
    for name in INPUTS:
        before, after = perturbed_outputs(unit, name, 1e-3)
        for var in outputs:
            if not var.depends_on:
                assert after[var.name] == before[var.name], (name, var.name)
    _, after = perturbed_outputs(unit, "line_a.payout", -1e-3)
    assert after["line_a.tension"] > unit.values["line_a.tension"]
    _, after = perturbed_outputs(unit, "mover_a.position", -1e-3)  # rod retracts: rope eases
    assert after["mover_a.force"] != unit.values["mover_a.force"]
    if effects:
        _, after = perturbed_outputs(unit, "line_a.payout_rate", -1e-2)
        assert after["line_a.tension"] > unit.values["line_a.tension"]


def test_evaluating_outputs_leaves_the_state_alone():
    unit = make_unit(tensioner_like(), "rope_damping")
    state = json.dumps(unit.get_state())
    unit.values["mover_a.position"] = 0.01
    unit.evaluate_outputs()
    assert json.dumps(unit.get_state()) == state


def test_facade_maps_every_declared_variable():
    facade = load_facade_class("block_train", "BlockTrain")(instance_name="bt", resources=None)
    assert_maps_every_declared_variable(facade, BlockTrainUnit, "BlockTrain")


def test_facade_steps_like_the_core():
    """Same inputs, same numbers: the facade adds nothing to the physics."""
    effects = "rope_damping,sheave_inertia,bearing_friction"
    facade, refs = started_facade(load_facade_class("block_train", "BlockTrain"), "bt", effects)
    unit = make_unit(drilling_block_train(4), effects)
    for i in range(20):
        for target in (facade, None):
            if target is None:
                unit.values["line_a.payout_rate"] = 0.2
                unit.values["line_a.payout"] = 0.2 * i * 0.01
                unit.advance(i * 0.01, 0.01)
            else:
                facade.set_real(
                    [refs["line_a.payout_rate"], refs["line_a.payout"]], [0.2, 0.2 * i * 0.01]
                )
                facade.do_step(i * 0.01, 0.01)
    names = ["line_a.tension", "block_a.position", "energy_balance"]
    got = facade.get_real([refs[n] for n in names])
    assert got == [unit.values[n] for n in names]
    assert np.isfinite(got).all()
