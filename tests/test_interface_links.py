"""Interface models across port bonds: the master's links, checks, run and exports.

A bond written as two ports whose FMUs both declare an interface model offers five more
links, ``effort_unit.{port}.{quantity} -> flow_unit.{port}.{quantity}``; the scene wires
them with ``run.interface_models`` (or the bond's own ``interface_model``), the master then
sets the effort unit's switch, holds the links and the bond's effort over the step, and the
links are ordinary connections to the checks, the recorder and the SSP and OSP exports.
"""

from __future__ import annotations

import textwrap
import tomllib
import zipfile
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest
from lxml import etree

from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES
from wire_fmu.master import validate
from wire_fmu.master.ports import PortDeclaration, interface_links, port_links
from wire_fmu.master.scene import (
    HELD,
    INTERFACE_ROLE,
    SceneError,
    interface_warnings,
    parse_scene,
    read_scene_data,
)
from wire_fmu.master.scene import reading as scene_reading
from wire_fmu.master.simulation import Simulation

SCENES = Path(__file__).resolve().parents[1] / "wire_fmu" / "scenes"
SUPPORT = Path(__file__).resolve().parent / "support"

ROD_EFFORT = PortDeclaration(
    "mover_a",
    "translational",
    "effort",
    "mover_a.force",
    "mover_a.velocity",
    "mover_a.position",
    interface=True,
    interface_switch="interface_model",
)
ROD_FLOW = PortDeclaration(
    "rod", "translational", "flow", "rod.force", "rod.velocity", "rod.displacement", interface=True
)
PLAIN_FLOW = replace(ROD_FLOW, interface=False)


# -- links from declarations ----------------------------------------------------------------
def test_both_ports_with_the_model_give_five_links_from_the_effort_side_in_either_order():
    flow, effort = ("cylinder", ROD_FLOW), ("rope", ROD_EFFORT)
    for pair in [(flow, effort), (effort, flow)]:
        links, problems = port_links(*pair)
        assert problems == []
        assert links.interface == tuple(
            (f"rope.mover_a.{q}", f"cylinder.rod.{q}") for q in INTERFACE_QUANTITIES
        )
        assert links.switch == "rope.interface_model" and links.lacking == ()
        assert links.effort == ("rope.mover_a.force", "cylinder.rod.force")


@pytest.mark.parametrize(
    ("effort", "flow", "lacking"),
    [
        (ROD_EFFORT, PLAIN_FLOW, ("cylinder.rod (flow side)",)),
        (replace(ROD_EFFORT, interface=False), ROD_FLOW, ("rope.mover_a (effort side)",)),
        (
            replace(ROD_EFFORT, interface=False),
            PLAIN_FLOW,
            ("rope.mover_a (effort side)", "cylinder.rod (flow side)"),
        ),
    ],
)
def test_a_port_without_the_model_gives_no_interface_links_and_is_named(effort, flow, lacking):
    links, switch, named = interface_links(("rope", effort), ("cylinder", flow))
    assert links == () and switch is None and named == lacking
    bond, _ = port_links(("cylinder", flow), ("rope", effort))
    assert bond.interface == () and bond.lacking == lacking and bond.position is not None


# -- the scene's choice ----------------------------------------------------------------------
def _riser_data(**run) -> dict:
    """The shipped riser scene without its own choice of coupling, ``run`` settings added."""
    data = tomllib.loads((SCENES / "riser_tensioner.toml").read_text())
    data["run"].pop("interface_models", None)
    data["run"].pop("ramped_flows", None)
    data["run"].update(run)
    return data


@pytest.fixture
def declared(monkeypatch):
    """The riser's two units declare the rod's ports as given (no FMU is opened)."""
    ports = {"rope": {"mover_a": ROD_EFFORT}, "cylinder": {"rod": ROD_FLOW}}

    def reader(units, base_dir):
        return lambda unit: (ports[unit], None)

    monkeypatch.setattr(scene_reading, "_port_reader", reader)
    return ports


