"""Scene parsing and validation: every problem at once, each naming unit and variable."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from fmi_test_tools import FACADES  # noqa: E402

from wire_fmu.cli import main  # noqa: E402
from wire_fmu.export.builder import build_fmu  # noqa: E402
from wire_fmu.master.scene import SceneError, parse_scene, read_scene_data  # noqa: E402
from wire_fmu.master.validate import validate_scene  # noqa: E402


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("fmus")
    return {
        "osc": build_fmu(
            FACADES / "oscillator.py", out, extra_modules=[SUPPORT / "wire_fmu_test_units.py"]
        ),
        "mass": build_fmu(
            FACADES / "coupled_mass.py", out, extra_modules=[SUPPORT / "wire_fmu_master_units.py"]
        ),
    }


def test_parse_errors_are_all_listed(tmp_path):
    data = {
        "colour": "red",
        "run": {"step": -1, "algorithm": "newton", "extrapolation": "cubic"},
        "units": {"a": {"fmu": 3}, "b.c": {"fmu": "X.fmu", "effects": 5}},
        "bonds": [{"name": "x", "kind": "magnetic", "effort": "a.f -> b.f"}],
        "connections": [{"from": "nodot", "to": "a.x"}],
        "events": [{"time": -2, "set": {"a.x": 1}}],
    }
    with pytest.raises(SceneError) as info:
        parse_scene(data, base_dir=tmp_path)
    text = str(info.value)
    for needle in (
        "unknown top-level key 'colour'",
        "run.step must be a positive number",
        "run.algorithm must be one of",
        "run.extrapolation must be one of",
        "unit 'a': 'fmu' must name",
        "unit 'b.c': a unit name is a letter or '_'",
        "'effects' must be a list",
        "'kind' must be one of",
        "'flow' is required",
        "connection 0",
        "event 0: 'time'",
    ):
        assert needle in text, needle


def broken_scene(fmus) -> dict:
    return {
        "name": "broken",
        "units": {
            "a": {"fmu": str(fmus["osc"]), "effects": ["magic"]},
            "b": {"fmu": str(fmus["mass"]), "parameters": {"colour": 1.0}},
            "c": {"fmu": str(fmus["mass"])},
            "d": {"fmu": str(fmus["mass"])},
        },
        "bonds": [
            {
                "name": "wrong",
                "kind": "translational",
                "effort": "b.force_on_flange -> a.force",
                "flow": "a.position -> b.flange.velocity",
            }
        ],
        "connections": [
            {"from": "a.velocity", "to": "b.flange.velocity"},  # fed twice (bond above)
            {"from": "a.position", "to": "a.velocity"},  # output to output
            {"from": "a.nothing", "to": "c.flange.position"},  # unknown variable
            {"from": "ghost.x", "to": "c.flange.velocity"},  # unknown unit
            {"from": "c.stretch", "to": "d.flange.position"},  # an algebraic loop ...
            {"from": "d.stretch", "to": "c.flange.position"},  # ... through feedthrough
            {"from": "a.velocity", "to": "d.flange.velocity"},
        ],
        "drivers": [{"target": "a.force", "kind": "constant", "value": 1.0}],
        "outputs": {"variables": ["a.nope"]},
    }


def test_structure_problems_are_all_listed_naming_unit_and_variable(fmus, tmp_path):
    scene, found = read_scene_data(broken_scene(fmus), base_dir=tmp_path)
    with pytest.raises(SceneError) as info:  # the data's problems and the structure's, at once
        validate_scene(scene, through_fmi=False, problems=found)
    text = str(info.value)
    expected = [
        "input b.flange.velocity is fed twice",
        "input a.force is fed twice",  # by the bond and by the driver
        "a.velocity: is an output, expected an input",
        "unit 'a' has no variable 'nothing'",
        "names no unit 'ghost'",
        "a.position has unit m but a flow of a translational bond is in m/s",
        "unit mismatch, m feeds m/s",
        "algebraic loop through direct feedthrough",
        "unit 'b': no parameter 'colour'",
        "unit 'a': effects are only known for our FMUs",
        "recorded/plotted variable a.nope does not exist",
    ]
    for needle in expected:
        assert needle in text, f"missing: {needle}\n{text}"
    assert len(info.value.problems) >= len(expected)


def test_check_command_lists_problems_and_exits_nonzero(fmus, tmp_path, capsys):
    import tomllib  # noqa: F401 - the scene is written as TOML below

    lines = [
        'name = "cli_broken"',
        "[units.a]",
        f'fmu = "{fmus["osc"]}"',
        "[units.b]",
        f'fmu = "{fmus["mass"]}"',
        "[[connections]]",
        'from = "a.position"',
        'to = "a.velocity"',
        "[[connections]]",
        'from = "b.nothing"',
        'to = "a.force"',
    ]
    path = tmp_path / "broken.toml"
    path.write_text("\n".join(lines) + "\n")
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr().out
    assert "a.velocity: is an output" in out and "no variable 'nothing'" in out


def test_configuration_problems_come_back_through_fmi(tmp_path):
    """A bad reeving inside our BlockTrain is reported by the FMU itself, all problems."""
    from wire_fmu.core.units.block_train.reevings import drilling_block_train

    reeving = drilling_block_train(4)
    reeving["sheaves"]["crown_0"]["radius"] = -1
    reeving["path"][1]["wrap"] = "sideways"
    data = {
        "units": {
            "rope": {
                "fmu": "BlockTrain",
                "effects": ["rope_dampingg"],
                "parameters": {"reeving": reeving},
            }
        }
    }
    scene = parse_scene(data, base_dir=tmp_path)
    with pytest.raises(SceneError) as info:
        validate_scene(scene)
    text = str(info.value)
    assert "'radius' must be > 0" in text and "'wrap' must be" in text
    assert "did you mean 'rope_damping'" in text
