"""The winch's ports, causality and feedthrough, its configuration errors and its facade,
without building an FMU."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wire_fmu.core.components.drum import Drum, LayeredDrum
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import Causality
from wire_fmu.core.units.winch.unit import WinchUnit
from wire_fmu.export.model_description import check_units

from .facade_checks import (
    assert_maps_every_declared_variable,
    load_facade_class,
    started_facade,
)
from .winch_helpers import make_unit, run

INPUTS = [v.name for v in WinchUnit.VARIABLES if v.causality is Causality.input]
OUTPUTS = [v for v in WinchUnit.VARIABLES if v.causality is Causality.output]
ALL = "drum_inertia,band_brake,motor_characteristic,elastic_drive_train,rope_layers"

SCENES = {
    "kinetostatic": (
        "band_brake,rope_layers",
        {"drum.speed_command": 3.0, "brake.lever_force": 300.0, "rope.tension": 1e5},
    ),
    "held": ("drum_inertia,band_brake", {"brake.lever_force": 3000.0, "rope.tension": 1e5}),
    "sliding": (ALL, {"brake.lever_force": 500.0, "rope.tension": 1.5e5, "motor.command": -500.0}),
    "free": ("drum_inertia,elastic_drive_train", {"rope.tension": 1e5, "motor.command": 1e3}),
}
_ROPE_MODEL = {
    "rope.stiffness": 2.0e5,
    "rope.damping": 3.0e3,
    "rope.effort_rate": 1.0e4,
    "rope.reference_position": 0.5,
    "rope.reference_velocity": 0.5,
}
SCENES |= {  # the tension from the block train's interface model
    "kinetostatic, rope model": ("band_brake", {**SCENES["kinetostatic"][1], **_ROPE_MODEL}),
    "held, rope model": ("drum_inertia,band_brake", {**SCENES["held"][1], **_ROPE_MODEL}),
}


def scene(name: str) -> WinchUnit:
    effects, inputs = SCENES[name]
    unit = make_unit(effects, **{k.replace(".", "__"): v for k, v in inputs.items()})
    run(unit, 0.2, 0.05)
    return unit


def test_declarations_are_sound():
    assert WinchUnit.check_declarations() == []
    assert check_units(WinchUnit) == []
    for var in WinchUnit.VARIABLES:
        assert var.description
        if var.type is float:
            assert var.unit
    assert set(INPUTS) >= {"rope.tension", "brake.lever_force", "motor.command"}
    names = {v.name for v in OUTPUTS}
    assert names >= {
        "rope.payout",
        "rope.payout_rate",
        "drum.speed",
        "brake.torque",
        "brake.state",
        "stored_energy",
        "dissipated_energy",
        "external_work",
        "energy_balance",
        "mode_changes",
    }
    assert WinchUnit.variable("brake.state").type is int
    assert WinchUnit.variable("mode_changes").type is int


def test_rope_port_outputs_come_from_the_drum_state():
    """The block train takes these as inputs: no feedthrough, so no algebraic loop."""
    for name in (
        "rope.payout",
        "rope.payout_rate",
        "drum.speed",
        "drum.angle",
        "motor.speed",
        "stored_energy",
        "dissipated_energy",
        "external_work",
        "energy_balance",
    ):
        assert WinchUnit.variable(name).depends_on == (), name


def perturbed(unit: WinchUnit, name: str, delta: float) -> tuple[dict, dict]:
    unit.evaluate_outputs()  # a rope model's tension about now, not about the last step's start
    before = dict(unit.values)
    unit.values[name] += delta
    unit.evaluate_outputs()
    after = dict(unit.values)
    unit.values[name] = before[name]
    unit.evaluate_outputs()
    assert unit.values == before
    return before, after


@pytest.mark.parametrize("name", list(SCENES))
def test_declared_feedthrough_matches_the_numbers(name):
    """An output declared without dependencies never moves when an input changes."""
    unit = scene(name)
    for inp in INPUTS:
        for delta in (0.37, -5.0e3):
            before, after = perturbed(unit, inp, delta)
            for var in OUTPUTS:
                if inp not in var.depends_on:
                    assert after[var.name] == before[var.name], (inp, var.name)


def test_declared_dependencies_are_real():
    """Each declared dependency shows up in at least one configuration."""
    seen: dict[str, set[str]] = {v.name: set() for v in OUTPUTS}
    for name in SCENES:
        unit = scene(name)
        for inp in INPUTS:
            for delta in (-1.0e4, 1.0e6):
                before, after = perturbed(unit, inp, delta)
                for var in OUTPUTS:
                    if after[var.name] != before[var.name]:
                        seen[var.name].add(inp)
    for var in OUTPUTS:
        assert seen[var.name] == set(var.depends_on), var.name


def test_evaluating_outputs_leaves_the_state_alone():
    unit = scene("held")
    state = json.dumps(unit.get_state())
    unit.values["rope.tension"] = 1e7  # would break the brake away
    unit.evaluate_outputs()
    assert unit.values["brake.state"] == 1
    assert json.dumps(unit.get_state()) == state


@pytest.mark.parametrize("name", list(SCENES))
def test_core_state_round_trips_bit_for_bit(name):
    unit = scene(name)
    saved = json.loads(json.dumps(unit.get_state()))

    def go(u):
        return run(
            u,
            0.3,
            0.05,
            record=("rope.payout", "drum.speed", "brake.torque", "energy_balance", "mode_changes"),
            start=0.2,
        )

    first = go(unit)
    unit.set_state(saved)
    again = go(unit)
    for key in first:
        assert np.array_equal(first[key], again[key]), key


def test_bad_parameters_give_one_error_listing_every_problem():
    unit = WinchUnit("bad")
    unit.values.update(
        {
            "effects": "drum_inertia,brake,elastic_drive_train,band_brake,rope_layers",
            "solver": "energy",
            "solver_max_step": 0.0,
            "drive_train_masses": 7,
            "brake_friction": -0.1,
            "brake_efficiency": 1.5,
            "rope_on_drum": 1e6,
        }
    )
    with pytest.raises(ConfigurationError) as err:
        unit.configure()
    text = str(err.value)
    for needle in (
        "unknown effect 'brake'",
        "solver_max_step",
        "drive_train_masses",
        "brake_friction",
        "brake_efficiency",
        "rope_on_drum",
    ):
        assert needle in text, needle
    assert len(err.value.problems) == 6


def test_a_band_friction_or_wrap_beyond_any_real_band_brake_is_refused_with_its_range():
    """A friction of 12 (a slip for 0.12) over 300 deg gave e^(mu alpha) of about 2e27, silently;
    linings lie below about 0.65 and a band wraps at most one turn. Both bounds are
    declared, so the reference shows them."""
    unit = WinchUnit("mu")
    unit.values.update(
        {"effects": "drum_inertia,band_brake", "brake_friction": 12.0, "brake_wrap_angle": 7.0}
    )
    with pytest.raises(ConfigurationError) as err:
        unit.configure()
    assert err.value.problems == [
        "parameter 'brake_friction' must be in (0, 1] (brake linings: 0.3-0.65), got 12.0",
        "parameter 'brake_wrap_angle' must be in (0, 2 pi] rad (a band wraps at most one turn), "
        "got 7.0",
    ]
    declared = {v.name: v for v in WinchUnit.VARIABLES}
    assert declared["brake_friction"].max == 1.0
    assert declared["brake_wrap_angle"].max == pytest.approx(2.0 * np.pi)
    for edge in ({"brake_friction": 1.0}, {"brake_wrap_angle": 2.0 * np.pi}):
        unit = WinchUnit("edge")
        unit.values.update({"effects": "drum_inertia,band_brake", **edge})
        unit.configure()


def test_energy_solver_needs_a_rigid_machine_and_other_solvers_are_listed():
    for effects, params, needle in (
        ("drum_inertia,elastic_drive_train", {"solver": "energy"}, "rigid one-degree"),
        ("", {"solver": "energy1"}, "add the effect 'drum_inertia'"),
        ("drum_inertia", {"solver": "euler"}, "energy1"),
        ("motor_characteristic", {}, "needs effect 'drum_inertia'"),
        ("drum_inertia", {"drive_train": "{bad json"}, "not valid JSON"),
    ):
        unit = WinchUnit("bad")
        unit.values.update({"effects": effects, **params})
        with pytest.raises(ConfigurationError, match=needle):
            unit.configure()
    # a rigid reduction is a rigid machine
    make_unit("drum_inertia,elastic_drive_train", solver="energy", drive_train_masses=1)


def test_an_unstable_explicit_solver_is_refused_before_it_runs():
    """A stiff shaft (1e10 N m/rad on a 1 kg m^2 rotor: 1e5 1/s) cannot be stepped by rk4
    at 1 ms; the message says what to do."""
    stiff = json.dumps(
        {
            "masses": [{"name": "rotor", "inertia": 1.0}, {"name": "drum", "inertia": 100.0}],
            "shafts": [{"stiffness": 1e10}],
        }
    )
    unit = WinchUnit("stiff")
    unit.values.update({"effects": "drum_inertia,elastic_drive_train", "drive_train": stiff})
    with pytest.raises(ConfigurationError, match="set solver_max_step below 2.4"):
        unit.configure()
    make_unit("drum_inertia,elastic_drive_train", drive_train=stiff, solver="ros2")
    make_unit("drum_inertia,elastic_drive_train", drive_train=stiff, solver_max_step=2e-5)


def test_non_finite_input_refuses_the_step():
    unit = scene("free")
    unit.values["rope.tension"] = float("nan")
    result = unit.advance(0.2, 0.05)
    assert not result.success and "rope.tension" in result.message


def test_facade_maps_every_declared_variable():
    facade = load_facade_class("winch", "Winch")(instance_name="w", resources=None)
    assert_maps_every_declared_variable(facade, WinchUnit, "Winch")


def test_facade_steps_like_the_core():
    """Same inputs, same numbers: the facade adds nothing to the physics."""
    facade, refs = started_facade(load_facade_class("winch", "Winch"), "w", ALL)
    unit = make_unit(ALL)
    names = ["rope.tension", "brake.lever_force", "motor.command"]
    for i in range(20):
        values = [1.2e5, 800.0 if i > 10 else 0.0, -400.0]
        facade.set_real([refs[n] for n in names], values)
        unit.values.update(dict(zip(names, values, strict=True)))
        assert facade.do_step(i * 0.01, 0.01)
        assert unit.advance(i * 0.01, 0.01).success
    watch = ["rope.payout", "drum.speed", "brake.torque", "energy_balance"]
    assert facade.get_real([refs[n] for n in watch]) == [unit.values[n] for n in watch]
    assert facade.get_integer([refs["brake.state"]]) == [unit.values["brake.state"]]


def test_absent_effects_cost_nothing():
    """An effect not asked for adds no state, no guard, and its inputs and parameters do
    nothing."""
    rigid = make_unit("drum_inertia")
    assert len(rigid.get_state()["x"]) == 4  # drum angle, speed, two ledger integrals
    assert rigid.model.guards(0.0, rigid.model.state).size == 0
    assert rigid.model.config.brake is None and rigid.model.friction.links == ()
    assert type(rigid.model.drum) is Drum  # one layer: no layer edges, no rope inertia
    braked = make_unit("drum_inertia,band_brake,rope_layers")
    assert isinstance(braked.model.drum, LayeredDrum) and len(braked.model.friction.links) == 1
    assert braked.model.guards(0.0, braked.model.state).size == 4  # brake 2, layer edges 2
    full = make_unit("drum_inertia,elastic_drive_train")
    assert len(full.get_state()["x"]) == 2 * 3 + 2  # the default chain has three masses

    def trajectory(**params):
        unit = make_unit("drum_inertia", **params, **{"rope.tension": 1e5, "motor.command": -500.0})
        return run(unit, 0.3, 0.05, record=("rope.payout", "drum.speed", "energy_balance"))

    plain = trajectory()
    for params in (
        {"brake__lever_force": 5e3},
        {"motor_slope": 1.0},
        {"rope_linear_mass": 50.0},
        {"drive_train_masses": 2},
    ):
        other = trajectory(**params)
        for key in plain:
            assert np.array_equal(plain[key], other[key]), (params, key)
