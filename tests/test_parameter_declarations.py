"""The units' declarations tell the truth: declared ranges are what the units refuse, and a
parameter declared to act only with an effect changes nothing without it (and does with it).

Each unit is stepped directly (no FMU) from its declared defaults with inputs that keep it
moving; a parameter is changed within its range and the outputs compared.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable

import numpy as np
import pytest

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.variables import Causality, Variable
from wire_fmu.core.units.block_train.reevings import drilling_block_train
from wire_fmu.registry import UNIT_TYPES

STEP, STEPS = 0.01, 30


def _block_train(unit, t: float) -> None:
    unit.values["line_a.payout_rate"] = 0.5 * math.cos(3.0 * t)
    unit.values["line_a.payout"] = 0.5 * math.sin(3.0 * t) / 3.0


def _winch(unit, t: float) -> None:
    unit.values["rope.tension"] = 2.0e5 + 5.0e4 * math.sin(5.0 * t)
    unit.values["motor.command"] = 3.0e3 if t < 0.1 else 1.0e4
    unit.values["brake.lever_force"] = 0.0 if t < 0.15 else 100.0
    unit.values["drum.speed_command"] = 2.0 * t


def _hydraulics(unit, t: float) -> None:
    unit.values["rod.force"] = -1.424e6 * (1.0 + 0.05 * math.sin(20.0 * t))


def _jack(unit, t: float) -> None:
    unit.values["handle.speed_command"] = -12.0 + 80.0 * t
    unit.values["handle.torque_command"] = 2.0 * math.sin(10.0 * t)


def _drive(unit, t: float) -> None:
    unit.values["motor.torque"] = 300.0 if t > 0.05 else 0.0
    unit.values["load.torque"] = 100.0


def _machine(unit, t: float) -> None:
    unit.values["load.torque"] = 50.0 * math.sin(7.0 * t)


DRIVE: dict[str, Callable] = {
    "BlockTrain": _block_train,
    "Winch": _winch,
    "Hydraulics": _hydraulics,
    "ScissorJack": _jack,
    "MultiMassDrive": _drive,
    "MachineUnit": _machine,
}
"""Inputs at time t that keep each unit moving (and its brakes, seals, layers working)."""

BASE = {
    # the drilling block train with friction to act on: every sheave's bearing and groove
    "BlockTrain": {"reeving": json.dumps(drilling_block_train(4))},
    # the rope 0.6 m beyond the first layer's edge (105.6 m with 40 wraps of 0.42 m)
    "Winch": {"rope_on_drum": 106.2},
}


SETTING = {
    # parameters that another parameter switches on
    "Hydraulics.initial_gas_pressure": {"initial_equilibrium": False},
    "Winch.solver_rtol": {"solver": "rk45", "solver_max_step": 0.01},
    "Winch.solver_atol": {"solver": "rk45", "solver_max_step": 0.01},
    # held by the regularised friction: it creeps at a speed set by the scale
    "ScissorJack.friction_speed_scale": {
        "friction_model": "tanh",
        "handle_drive": "torque",
        "solver": "radau",
    },
}
ALSO = {
    # effects a parameter needs besides the one it is declared to act with
    "Winch.rope_linear_mass": {"drum_inertia"},  # the rope's inertia on a turning drum
}


def _catalogue(unit_type) -> dict[str, tuple[str, ...]]:
    cat = unit_type.effect_catalogue()
    return {e.name: e.requires for e in cat.effects} if cat else {}


def _with(effects: dict[str, tuple[str, ...]], names) -> set[str]:
    """``names`` and every effect they need."""
    out, todo = set(), list(names)
    while todo:
        name = todo.pop()
        if name not in out:
            out.add(name)
            todo += effects[name]
    return out


def _acting(unit_type, var: Variable) -> set[str]:
    """Effects with which ``var`` acts: one it needs (with what that needs), none it must not."""
    effects = _catalogue(unit_type)
    chosen = _with(effects, var.acts_with[:1])
    assert not chosen & set(var.acts_without)
    return chosen


def _silent(unit_type, var: Variable) -> set[str]:
    """Effects with which ``var`` has no influence."""
    effects = _catalogue(unit_type)
    if var.acts_without:
        return _with(effects, var.acts_without[:1])
    return set()


def _run(unit_type, effects: set[str], changes: dict) -> np.ndarray:
    """The unit's Real outputs after each step, as rows (``changes`` set after the inputs)."""
    unit = unit_type.core_class()()
    unit.values.update(BASE.get(unit_type.name, {}))
    unit.values["effects"] = ",".join(sorted(effects))
    DRIVE[unit_type.name](unit, 0.0)
    unit.values.update(changes)
    unit.configure()
    unit.initialize(0.0)
    outputs = [
        v.name for v in unit.VARIABLES if v.causality is Causality.output and v.type is float
    ]
    rows = []
    for k in range(STEPS):
        t = k * STEP
        DRIVE[unit_type.name](unit, t)
        unit.values.update(changes)
        result = unit.advance(t, STEP)
        assert result.success, result.message
        rows.append([float(unit.values[n]) for n in outputs])
    return np.array(rows)


def _changed(var: Variable):
    """A different value inside the declared range."""
    if var.type is int:
        return int(var.start) + 1
    value = float(var.start)
    new = value * 1.5 if value != 0.0 else 0.5
    if var.max is not None and new > var.max:
        new = 0.5 * (value + (var.min if var.min is not None else 0.0))
    return new