def _read(data: dict):
    return read_scene_data(data, base_dir=SCENES, source=SCENES / "riser_tensioner.toml")


def test_with_the_setting_on_the_bond_carries_the_model_and_the_switch_is_set(declared):
    scene, problems = _read(_riser_data(interface_models=True))
    assert problems == []
    (bond,) = scene.bonds
    assert bond.wired and scene.interface_bonds == (bond,)
    interface = [c for c in bond.connections if c.role == INTERFACE_ROLE]
    assert [(str(c.source), str(c.target)) for c in interface] == [
        (f"rope.mover_a.{q}", f"cylinder.rod.{q}") for q in INTERFACE_QUANTITIES
    ]
    assert len(scene.all_connections) == 3 + 5
    assert {c.extrapolation for c in interface} == {HELD} and bond.effort.extrapolation == HELD
    assert bond.flow.extrapolation is None  # the run's linear extrapolation
    rope = scene.units["rope"]
    assert rope.parameters["interface_model"] is True and rope.switched_on == ("interface_model",)
    assert rope.parameter_values()["interface_model"] is True
    assert interface_warnings(scene) == []


def test_off_by_default_the_bond_keeps_its_three_links_and_sets_nothing(declared):
    scene, problems = _read(_riser_data())
    assert problems == [] and scene.run.interface_models is False
    (bond,) = scene.bonds
    assert not bond.wired and len(bond.connections) == 3 and len(bond.interface) == 5
    assert bond.effort.extrapolation is None
    assert "interface_model" not in scene.units["rope"].parameters
    assert interface_warnings(scene) == []


def test_other_run_settings_rewire_the_scene_and_the_scenes_own_switch_stays(declared):
    scene, _ = _read(_riser_data())
    on = replace(scene, run=replace(scene.run, interface_models=True))
    assert on.bonds[0].wired and on.units["rope"].parameters["interface_model"] is True
    off = replace(on, run=replace(on.run, interface_models=False))
    assert not off.bonds[0].wired and off.bonds[0].effort.extrapolation is None
    assert off.units["rope"].parameters == scene.units["rope"].parameters
    assert off.units["rope"].switched_on == ()
    data = _riser_data()
    data["units"]["rope"]["parameters"]["interface_model"] = True
    own, _ = _read(data)
    wired = replace(own, run=replace(own.run, interface_models=True))
    assert wired.units["rope"].switched_on == ()  # the scene set it: it stays the scene's
    unwired = replace(wired, run=replace(wired.run, interface_models=False))
    assert unwired.units["rope"].parameters["interface_model"] is True


@pytest.mark.parametrize(("run", "bond", "wired"), [(True, False, False), (False, True, True)])
def test_a_bond_chooses_for_itself(declared, run, bond, wired):
    data = _riser_data(interface_models=run)
    data["bonds"][0]["interface_model"] = bond
    scene, problems = _read(data)
    assert problems == [] and scene.bonds[0].wired is wired
    assert ("interface_model" in scene.units["rope"].parameters) is wired
    assert interface_warnings(scene) == []


def test_a_port_without_the_model_keeps_three_links_and_check_warns(declared):
    declared["cylinder"]["rod"] = PLAIN_FLOW
    scene, problems = _read(_riser_data(interface_models=True))
    assert problems == []
    (bond,) = scene.bonds
    assert not bond.wired and len(bond.connections) == 3 and len(scene.all_connections) == 3
    assert "interface_model" not in scene.units["rope"].parameters
    assert interface_warnings(scene) == [
        "bond 'rod': run.interface_models asks for interface models, but cylinder.rod "
        "(flow side) declares no interface model; the bond keeps its effort, flow and "
        "position links"
    ]


