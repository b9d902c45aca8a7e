"""The hydraulics unit's ports, causality and feedthrough, state round trip and facade,
without building an FMU."""

from __future__ import annotations

import json
import math

import pytest

from wire_fmu.core.framework.unit import Causality
from wire_fmu.core.units.hydraulics.interface import INTERFACE_INPUTS
from wire_fmu.core.units.hydraulics.model import HYDRAULICS_EFFECTS
from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit
from wire_fmu.export.model_description import check_units

from .facade_checks import (
    assert_maps_every_declared_variable,
    load_facade_class,
    started_facade,
)
from .hydraulics_helpers import ALL_EFFECTS, make_free_rod, make_unit, run

OUTPUTS = [v for v in HydraulicsUnit.VARIABLES if v.causality is Causality.output]
F0 = -4 * 356.0e3


def test_declarations_are_sound():
    assert HydraulicsUnit.check_declarations() == []
    assert check_units(HydraulicsUnit) == []
    for var in HydraulicsUnit.VARIABLES:
        assert var.description
        if var.type is float:
            assert var.unit
    inputs = [v.name for v in HydraulicsUnit.VARIABLES if v.causality is Causality.input]
    assert inputs == ["rod.force", *INTERFACE_INPUTS]
    effects_doc = HydraulicsUnit.variable("effects").description
    assert all(name in effects_doc for name in HYDRAULICS_EFFECTS.names)


def test_rod_motion_is_a_state_with_no_direct_feedthrough():
    """The cut is at the rod's inertia: position and velocity depend on no input."""
    for name in (
        "rod.position",
        "rod.velocity",
        "rod.displacement",
        "gas.pressure",
        "gas.volume",
        "stored_energy",
        "dissipated_energy",
        "external_work",
        "energy_balance",
        "mode_changes",
    ):
        assert HydraulicsUnit.variable(name).depends_on == ()
    for name in ("rod.acceleration", "chamber.pressure", "seal.friction_force"):
        assert HydraulicsUnit.variable(name).depends_on == ("rod.force", *INTERFACE_INPUTS)


def perturbed(unit: HydraulicsUnit, delta: float) -> tuple[dict, dict]:
    before = dict(unit.values)
    unit.values["rod.force"] += delta
    unit.evaluate_outputs()
    after = dict(unit.values)
    unit.values["rod.force"] -= delta
    unit.evaluate_outputs()
    assert unit.values == before
    return before, after


@pytest.mark.parametrize(
    "effects",
    [
        "",
        "line_inertance",
        "seal_friction",
        "end_stops",
        "oil_compressibility,line_inertance",
        ALL_EFFECTS,
    ],
)
def test_declared_feedthrough_matches_the_numbers(effects):
    """Outputs declared without dependencies never move when the input does, at rest
    and in motion; the declared ones do where the physics says so."""
    unit = make_unit(effects)
    run(unit, 0.3, 0.01, force=lambda t: F0 * (1 + 0.05 * math.sin(6 * t)))
    for delta in (1e3, -2.5e4):
        before, after = perturbed(unit, delta)
        for var in OUTPUTS:
            if not var.depends_on:
                assert after[var.name] == before[var.name], var.name
        stuck = after["seal.stuck"]
        if not stuck:
            assert after["rod.acceleration"] != before["rod.acceleration"]
        else:  # the seals carry the change
            assert after["seal.friction_force"] - before["seal.friction_force"] == (
                pytest.approx(-delta)
            )
        if effects == "line_inertance":  # the line's oil column is accelerated with the rod
            assert after["chamber.pressure"] != before["chamber.pressure"]


def test_evaluating_outputs_leaves_the_state_alone():
    unit = make_unit(ALL_EFFECTS)
    run(unit, 0.2, 0.01, force=lambda t: F0 * 1.03)
    state = json.dumps(unit.get_state())
    unit.values["rod.force"] = 0.0
    unit.evaluate_outputs()
    assert json.dumps(unit.get_state()) == state


def replay(unit: HydraulicsUnit, start: float, steps: int, force) -> list[list[float]]:
    rows = []
    for i in range(steps):
        t = start + i * 0.01
        unit.values["rod.force"] = force(t)
        assert unit.advance(t, 0.01).success
        rows.append([unit.values[v.name] for v in OUTPUTS])
    return rows


