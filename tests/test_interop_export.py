"""SSP and OSP export: schema validity, what the files say, SSP read back exactly.

A test that compared the writer's output with itself would prove nothing, so
the files are checked against the public schemas, read by FMPy's SSP reader
(a parser we did not write), and the scene read back from the package must
run to bit-identical results.
"""

from __future__ import annotations

import json
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from wire_fmu.cli import main
from wire_fmu.core.errors import WireFmuError
from wire_fmu.interop import export_osp, export_ssp, plan_export, read_ssp
from wire_fmu.interop.osp import OSP_MD_NS, OSP_NS
from wire_fmu.interop.ssp import NS, SSD_NAME
from wire_fmu.master.scene import SceneError, parse_scene

from .interop_helpers import (
    build_test_fmus,
    run_ours,
    schema_errors,
    two_mass_data,
    two_mass_scene,
)

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    return build_test_fmus(tmp_path_factory.mktemp("fmus"))


@pytest.fixture(scope="module")
def ssp(fmus, tmp_path_factory) -> Path:
    scene = two_mass_scene(fmus, tmp_path_factory.mktemp("scene"))
    return export_ssp(scene, tmp_path_factory.mktemp("ssp"), fmu_dir=fmus["osc"].parent)


@pytest.fixture(scope="module")
def osp(fmus, tmp_path_factory) -> Path:
    scene = two_mass_scene(fmus, tmp_path_factory.mktemp("scene"))
    return export_osp(scene, tmp_path_factory.mktemp("osp"), fmu_dir=fmus["osc"].parent)


def _ssd(ssp: Path) -> etree._Element:
    with zipfile.ZipFile(ssp) as archive:
        return etree.fromstring(archive.read(SSD_NAME))


def test_exported_ssp_validates_against_the_ssp_1_0_schemas(ssp):
    with zipfile.ZipFile(ssp) as archive:
        names = archive.namelist()
        assert schema_errors(archive.read(SSD_NAME), "ssp/SystemStructureDescription.xsd") == []
        ssvs = [n for n in names if n.endswith(".ssv")]
        assert sorted(ssvs) == [f"resources/{u}.ssv" for u in ("a", "b", "c", "d", "e", "signals")]
        for name in ssvs:
            assert (
                schema_errors(archive.read(name), "ssp/SystemStructureParameterValues.xsd") == []
            ), name
    # each unit's own FMU, configured with its parameters (two units of one model: two files)
    assert sorted(n for n in names if n.endswith(".fmu")) == [
        f"resources/{u}.fmu" for u in ("a", "b", "c", "d", "e", "signals")
    ]
    sources = {c.get("name"): c.get("source") for c in _ssd(ssp).iter(f"{{{NS['ssd']}}}Component")}
    assert sources == {u: f"resources/{u}.fmu" for u in ("a", "b", "c", "d", "e", "signals")}