def test_a_bond_that_asks_for_a_model_its_ports_lack_is_a_problem(declared):
    declared["rope"]["mover_a"] = replace(ROD_EFFORT, interface=False)
    data = _riser_data()
    data["bonds"][0]["interface_model"] = True
    _, problems = _read(data)
    assert problems == [
        "bond 'rod': 'interface_model' = true, but rope.mover_a (effort side) declares no "
        "interface model; leave the key out or set it false to keep the bond's effort, flow "
        "and position links"
    ]


@pytest.mark.parametrize("value", ["yes", 1, [True]])
def test_bad_values_of_the_setting_are_problems_named_with_what_was_expected(declared, value):
    data = _riser_data(interface_models=value)
    data["bonds"][0]["interface_model"] = value
    scene, problems = _read(data)
    assert f"run.interface_models must be true or false, got {value!r}" in problems
    assert f"bond 'rod': 'interface_model' must be true or false, got {value!r}" in problems
    assert scene.run.interface_models is False and not scene.bonds[0].wired
    with pytest.raises(SceneError) as caught:
        parse_scene(data, base_dir=SCENES)
    assert len(caught.value.problems) == 2


def test_the_interface_links_count_with_the_effort_in_the_step_order(declared):
    scene, _ = _read(_riser_data(interface_models=True))
    host = SimpleNamespace(scene=scene, run_settings=scene.run)
    assert Simulation._order(host, None) == ["cylinder", "rope"]  # the flow side first


def _structure(switch_start: str = "false") -> validate.Structure:
    """Model descriptions with just what the interface checks read."""

    def var(name, causality, vtype="Real", unit=None, start=None):
        return SimpleNamespace(name=name, causality=causality, type=vtype, unit=unit, start=start)

    units = dict(zip(INTERFACE_QUANTITIES, ("N/m", "N.s/m", "N/s", "m", "m/s"), strict=True))
    rope = [var("interface_model", "parameter", "Boolean", start=switch_start)]
    rope += [var(f"mover_a.{q}", "output", unit=u) for q, u in units.items()]
    rope += [var("mover_a.force", "output", unit="N")]
    cylinder = [var(f"rod.{q}", "input", unit=u) for q, u in units.items()]
    cylinder += [var("rod.velocity", "output", unit="m/s")]
    cylinder += [var("rod.displacement", "output", unit="m")]
    descriptions = {
        "rope": SimpleNamespace(modelVariables=rope),
        "cylinder": SimpleNamespace(modelVariables=cylinder),
    }
    return validate.Structure({}, descriptions)


def test_a_switch_the_scene_turns_off_under_a_wired_model_is_a_clear_problem(declared):
    data = _riser_data(interface_models=True)
    data["units"]["rope"]["parameters"]["interface_model"] = False
    scene, problems = _read(data)
    assert problems == [] and scene.bonds[0].wired
    assert validate._bond_problems(scene, _structure()) == [
        "bond 'rod': its interface model is wired (run.interface_models), but unit 'rope' "
        "sets interface_model = false, so rope.mover_a.stiffness and the model's other "
        "outputs would carry zeros; expected interface_model = true: leave interface_model "
        "out (the master sets it) or set interface_model = false on the bond"
    ]
    on, _ = _read(_riser_data(interface_models=True))
    assert validate._bond_problems(on, _structure()) == []


