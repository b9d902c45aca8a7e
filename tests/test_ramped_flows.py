"""Ramped flows: the block train takes a flow with its slope over the step (issue 17).

A port's rate input is then its value at the step's start and ramps with the
acceleration input (``payout_acceleration``, ``acceleration``); its position advances
with the ramping rate. The master sets the ramp from the flow's extrapolation: the
slope of the polynomial over the step, and the start chosen so that the ramp's
average is the value it would hold (:func:`wire_fmu.master.extrapolation.ramp`).

Closed forms: the riser's rope has no coordinates, so its rod force at the step's end
is the rope's algebraic force at the ramp's end point, ``y0 + v0 h + a h^2 / 2`` moving
at ``v0 + a h``; the rope's work on the rod closes its ledger; both kernels agree.
"""

from __future__ import annotations

import math
import zipfile
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled import KERNEL_ENV
from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.export.model_description import patch_model_description
from wire_fmu.master import validate
from wire_fmu.master.extrapolation import History, held_value, ramp
from wire_fmu.master.scene import interface_warnings
from wire_fmu.master.scene import reading as scene_reading
from wire_fmu.master.scene.data import RAMP_ROLE, RunSettings
from wire_fmu.study.accuracy import run_accuracy_study
from wire_fmu.study.plan import load_study_scene, study_settings

from . import test_interface_links as links_helpers
from .block_train_helpers import long_form_rope_data
from .facade_checks import load_facade_class
from .test_block_train_interface import RING_SPEED, riser_rope
from .test_kernels import assert_tables_agree

STEP = 2e-3  # s
ROD = {"position": 0.01, "velocity": 0.2, "acceleration": 50.0}  # m, m/s, m/s2


def ramped_riser(interface_model: bool = False, **rod: float):
    """:func:`riser_rope` with the rod's inputs ``rod`` (position, velocity, acceleration)."""
    unit = riser_rope(interface_model)
    for name, value in rod.items():
        unit.values[f"mover_a.{name}"] = value
    return unit


def ramp_end(position: float, velocity: float, acceleration: float, h: float) -> tuple:
    """Where a ramp from ``(position, velocity)`` at ``acceleration`` is after ``h``."""
    return position + velocity * h + 0.5 * acceleration * h * h, velocity + acceleration * h


def test_the_rod_force_at_the_step_end_is_the_ropes_force_at_the_ramps_end():
    """The ramped step's rod force against the rope evaluated at the ramp's end point."""
    stepped = ramped_riser(**ROD)
    assert stepped.advance(0.0, STEP).success
    position, velocity = ramp_end(ROD["position"], ROD["velocity"], ROD["acceleration"], STEP)
    at_end = ramped_riser(position=position, velocity=velocity)
    at_end.values["mover_b.position"] = RING_SPEED * STEP
    at_end.evaluate_outputs()
    force = at_end.values["mover_a.force"]
    assert stepped.values["mover_a.force"] == pytest.approx(force, rel=1e-12)
    # held at the step's start, the damper would see 0.1 m/s less: kilonewtons apart
    held = ramped_riser(position=ROD["position"], velocity=ROD["velocity"])
    assert held.advance(0.0, STEP).success
    assert abs(held.values["mover_a.force"] - force) > 1e3


def test_the_interface_model_is_taken_at_the_ramps_end():
    """A ramped port's reference motion is the ramp's end, not the held rate's."""
    unit = ramped_riser(interface_model=True, **ROD)
    assert unit.advance(0.0, STEP).success
    position, velocity = ramp_end(ROD["position"], ROD["velocity"], ROD["acceleration"], STEP)
    assert unit.values["mover_a.reference_position"] == pytest.approx(position, rel=1e-12)
    assert unit.values["mover_a.reference_velocity"] == pytest.approx(velocity, rel=1e-12)


