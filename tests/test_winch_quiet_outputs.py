"""A winch's quiet steps, taken with their outputs in one compiled call (issue 16).

A step in which the brake keeps its mode and no event falls is taken by
``WinchModel.quiet_step_outputs`` without the Python around the compiled step (inputs
object, checks, undo snapshot, report): the same numbers to the last bit as the general
way (``advance`` then ``_update_outputs``), which steps with events, brake modes to
settle and inputs the winch cannot take still go. Each test steps two copies of a unit,
one the quiet way where it can and one always the general way, and compares every
output after every step and the whole state at the end.
"""

from __future__ import annotations

import math

import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.units.winch import kernel
from wire_fmu.core.units.winch.base import FLAT_INPUTS
from wire_fmu.core.units.winch.unit import WinchUnit
from wire_fmu.core.units.winch.variables import winch_inputs, winch_outputs

from .quiet_step_helpers import counted, general_way, step_both
from .winch_helpers import BRAKE, make_unit, two_mass

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")

ALL_EFFECTS = "drum_inertia,band_brake,motor_characteristic,rope_layers,elastic_drive_train"
LAYERED = {"rope_on_drum": 400.0, "drum_wraps_per_layer": 30, "drum_layers": 6}


def pair(effects: str, **params) -> tuple[WinchUnit, WinchUnit, list[bool]]:
    """Two equal winches, the second made to step the general way, and the record of
    which of the first one's steps were quiet."""
    quiet = make_unit(effects, **params)
    general = general_way(make_unit(effects, **params))
    return quiet, general, counted(quiet)


def lower_then_brake(t: float) -> dict[str, float]:
    """Lower under 1.2e5 N with the motor holding back, brake hard at 0.3 s, hold."""
    return {
        "rope.tension": 1.2e5,
        "motor.command": 2.0e3 if t < 0.3 else 0.0,
        "brake.lever_force": 0.0 if t < 0.3 else 2.0e4,
    }


def test_the_outputs_a_quiet_step_writes_are_the_winchs_own_outputs():
    outputs = {v.name for v in winch_outputs()}
    inputs = {v.name for v in winch_inputs()}
    assert set(kernel.OUTPUTS) <= outputs
    assert set(FLAT_INPUTS) <= inputs
    # what a quiet step leaves alone is what it cannot change
    left = outputs - set(kernel.OUTPUTS)
    assert left == {"drum.layer", "drum.radius", "brake.state", "mode_changes", "mode_change_time"}


@pytest.mark.parametrize("solver", ["rk4", "ros2"])
def test_lowering_braking_and_holding_give_the_general_ways_numbers(solver):
    params = {**BRAKE, **LAYERED, "motor_slope": 40.0, "solver": solver}
    params["drive_train"] = two_mass(2.0, 40.0, 2.0e6, damping=50.0)
    quiet, general, taken = pair(ALL_EFFECTS, **params)
    step_both(quiet, general, lower_then_brake, 400, 0.002)
    # released while lowering, slipping, then held: quiet steps in every phase, and the
    # steps with the brake's events taken the general way
    assert quiet.model.mode_changes == general.model.mode_changes >= 2
    assert taken.count(True) > 300 and not all(taken)
    assert quiet.values["brake.state"] == 2  # holding at the end
    assert quiet.get_state() == general.get_state()
    assert quiet.model.solver.rhs_calls == general.model.solver.rhs_calls


def test_a_layer_change_is_taken_the_general_way():
    params = {**LAYERED, "rope_on_drum": 20.0, "drum_wraps_per_layer": 3}
    quiet, general, taken = pair("drum_inertia,rope_layers", **params)

    def haul(t: float) -> dict[str, float]:
        return {"rope.tension": 1.0e3, "motor.command": -3.0e4}

    step_both(quiet, general, haul, 300, 0.002)
    assert quiet.values["drum.layer"] > 1  # wound onto the next layers
    assert quiet.model.mode_changes == general.model.mode_changes > 0
    assert taken.count(False) == quiet.model.mode_changes
    assert quiet.get_state() == general.get_state()


def test_the_rope_models_quiet_steps_give_the_general_ways_numbers():
    quiet, general, taken = pair("drum_inertia,band_brake", **BRAKE)

    def rope(t: float) -> dict[str, float]:
        return {
            "rope.tension": 1.0e5 + 2.0e4 * math.sin(3.0 * t),
            "rope.stiffness": 2.0e6,
            "rope.damping": 1.0e4,
            "rope.effort_rate": 6.0e4 * math.cos(3.0 * t),
            "rope.reference_position": 0.01 * t,
            "rope.reference_velocity": 0.01,
            "brake.lever_force": 0.0,
        }

    step_both(quiet, general, rope, 300, 0.002)
    assert all(taken)
    assert quiet.model.inputs.rope_model == general.model.inputs.rope_model
    assert quiet.get_state() == general.get_state()


def test_inputs_the_winch_cannot_take_refuse_the_step_by_name_the_general_way():
    quiet = make_unit("drum_inertia")
    taken = counted(quiet)
    quiet.values["rope.stiffness"] = -1.0
    result = quiet.advance(0.0, 0.002)
    assert not result.success and "rope.stiffness" in result.message
    quiet.values["rope.stiffness"] = 0.0
    quiet.values["motor.command"] = math.nan
    result = quiet.advance(0.0, 0.002)
    assert not result.success and "motor.command" in result.message
    assert taken == [False, False] and quiet.time == 0.0


def test_outputs_that_are_not_finite_send_the_step_the_general_way(monkeypatch):
    quiet, general, taken = pair("drum_inertia,band_brake", **BRAKE)
    computed = kernel.quiet_step

    def not_finite(*args):
        return (*computed(*args)[:-1], False)

    monkeypatch.setattr(kernel, "quiet_step", not_finite)
    step_both(quiet, general, lower_then_brake, 20, 0.002)
    assert not any(taken)  # nothing was taken the quiet way, and nothing changed by trying
    assert quiet.get_state() == general.get_state()


def test_a_step_refused_after_a_quiet_one_restores_the_inputs_held_before_it():
    quiet, general, _ = pair("drum_inertia,band_brake", **BRAKE)
    step_both(quiet, general, lower_then_brake, 5, 0.002)
    held = quiet.model.inputs
    quiet.values["rope.tension"] = math.inf
    assert not quiet.advance(0.01, 0.002).success
    assert quiet.model.inputs == held  # the quiet attempt changed nothing