def test_a_long_form_bond_lists_its_links_and_its_scene_sets_the_switch(declared):
    data = _riser_data()
    data["bonds"] = [
        {
            "name": "rod",
            "kind": "translational",
            "effort": "rope.mover_a.force -> cylinder.rod.force",
            "flow": "cylinder.rod.velocity -> rope.mover_a.velocity",
            "position": "cylinder.rod.displacement -> rope.mover_a.position",
            "interface": [f"rope.mover_a.{q} -> cylinder.rod.{q}" for q in INTERFACE_QUANTITIES],
            "interface_model": True,
        }
    ]
    scene, problems = _read(data)
    assert problems == [] and scene.bonds[0].wired and len(scene.all_connections) == 8
    assert "interface_model" not in scene.units["rope"].parameters  # no port named it
    structure = _structure()
    structure.paths["rope"] = Path("no such file.fmu")  # its declarations cannot be read
    assert validate._bond_problems(scene, structure) == []
    assert validate._bond_problems(scene, _structure("true")) == []
    data["bonds"][0]["interface"] = [
        "cylinder.rod.velocity -> rope.mover_a.stiffness",
        3,
        "rope.mover_a.damping -> cylnder.rod.damping",
    ]
    data["bonds"][0]["interface_model"] = "on"
    _, problems = _read(data)
    assert problems == [
        "bond 'rod': 'interface_model' must be true or false, got 'on'",
        "bond 'rod' interface link 1: must read 'unit.output -> unit.input', got 3",
        "bond 'rod': interface link cylinder.rod.velocity -> rope.mover_a.stiffness must go "
        "the effort's way, from unit 'rope' to unit 'cylinder'",
        "bond 'rod': interface link rope.mover_a.damping -> cylnder.rod.damping must go the "
        "effort's way, from unit 'rope' to unit 'cylinder'",
        "bond 'rod' interface: cylnder.rod.damping names no unit 'cylnder'; the scene's "
        "units: cylinder, rope",
    ]


def test_an_interface_quantity_in_the_wrong_unit_is_named(declared):
    scene, _ = _read(_riser_data(interface_models=True))
    structure = _structure()
    damping = structure.variable(validate.VarRef("rope", "mover_a.damping"))
    damping.unit = "N/m"
    assert validate._bond_problems(scene, structure) == [
        "bond 'rod' (translational): interface link rope.mover_a.damping -> "
        "cylinder.rod.damping: rope.mover_a.damping has unit N/m, expected N.s/m (the "
        "interface model of a translational bond)"
    ]