def rod_ramps(unit, steps: int, h: float = STEP) -> None:
    """Step ``unit`` with the rod's velocity ramping up and down, as a master sets it."""
    position, velocity = 0.0, 0.0
    for k in range(steps):
        acceleration = 40.0 * math.sin(2.0 * math.pi * k / steps)
        unit.values.update(
            {
                "mover_a.position": position,
                "mover_a.velocity": velocity,
                "mover_a.acceleration": acceleration,
            }
        )
        assert unit.advance(k * h, h).success
        position, velocity = ramp_end(position, velocity, acceleration, h)


def test_the_ropes_work_on_a_ramped_rod_closes_its_ledger():
    """Stored change + dissipated = the ports' work, with the rod's rate ramping every step."""
    unit = ramped_riser()
    rod_ramps(unit, 50)
    values = unit.values
    assert abs(values["external_work"]) > 1e3  # J: the rod did real work
    assert abs(values["energy_balance"]) <= 1e-9 * abs(values["external_work"])


@pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")
def test_both_kernels_agree_on_ramped_steps(monkeypatch):
    """The compiled kernel's ramp (and its interface model about the ramp's end) against the
    Python reference, over steps whose rate ramps differently each time."""
    record = ("mover_a.force", "mover_b.force", "external_work", "energy_balance")
    record += ("mover_a.stiffness", "mover_a.reference_position", "mover_a.reference_velocity")
    tables = []
    for kernel in ("python", "compiled"):
        monkeypatch.setenv(KERNEL_ENV, kernel)
        unit = ramped_riser(interface_model=True)
        assert unit.model.compiled == (kernel == "compiled")
        rows = []
        for steps in (10, 20, 30):
            rod_ramps(unit, steps)
            rows.append([unit.values[name] for name in record])
        columns = np.array(rows).T
        tables.append({name: column for name, column in zip(record, columns, strict=True)})
    assert_tables_agree(*tables, "ramped riser")


# ----------------------------------------------------------------- the master's ramp
def history(*points: tuple[float, float]) -> History:
    """A source's history through ``points`` (time s, value)."""
    h = History()
    for t, value in points:
        h.push(t, value)
    return h


def test_a_ramp_from_the_sources_new_value_ends_there():
    """Gauss-Seidel, linear: start at the source's value, slope to its new one."""
    start, slope = ramp(history((0.0, 1.0), (0.1, 2.0)), 0.1, 0.1, "linear", fresh=2.5)
    assert start == pytest.approx(2.0, rel=1e-15)
    assert slope == pytest.approx(5.0, rel=1e-14)


def test_a_ramp_extrapolated_from_the_past_keeps_the_held_average():
    """Jacobi, linear and quadratic: the slope of the polynomial over the step, the start
    such that the ramp's average is the held value; constant gives no slope."""
    past = history((0.0, 1.0), (0.1, 1.5), (0.2, 2.5))
    for scheme in ("linear", "quadratic"):
        start, slope = ramp(past, 0.2, 0.1, scheme)
        assert start + 0.5 * slope * 0.1 == pytest.approx(held_value(past, 0.2, 0.1, scheme))
    start, slope = ramp(past, 0.2, 0.1, "linear")
    assert slope == pytest.approx((2.5 - 1.5) / 0.1)
    start, slope = ramp(past, 0.2, 0.1, "quadratic")  # through the three points
    parabola = np.polynomial.polynomial.Polynomial.fit([0.0, 0.1, 0.2], [1.0, 1.5, 2.5], 2)
    assert slope == pytest.approx((parabola(0.3) - parabola(0.2)) / 0.1, rel=1e-9)
    assert ramp(past, 0.2, 0.1, "constant") == (2.5, 0.0)
    assert ramp(history((0.0, 4.0)), 0.0, 0.1, "linear") == (4.0, 0.0)  # one point: held


