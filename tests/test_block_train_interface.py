"""The block train's interface model: each port's effort linearised (issue 17).

Over massless frictionless sheaves with fixed line directions the rope is one span
of unstretched length ``l``; a port that moves the rope's geometric length ``L`` by
``J`` per metre then sees the spring ``J^2 EA / l`` and the damper ``J^2 c / l``,
and the other ports' motion moves its effort at ``-J (EA / l) J' v'``. The riser
tensioner's rod carries 4 parts (``J = 4``): the figure its scene states,
``16 EA / L = 3.07e7 N/m``.
"""

from __future__ import annotations

from xml.etree import ElementTree as ET

import numpy as np
import pytest

from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES, INTERFACE_UNITS
from wire_fmu.core.units.block_train.interface import interface_plan, port_linearisations
from wire_fmu.core.units.block_train.reevings import (
    drilling_block_train,
    riser_tensioner,
    single_fall,
)
from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.export.model_description import patch_model_description

from .block_train_helpers import make_unit
from .facade_checks import load_facade_class

RING_SPEED = 0.5  # m/s, the riser's ring moving along its direction (down)


def riser_rope(interface_model: bool = True):
    """The riser tensioner's rope at its 356 kN set tension, the ring moving; not stepped."""
    unit = make_unit(
        riser_tensioner(),
        "rope_damping",
        initial_equilibrium=False,
        pretension=356.0e3,
        interface_model=interface_model,
    )
    unit.values["mover_b.velocity"] = RING_SPEED
    return unit


def riser(interface_model: bool = True):
    """:func:`riser_rope` after one short step."""
    unit = riser_rope(interface_model)
    assert unit.advance(0.0, 1e-4).success
    return unit


def unstretched_length(unit, rate: float) -> float:
    """``l`` from the tension ``T = (EA (L - l) + c dL/dt) / l`` and the geometric length."""
    model = unit.model
    rope = model.rope
    held = model.held_parts()
    moved = held.mover_positions + held.mover_velocities * 1e-4
    y = np.concatenate((model.q[: len(model.blocks)], moved))
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


def test_effort_rate_follows_the_blocks_own_motion():
    """A hook moving at ``v`` stretches the one merged span at ``J v`` (``J = dL/dy``, the
    4 parts it hangs in): the fast line, held still, sees its tension move at
    ``(EA / l) J v`` -- the block's state is not frozen over the step.

    Mutation: the coordinates left where they are (the rate taken at the frozen state):
    the rate is 0 and this fails.
    """
    unit = make_unit(drilling_block_train(4), "", interface_model=True)
    assert unit.advance(0.0, 1e-4).success
    model = unit.model
    assert model.n_coords == 1 and len(model.spans) == 1
    speed = 0.3  # m/s, the hook moving along its direction
    x = model.state.copy()
    x[model.n_coords] = speed
    lengths, jacobian = model.span_lengths(x[:1])
    ea = model.rope.axial_stiffness
    length = ea * float(lengths.sum()) / (unit.values["line_a.tension"] + ea)
    rate = port_linearisations(model, unit.time, x)["line_a"].effort_rate
    assert abs(jacobian[0, 0]) == pytest.approx(4.0, rel=1e-9)
    assert rate == pytest.approx(ea / length * jacobian[0, 0] * speed, rel=1e-5)


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


# -- the reference point ------------------------------------------------------------
STEP = 1e-3  # s


def reversed_fall():
    """One vertical rope from a hanging block up to ``line_b``, the path's last node: a line
    end whose payout runs against the path (held with the sign -1)."""
    reeving = single_fall()
    top = {"line_end": "line_b", "point": [0.0, 10.0, 0.0]}
    reeving["path"] = [{"anchor": "hook"}, top]
    return reeving


def stepped(unit, inputs: dict[str, float]):
    """``unit`` with ``inputs`` set, after one step of :data:`STEP` from 0."""
    unit.values.update(inputs)
    result = unit.advance(0.0, STEP)
    assert result.success, result.message
    return unit