# -- test FMUs that declare the model ----------------------------------------------------------
EFFORT_UNITS = '''
"""A coupled mass whose flange port offers an interface model (test unit)."""

from wire_fmu.core.framework.ports import (
    INTERFACE_QUANTITIES,
    INTERFACE_UNITS,
    Port,
    PortSide,
)
from wire_fmu.core.framework.unit import output, parameter
from wire_fmu_master_units import CoupledMassUnit

_QUANTITIES = dict(
    zip(INTERFACE_QUANTITIES, INTERFACE_UNITS["translational"], strict=True)
)


class InterfaceMassUnit(CoupledMassUnit):
    """The coupled mass; with ``interface_model`` its flange force's linearisation."""

    NAME = "InterfaceMass"
    DESCRIPTION = "Coupled mass offering its flange force's interface model (test unit)"
    VARIABLES = CoupledMassUnit.VARIABLES + (
        parameter("interface_model", False, "", "Publish the interface model", type=bool),
        *(output(f"flange.{q}", u, f"Interface model: {q}") for q, u in _QUANTITIES.items()),
    )
    PORTS = (
        Port(
            "flange",
            "translational",
            PortSide.effort,
            "force_on_flange",
            "flange.velocity",
            "flange.position",
            interface=True,
            interface_switch="interface_model",
        ),
    )

    def _publish(self, xf, vf):
        super()._publish(xf, vf)
        p, on = self.values, self.values["interface_model"]
        p["flange.stiffness"] = float(p["stiffness"]) if on else 0.0
        p["flange.damping"] = float(p["damping"]) if on else 0.0
        p["flange.effort_rate"] = 0.0
        p["flange.reference_position"] = float(xf) if on else 0.0
        p["flange.reference_velocity"] = float(vf) if on else 0.0
'''
FLOW_UNITS = '''
"""An oscillator whose body port takes an interface model (test unit)."""

from wire_fmu.core.framework.ports import (
    INTERFACE_QUANTITIES,
    INTERFACE_UNITS,
    Port,
    PortSide,
)
from wire_fmu.core.framework.unit import input_, output
from wire_fmu_test_units import OscillatorUnit

_QUANTITIES = dict(
    zip(INTERFACE_QUANTITIES, INTERFACE_UNITS["translational"], strict=True)
)


class InterfaceOscillatorUnit(OscillatorUnit):
    """The oscillator; it shows the stiffness its body port was handed over the step."""

    NAME = "InterfaceOscillator"
    DESCRIPTION = "Oscillator taking an interface model at its body port (test unit)"
    VARIABLES = OscillatorUnit.VARIABLES + (
        *(input_(f"body.{q}", 0.0, u, f"Interface model: {q}") for q, u in _QUANTITIES.items()),
        output("seen_stiffness", "N/m", "The body.stiffness input over the last step"),
    )
    PORTS = (
        Port(
            "body",
            "translational",
            PortSide.flow,
            "force",
            "velocity",
            "position",
            interface=True,
        ),
    )

    def _publish(self):
        super()._publish()
        self.values["seen_stiffness"] = float(self.values["body.stiffness"])
'''
FACADE = '''
"""Facade script of a test FMU."""

from {module} import {cls}

from wire_fmu.export.facade import CoreFacade


class {name}(CoreFacade):
    """FMU facade of :class:`{cls}`."""

    unit_class = {cls}
'''


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    """The effort-side (``mass``), flow-side (``osc``) and plain oscillator (``plain``) FMUs."""
    from wire_fmu.export.builder import build_fmu

    from .interop_helpers import build_test_fmus

    root = tmp_path_factory.mktemp("interface_fmus")
    built = build_test_fmus(root / "plain")
    out = {"plain": built["osc"]}
    for key, module, cls, name, body, extra in [
        (
            "mass",
            "wire_fmu_iface_effort",
            "InterfaceMassUnit",
            "InterfaceMass",
            EFFORT_UNITS,
            "wire_fmu_master_units.py",
        ),
        (
            "osc",
            "wire_fmu_iface_flow",
            "InterfaceOscillatorUnit",
            "InterfaceOscillator",
            FLOW_UNITS,
            "wire_fmu_test_units.py",
        ),
    ]:
        source = root / f"{module}.py"
        source.write_text(textwrap.dedent(body))
        facade = root / f"facade_{key}.py"
        facade.write_text(FACADE.format(module=module, cls=cls, name=name))
        out[key] = build_fmu(facade, root / "fmus", extra_modules=[source, SUPPORT / extra])
    return out


def _pair_data(fmus: dict[str, Path], flow: str = "osc", **run) -> dict:
    return {
        "name": "interface_pair",
        "run": {
            "stop_time": 0.1,
            "step": 0.01,
            "algorithm": "gauss_seidel",
            "extrapolation": "linear",
            "interface_models": True,
            **run,
        },
        "units": {
            "a": {"fmu": str(fmus[flow]), "parameters": {"mass": 1.0, "x0": 0.0}},
            "b": {
                "fmu": str(fmus["mass"]),
                "parameters": {"mass": 2.0, "stiffness": 60.0, "damping": 0.5, "x0": 0.1},
            },
        },
        "bonds": [{"name": "spring", "ports": "a.body <-> b.flange"}],
        "outputs": {
            "variables": ["a.position", "a.seen_stiffness", "b.flange.stiffness", "a.body.damping"]
        },
    }


@pytest.mark.integration
def test_the_fmus_declare_the_model_and_check_lists_the_wired_bond(fmus, tmp_path, capsys):
    from wire_fmu.cli import main

    scene = parse_scene(_pair_data(fmus), base_dir=tmp_path)
    assert scene.bonds[0].wired and len(scene.all_connections) == 8
    validate.validate_scene(scene, dry_run=True)
    path = tmp_path / "pair.toml"
    path.write_text(_toml(_pair_data(fmus)))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "no problems (2 units, 1 bond (1 with interface model), 0 connections)" in out
    assert "warning" not in out


