"""A block train's quiet steps, taken with their outputs in a few compiled calls (issue 16).

A step in which no mode changes is taken by ``quiet_step_outputs`` without the Python
between the compiled calls (inputs, undo snapshot, outputs): the same numbers to the
last bit as the general way (``advance`` then ``_update_outputs``), which the steps with
events still take. Each test steps two copies of a unit, one the quiet way where it can
and one always the general way, and compares every output after every step and the
whole state at the end.
"""

from __future__ import annotations

import math

import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.units.block_train import kernel_outputs

from .quiet_step_helpers import counted, general_way, scene_rope, step_both

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")


def riser_motion(amplitude: float, w2: float = 0.6):
    """The riser's rod and the riser heaving by ``amplitude`` (m) at ``w2`` (rad/s)."""

    def inputs(t: float) -> dict[str, float]:
        w1 = 2.0
        return {
            "mover_a.position": 0.002 * math.sin(w1 * t),
            "mover_a.velocity": 0.002 * w1 * math.cos(w1 * t),
            "mover_a.acceleration": -0.002 * w1 * w1 * math.sin(w1 * t),
            "mover_b.position": amplitude * math.sin(w2 * t),
            "mover_b.velocity": amplitude * w2 * math.cos(w2 * t),
        }

    return inputs


@pytest.mark.parametrize("interface", [True, False])
def test_the_riser_ropes_quiet_steps_give_the_general_ways_numbers(interface):
    switch = {"mover_a.interface_model": interface}
    quiet = scene_rope("riser_tensioner", **switch)
    general = general_way(scene_rope("riser_tensioner", **switch))
    taken = counted(quiet)
    step_both(quiet, general, riser_motion(0.003), 300, 0.004)
    assert all(taken)  # nothing happens: every step the quiet way
    assert quiet.get_state() == general.get_state()
    assert ("mover_a.stiffness" in quiet._quiet_plan().names) == interface


def test_steps_with_events_are_taken_the_general_way_and_the_two_agree():
    # the riser heaves by 0.5 m: the wire goes slack and snaps taut again, again and again
    quiet = scene_rope("riser_tensioner", **{"mover_a.interface_model": True})
    general = general_way(scene_rope("riser_tensioner", **{"mover_a.interface_model": True}))
    taken = counted(quiet)
    step_both(quiet, general, riser_motion(0.5, 3.0), 1000, 0.004)
    assert quiet.model.mode_changes == general.model.mode_changes > 2
    assert 0 < taken.count(False) < len(taken) // 2  # the steps with events
    assert quiet.get_state() == general.get_state()


def test_the_drawworks_quiet_steps_with_friction_links_agree_with_the_general_way():
    # 12 coordinates, bearing friction: lowering, the bearings break loose and stick
    quiet = scene_rope("drawworks", solver="rk4")
    general = general_way(scene_rope("drawworks", solver="rk4"))
    taken = counted(quiet)

    def lowering(t: float) -> dict[str, float]:
        rate = -1.0 if t < 0.2 else 0.0
        return {"line_a.payout_rate": rate, "line_a.payout": -1.0 * min(t, 0.2)}

    step_both(quiet, general, lowering, 200, 0.002)
    assert quiet.model.mode_changes == general.model.mode_changes > 0
    assert taken.count(True) > 100 and not all(taken)
    assert quiet.get_state() == general.get_state()
    assert quiet.model.solver.rhs_calls == general.model.solver.rhs_calls


def test_outputs_that_are_not_finite_send_the_step_the_general_way(monkeypatch):
    quiet = scene_rope("riser_tensioner")
    general = general_way(scene_rope("riser_tensioner"))
    taken = counted(quiet)
    computed = kernel_outputs.quiet_step_outputs

    def not_finite(*args):
        return (*computed(*args)[:-1], False)

    monkeypatch.setattr(kernel_outputs, "quiet_step_outputs", not_finite)
    step_both(quiet, general, riser_motion(0.003), 20, 0.004)
    assert not any(taken)  # nothing was taken the quiet way, and nothing changed by trying
    assert quiet.get_state() == general.get_state()


def test_a_commanded_break_is_taken_the_general_way():
    quiet = scene_rope("riser_tensioner")
    taken = counted(quiet)
    quiet.values["break_segment"] = 2
    assert quiet.advance(0.0, 0.004).success
    assert taken == [False] and quiet.values["broken"]
