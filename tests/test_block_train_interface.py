"""The block train's interface model: each port's effort linearised (issue 17).

Over massless frictionless sheaves with fixed line directions the rope is one span
of unstretched length ``l``; a port that moves the rope's geometric length ``L`` by
``J`` per metre then sees the spring ``J^2 EA / l`` and the damper ``J^2 c / l``,
and the other ports' motion moves its effort at ``-J (EA / l) J' v'``. The riser
tensioner's rod carries 4 parts (``J = 4``): the figure its scene states,
``16 EA / L = 3.07e7 N/m``.
"""

from __future__ import annotations

import numpy as np
import pytest

from wire_fmu.core.units.block_train.reevings import drilling_block_train, riser_tensioner

from .block_train_helpers import make_unit

RING_SPEED = 0.5  # m/s, the riser's ring moving along its direction (down)


def riser(interface_model: bool = True):
    """The riser tensioner's rope at its 356 kN set tension, the ring moving; one short step."""
    unit = make_unit(
        riser_tensioner(),
        "rope_damping",
        initial_equilibrium=False,
        pretension=356.0e3,
        interface_model=interface_model,
    )
    unit.values["mover_b.velocity"] = RING_SPEED
    assert unit.advance(0.0, 1e-4).success
    return unit


def unstretched_length(unit, rate: float) -> float:
    """``l`` from the tension ``T = (EA (L - l) + c dL/dt) / l`` and the geometric length."""
    model = unit.model
    rope = model.rope
    y = np.concatenate((model.q[: len(model.blocks)], model._mover_y0 + model._mover_v * 1e-4))
    big_l = float(model.span_lengths(y)[0].sum())
    tension = unit.values["path_end.tension"]
    return (rope.axial_stiffness * big_l + rope.damping * rate) / (tension + rope.axial_stiffness)


def test_riser_rod_sees_sixteen_times_the_span_stiffness():
    """Stiffness, damping and the ring's share of the rod force against the closed forms."""
    unit = riser()
    model = unit.model
    assert len(model.spans) == 1
    ea, c = model.rope.axial_stiffness, model.rope.damping
    length = unstretched_length(unit, RING_SPEED)
    values = unit.values
    assert values["mover_a.stiffness"] == pytest.approx(16.0 * ea / length, rel=1e-6)
    assert values["mover_a.damping"] == pytest.approx(16.0 * c / length, rel=1e-6)
    assert values["mover_a.effort_rate"] == pytest.approx(-4.0 * ea / length * RING_SPEED, rel=1e-6)
    assert values["mover_a.stiffness"] == pytest.approx(3.07e7, rel=5e-3)  # the scene's figure
    # the ring, one part: its own spring, and the rod still
    assert values["mover_b.stiffness"] == pytest.approx(ea / length, rel=1e-6)
    assert values["mover_b.effort_rate"] == pytest.approx(0.0, abs=1e-6 * ea / length)


def test_fast_line_sees_the_whole_rope_as_one_spring():
    """Rope paid in slackens the line: ``-dT/d payout = EA L / l^2`` for one merged span."""
    unit = make_unit(drilling_block_train(4), "", interface_model=True)
    assert unit.advance(0.0, 1e-4).success
    model = unit.model
    assert len(model.spans) == 1
    ea = model.rope.axial_stiffness
    big_l = float(model.span_lengths(np.zeros(len(model.body_dof)))[0].sum())
    length = ea * big_l / (unit.values["line_a.tension"] + ea)
    assert unit.values["line_a.stiffness"] == pytest.approx(ea * big_l / length**2, rel=1e-6)
    assert unit.values["line_a.damping"] == 0.0  # no rope damping among the effects


def test_without_the_interface_model_nothing_is_published():
    """Off by default: the outputs stay 0 and no differencing is paid for."""
    unit = riser(interface_model=False)
    assert unit.values["mover_a.stiffness"] == 0.0
    assert unit.values["mover_a.effort_rate"] == 0.0


def test_linearisation_leaves_the_step_untouched():
    """The differencing restores the held inputs: the next step is the one without it."""
    with_model, without = riser(True), riser(False)
    for unit in (with_model, without):
        assert unit.advance(1e-4, 1e-3).success
    assert with_model.values["mover_a.force"] == without.values["mover_a.force"]
    np.testing.assert_array_equal(with_model.model.state, without.model.state)