@pytest.mark.integration
def test_a_run_hands_the_flow_side_the_effort_sides_model(fmus, tmp_path):
    from wire_fmu.master.run import read_results_frame, run_scene

    scene = parse_scene(_pair_data(fmus), base_dir=tmp_path)
    outcome = run_scene(scene, tmp_path / "on", plots=False)
    assert outcome.result.status == "finished"
    frame = read_results_frame(tmp_path / "on")
    assert (frame["b.flange.stiffness"].iloc[1:] == 60.0).all()
    assert (frame["a.seen_stiffness"].iloc[1:] == 60.0).all()
    assert (frame["a.body.damping"].iloc[1:] == 0.5).all()  # an input, recorded when listed
    off = parse_scene(_pair_data(fmus, interface_models=False), base_dir=tmp_path)
    run_scene(off, tmp_path / "off", plots=False)
    plain = read_results_frame(tmp_path / "off")
    assert (plain["a.seen_stiffness"] == 0.0).all() and (plain["b.flange.stiffness"] == 0.0).all()


@pytest.mark.integration
def test_link_problems_name_the_unit_the_variable_and_what_was_expected(fmus, tmp_path):
    data = _pair_data(fmus)
    data["units"]["b"]["parameters"]["interface_model"] = False
    data["bonds"].append(
        {
            "name": "bad",
            "kind": "translational",
            "effort": "b.force_on_flange -> a.force",
            "flow": "a.velocity -> b.flange.velocity",
            "interface": ["b.flange.damping -> a.body.stiffnes", "b.position -> a.label"],
            "interface_model": True,
        }
    )
    scene = parse_scene(data, base_dir=tmp_path)
    with pytest.raises(SceneError) as caught:
        validate.validate_scene(scene, through_fmi=False)
    problems = caught.value.problems
    assert (
        "bond 'bad' interface to a.body.stiffnes: unit 'a' has no variable 'body.stiffnes'; "
        "its inputs: force, body.stiffness, body.damping, body.effort_rate, "
        "body.reference_position, body.reference_velocity" in problems
    )
    assert "bond 'bad' interface to a.label: is a parameter, expected an input" in problems
    wired = [
        ("spring", "run.interface_models", "stiffness"),
        ("bad", "its interface_model = true", "damping"),
    ]
    for bond, asked, first in wired:
        assert (
            f"bond {bond!r}: its interface model is wired ({asked}), but unit 'b' sets "
            f"interface_model = false, so b.flange.{first} and the model's other outputs "
            "would carry zeros; expected interface_model = true: leave interface_model out "
            "(the master sets it) or set interface_model = false on the bond"
        ) in problems


@pytest.mark.integration
def test_a_long_form_bond_that_leaves_the_switch_at_its_default_is_told_to_set_it(fmus, tmp_path):
    data = _pair_data(fmus, interface_models=False)
    data["bonds"] = [
        {
            "name": "spring",
            "kind": "translational",
            "effort": "b.force_on_flange -> a.force",
            "flow": "a.velocity -> b.flange.velocity",
            "position": "a.position -> b.flange.position",
            "interface": [f"b.flange.{q} -> a.body.{q}" for q in INTERFACE_QUANTITIES],
            "interface_model": True,
        }
    ]
    scene = parse_scene(data, base_dir=tmp_path)
    with pytest.raises(SceneError) as caught:
        validate.validate_scene(scene, through_fmi=False)
    assert caught.value.problems == [
        "bond 'spring': its interface model is wired (its interface_model = true), but unit "
        "'b' leaves interface_model at false, so b.flange.stiffness and the model's other "
        "outputs would carry zeros; expected interface_model = true: set interface_model = "
        "true on unit 'b' or interface_model = false on the bond"
    ]
    data["units"]["b"]["parameters"]["interface_model"] = True
    validate.validate_scene(parse_scene(data, base_dir=tmp_path), through_fmi=False)