def test_state_round_trip_is_bit_identical_in_stick_mode():
    unit = make_unit(ALL_EFFECTS)

    def force(t):
        return F0 * (1 + 0.03 * math.sin(5 * t))

    replay(unit, 0.0, 30, force)
    saved = json.loads(json.dumps(unit.get_state()))
    first = replay(unit, 0.3, 40, force)
    assert unit.values["mode_changes"] > 0
    unit.set_state(saved)
    assert replay(unit, 0.3, 40, force) == first


def test_state_round_trip_is_bit_identical_on_an_end_stop():
    unit = make_free_rod(
        "end_stops,seal_friction",
        0.5,
        cushion_length=0.0,
        stop_stiffness=1e8,
        initial_position=3.99,
        seal_static_friction=10.0,
        seal_coulomb_friction=5.0,
        seal_viscous_friction=0.0,
    )
    hold = unit.values["rod.force"]
    for i in range(1000):  # into the contact
        assert unit.advance(i * 1e-4, 1e-4).success
        if unit.values["end_stop.contact"]:
            break
    assert unit.values["end_stop.contact"]
    saved = json.loads(json.dumps(unit.get_state()))
    other = make_free_rod(
        "end_stops,seal_friction",
        0.5,
        cushion_length=0.0,
        stop_stiffness=1e8,
        initial_position=3.99,
        seal_static_friction=10.0,
        seal_coulomb_friction=5.0,
        seal_viscous_friction=0.0,
    )
    other.set_state(saved)
    start = (i + 1) * 1e-4
    first = replay(unit, start, 20, lambda t: hold)
    again = replay(other, start, 20, lambda t: hold)
    assert again == first
    assert not unit.values["end_stop.contact"]  # it bounced off


def test_facade_maps_every_declared_variable():
    facade = load_facade_class("hydraulics", "Hydraulics")(instance_name="hyd", resources=None)
    assert_maps_every_declared_variable(facade, HydraulicsUnit, "Hydraulics")


def test_facade_steps_like_the_core():
    """Same inputs, same numbers: the facade adds nothing to the physics."""
    facade, refs = started_facade(load_facade_class("hydraulics", "Hydraulics"), "hyd", ALL_EFFECTS)
    unit = make_unit(ALL_EFFECTS)
    for i in range(30):
        force = F0 * (1 + 0.05 * math.sin(0.3 * i))
        facade.set_real([refs["rod.force"]], [force])
        assert facade.do_step(i * 0.01, 0.01)
        unit.values["rod.force"] = force
        assert unit.advance(i * 0.01, 0.01).success
    names = ["rod.position", "chamber.pressure", "gas.volume", "energy_balance"]
    assert facade.get_real([refs[n] for n in names]) == [unit.values[n] for n in names]
    assert facade.get_integer([refs["mode_changes"]]) == [unit.values["mode_changes"]]


@pytest.mark.parametrize(
    "effects", ["seal_friction,line_losses", "oil_compressibility,line_inertance,polytropic_gas"]
)
def test_ode_view_integrates_like_the_unit(effects):
    """As a piece of a monolithic model the unit is the same hybrid ODE: integrated
    by the shared solver with a held force it matches the unit's own steps, and the
    external work it integrates is force times displacement."""
    from wire_fmu.core.framework.hybrid import SolverSettings, make_solver

    force = F0 * 1.02
    stepped = make_unit(effects, solver="radau", solver_rtol=1e-10, solver_atol=1e-10)
    stepped.values["rod.force"] = force
    for i in range(50):
        assert stepped.advance(i * 0.01, 0.01).success
    unit = make_unit(effects)
    unit.values["rod.force"] = force
    view = unit.ode()
    view.bind_inputs(0.0)
    x = view.reconcile(0.0, view.state)
    solver = make_solver(SolverSettings("radau", max_step=0.01, rtol=1e-10, atol=1e-10))
    x, _ = solver.advance(view, 0.0, x, 0.5)
    view.set_state(x, 0.5)
    for name in ("rod.position", "rod.velocity", "gas.pressure", "dissipated_energy"):
        assert unit.values[name] == pytest.approx(stepped.values[name], rel=1e-6, abs=1e-9)
    moved = unit.values["rod.position"] - 1.905
    assert unit.values["external_work"] == pytest.approx(force * moved, rel=1e-8)
    assert abs(unit.values["energy_balance"]) < 1e-6 * abs(unit.values["external_work"])