def test_each_units_fmu_starts_with_the_units_parameter_values(ssp, tmp_path):
    """What FMPy's runner needs (it applies no binding and sets no String): the FMU's
    own start values, in its model description and set by its facade, are the SSV's."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    with zipfile.ZipFile(ssp) as archive:
        ssv = etree.fromstring(archive.read("resources/a.ssv"))
        archive.extract("resources/a.fmu", tmp_path)
    bound = {}
    for parameter in ssv.iter(f"{{{NS['ssv']}}}Parameter"):
        typed = parameter[0]
        bound[parameter.get("name")] = (etree.QName(typed).localname, typed.get("value"))
    assert bound["label"][0] == "String" and bound["mass"][0] == "Real"
    fmu = tmp_path / "resources" / "a.fmu"
    model = read_model_description(str(fmu))
    starts = {v.name: v for v in model.modelVariables}
    for name, (_, text) in bound.items():
        assert starts[name].start == text, name
    fmu_unzipped = extract(str(fmu))
    slave = FMU2Slave(
        guid=model.guid,
        unzipDirectory=fmu_unzipped,
        modelIdentifier=model.coSimulation.modelIdentifier,
        instanceName="a",
    )
    slave.instantiate()
    try:
        for name, (kind, text) in bound.items():
            ref = [starts[name].valueReference]
            if kind == "Real":
                assert slave.getReal(ref)[0] == float(text), name
            elif kind == "String":
                assert slave.getString(ref)[0].decode() == text, name
    finally:
        slave.freeInstance()


def test_the_signals_fmu_is_built_beside_the_export_never_into_the_shared_fmu_folder(
    fmus, ssp, osp
):
    assert not list(fmus["osc"].parent.glob("Signals_*.fmu"))
    assert (ssp.parent / "Signals_two_mass.fmu").is_file()
    assert (osp.parent / "Signals_two_mass.fmu").is_file()  # in the configuration folder


def test_declared_connectors_are_outputs_parameters_and_the_inputs_a_connection_feeds(ssp):
    root = _ssd(ssp)
    fed = {
        (c.get("endElement"), c.get("endConnector"))
        for c in root.iter(f"{{{NS['ssd']}}}Connection")
    }
    inputs = {
        (component.get("name"), connector.get("name"))
        for component in root.iter(f"{{{NS['ssd']}}}Component")
        for connector in component.iter(f"{{{NS['ssd']}}}Connector")
        if connector.get("kind") == "input"
    }
    assert inputs == fed
    kinds = {
        connector.get("kind")
        for component in root.iter(f"{{{NS['ssd']}}}Component")
        for connector in component.iter(f"{{{NS['ssd']}}}Connector")
    }
    assert kinds == {"input", "output", "parameter"}


def test_fmpy_reads_the_package_with_its_own_validating_ssp_reader(ssp):
    from fmpy.ssp.ssd import read_ssd

    ssd = read_ssd(str(ssp), validate=True)
    components = {c.name: c for c in ssd.system.elements}
    assert set(components) == {"a", "b", "c", "d", "e", "signals"}
    label = {
        p.name: p.value for p in components["a"].parameterBindings[0].parameterValues[0].parameters
    }["label"]
    assert label == 'left <mass> & "quoted" {"json": [1, 2]}'  # a String parameter survives
    assert len(ssd.system.connections) == 3 + 3 + 4  # bond, plain, signals


def test_ssp_marks_the_bond_with_its_name_kind_and_roles(ssp):
    root = _ssd(ssp)
    marks = {}
    for c in root.iter(f"{{{NS['ssd']}}}Connection"):
        bond = c.find(f".//{{{NS['wf']}}}Bond")
        if bond is not None:
            marks[bond.get("role")] = (
                bond.get("name"),
                bond.get("kind"),
                f"{c.get('startElement')}.{c.get('startConnector')}",
            )
    assert marks == {
        "effort": ("spring", "translational", "b.force_on_flange"),
        "flow": ("spring", "translational", "a.velocity"),
        "position": ("spring", "translational", "a.position"),
    }
    units = {
        u.get("name"): u.find(f"{{{NS['ssc']}}}BaseUnit").attrib
        for u in root.iter(f"{{{NS['ssc']}}}Unit")
    }
    assert units["N"] == {"kg": "1", "m": "1", "s": "-2"}  # SI exponents from the FMU
    step = root.find(f".//{{{NS['osp']}}}FixedStepAlgorithm").get("baseStepSize")
    assert float(step) == 0.01


def test_exported_osp_validates_and_groups_the_bond_as_mechanical_ports(osp):
    folder = osp.parent
    assert schema_errors(osp.read_bytes(), "osp/OspSystemStructure.xsd") == []
    for model in ("Oscillator", "CoupledMass"):
        path = folder / f"{model}_OspModelDescription.xml"
        assert schema_errors(path.read_bytes(), "osp/OspModelDescription-1.0.1.xsd") == [], model
    md = etree.parse(str(folder / "Oscillator_OspModelDescription.xml")).getroot()
    port = md.find(f".//{{{OSP_MD_NS}}}LinearMechanicalPort")
    refs = [
        (
            etree.QName(g).localname,
            g.find(f"{{{OSP_MD_NS}}}Variable").get("ref"),
            g.find(f"{{{OSP_MD_NS}}}Variable").get("unit"),
        )
        for g in port
    ]
    assert refs == [("Force", "force", "N"), ("LinearVelocity", "velocity", "m/s")]
    root = etree.parse(str(osp)).getroot()
    assert root.findtext(f"{{{OSP_NS}}}Algorithm") == "fixedStep"
    groups = [
        [(v.get("simulator"), v.get("name")) for v in c]
        for c in root.iter(f"{{{OSP_NS}}}VariableGroupConnection")
    ]
    assert [("b", "force_on_flange|flange.velocity"), ("a", "force|velocity")] in groups
    assert "power bond 'spring' (translational)" in osp.read_text()


def test_ssp_round_trip_restores_the_scene_and_runs_bit_identically(fmus, ssp, tmp_path):
    original = two_mass_scene(fmus, tmp_path)
    back = read_ssp(ssp, extract_to=tmp_path / "x")
    assert back.bonds == original.bonds and back.connections == original.connections
    assert back.drivers == original.drivers and back.events == original.events
    assert back.run == original.run and back.plots == original.plots
    assert back.units["a"].parameters == original.units["a"].parameters
    assert "signals" not in back.units  # drivers and events are ours again
    names, ours = run_ours(original)
    names_back, again = run_ours(back)
    assert names_back == names
    np.testing.assert_array_equal(again, ours)


def test_the_energy_guard_turned_off_survives_the_round_trip(fmus, tmp_path):
    scene = two_mass_scene(fmus, tmp_path, energy_guard=math.inf)
    package = export_ssp(scene, tmp_path / "ssp", fmu_dir=fmus["osc"].parent)
    annotation = _ssd(package).find(f".//{{{NS['wf']}}}Scene").text
    meta = json.loads(annotation, parse_constant=_no_constant)  # strict JSON: no Infinity
    assert meta["run"]["energy_guard"] == "inf"
    back = read_ssp(package, extract_to=tmp_path / "x")
    assert math.isinf(back.run.energy_guard) and back.run == scene.run


def _no_constant(name: str):
    raise ValueError(f"not JSON: {name}")


def test_a_plain_ssp_without_our_annotations_runs_as_plain_connections(fmus, ssp, tmp_path):
    """A system made in another tool: no scene annotation, no bond marks."""
    folder = tmp_path / "foreign"
    with zipfile.ZipFile(ssp) as archive:
        archive.extractall(folder)
    root = etree.parse(str(folder / SSD_NAME)).getroot()
    for note in list(root.iter(f"{{{NS['ssd']}}}Annotations")):
        if note.getparent().tag != f"{{{NS['ssd']}}}DefaultExperiment":
            note.getparent().remove(note)
    (folder / SSD_NAME).write_bytes(etree.tostring(root))
    package = tmp_path / "foreign.ssp"
    with zipfile.ZipFile(package, "w") as archive:
        for path in folder.rglob("*"):
            archive.write(path, path.relative_to(folder).as_posix())
    scene = read_ssp(package, extract_to=tmp_path / "y")
    assert scene.bonds == () and len(scene.connections) == 10
    assert "signals" in scene.units and scene.drivers == ()
    assert (scene.run.stop_time, scene.run.step) == (1.0, 0.01)
    assert scene.run.algorithm == "gauss_seidel"  # our default: nothing said otherwise
    from wire_fmu.master.run import with_run_settings

    names, plain = run_ours(with_run_settings(scene, algorithm="jacobi", extrapolation="constant"))
    names_ours, ours = run_ours(two_mass_scene(fmus, tmp_path))
    plain_cols = {n: plain[:, i + 1] for i, n in enumerate(names)}
    for i, n in enumerate(names_ours):  # the signals unit replays drivers and events exactly
        np.testing.assert_allclose(plain_cols[n], ours[:, i + 1], rtol=1e-12, atol=1e-12)


def test_reader_reports_what_it_cannot_run(tmp_path):
    ssd = f"""<ssd:SystemStructureDescription xmlns:ssd="{NS["ssd"]}" xmlns:ssc="{NS["ssc"]}"
        version="1.0" name="x"><ssd:System name="x"><ssd:Elements>
        <ssd:Component name="u" source="resources/U.fmu"/>
        <ssd:System name="inner"/></ssd:Elements><ssd:Connections>
        <ssd:Connection startConnector="in" endElement="u" endConnector="y"/>
        </ssd:Connections></ssd:System></ssd:SystemStructureDescription>"""
    package = tmp_path / "x.ssp"
    with zipfile.ZipFile(package, "w") as archive:
        archive.writestr(SSD_NAME, ssd)
    with pytest.raises(SceneError) as err:
        read_ssp(package, extract_to=tmp_path / "x")
    text = str(err.value)
    assert "only FMU components" in text and "system connectors" in text


def test_an_event_on_a_connected_input_cannot_be_exported(fmus, tmp_path):
    data = two_mass_data(fmus)
    data["events"].append({"time": 0.2, "set": {"d.position_b": 0.0}})
    scene = parse_scene(data, base_dir=tmp_path)
    # refused before any export: an event may not set an input a connection feeds
    with pytest.raises(WireFmuError, match=r"d\.position_b, which is fed by connection"):
        plan_export(scene, fmu_dir=fmus["osc"].parent)


def test_signals_program_records_modes_and_metadata_is_json(fmus, tmp_path):
    plan = plan_export(two_mass_scene(fmus, tmp_path), fmu_dir=fmus["osc"].parent)
    signals = plan.unit("signals")
    outputs = {v.name: v.unit for v in signals.model.modelVariables if v.causality == "output"}
    assert outputs == {
        "d.position_a": "m",
        "d.velocity_a": "m/s",
        "e.position_a": "m",
        "c.force": "N",
    }
    meta = json.loads(json.dumps(plan.metadata))
    assert meta["drivers"][1]["spec"] == {
        "kind": "ramp",
        "points": [[0.0, 0.0], [0.3, 2.0], [0.6, -1.0]],
    }
    assert plan.signals == "signals" and plan.units[-1].generated


def test_cli_exports_and_runs_an_ssp_package(fmus, ssp, tmp_path, capsys):
    scene_file = tmp_path / "two_mass.toml"
    scene_file.write_text(_toml(two_mass_data(fmus, signals=False, stop_time=0.1)))
    fmu_dir = ["--fmu-dir", str(fmus["osc"].parent)]
    assert (
        main([*fmu_dir, "export", str(scene_file), "--format", "ssp", "-o", str(tmp_path / "out")])
        == 0
    )
    assert (
        main([*fmu_dir, "export", str(scene_file), "--format", "osp", "-o", str(tmp_path / "osp")])
        == 0
    )
    assert (tmp_path / "osp" / "OspSystemStructure.xml").exists()
    package = tmp_path / "out" / "two_mass.ssp"
    assert main([*fmu_dir, "check", str(package)]) == 0
    assert main([*fmu_dir, "run", str(package), "-q", "-o", str(tmp_path / "res")]) == 0
    out = capsys.readouterr().out
    assert "no problems (2 units, 1 bond," in out and "timeseries.csv" in out


def _toml(data: dict) -> str:
    """Just enough TOML for the test scene (tables, arrays of tables, scalars)."""
    lines = [f"name = {json.dumps(data['name'])}", "[run]"]
    lines += [f"{k} = {json.dumps(v)}" for k, v in data["run"].items()]
    for unit, spec in data["units"].items():
        lines += [
            f"[units.{unit}]",
            f"fmu = {json.dumps(spec['fmu'])}",
            f"[units.{unit}.parameters]",
        ]
        lines += [f"{k} = {json.dumps(v)}" for k, v in spec["parameters"].items()]
    for bond in data["bonds"]:
        lines += ["[[bonds]]"] + [f"{k} = {json.dumps(v)}" for k, v in bond.items()]
    return "\n".join(lines) + "\n"
