"""``check`` and ``run`` warn about every setting a scene's effects leave without influence."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import pytest

from wire_fmu.cli import main
from wire_fmu.master.run import load_scene_file, shipped_scenes
from wire_fmu.unit_reference.scene_warnings import inactive_settings

SCENE = """
name = "warned"
description = "A hoist whose settings its effects partly ignore."

[run]
stop_time = 0.05
step = 0.01

[units.winch]
fmu = "Winch"
effects = {winch_effects}

[units.winch.parameters]
rope_diameter = 0.0381
brake_friction = 0.35

[units.rope]
fmu = "BlockTrain"
effects = {rope_effects}

[units.rope.parameters.reeving]
rope = {{ axial_stiffness = 5.8e7, damping = 1.2e5, linear_mass = 6.2 }}
[units.rope.parameters.reeving.bodies]
block = {{ kind = "block", mass = 1.0e4, position = 10.0, port = "block_a" }}
[units.rope.parameters.reeving.sheaves]
crown = {{ centre = [0.0, 30.0, 0.0], radius = 0.5, inertia = 50.0, efficiency = 0.96 }}
travel = {{ body = "block", centre = [1.0, 10.0, 0.0], radius = 0.5, efficiency = 0.96 }}
[units.rope.parameters.reeving.anchors]
dead = {{ point = [1.5, 0.0, 0.0] }}
[[units.rope.parameters.reeving.path]]
line_end = "line_a"
point = [-0.5, 0.0, 0.0]
[[units.rope.parameters.reeving.path]]
sheave = "crown"
wrap = "cw"
[[units.rope.parameters.reeving.path]]
sheave = "travel"
wrap = "ccw"
[[units.rope.parameters.reeving.path]]
anchor = "dead"

[[bonds]]
name = "fast_line"
ports = "winch.rope <-> rope.line_a"

