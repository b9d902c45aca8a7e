"""Stick/slip links on their own: holding, breakaway, direction-dependent capacity."""

from __future__ import annotations

import numpy as np
import pytest

from wire_fmu.core.components.friction import GROUND, FrictionLink, StickSlip


def one_link(mass=2.0):
    return StickSlip(np.array([mass]), (FrictionLink("brake", 0, GROUND),))


def test_stuck_link_holds_exactly_what_the_other_forces_need():
    friction = one_link()
    acc, held = friction.accelerations(np.array([30.0]), np.array([50.0]))
    assert acc[0] == 0.0 and held[0] == -30.0
    assert friction.guards(np.zeros(1), held, np.array([50.0]))[0] == 20.0


def test_breakaway_when_the_load_exceeds_capacity_then_slides_against_motion():
    friction = one_link(mass=2.0)
    v = friction.switch(np.zeros(1), np.array([80.0]), np.array([50.0]), [])
    assert friction.get_mode() == [1]  # pushed positive, slides positive
    acc, force = friction.accelerations(np.array([80.0]), np.array([50.0]))
    assert force[0] == -50.0 and acc[0] == pytest.approx((80.0 - 50.0) / 2.0)
    assert v[0] == 0.0


def test_direction_dependent_capacity():
    """Column 0 opposes positive motion, column 1 negative: a self-energising band."""
    friction = one_link()
    caps = np.array([[100.0, 20.0]])
    _, held = friction.accelerations(np.array([-30.0]), caps)  # pushed negative: 20 N holds
    assert friction.guards(np.zeros(1), held, caps)[0] == pytest.approx(20.0 - 30.0)
    friction.switch(np.zeros(1), np.array([-30.0]), caps, [])
    assert friction.get_mode() == [-1]
    _, force = friction.accelerations(np.array([-30.0]), caps)
    assert force[0] == 20.0
    friction.set_mode([0])
    friction.switch(np.zeros(1), np.array([30.0]), caps, [])  # the strong direction holds
    assert friction.get_mode() == [0]


def test_sliding_force_may_differ_from_static_capacity():
    friction = one_link()
    friction.set_mode([1])
    _, force = friction.accelerations(np.array([0.0]), np.array([50.0]), sliding=np.array([35.0]))
    assert force[0] == -35.0
    assert friction.loss_power(np.array([2.0]), force) == pytest.approx(70.0)


def test_two_bodies_stuck_together_share_acceleration_and_stop_conserving_momentum():
    links = (FrictionLink("groove", 0, 1),)
    friction = StickSlip(np.array([1.0, 3.0]), links)
    acc, held = friction.accelerations(np.array([8.0, 0.0]), np.array([100.0]))
    assert acc[0] == acc[1] == pytest.approx(2.0)
    assert held[0] == pytest.approx(-6.0)  # the link pulls body 0 back by 6 N
    friction.set_mode([1])
    v = friction.switch(np.array([2.0, 1.0]), np.zeros(2), np.array([100.0]), [0])
    assert v[0] == v[1] == pytest.approx((1.0 * 2.0 + 3.0 * 1.0) / 4.0)
    assert friction.get_mode() == [0]