@pytest.mark.parametrize(
    ("reeving", "port", "position", "velocity"),
    [
        (riser_tensioner, "mover_a", "position", "velocity"),
        (riser_tensioner, "mover_b", "position", "velocity"),
        (reversed_fall, "line_b", "payout", "payout_rate"),
        (lambda: drilling_block_train(4), "line_a", "payout", "payout_rate"),
    ],
)
def test_the_reference_is_the_port_motion_held_to_the_step_end(reeving, port, position, velocity):
    """``reference_position`` is the port's own position input moved on by its rate over the
    step (what the flow side will connect), ``reference_velocity`` its rate; and at that point
    the effort is the one published, with the published stiffness about it."""
    unit = make_unit(reeving(), "rope_damping", interface_model=True)
    held = {f"{port}.{position}": 1e-3, f"{port}.{velocity}": -0.03}
    stepped(unit, held)
    values = dict(unit.values)
    reference = held[f"{port}.{position}"] + held[f"{port}.{velocity}"] * STEP
    assert values[f"{port}.reference_position"] == pytest.approx(reference, rel=1e-12)
    assert values[f"{port}.reference_velocity"] == held[f"{port}.{velocity}"]
    effort = "tension" if port.startswith("line") else "force"
    e0, stiffness = values[f"{port}.{effort}"], values[f"{port}.stiffness"]
    assert stiffness > 0.0

    def effort_at(moved: float) -> float:
        """The effort with the port's inputs at the reference, moved by ``moved`` (m)."""
        unit.values[f"{port}.{position}"] = values[f"{port}.reference_position"] + moved
        unit.values[f"{port}.{velocity}"] = values[f"{port}.reference_velocity"]
        unit.evaluate_outputs()
        return unit.values[f"{port}.{effort}"]

    assert effort_at(0.0) == pytest.approx(e0, rel=1e-9)
    moved = 1e-5  # m
    assert effort_at(moved) - e0 == pytest.approx(-stiffness * moved, rel=1e-4)


def test_without_the_interface_model_the_reference_is_not_published():
    """Off: the reference outputs stay 0 whatever the port's motion."""
    unit = make_unit(riser_tensioner(), "rope_damping", interface_model=False)
    stepped(unit, {"mover_a.position": 0.01, "mover_a.velocity": 0.2})
    assert unit.values["mover_a.reference_position"] == 0.0
    assert unit.values["mover_a.reference_velocity"] == 0.0


def test_the_linearisation_carries_its_reference_point():
    """``port_linearisations`` gives the reference with the derivatives, port by port."""
    unit = make_unit(riser_tensioner(), "rope_damping", interface_model=True)
    stepped(unit, {"mover_b.position": -0.02, "mover_b.velocity": RING_SPEED})
    model = unit.model
    lins = port_linearisations(model, unit.time, model.state)
    assert set(lins) == {"mover_a", "mover_b"}
    ring = lins["mover_b"]
    assert ring.reference_position == pytest.approx(-0.02 + RING_SPEED * STEP, rel=1e-12)
    assert ring.reference_velocity == RING_SPEED
    assert (lins["mover_a"].reference_position, lins["mover_a"].reference_velocity) == (0.0, 0.0)


def test_every_port_declares_its_interface_model_and_its_switch():
    """The framework's check passes; the built model description marks each port as carrying
    the interface model switched by ``interface_model``, its outputs declared in their units."""
    assert BlockTrainUnit.check_declarations() == []
    facade = load_facade_class("block_train", "BlockTrain")(instance_name="xml", resources=None)
    raw = ET.tostring(facade.to_xml(), encoding="UTF-8")
    root = ET.fromstring(patch_model_description(raw, BlockTrainUnit, "test"))
    ports = root.findall("VendorAnnotations/Tool/Ports/Port")
    assert {p.get("name") for p in ports} == {"line_a", "line_b", "mover_a", "mover_b"}
    variables = {v.get("name"): v for v in root.find("ModelVariables")}
    for element in ports:
        assert element.get("interface") == "true"
        switch = element.get("interface_switch")
        assert switch == f"{element.get('name')}.interface_model"  # the port's own
        assert variables[switch].get("causality") == "parameter"
        kind = element.get("kind")
        for quantity, unit in zip(INTERFACE_QUANTITIES, INTERFACE_UNITS[kind], strict=True):
            variable = variables[f"{element.get('name')}.{quantity}"]
            assert variable.get("causality") == "output"
            assert variable.find("Real").get("unit") == unit
    assert variables["interface_model"].get("causality") == "parameter"


def test_a_ports_own_switch_publishes_its_model_alone():
    """``mover_a.interface_model``, what the master sets for a bond that wires the rod's
    model: the rod's port publishes it bit for bit as with every port's switched on, and
    the ring's port, which no bond reads here, is not linearised at all."""
    every = riser(True)
    unit = riser_rope(False)
    unit.values["mover_a.interface_model"] = True
    assert unit.advance(0.0, 1e-4).success
    for quantity in INTERFACE_QUANTITIES:
        assert unit.values[f"mover_a.{quantity}"] == every.values[f"mover_a.{quantity}"]
        assert unit.values[f"mover_b.{quantity}"] == 0.0
        assert every.values[f"mover_b.{quantity}"] != 0.0 or quantity == "effort_rate"
    assert interface_plan(unit.model, ("mover_a",)).names == ("mover_a",)
    assert interface_plan(unit.model).names == ("mover_a", "mover_b")