def _declared(predicate) -> list:
    return [
        pytest.param(u, v, id=f"{u.name}.{v.name}")
        for u in UNIT_TYPES
        for v in u.core_class().VARIABLES
        if predicate(v)
    ]


def _bounded(v: Variable) -> bool:
    return v.causality is Causality.parameter and (v.min is not None or v.max is not None)


def _conditional(v: Variable) -> bool:
    return v.type in (float, int) and bool(v.acts_with or v.acts_without)


def test_every_effect_a_declaration_names_is_in_its_units_catalogue():
    for u in UNIT_TYPES:
        known = set(_catalogue(u))
        for v in u.core_class().VARIABLES:
            assert set(v.acts_with + v.acts_without) <= known, (u.name, v.name)
        for fields in u.core_class().DATA_FIELDS.values():
            for f in fields:
                assert set(f.acts_with + f.acts_without) <= known, (u.name, f.path)


@pytest.mark.parametrize(("unit_type", "var"), _declared(_bounded))
def test_declared_ranges_hold_the_default_and_the_unit_refuses_what_lies_outside(unit_type, var):
    effects = _acting(unit_type, var)
    low, high = var.min, var.max
    start = float(var.start)
    assert low is None or start > low or (start == low and not var.min_exclusive)
    assert high is None or start <= high
    outside = []
    if low is not None:
        outside.append(low if var.min_exclusive else low - max(1.0, abs(low)))
    if high is not None:
        outside.append(high + max(1.0, abs(high)))
    for value in outside:
        value = var.type(value)
        unit = unit_type.core_class()()
        unit.values.update(BASE.get(unit_type.name, {}))
        unit.values["effects"] = ",".join(sorted(effects))
        unit.values.update(SETTING.get(f"{unit_type.name}.{var.name}", {}))
        unit.values[var.name] = value
        with pytest.raises(ConfigurationError):
            unit.configure()
            unit.initialize(0.0)


@pytest.mark.parametrize(("unit_type", "var"), _declared(_conditional))
def test_a_value_declared_without_influence_changes_no_output(unit_type, var):
    effects = _silent(unit_type, var)
    setting = SETTING.get(f"{unit_type.name}.{var.name}", {})
    base = _run(unit_type, effects, setting)
    other = _run(unit_type, effects, setting | {var.name: _changed(var)})
    np.testing.assert_array_equal(other, base)


NOT_REACHED = {
    # limits a short, gentle run does not reach: the stroke's ends, the drum's last layer
    "Hydraulics.cushion_length": "the rod stays far from the ends of its stroke",
    "Hydraulics.cushion_coefficient": "the rod stays far from the ends of its stroke",
    "Hydraulics.stop_stiffness": "the rod stays far from the ends of its stroke",
    "Hydraulics.stop_restitution": "the rod stays far from the ends of its stroke",
    "Winch.drum_layers": "the rope stays on the first layers",
}


@pytest.mark.parametrize(("unit_type", "var"), _declared(_conditional))
def test_a_value_declared_to_act_with_an_effect_does_act_with_it(unit_type, var):
    reason = NOT_REACHED.get(f"{unit_type.name}.{var.name}")
    if reason:
        pytest.skip(reason)
    name = f"{unit_type.name}.{var.name}"
    effects = _acting(unit_type, var) | ALSO.get(name, set())
    setting = SETTING.get(name, {})
    base = _run(unit_type, effects, setting)
    other = _run(unit_type, effects, setting | {var.name: _changed(var)})
    assert not np.array_equal(other, base)


REEVING_CHANGES = {
    # reeving key -> a value that must matter when its effect is on
    "rope.damping": 3.0e5,
    "rope.linear_mass": 60.0,
    "sheaves.<name>.inertia": 400.0,
    "sheaves.<name>.bearing_torque": 2.0e3,
    "sheaves.<name>.efficiency": 0.9,
    "sheaves.<name>.groove_friction": 1.0e-3,  # the rope slips on the grooves
}


def _reeving_with(path: str, value: float) -> str:
    data = drilling_block_train(4)
    table, key = path.rsplit(".", 1)
    if table.startswith("sheaves"):
        for sheave in data["sheaves"].values():
            sheave[key] = value
    else:
        data[table][key] = value
    return json.dumps(data)


def _all_but(effects: dict[str, tuple[str, ...]], left_out: set[str]) -> set[str]:
    """Every effect but ``left_out`` and those that need them."""
    chosen = set(effects) - left_out
    while any(not set(effects[e]) <= chosen for e in chosen):
        chosen = {e for e in chosen if set(effects[e]) <= chosen}
    return chosen


@pytest.mark.parametrize("path", sorted(REEVING_CHANGES))
def test_a_reeving_key_acts_only_with_the_effect_it_is_declared_to_need(path):
    from wire_fmu.core.units.block_train.reeving_fields import FIELD
    from wire_fmu.registry import BY_NAME

    unit_type = BY_NAME["BlockTrain"]
    field = FIELD[path]
    assert field.acts_with, path
    effects = _catalogue(unit_type)
    changed = {"reeving": _reeving_with(path, REEVING_CHANGES[path])}
    for chosen, acts in (
        (_all_but(effects, set(field.acts_with) | {"spatial_geometry"}), False),
        (_with(effects, field.acts_with[:1]), True),
    ):
        base = _run(unit_type, chosen, {})
        other = _run(unit_type, chosen, changed)
        assert np.array_equal(other, base) is not acts, (sorted(chosen), acts)