@pytest.mark.integration
def test_a_flow_side_without_the_model_keeps_three_links_with_a_warning(fmus, tmp_path, capsys):
    from wire_fmu.cli import main

    data = _pair_data(fmus, flow="plain")
    data["bonds"] = [
        {
            "name": "spring",
            "kind": "translational",
            "effort": "b.force_on_flange -> a.force",
            "flow": "a.velocity -> b.flange.velocity",
            "position": "a.position -> b.flange.position",
        }
    ]
    data["outputs"] = {"variables": "all"}
    path = tmp_path / "plain.toml"
    path.write_text(_toml(data))
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "no problems (2 units, 1 bond, 0 connections)" in out
    assert (
        "warning: bond 'spring': run.interface_models asks for interface models, but it is "
        "written link by link without 'interface' links" in out
    )


def _toml(data: dict) -> str:
    import json

    lines = []
    for key in ("name",):
        lines.append(f"{key} = {json.dumps(data[key])}")
    lines.append("[run]")
    lines += [f"{k} = {json.dumps(v)}" for k, v in data["run"].items()]
    for name, unit in data["units"].items():
        lines.append(f"[units.{name}]")
        lines.append(f"fmu = {json.dumps(unit['fmu'])}")
        lines.append(f"[units.{name}.parameters]")
        lines += [f"{k} = {json.dumps(v)}" for k, v in unit["parameters"].items()]
    for bond in data["bonds"]:
        lines += ["[[bonds]]"] + [f"{k} = {json.dumps(v)}" for k, v in bond.items()]
    lines += ["[outputs]", f"variables = {json.dumps(data['outputs']['variables'])}"]
    return "\n".join(lines) + "\n"


# -- exports -------------------------------------------------------------------------------
@pytest.mark.integration
def test_ssp_carries_the_links_and_the_switch_and_reads_them_back(fmus, tmp_path):
    from wire_fmu.interop.ssp import NS, export_ssp
    from wire_fmu.interop.ssp_read import read_ssp
    from wire_fmu.master.run import read_results_frame, run_scene

    scene = parse_scene(_pair_data(fmus), base_dir=tmp_path)
    package = export_ssp(scene, tmp_path / "pair.ssp")
    with zipfile.ZipFile(package) as archive:
        ssd = etree.fromstring(archive.read("SystemStructure.ssd"))
        ssv = etree.fromstring(archive.read("resources/b.ssv"))
    marked = {}
    for connection in ssd.iter(f"{{{NS['ssd']}}}Connection"):
        (note,) = connection.iter(f"{{{NS['wf']}}}Bond")
        link = (
            f"{connection.get('startElement')}.{connection.get('startConnector')}",
            f"{connection.get('endElement')}.{connection.get('endConnector')}",
        )
        marked[link] = note.get("role")
    assert [link for link, role in marked.items() if role == INTERFACE_ROLE] == [
        (f"b.flange.{q}", f"a.body.{q}") for q in INTERFACE_QUANTITIES
    ]
    assert len(marked) == 8
    (switch,) = [
        p for p in ssv.iter(f"{{{NS['ssv']}}}Parameter") if p.get("name") == "interface_model"
    ]
    assert switch[0].get("value") == "true"
    back = read_ssp(package, extract_to=tmp_path / "extracted")
    assert back.run.interface_models is True and back.bonds[0].wired
    links = {(str(c.source), str(c.target), c.role, c.extrapolation) for c in back.all_connections}
    assert links == {
        (str(c.source), str(c.target), c.role, c.extrapolation) for c in scene.all_connections
    }
    assert back.units["b"].parameter_values() == scene.units["b"].parameter_values()
    run_scene(scene, tmp_path / "original", plots=False)
    run_scene(back, tmp_path / "back", plots=False)
    original, again = (read_results_frame(tmp_path / d) for d in ("original", "back"))
    assert original[list(again.columns)].equals(again)


