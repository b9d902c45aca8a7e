"""Ports: declared by the core units, carried in the FMUs' model descriptions, bonded by name
in a scene ("cylinder.rod <-> rope.mover_a") with the same links as the long form."""

from __future__ import annotations

import copy
import tomllib
import zipfile
from pathlib import Path

import pytest

from wire_fmu.core.framework.ports import Port, PortSide
from wire_fmu.core.framework.unit import Unit, input_, output
from wire_fmu.master.catalog import DEFAULT_FMU_DIR, resolve_fmu
from wire_fmu.master.ports import PortDeclaration, port_links, read_ports
from wire_fmu.master.scene import read_scene_data
from wire_fmu.registry import UNIT_TYPES

SCENES = Path(__file__).resolve().parents[1] / "wire_fmu" / "scenes"

LONG_BONDS = {
    "riser_tensioner": [
        {
            "name": "rod",
            "kind": "translational",
            "effort": "rope.mover_a.force -> cylinder.rod.force",
            "flow": "cylinder.rod.velocity -> rope.mover_a.velocity",
            "position": "cylinder.rod.displacement -> rope.mover_a.position",
        }
    ],
    "drawworks": [
        {
            "name": "fast_line",
            "kind": "rope",
            "effort": "rope.line_a.tension -> winch.rope.tension",
            "flow": "winch.rope.payout_rate -> rope.line_a.payout_rate",
            "position": "winch.rope.payout -> rope.line_a.payout",
        }
    ],
    "heave_compensated_hoist": [
        {
            "name": "fast_line",
            "kind": "rope",
            "effort": "rope.line_a.tension -> winch.rope.tension",
            "flow": "winch.rope.payout_rate -> rope.line_a.payout_rate",
            "position": "winch.rope.payout -> rope.line_a.payout",
        },
        {
            "name": "crown",
            "kind": "translational",
            "effort": "rope.mover_a.force -> compensator.rod.force",
            "flow": "compensator.rod.velocity -> rope.mover_a.velocity",
            "position": "compensator.rod.displacement -> rope.mover_a.position",
        },
    ],
}
"""The shipped scenes' bonds as the long form writes them (checked against their short form)."""


def scene_data(name: str) -> dict:
    return tomllib.loads((SCENES / f"{name}.toml").read_text())


def read(data: dict):
    return read_scene_data(data, base_dir=SCENES, source=SCENES / "x.toml")


def problems_of(bonds: list) -> list[str]:
    data = scene_data("riser_tensioner")
    data["bonds"] = bonds
    return read(data)[1]


# -- declarations -----------------------------------------------------------------
@pytest.mark.integration
@pytest.mark.parametrize("unit", UNIT_TYPES, ids=lambda u: u.name)
def test_every_fmu_declares_its_core_units_ports(unit):
    path, problem = resolve_fmu(unit.name, SCENES, DEFAULT_FMU_DIR)
    assert problem is None
    declared = read_ports(path)
    expected = {
        p.name: PortDeclaration(
            p.name,
            p.kind,
            p.side.value,
            p.effort,
            p.flow,
            p.position,
            p.description,
            p.interface,
            p.interface_switch,
            p.flow_ramp,
        )
        for p in unit.core_class().PORTS
    }
    assert declared == expected


def test_the_hoisting_units_offer_the_ports_their_bonds_use():
    ports = {u.name: {p.name: p for p in u.core_class().PORTS} for u in UNIT_TYPES}
    assert ports["Hydraulics"]["rod"].side is PortSide.flow
    assert ports["Winch"]["rope"].side is PortSide.flow
    assert {"line_a", "line_b", "mover_a", "mover_b"} <= set(ports["BlockTrain"])
    assert all(p.side is PortSide.effort for p in ports["BlockTrain"].values())


class _BadPorts(Unit):
    NAME = "BadPorts"
    VARIABLES = (
        input_("f", 0.0, "N", "a force in"),
        output("v", "m/s", "a velocity out"),
        output("x", "rad", "an angle, not a position"),
    )
    PORTS = (
        Port("p", "translational", PortSide.effort, "f", "v", "x"),  # sides reversed
        Port("q", "translational", PortSide.flow, "f", "v", "x"),  # x has the wrong unit
        Port("q", "hydraulic", PortSide.flow, "f", "v"),  # twice, of an unknown kind
    )

    def configure(self):  # pragma: no cover - declarations only
        pass

    def initialize(self, start_time):  # pragma: no cover
        pass

    def get_state(self):  # pragma: no cover
        return {}

    def set_state(self, state):  # pragma: no cover
        pass


def test_a_port_that_does_not_match_its_variables_is_named_with_what_is_wrong():
    problems = _BadPorts.check_declarations()
    assert "BadPorts: port 'q' declared twice" in problems
    assert "BadPorts: port 'p': 'f' must be an output of the unit" in problems
    assert "BadPorts: port 'p': 'v' must be an input of the unit" in problems
    assert "BadPorts: port 'q': 'x' must be in m" in problems
    assert any("kind 'hydraulic' is not one of" in p for p in problems)


# -- the short form ----------------------------------------------------------------
@pytest.mark.integration
@pytest.mark.parametrize("name", sorted(LONG_BONDS))
def test_a_bond_written_as_two_ports_is_the_long_form(name):
    data = scene_data(name)
    data["run"].pop("interface_models", None)  # the long forms below list no interface links
    data["run"].pop("ramped_flows", None)  # nor ramps
    short, problems = read(data)
    assert problems == []
    long_form = copy.deepcopy(data)
    long_form["bonds"] = LONG_BONDS[name]
    long, problems = read(long_form)
    assert problems == []
    # the same links; the short form also knows what its ports offer (interface models)
    assert [(b.name, b.kind, b.connections) for b in short.bonds] == [
        (b.name, b.kind, b.connections) for b in long.bonds
    ]
    assert short.all_connections == long.all_connections


