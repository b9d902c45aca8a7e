"""One compiled entry point per kernel, loaded when the unit is initialised (issue 16).

A compiled function is loaded from the on-disk cache at its first call with given
argument types. The block train has one entry point for all it does from Python (the
start's evaluation, its quiet steps, the general way's step and the loop after an
event); the winch's loop after an event goes through its quiet step's own function
(``resume``); initialisation calls each with a step of nothing, so that no loading
falls inside the stepping. The cylinder's quiet step and its loop after an event are
two functions, and initialisation loads both.
These tests check that that call takes the very argument types of the steps that
follow (else it would load a specialisation no step uses) and that it changes nothing.
"""

from __future__ import annotations

import json
import tomllib

import numba
import numpy as np
import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled_step import CompiledFixedStep
from wire_fmu.core.units.block_train import kernel as block_train_kernel
from wire_fmu.core.units.block_train import kernel_outputs as block_train_kernel_outputs
from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.core.units.hydraulics import kernel as hydraulics_kernel
from wire_fmu.core.units.winch import kernel as winch_kernel
from wire_fmu.master.run import find_scene

from .hydraulics_helpers import make_free_rod
from .quiet_step_helpers import scene_rope
from .winch_helpers import make_unit as make_winch

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")


def recorded_calls(monkeypatch, module, name: str = "quiet_step") -> list[tuple]:
    """The numba types of every call of ``module.<name>`` from now on (still called)."""
    calls: list[tuple] = []
    original = getattr(module, name)

    def recording(*args):
        calls.append(tuple(numba.typeof(a) for a in args))
        return original(*args)

    monkeypatch.setattr(module, name, recording)
    return calls


def drawworks_rope() -> BlockTrainUnit:
    """The drawworks scene's block train (12 coordinates, bearing friction), not initialised."""
    scene = tomllib.loads(find_scene("drawworks").read_text())["units"]["rope"]
    unit = BlockTrainUnit("rope")
    unit.values["reeving"] = json.dumps(scene["parameters"]["reeving"])
    unit.values["effects"] = ",".join(scene["effects"])
    unit.values["solver"] = "rk4"
    unit.configure()
    return unit


def test_the_block_train_loads_one_entry_with_the_types_all_its_modes_use(monkeypatch):
    # the start's evaluation, the quiet steps, the general way's step and its resume
    # after events: one compiled function, called with the same argument types
    entry = block_train_kernel_outputs.quiet_step_outputs
    calls, modes = [], []

    def recording(*args):
        calls.append(tuple(numba.typeof(a) for a in args))
        modes.append(args[22])
        return entry(*args)

    monkeypatch.setattr(block_train_kernel_outputs, "quiet_step_outputs", recording)
    direct = recorded_calls(monkeypatch, block_train_kernel)  # the step's own function
    unit = drawworks_rope()
    assert unit.model.compiled and isinstance(unit.model.solver, CompiledFixedStep)
    unit.initialize(0.0)
    assert calls  # at initialisation: the preload, the start's evaluation
    unit.values["line_a.payout_rate"] = -1.0  # lowering: the bearings break loose
    for k in range(50):
        unit.values["line_a.payout"] = -1.0 * k * 0.002
        assert unit.advance(k * 0.002, 0.002).success
    assert unit.model.mode_changes > 0  # events: the loop went on through ``resume``
    kinds = block_train_kernel_outputs
    assert set(modes) == {kinds.EVALUATE, kinds.STEP_WITH_OUTPUTS, kinds.STEP, kinds.RESUME}
    assert set(calls) == {calls[0]}
    assert direct == []  # never called from Python: not loaded on its own


def test_the_preload_changes_nothing():
    unit = drawworks_rope()
    unit.initialize(0.0)
    model = unit.model
    state, held = model.state.copy(), model.held_vector.copy()
    counts = (model.solver.steps, model.solver.rhs_calls)
    outputs = dict(unit.values)
    model.preload_kernel(0.0)
    np.testing.assert_array_equal(model.state, state)
    np.testing.assert_array_equal(model.held_vector, held)
    assert (model.solver.steps, model.solver.rhs_calls) == counts
    assert unit.values == outputs


def test_the_winch_loads_its_step_with_the_types_its_steps_use(monkeypatch):
    calls = recorded_calls(monkeypatch, winch_kernel)
    unit = make_winch("drum_inertia,band_brake", solver="rk4", brake__lever_force=0.0)
    assert isinstance(unit.model.solver, CompiledFixedStep)
    assert calls
    unit.values["tension"] = 5e4
    for k in range(50):
        unit.values["brake.lever_force"] = 2000.0 if k >= 20 else 0.0  # the brake catches
        assert unit.advance(k * 0.002, 0.002).success
    assert unit.model.mode_changes > 0
    assert len(calls) > 50
    assert set(calls) == {calls[0]}


def test_the_cylinder_loads_its_loop_after_an_event_before_its_first_step(monkeypatch):
    calls = recorded_calls(monkeypatch, hydraulics_kernel, "resume")
    unit = make_free_rod("seal_friction", 0.05, solver="rk4")  # friction stops the rod
    assert isinstance(unit.model.solver, CompiledFixedStep)
    assert len(calls) == 1  # the preload, at initialisation
    for k in range(100):
        assert unit.advance(k * 0.002, 0.002).success
    assert unit.model.mode_changes > 0  # the seal stuck: the loop went on through ``resume``
    assert len(calls) > 1
    assert set(calls) == {calls[0]}


def test_the_block_train_loads_its_quiet_steps_outputs_at_initialisation(monkeypatch):
    unit = drawworks_rope()
    calls = recorded_calls(monkeypatch, block_train_kernel_outputs, "quiet_step_outputs")
    unit.initialize(0.0)
    assert len(calls) == 2  # the loop's preload and the start's evaluation
    for k in range(20):
        unit.values["line_a.payout"] = 0.01 * k * 0.002
        unit.values["line_a.payout_rate"] = 0.01
        assert unit.advance(k * 0.002, 0.002).success
    assert len(calls) > 10  # the quiet steps
    assert set(calls) == {calls[0]}


def test_the_block_trains_start_is_evaluated_by_its_quiet_steps_entry_alone(monkeypatch):
    # the start's summary and interface models come from the call that loads the quiet
    # step's entry point: no other compiled function is loaded for them
    from wire_fmu.core.units.block_train import kernel_interface

    own = {"summary": recorded_calls(monkeypatch, block_train_kernel, "summary")}
    own["interface"] = recorded_calls(monkeypatch, kernel_interface, "port_linearisations")
    unit = scene_rope("riser_tensioner", **{"mover_a.interface_model": True})
    assert own == {"summary": [], "interface": []}
    # the same outputs, to the bit, as evaluated by those functions themselves
    unit.model.start_table = None
    unit.model._step_summary = None
    kept = dict(unit.values)
    unit._update_outputs()
    assert len(own["summary"]) > 0 and len(own["interface"]) == 1
    assert unit.values == kept
    assert unit.initial_energy == unit.model.stored_energy(0.0)