@pytest.mark.integration
def test_an_ssp_without_our_run_settings_still_wires_the_links_it_carries(fmus, tmp_path):
    from wire_fmu.interop.ssp import export_ssp
    from wire_fmu.interop.ssp_read import read_ssp

    data = _pair_data(fmus, interface_models=False)
    data["bonds"][0]["interface_model"] = True
    package = export_ssp(parse_scene(data, base_dir=tmp_path), tmp_path / "pair.ssp")
    back = read_ssp(package, extract_to=tmp_path / "extracted")
    assert back.run.interface_models is False
    assert back.bonds[0].interface_model is True and back.bonds[0].wired


@pytest.mark.integration
def test_osp_carries_the_links_as_variable_connections_and_the_switch(fmus, tmp_path):
    from wire_fmu.interop.osp import OSP_NS, export_osp

    scene = parse_scene(_pair_data(fmus), base_dir=tmp_path)
    root = etree.parse(str(export_osp(scene, tmp_path / "osp"))).getroot()
    links = []
    for connection in root.iter(f"{{{OSP_NS}}}VariableConnection"):
        a, b = connection.iter(f"{{{OSP_NS}}}Variable")
        links.append(
            (f"{a.get('simulator')}.{a.get('name')}", f"{b.get('simulator')}.{b.get('name')}")
        )
    assert links == [(f"b.flange.{q}", f"a.body.{q}") for q in INTERFACE_QUANTITIES]
    assert len(list(root.iter(f"{{{OSP_NS}}}VariableGroupConnection"))) == 2
    values = {
        (sim.get("name"), v.get("variable")): v[0].get("value")
        for sim in root.iter(f"{{{OSP_NS}}}Simulator")
        for v in sim.iter(f"{{{OSP_NS}}}InitialValue")
    }
    assert values[("b", "interface_model")] == "true"


@pytest.mark.integration
@pytest.mark.parametrize("kind", ["ssp", "osp"])
def test_libcosim_runs_the_exported_links_as_our_master_does(fmus, tmp_path, kind):
    import numpy as np

    from wire_fmu.interop.osp import export_osp
    from wire_fmu.interop.ssp import export_ssp

    from .interop_helpers import run_libcosim, run_ours

    data = _pair_data(fmus, algorithm="jacobi", extrapolation="constant")
    scene = parse_scene(data, base_dir=tmp_path)
    path = (export_ssp if kind == "ssp" else export_osp)(scene, tmp_path / kind)
    names, ours = run_ours(scene)
    theirs = run_libcosim(path, names, step=0.01, stop=0.1, kind=kind)
    seen = names.index(("a", "seen_stiffness")) + 1
    assert (theirs[:, seen] == 60.0).all()
    assert np.abs(theirs - ours).max() <= 1e-12 * max(1.0, np.abs(ours).max())


# -- the riser tensioner -----------------------------------------------------------------------
@pytest.mark.integration
def test_the_riser_cylinder_receives_the_ropes_stiffness_through_the_rod_bond(tmp_path):
    from wire_fmu.master.run import read_results_frame, run_scene
    from wire_fmu.master.scene import load_scene

    scene = load_scene(SCENES / "riser_tensioner.toml")
    if scene.bonds[0].interface_lacking:
        pytest.skip(f"no interface model yet at {', '.join(scene.bonds[0].interface_lacking)}")
    on = replace(scene, run=replace(scene.run, interface_models=True, stop_time=0.2))
    on = replace(on, outputs=(*on.outputs, *(c.target for c in on.bonds[0].interface)))
    outcome = run_scene(on, tmp_path / "riser", plots=False)
    assert outcome.result.status == "finished", outcome.result.message
    frame = read_results_frame(tmp_path / "riser").iloc[1:]
    # 16 EA / L through the 4:1 reeving: EA = 1.3e8 N over one span of 67.8 m
    assert frame["cylinder.rod.stiffness"].to_numpy() == pytest.approx(16 * 1.3e8 / 67.8, rel=0.02)
    assert (frame["cylinder.rod.damping"] > 0.0).all()