def test_values_a_microsecond_apart_are_not_extrapolated_over_a_step():
    """After a step shortened to a mode change the newest two values may be 1 us apart: a
    line through them over a 2 ms step would multiply their difference by 1000. The
    older value half a step or more back is taken instead, or none."""
    jumped = history((0.0, 0.0), (0.002, 1.0), (0.002001, 1.5))  # a kink at the event
    slope = 1.5 / 0.002001  # through (0, 0) and the newest value
    assert held_value(jumped, 0.002001, 0.002, "linear") == pytest.approx(1.5 + 0.001 * slope)
    assert ramp(jumped, 0.002001, 0.002, "linear")[1] == pytest.approx(slope)
    close = history((0.002, 1.0), (0.002001, 1.5))
    assert held_value(close, 0.002001, 0.002, "linear") == 1.5
    assert held_value(close, 0.002001, 0.002, "quadratic") == 1.5


# ----------------------------------------------------------------- the scene's ramp link
ROD_EFFORT = replace(links_helpers.ROD_EFFORT, flow_ramp="mover_a.acceleration")


@pytest.fixture
def declared(monkeypatch):
    """The riser's rope takes a ramp at its rod port (no FMU is opened)."""
    ports = {"rope": {"mover_a": ROD_EFFORT}, "cylinder": {"rod": links_helpers.ROD_FLOW}}
    monkeypatch.setattr(
        scene_reading, "_port_reader", lambda units, base_dir: lambda unit: (ports[unit], None)
    )
    return ports


def test_the_setting_wires_the_ramp_link_from_the_flow_to_the_effort_sides_ramp(declared):
    scene, problems = links_helpers._read(links_helpers._riser_data(ramped_flows=True))
    assert problems == []
    (bond,) = scene.bonds
    assert bond.ramped and not bond.wired
    (link,) = [c for c in scene.all_connections if c.role == RAMP_ROLE]
    assert (str(link.source), str(link.target)) == (
        "cylinder.rod.velocity",
        "rope.mover_a.acceleration",
    )
    assert link.extrapolation == bond.flow.extrapolation  # the flow's scheme
    assert interface_warnings(scene) == []


def test_off_by_default_and_warned_where_no_ramp_is_declared(declared):
    assert RunSettings().ramped_flows is False
    scene, _ = links_helpers._read(links_helpers._riser_data(ramped_flows=False))
    assert not scene.bonds[0].ramped
    assert not any(c.role == RAMP_ROLE for c in scene.all_connections)
    declared["rope"]["mover_a"] = links_helpers.ROD_EFFORT  # no flow ramp declared
    scene, problems = links_helpers._read(links_helpers._riser_data(ramped_flows=True))
    assert problems == [] and not scene.bonds[0].ramped
    (warning,) = interface_warnings(scene)
    assert "'rod'" in warning and "rope.mover_a.velocity" in warning and "held" in warning


def test_a_ramp_takes_the_flows_unit_per_second():
    """The validation expects ``m/s2`` behind a ``m/s`` flow and names what it wanted."""
    flow = SimpleNamespace(role=RAMP_ROLE)
    assert validate._target_unit(flow, "m/s") == "m/s2"
    assert validate._target_unit(flow, "rad/s") == "rad/s2"
    assert validate._target_unit(flow, "m3/s") == "m3/s2"
    assert validate._target_unit(SimpleNamespace(role="flow"), "m/s") == "m/s"


def test_the_block_train_declares_its_ramps_in_its_model_description():
    """Every port of the FMU names its ramp input, declared as an input in m/s2."""
    facade = load_facade_class("block_train", "BlockTrain")(instance_name="xml", resources=None)
    raw = ET.tostring(facade.to_xml(), encoding="UTF-8")
    root = ET.fromstring(patch_model_description(raw, BlockTrainUnit, "test"))
    variables = {v.get("name"): v for v in root.find("ModelVariables")}
    ramps = {p.get("name"): p.get("flow_ramp") for p in root.iter("Port")}
    assert ramps == {
        "line_a": "line_a.payout_acceleration",
        "line_b": "line_b.payout_acceleration",
        "mover_a": "mover_a.acceleration",
        "mover_b": "mover_b.acceleration",
    }
    for name in ramps.values():
        assert variables[name].get("causality") == "input"
        assert variables[name].find("Real").get("unit") == "m/s2"
    assert BlockTrainUnit.check_declarations() == []


