"""Event-synchronised macro steps: units tell when their mode changed inside a step, and
with ``run.synchronise_events`` the master steps every unit to that instant.

Unit level: the kinetostatic winch crosses a layer edge at a time known in closed form
(``t0 + (phi_edge - phi0) / omega``); ``mode_change_time`` must say exactly that, and
stay as it was through steps in which nothing happened. Master level: on the riser
tensioner, whose cylinder seal sticks and breaks away within the first second of heave,
no unit's mode change may lie inside an accepted step once the steps are synchronised --
and without synchronisation some do (so the check can fail).
"""

from __future__ import annotations

import pytest

from wire_fmu.core.framework.unit import MODE_CHANGE_TIME as CORE_MODE_CHANGE_TIME
from wire_fmu.core.framework.unit import Causality
from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit
from wire_fmu.core.units.winch.unit import WinchUnit
from wire_fmu.master.macro_step import MODE_CHANGE_TIME, SYNC_RESOLUTION_NS
from wire_fmu.master.run import run_scene
from wire_fmu.master.scene import SceneError, parse_scene

from .winch_helpers import make_unit

STOP_TIME = 1.0
"""Simulated riser time, s: the seal's first stick/slip switches."""


def test_a_layer_change_is_told_at_its_closed_form_time():
    """Kinetostatic winch paying out at a constant speed: the rope leaves layer k at
    ``phi = theta0 - k Theta``; the step that crosses it reports that time exactly."""
    speed = 2.0  # rad/s, paying out
    unit = make_unit("rope_layers", **{"drum.speed_command": speed})
    model = unit.model
    _, high = model.drum.phi_bounds(model.layer)  # paying out leaves the layer at its top
    crossing = high / speed  # s, from phi = 0 at t = 0
    h = 0.01
    k = int(crossing // h)
    for i in range(k):
        assert unit.advance(i * h, h).success
        assert unit.values[MODE_CHANGE_TIME] == 0.0  # nothing happened yet
    assert unit.advance(k * h, h).success
    assert k * h < crossing < (k + 1) * h
    assert unit.values[MODE_CHANGE_TIME] == pytest.approx(crossing, rel=1e-12)


def _mode_changes_inside_steps(out, synchronise: bool) -> tuple[int, int]:
    """Run the riser; count the accepted steps in which a unit's mode changed strictly
    inside (more than the synchronisation resolution from the step's end)."""
    inside = []

    class Watch:
        def on_start(self, sim):
            self.counts = {
                name: int(sim.slaves[name].get(["mode_changes"])["mode_changes"])
                for name in sim.event_time_units
            }
            self.t = sim.time

        def on_step(self, sim):
            for name in sim.event_time_units:
                slave = sim.slaves[name]
                count = int(slave.get(["mode_changes"])["mode_changes"])
                if count != self.counts[name]:
                    when = float(slave.get([MODE_CHANGE_TIME])[MODE_CHANGE_TIME])
                    if (sim.time - when) * 1e9 > SYNC_RESOLUTION_NS and when > self.t:
                        inside.append((name, self.t, when, sim.time))
                    self.counts[name] = count
            self.t = sim.time

        def on_end(self, sim, result):
            pass

    outcome = run_scene(
        "riser_tensioner",
        out,
        plots=False,
        stop_time=STOP_TIME,
        step=0.002,
        synchronise_events=synchronise,
        observers=[Watch()],
    )
    assert outcome.result.status == "finished", outcome.result.message
    return len(inside), outcome.result.synchronised


@pytest.mark.integration
def test_synchronised_steps_leave_no_mode_change_inside_a_step(tmp_path):
    """The riser's seal switches mode inside 2 ms steps; synchronised, every switch ends
    its step (within 1 us), at the price of one shortened step per switch."""
    free_inside, free_synchronised = _mode_changes_inside_steps(tmp_path / "free", False)
    assert free_inside > 0 and free_synchronised == 0
    inside, synchronised = _mode_changes_inside_steps(tmp_path / "sync", True)
    assert inside == 0
    assert synchronised >= free_inside


def test_synchronise_events_must_be_true_or_false(tmp_path):
    """A setting of the wrong type is named with what it should be."""
    data = {"name": "x", "run": {"synchronise_events": "yes"}, "units": {}}
    with pytest.raises(SceneError, match=r"run.synchronise_events must be true or false"):
        parse_scene(data, base_dir=tmp_path)


@pytest.mark.parametrize("unit_class", [BlockTrainUnit, HydraulicsUnit, WinchUnit])
def test_mode_change_time_is_declared_on_every_unit_that_changes_mode(unit_class):
    """The three hoisting units declare it as a Real output in s, under the name the master
    asks for (the master cannot import the core, so it spells the name itself)."""
    variable = unit_class.variable(MODE_CHANGE_TIME)
    assert MODE_CHANGE_TIME == CORE_MODE_CHANGE_TIME
    assert variable.unit == "s" and variable.type is float
    assert variable.causality is Causality.output


class _MarkerLedger:
    """For every unit with both outputs, whether ``mode_change_time`` moved in each step in
    which ``mode_changes`` did, and only then (read directly, not from the master's plan)."""

    def __init__(self) -> None:
        self.steps = self.changes = 0
        self.mismatches: list[tuple[str, float]] = []

    def _read(self, sim) -> dict[str, tuple[int, float]]:
        out = {}
        for name in sim.event_time_units:
            got = sim.slaves[name].get(["mode_changes", MODE_CHANGE_TIME])
            out[name] = (int(got["mode_changes"]), float(got[MODE_CHANGE_TIME]))
        return out

    def on_start(self, sim):
        self.before, self.t = self._read(sim), sim.time

    def on_step(self, sim):
        now = self._read(sim)
        for name, (count, when) in now.items():
            counted, told = count != self.before[name][0], when != self.before[name][1]
            self.changes += counted
            if counted != told or (told and not self.t < when <= sim.time):
                self.mismatches.append((name, sim.time))
        self.before, self.t = now, sim.time
        self.steps += 1

    def on_end(self, sim, result):
        pass


@pytest.mark.integration
@pytest.mark.parametrize(("scene", "stop"), [("riser_tensioner", STOP_TIME), ("drawworks", 3.0)])
def test_mode_change_time_moves_exactly_when_mode_changes_does(tmp_path, scene, stop):
    """The master watches a unit's mode through ``mode_change_time`` alone (one get of
    Reals per step); that is right only if it moves in exactly the steps where the
    ``mode_changes`` counter does, to an instant inside the step, located or not."""
    ledger = _MarkerLedger()
    outcome = run_scene(
        scene,
        tmp_path,
        plots=False,
        stop_time=stop,
        step=0.002,
        output_interval=1.0,  # a recorded Integer output is read with its rows
        observers=[ledger],
    )
    assert outcome.result.status == "finished", outcome.result.message
    assert outcome.simulation.event_time_units  # the scene's units tell when
    assert ledger.changes > 0 and ledger.mismatches == []
    for name in outcome.simulation.event_time_units:  # the master reads no Integer per step
        own = ledger.steps + 1  # the ledger's reads, one per step and at the start
        assert outcome.simulation.slaves[name].calls["getInteger"] - own <= 2 + stop