@pytest.mark.integration
def test_ports_may_be_written_in_either_order_and_in_a_named_table():
    data = scene_data("riser_tensioner")
    data["bonds"] = [{"name": "rod", "ports": "rope.mover_a <-> cylinder.rod"}]
    reversed_, problems = read(data)
    assert problems == []
    data["bonds"] = ["cylinder.rod <-> rope.mover_a"]
    assert read(data)[0].bonds == reversed_.bonds
    data["bonds"] = [{"ports": "cylinder.rod <-> rope.mover_a", "extrapolation": "constant"}]
    bond = read(data)[0].bonds[0]
    assert {c.extrapolation for c in bond.connections} == {"constant"}


@pytest.mark.integration
def test_every_problem_of_port_bonds_is_named_at_once():
    problems = problems_of(
        [
            "cylinder.rod <-> rope.mover_c",
            "cylinder.piston <-> rope.mover_a",
            "crane.hook <-> rope.mover_a",
            "cylinder.rod -> rope.mover_a",
            {"ports": "rope.line_a <-> rope.mover_a", "name": "same_side"},
            {"ports": "cylinder.rod <-> rope.mover_a", "kind": "rope", "colour": "red"},
        ]
    )
    assert (
        "bond 'rod': unit 'rope' has no port 'mover_c'; its ports: line_a, line_b, mover_a, "
        "mover_b" in problems
    )
    assert any("unit 'cylinder' has no port 'piston'; its ports: rod" in p for p in problems)
    assert any("names unit 'crane', which is no unit of the scene" in p for p in problems)
    assert any(
        "'ports' must read 'unit.port <-> unit.port', got 'cylinder.rod -> rope.mover_a'" in p
        for p in problems
    )
    assert any(
        p.startswith("bond 'same_side': ports rope.line_a") and "both compute the effort" in p
        for p in problems
    )
    assert any("'kind' 'rope' differs from the ports' kind 'translational'" in p for p in problems)
    assert any("unknown keys ['colour']" in p for p in problems)
    assert any("bond 'rod': defined twice" in p for p in problems)


def test_a_unit_whose_fmu_cannot_be_found_is_a_problem_of_the_bond():
    data = scene_data("riser_tensioner")
    data["units"]["cylinder"]["fmu"] = "missing/Nowhere.fmu"
    data["bonds"] = ["cylinder.rod <-> rope.mover_a"]
    problems = read(data)[1]
    assert any(
        p.startswith("bond 'rod': cannot read the ports of unit 'cylinder': FMU file")
        for p in problems
    )


def _declaration(name: str, kind: str, side: str, position: str | None) -> PortDeclaration:
    return PortDeclaration(name, kind, side, f"{name}.e", f"{name}.f", position)


def test_links_run_effort_to_the_flow_side_and_flow_and_position_back():
    effort = ("a", _declaration("p", "rope", "effort", "p.x"))
    flow = ("b", _declaration("q", "rope", "flow", "q.x"))
    links, problems = port_links(flow, effort)
    assert problems == []
    assert (links.kind, links.effort, links.flow, links.position) == (
        "rope",
        ("a.p.e", "b.q.e"),
        ("b.q.f", "a.p.f"),
        ("b.q.x", "a.p.x"),
    )


def test_an_effort_side_that_needs_a_position_the_other_does_not_give_is_refused():
    effort = ("a", _declaration("p", "rotational", "effort", "p.x"))
    flow = ("b", _declaration("q", "rotational", "flow", None))
    links, problems = port_links(effort, flow)
    assert links is None
    assert "takes a position (p.x) that port b.q does not give" in problems[0]
    links, problems = port_links(("a", _declaration("p", "rotational", "effort", None)), flow)
    assert problems == [] and links.position is None


def test_ports_of_different_kinds_are_not_bonded():
    links, problems = port_links(
        ("a", _declaration("p", "rope", "effort", None)),
        ("b", _declaration("q", "rotational", "flow", None)),
    )
    assert links is None and "are of different kinds" in problems[0]


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (b"<not xml", "cannot read the model description"),
        (
            b'<fmiModelDescription><VendorAnnotations><Tool name="wire_fmu"><Ports>'
            b'<Port name="p" kind="rope" side="both" effort="e" flow="f"/>'
            b"</Ports></Tool></VendorAnnotations></fmiModelDescription>",
            "side 'both' is not one of",
        ),
        (
            b'<fmiModelDescription><VendorAnnotations><Tool name="wire_fmu"><Ports>'
            b'<Port name="p" kind="rope" side="flow"/>'
            b"</Ports></Tool></VendorAnnotations></fmiModelDescription>",
            "lacks ['effort', 'flow']",
        ),
    ],
)
def test_malformed_port_declarations_are_refused_with_the_reason(tmp_path, content, reason):
    fmu = tmp_path / "Odd.fmu"
    with zipfile.ZipFile(fmu, "w") as archive:
        archive.writestr("modelDescription.xml", content)
    with pytest.raises(ValueError, match=reason.replace("[", r"\[").replace("(", r"\(")):
        read_ports(fmu)


def test_an_fmu_without_declarations_has_no_ports(tmp_path):
    fmu = tmp_path / "Plain.fmu"
    with zipfile.ZipFile(fmu, "w") as archive:
        archive.writestr("modelDescription.xml", b"<fmiModelDescription/>")
    assert read_ports(fmu) == {}