# ----------------------------------------------------------------- the drawworks' release
@pytest.mark.integration
def test_the_drawworks_release_is_within_1e_3_of_the_monolithic_solve(tmp_path):
    """Over the first 2.5 s (brake release at 1 s: the drum gains 2.7 m/s in 10 ms, the
    fast line goes slack and snaps), at the scene's 2 ms: the ramped payout rate brings
    the co-simulation within 1e-3 of the same units solved as one ODE; holding the rate
    at its step average, the fast line's damper reads it wrong right after the release
    and the error is several times larger."""
    scene = load_study_scene("drawworks")
    assert scene.run.ramped_flows and scene.run.step == 0.002
    settings = replace(
        study_settings(scene),
        stop_time=2.5,
        steps=(0.002,),
        algorithms=("gauss_seidel",),
        extrapolations=("linear",),
        couplings=("held", "ramped+synchronised"),
        solvers=(),
        monolithic_rtols=(),
        solver_floors=False,
        window_start=0.0,
    )
    study = run_accuracy_study(scene, tmp_path, settings=settings, progress=False)
    errors = {row.coupling: row.error for row in study.rows if row.algorithm != "monolithic"}
    assert errors["ramped"] < 1e-3
    assert errors["held"] > 3.0 * errors["ramped"]
    # rolled back to the brake's and the rope's mode changes, and back on the step grid
    # after each: as accurate (stepping on from the event by a whole step put the rows
    # off the output grid, and the error at 1.3e-2)
    assert errors["ramped+synchronised"] < 1e-3


@pytest.mark.integration
def test_ssp_names_the_ramp_without_connecting_it_and_reads_it_back(tmp_path):
    """Another tool must not connect the payout rate to the ramp input (it would set the
    acceleration to the rate): the ramp is named on the flow's annotation, and our master
    reading the package back wires it again."""
    from lxml import etree

    from wire_fmu.interop.ssp import NS, export_ssp
    from wire_fmu.interop.ssp_read import read_ssp
    from wire_fmu.master.run import find_scene
    from wire_fmu.master.scene import load_scene

    scene = load_scene(find_scene("drawworks"))
    assert scene.bonds[0].ramped
    package = export_ssp(scene, tmp_path / "drawworks.ssp")
    with zipfile.ZipFile(package) as archive:
        ssd = etree.fromstring(archive.read("SystemStructure.ssd"))
    targets = [c.get("endConnector") for c in ssd.iter(f"{{{NS['ssd']}}}Connection")]
    assert "line_a.payout_rate" in targets and "line_a.payout_acceleration" not in targets
    marks = [m.get("ramp") for m in ssd.iter(f"{{{NS['wf']}}}Bond") if m.get("role") == "flow"]
    assert marks == ["line_a.payout_acceleration"]
    back = read_ssp(package, extract_to=tmp_path / "extracted")
    (bond,) = back.bonds
    assert back.run.ramped_flows and bond.ramped
    assert (str(bond.ramp.source), str(bond.ramp.target)) == (
        "winch.rope.payout_rate",
        "rope.line_a.payout_acceleration",
    )


def _long_form(ramp: str, **run) -> dict:
    return long_form_rope_data({"ramp": ramp}, run=run)


def test_a_long_form_bond_names_its_ramp_from_the_flows_source():
    from wire_fmu.master.scene import SceneError, parse_scene

    scene = parse_scene(
        _long_form("w.rope.payout_rate -> r.line_a.payout_acceleration", ramped_flows=True),
        base_dir=Path("."),
    )
    assert scene.bonds[0].ramped
    with pytest.raises(SceneError) as refused:
        parse_scene(
            _long_form("w.rope.tension -> r.line_a.payout_acceleration"), base_dir=Path(".")
        )
    assert "the ramp must go from the flow's source w.rope.payout_rate" in str(refused.value)