[[events]]
time = 0.02
label = "brake on"
set = {{ "winch.brake.lever_force" = 500.0 }}
"""


def _scene(tmp_path: Path, winch: list[str], rope: list[str]) -> Path:
    path = tmp_path / "warned.toml"
    text = SCENE.format(winch_effects=repr(winch), rope_effects=repr(rope))
    path.write_text(textwrap.dedent(text).replace("'", '"'), encoding="utf-8")
    return path


def _warnings(tmp_path: Path, winch: list[str], rope: list[str]) -> list[str]:
    return inactive_settings(load_scene_file(_scene(tmp_path, winch, rope)))


def test_every_ignored_setting_is_named_with_its_unit_and_the_effect_it_needs(tmp_path):
    warnings = _warnings(tmp_path, ["drum_inertia"], [])

    def about(unit: str, what: str) -> str:
        (found,) = [w for w in warnings if w.startswith(f"unit {unit!r}: ") and what in w]
        return found

    assert "'rope_layers'" in about("winch", "parameter 'rope_diameter'")
    assert "'band_brake'" in about("winch", "parameter 'brake_friction'")
    lever = about("winch", "input 'brake.lever_force'")
    assert "event 'brake on'" in lever and "'band_brake'" in lever
    efficiency = about("rope", "'sheaves.<name>.efficiency' (crown, travel)")
    assert "'bearing_friction' (which needs 'sheave_inertia')" in efficiency
    assert "'rope_damping'" in about("rope", "'rope.damping'")
    assert "'sheave_inertia'" in about("rope", "'sheaves.<name>.inertia' (crown)")
    assert "'rope_slip'" in about("rope", "'rope.linear_mass'")
    assert len(warnings) == 7


def test_a_scene_whose_effects_use_what_it_sets_has_no_warning(tmp_path):
    winch = ["drum_inertia", "band_brake", "rope_layers"]
    rope = ["rope_damping", "sheave_inertia", "bearing_friction", "rope_slip"]
    assert _warnings(tmp_path, winch, rope) == []


def test_an_effect_that_silences_an_input_is_named(tmp_path):
    scene = load_scene_file(_scene(tmp_path, ["drum_inertia", "band_brake"], []))
    scene.events[0].values.clear()
    from wire_fmu.master.scene.data import VarRef

    scene.events[0].values[VarRef("winch", "drum.speed_command")] = 1.0
    (warning,) = [w for w in inactive_settings(scene) if "speed_command" in w]
    assert "acts only without effect 'drum_inertia'" in warning


@pytest.mark.parametrize("name", sorted(shipped_scenes()))
def test_no_shipped_scene_sets_what_its_effects_ignore(name):
    assert inactive_settings(load_scene_file(shipped_scenes()[name])) == []


def test_check_prints_the_warnings_and_succeeds(tmp_path, capsys):
    assert main(["check", str(_scene(tmp_path, ["drum_inertia", "band_brake"], []))]) == 0
    out = capsys.readouterr().out
    assert "no problems" in out
    warned = [ln for ln in out.splitlines() if ln.startswith("warning: ")]
    assert len(warned) == 5 and any(".efficiency'" in ln for ln in warned)


def test_run_prints_the_warnings_before_it_runs(tmp_path, capsys):
    scene = _scene(tmp_path, ["drum_inertia", "band_brake"], [])
    assert main(["run", str(scene), "-q", "-o", str(tmp_path / "out"), "--stop-time", "0.02"]) == 0
    out = capsys.readouterr().out
    warned = [ln for ln in out.splitlines() if ln.startswith("warning: ")]
    assert len(warned) == 5 and out.index(warned[-1]) < out.index("scene 'warned'")


def test_a_setting_equal_to_its_declared_default_asks_for_nothing_and_is_not_warned(tmp_path):
    path = _scene(tmp_path, ["drum_inertia", "band_brake"], [])
    text = path.read_text(encoding="utf-8").replace("damping = 1.2e5", "damping = 0.0")
    path.write_text(text.replace("efficiency = 0.96", "efficiency = 1.0"), encoding="utf-8")
    warnings = inactive_settings(load_scene_file(path))
    assert not [w for w in warnings if "damping" in w or "efficiency" in w]
    assert [w for w in warnings if "'sheaves.<name>.inertia' (crown)" in w]


def test_an_event_after_the_stop_time_is_a_warning_check_prints_and_run_records(tmp_path, capsys):
    path = _scene(tmp_path, ["drum_inertia", "band_brake", "rope_layers"], [])
    text = path.read_text(encoding="utf-8").replace("time = 0.02", "time = 0.5")
    path.write_text(text, encoding="utf-8")
    said = "event 'brake on' at 0.5 s is after the run's stop time, 0.05 s; it will not happen"
    assert main(["check", str(path)]) == 0
    assert f"warning: {said}" in capsys.readouterr().out.splitlines()
    assert main(["run", str(path), "-q", "-o", str(tmp_path / "out")]) == 0
    meta = json.loads((tmp_path / "out" / "metadata.json").read_text(encoding="utf-8"))
    assert said in [w["message"] for w in meta["warnings"] if w["level"] == "warning"]


def test_an_input_its_units_parameters_leave_without_influence_is_named(tmp_path):
    """A driver on the handle torque of a jack whose handle_drive is "speed" (it follows
    handle.speed_command): the parameter that silences the input is named."""
    text = shipped_scenes()["scissor_jack"].read_text(encoding="utf-8")
    text = text.replace('target = "self_locking.', 'target = "lift.')
    text = text.replace(
        'handle_drive = "torque"', 'handle_drive = "torque"\ninitial_handle_speed = 1.0'
    )
    text = text.replace(
        'handle_drive = "speed"', 'handle_drive = "speed"\ninitial_handle_speed = 2.0', 1
    )
    path = tmp_path / "jack.toml"
    path.write_text(text, encoding="utf-8")
    warnings = inactive_settings(load_scene_file(path))
    (driven,) = [w for w in warnings if "'handle.torque_command'" in w]
    assert driven.startswith("unit 'lift': input 'handle.torque_command' (set by driver ")
    assert 'no influence with handle_drive = "speed"' in driven
    assert 'it acts only with handle_drive = "torque"; change handle_drive' in driven
    (start,) = [w for w in warnings if "'initial_handle_speed'" in w]
    assert start.startswith("unit 'lift': parameter 'initial_handle_speed'")
    assert len(warnings) == 2


SPEED_SETTERS = {
    "event": ("", "event 'brake released, drive lowers at 5 m/s fast-line speed'"),
    "driver": (
        """
        [[drivers]]
        target = "winch.drum.speed_command"
        kind = "ramp"
        points = [[0.0, 0.0], [1.0, 2.0]]
        label = "speed ramp"
        """,
        "driver 'speed ramp'",
    ),
    "connection": (
        """
        [[connections]]
        from = "winch.motor.speed"
        to = "winch.drum.speed_command"
        """,
        "connection from winch.motor.speed",
    ),
}


@pytest.mark.parametrize("setter", sorted(SPEED_SETTERS))
def test_an_input_its_units_effects_silence_is_named_with_what_sets_it(tmp_path, capsys, setter):
    """The drawworks with an event, a driver or a connection on the drum's speed command,
    which acts only without drum_inertia (the scene's winch has it): the unit, the input,
    what sets it and the effect are named, by check (audit case
    w_speed_command_with_inertia: the event)."""
    text = shipped_scenes()["drawworks"].read_text(encoding="utf-8")
    if setter == "event":
        text = text.replace('"winch.motor.command" = 257.0e3', '"winch.drum.speed_command" = 5.0')
    table, who = SPEED_SETTERS[setter]
    path = tmp_path / "drawworks.toml"
    path.write_text(text + textwrap.dedent(table), encoding="utf-8")
    said = (
        f"unit 'winch': input 'drum.speed_command' (set by {who}) has no influence with its "
        "effects (band_brake, drum_inertia, motor_characteristic): it acts only without "
        "effect 'drum_inertia'; change the effects or leave it out"
    )
    assert inactive_settings(load_scene_file(path)) == [said]
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "no problems" in out and f"warning: {said}" in out.splitlines()
