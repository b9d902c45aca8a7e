"""A cylinder's quiet steps, taken without the undo snapshot (issue 16).

A step in which nothing happens is taken by ``quiet_advance`` (one call of the compiled
kernel) and the outputs written from its report; every other step -- an event, a
refinement at a stop, inputs the cylinder cannot take -- goes the general way. The two
must give the same numbers to the last bit: each test steps two copies of a cylinder,
one the quiet way where it can and one always the general way, and compares every
output after every step and the whole state at the end.
"""

from __future__ import annotations

import math

import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.units.hydraulics import stepping
from wire_fmu.core.units.hydraulics.interface import INTERFACE_INPUTS

from .hydraulics_helpers import ALL_EFFECTS, F_EQ, make_free_rod, make_unit, quiet_cylinder
from .quiet_step_helpers import counted, general_way

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")


def step_both(quiet, general, inputs, steps: int, h: float) -> None:
    """Step both with ``inputs(t)`` set before each step; outputs equal after every step
    (a refusal, too, the same for both)."""
    for k in range(steps):
        t = k * h
        results = []
        for unit in (quiet, general):
            unit.values.update(inputs(t))
            results.append(unit.advance(t, h))
        assert results[0] == results[1], f"step from t = {t}"
        assert quiet.values == general.values, f"outputs differ after the step from t = {t}"


def both(make):
    """Two cylinders made by ``make()``: one quiet where it can, one always general."""
    return make(), general_way(make())


def swaying(force0: float, interface: bool):
    """A rod force swinging about ``force0`` (N); with an interface model, if asked."""

    def inputs(t: float) -> dict[str, float]:
        out = {"rod.force": force0 + 2.0e4 * math.sin(2.0 * t)}
        if interface:
            model = (3.0e7, 2.0e5, 4.0e4 * math.cos(2.0 * t), 0.001 * math.sin(2.0 * t), 0.0)
            out.update(zip(INTERFACE_INPUTS, model, strict=True))
        return out

    return inputs


@pytest.mark.parametrize("interface", [False, True])
def test_quiet_steps_give_the_general_ways_numbers(interface):
    quiet, general = both(lambda: make_unit(ALL_EFFECTS, force=F_EQ, **quiet_cylinder()))
    taken = counted(quiet)
    step_both(quiet, general, swaying(F_EQ, interface), 200, 0.004)
    assert taken.count(True) > 50  # many steps quiet (the seal sticks and slips)
    assert quiet.get_state() == general.get_state()


def test_a_seal_that_sticks_is_switched_the_general_way_and_the_two_agree():
    quiet, general = both(lambda: make_free_rod("seal_friction", 0.05, solver="rk4"))
    taken = counted(quiet)
    step_both(quiet, general, lambda t: {}, 100, 0.002)
    assert quiet.model.mode_changes == general.model.mode_changes > 0
    assert taken.count(False) >= 1 and taken.count(True) > 50
    assert quiet.get_state() == general.get_state()


@pytest.mark.parametrize("cushion", [0.0, 0.05])
def test_a_rod_running_onto_its_stop_agrees_with_the_general_way(cushion):
    # 0.5 m/s towards the end 0.2 m away: the cushion and the impact are refined
    def make():
        return make_free_rod(
            "end_stops", 0.5, solver="rk4", initial_position=3.8, cushion_length=cushion
        )

    quiet, general = both(make)
    taken = counted(quiet)
    step_both(quiet, general, lambda t: {}, 300, 0.004)
    assert quiet.model.mode_changes == general.model.mode_changes > 0  # it hit the stop
    assert not all(taken) and any(taken)
    assert quiet.get_state() == general.get_state()


def test_inputs_the_cylinder_cannot_take_are_refused_the_general_way():
    quiet = make_unit("seal_friction", force=F_EQ, **quiet_cylinder())
    taken = counted(quiet)
    quiet.values["rod.stiffness"] = -1.0
    result = quiet.advance(0.0, 0.004)
    assert not result.success and "rod.stiffness" in result.message
    quiet.values["rod.stiffness"] = 0.0
    quiet.values["rod.damping"] = -2.0
    result = quiet.advance(0.0, 0.004)
    assert not result.success and "rod.damping" in result.message
    quiet.values["rod.damping"] = 0.0
    quiet.values["rod.force"] = math.nan
    result = quiet.advance(0.0, 0.004)
    assert not result.success and "rod.force" in result.message
    quiet.values["rod.force"] = F_EQ
    quiet.values["rod.reference_velocity"] = math.inf
    result = quiet.advance(0.0, 0.004)
    assert not result.success and "rod.reference_velocity" in result.message
    assert taken == [False] * 4
    quiet.values["rod.reference_velocity"] = 0.0
    assert quiet.advance(0.0, 0.004).success and taken[-1]


def test_one_compiled_specialisation_serves_the_quiet_and_the_general_way():
    # the unit's quiet step and the general way's first attempt call the same entry point
    # with arguments of the same types, so a run loads one specialisation from the cache
    quiet, general = both(lambda: make_unit(ALL_EFFECTS, force=F_EQ, **quiet_cylinder()))
    taken = counted(quiet)
    for interface in (False, True):
        step_both(quiet, general, swaying(F_EQ, interface), 20, 0.004)
    assert any(taken)
    assert len(stepping.kernel.quiet_step_outputs.signatures) == 1


def test_a_report_that_is_not_finite_changes_nothing_and_is_refused_the_general_way(
    monkeypatch,
):
    quiet, general = both(lambda: make_free_rod("", 0.05, solver="rk4"))  # the rod moves
    taken = counted(quiet)
    step_both(quiet, general, lambda t: {}, 5, 0.004)
    before = quiet.get_state()
    computed = stepping.kernel.quiet_step_outputs

    def spoiled(*args):
        taken, x, values, _ = computed(*args)
        values[0] = math.nan
        return taken, x, values, False

    monkeypatch.setattr(stepping.kernel, "quiet_step_outputs", spoiled)
    for unit in (quiet, general):
        result = unit.advance(0.02, 0.004)
        assert not result.success and "non-finite" in result.message
    assert taken[-1] is False
    assert quiet.get_state() == general.get_state() == before
    assert quiet.values == general.values
