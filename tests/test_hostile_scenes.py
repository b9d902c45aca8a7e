"""Hostile scenes: ``check`` finds, at once and each once, everything ``run`` would refuse.

Every case is a variant of a shipped scene with something wrong in it. The
check (Python API and command line) must list the offending item by name
with what was expected, never a traceback; problems in different places come
out together; a unit that fails its own initialisation is found by the
check's dry initialisation. Runs that fail end with a true status in
``metadata.json`` and the unit's message once. Command lines, and files that
are no scene files, are in ``test_hostile_commands``.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from wire_fmu.master.run import SCENE_DIR, run_scene
from wire_fmu.master.scene import SceneError

from .hostile_scene_helpers import (
    CYL,
    DRAWWORKS,
    LONG_BOND,
    PORTS,
    RISER,
    RISER_ROD,
    only,
    problems_of,
    variant,
)

pytestmark = pytest.mark.integration

MULTIMASS = SCENE_DIR / "multimass_drive.toml"


@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("hostile_scene_fmus")


# -- parameters of the wrong type: named, with the type they need -----------------------
@pytest.mark.parametrize(
    ("line", "parameter", "expected"),
    [
        ('initial_equilibrium = "false"', "initial_equilibrium", "true or false"),
        ("initial_equilibrium = 1", "initial_equilibrium", "true or false"),
        ('initial_position = "1.9"', "initial_position", "a number"),
        ("initial_position = true", "initial_position", "a number (Real), got a boolean"),
        ("initial_position = nan", "initial_position", "finite"),
        ("initial_position = inf", "initial_position", "must lie in"),  # the unit says
        ("initial_position = 1e999", "initial_position", "must lie in"),
        ("initial_position = [1.0, 2.0]", "initial_position", "a number (Real), got a list"),
        ("initial_position = { at = 1.9 }", "initial_position", "a number (Real), got a table"),
    ],
)
def test_a_parameter_of_the_wrong_type_is_named_with_its_type(
    tmp_path, fmu_dir, line, parameter, expected
):
    path = variant(
        tmp_path,
        sections={CYL: line},
        replace={
            "initial_equilibrium = true\n": "",
            "initial_position = 1.905      # m, mid stroke\n": "",
        },
    )
    problem = only(problems_of(path, fmu_dir), f"parameter {parameter!r}")
    assert "unit 'cylinder'" in problem and expected in problem


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("2.5", "whole number"),
        ("4294967297", "32-bit range"),
        ("2147483653", "32-bit range"),
        ('"2"', "whole number"),
        ("true", "whole number"),
    ],
)
def test_an_integer_parameter_takes_a_whole_32_bit_number(tmp_path, fmu_dir, value, expected):
    path = variant(
        tmp_path, DRAWWORKS, sections={"[units.winch.parameters]": f"drum_layers = {value}"}
    )
    problem = only(problems_of(path, fmu_dir), "'drum_layers'")
    assert expected in problem


# -- what a run would refuse at initialisation --------------------------------------------
@pytest.mark.parametrize(
    ("edits", "words"),
    [
        (
            {"replace": {RISER_ROD: '"rod.force" = -5.0e6'}},
            ("unit 'cylinder'", "precharge_pressure"),
        ),
        ({"replace": {RISER_ROD: '"rod.force" = 5.0e6'}}, ("unit 'cylinder'",)),
        ({"sections": {CYL: "moving_mass = 1e300"}}, ("unit 'cylinder'", "precharge_pressure")),
        ({"replace": {"heave_rao = 0.3": "heave_rao = 1e6"}}, ("unit 'cylinder'",)),
        (
            {"sections": {"[units.rope.parameters]": "break_segment = 99"}},
            ("unit 'rope'", "break_segment 99 does not exist"),
        ),
    ],
)
def test_a_unit_that_fails_its_initialisation_is_found_by_check(tmp_path, fmu_dir, edits, words):
    only(problems_of(variant(tmp_path, **edits), fmu_dir), *words)


def test_a_failing_initialisation_runs_to_a_failed_status_with_results_kept(tmp_path, fmu_dir):
    path = variant(tmp_path, replace={RISER_ROD: '"rod.force" = -5.0e6'})
    outcome = run_scene(path, tmp_path / "out", fmu_dir=fmu_dir, stop_time=0.1)
    assert outcome.result.status == "failed"
    assert outcome.result.message.count("precharge_pressure") == 1
    meta = json.loads((tmp_path / "out" / "metadata.json").read_text())
    assert meta["result"]["status"] == "failed"
    assert outcome.plots == []


# -- run settings: absurd step counts and contradictions ------------------------------------
@pytest.mark.parametrize(
    ("line", "words"),
    [
        ("stop_time = 1e300", ("macro steps", "max_steps")),
        ("step = 1e-12", ("macro steps", "max_steps")),
        (
            "stop_time = 100000000000000000000000000000000000000000",
            ("run.stop_time", "nanoseconds"),
        ),
        ("iterations = 2.5", ("run.iterations",)),
        ("energy_guard = -1.0", ("run.energy_guard",)),
        ('adaptive = "yes"', ("run.adaptive",)),
        ("order = 5", ("run.order",)),
        ("max_steps = 0", ("run.max_steps",)),
        ("iterations = 1000000", ("run.iterations", "at most 1000")),
        ('algorithm = "newton"', ("run.algorithm",)),
    ],
)
def test_bad_run_settings_are_named(tmp_path, fmu_dir, line, words):
    key = line.split(" =")[0]
    text = RISER.read_text(encoding="utf-8")
    replace = {m.group(0): "" for m in re.finditer(rf"^{key} = .*\n", text, flags=re.M)}
    path = variant(tmp_path, replace=replace, sections={"[run]": line})
    only(problems_of(path, fmu_dir), *words)


def test_min_step_above_max_step_with_adaptive_is_refused(tmp_path, fmu_dir):
    path = variant(
        tmp_path, sections={"[run]": "adaptive = true\nmin_step = 0.01\nmax_step = 0.001"}
    )
    only(problems_of(path, fmu_dir), "run.min_step", "run.max_step")


def test_the_step_count_message_says_how_to_allow_it(tmp_path, fmu_dir):
    path = variant(tmp_path, replace={"step = 0.004": "step = 1e-12"})
    problem = only(problems_of(path, fmu_dir), "macro steps")
    assert "3e+13" in problem and "raise max_steps" in problem


# -- events, drivers, connections -----------------------------------------------------------
@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ('"high"', "a whole number"),
        ("[1.0, 2.0]", "finite number"),
        ("true", "a whole number"),
        ("2.5", "a whole number"),
        ("nan", "finite number"),
    ],
)
def test_an_event_value_of_the_wrong_type_is_named(tmp_path, fmu_dir, value, expected):
    event = f'\n[[events]]\ntime = 1.0\nlabel = "cut"\nset = {{ "rope.break_segment" = {value} }}\n'
    path = variant(tmp_path, append=event)
    problem = only(problems_of(path, fmu_dir), "rope.break_segment")
    assert expected in problem


def test_an_event_on_an_input_a_bond_feeds_is_refused(tmp_path, fmu_dir):
    """It used to cut the bond silently from the event on (the rod ran away at 10 m/s)."""
    event = '\n[[events]]\ntime = 0.05\nlabel = "push"\nset = { "cylinder.rod.force" = 0.0 }\n'
    problem = only(problems_of(variant(tmp_path, append=event), fmu_dir), "cylinder.rod.force")
    assert "fed by bond 'rod' effort" in problem and "event 'push'" in problem


@pytest.mark.parametrize("time", ['"soon"', "-1.0", "nan"])
def test_an_event_time_that_is_not_a_time_is_named(tmp_path, fmu_dir, time):
    event = f'\n[[events]]\ntime = {time}\nset = {{ "cylinder.rod.force" = 1.0 }}\n'
    only(problems_of(variant(tmp_path, append=event), fmu_dir), "'time'")


def test_an_unknown_unit_in_a_bond_is_named_as_unknown(tmp_path, fmu_dir):
    path = variant(
        tmp_path,
        replace={PORTS: LONG_BOND},
    )
    problems = problems_of(path, fmu_dir)
    only(problems, "bond 'rod' effort", "no unit 'piston'")
    assert not any("effort must go from" in p for p in problems)


def test_an_unknown_variable_and_an_output_fed_into_an_output(tmp_path, fmu_dir):
    extra = (
        '\n[[connections]]\nfrom = "rope.no_such_output"\nto = "cylinder.rod.force2"\n'
        '\n[[connections]]\nfrom = "rope.tension_max"\nto = "cylinder.rod.position"\n'
    )
    problems = problems_of(variant(tmp_path, append=extra), fmu_dir)
    only(problems, "no_such_output")
    only(problems, "cylinder.rod.position", "expected an input")


def test_a_driver_on_an_output_is_named(tmp_path, fmu_dir):
    path = variant(
        tmp_path, replace={'target = "rope.mover_b.position"': 'target = "cylinder.rod.position"'}
    )
    only(problems_of(path, fmu_dir), "driver target cylinder.rod.position")


# -- names and files ----------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["../../x", "/abs", "a/b", "..", ".hidden", "x" * 300, ""])
def test_a_scene_name_that_is_not_a_plain_file_name_is_refused(tmp_path, fmu_dir, name):
    path = variant(tmp_path)
    text = path.read_text().replace('name = "hostile"', f"name = {json.dumps(name)}")
    path.write_text(text)
    only(problems_of(path, fmu_dir), "'name'", "plain file name")


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (b"\x00\xff\x8b binary", ("cannot read",)),
        (b"name = [", ("not valid TOML",)),
        (b"a = " + b"[" * 5000 + b"]" * 5000, ("nested too deeply",)),
        (b"name = 'x'\n", ("[units]",)),
        (b"units = 5\n", ("[units]",)),
    ],
)
def test_a_file_that_is_not_a_scene_gives_one_clean_problem(tmp_path, fmu_dir, content, words):
    path = tmp_path / "junk.toml"
    path.write_bytes(content)
    problems = problems_of(path, fmu_dir)
    assert any(all(w in p for w in words) for p in problems), problems


def test_problems_in_five_places_come_out_together_each_once(tmp_path, fmu_dir):
    path = variant(
        tmp_path,
        replace={
            "step = 0.004": "step = -1.0",
            "pretension = 356.0e3": 'pretension = "high"',
            PORTS: LONG_BOND,
        },
        sections={CYL: "no_such_parameter = 1.0"},
        append='\n[[events]]\ntime = 1.0\nset = { "rope.break_segment" = "x" }\n',
    )
    problems = problems_of(path, fmu_dir)
    for words in (
        ("run.step",),
        ("no unit 'piston'",),
        ("'no_such_parameter'",),
        ("'pretension'",),
        ("event", "rope.break_segment"),
    ):
        only(problems, *words)


def test_a_units_own_problems_come_out_with_its_parameter_of_the_wrong_type(tmp_path, fmu_dir):
    """The unit is checked without the value it cannot take, and says the rest."""
    full = "[units.full.parameters]\n"
    path = variant(
        tmp_path,
        MULTIMASS,
        replace={
            f"{full}motor_slope = 25.6": f'{full}motor_slope = "abc"\nsolver_rtol = 5.0',
            "masses_kept = 3": "masses_kept = 1",
        },
        sections={"[units.full.parameters]": 'solver = "rk5"'},
    )
    problems = problems_of(path, fmu_dir)
    own = only(problems, "unit 'full'", "solver 'rk5' is unknown", "solver_rtol")
    assert "found with 'motor_slope' left out" in own
    only(problems, "unit 'full'", "parameter 'motor_slope' = 'abc'", "got text")
    only(problems, "unit 'reduced3'", "masses_kept")
    assert len(problems) == 3


def test_run_lists_the_scenes_problems_with_those_its_units_find(tmp_path, fmu_dir):
    """An unknown unit no longer hides a misspelt variable of a known one from ``run``."""
    path = variant(
        tmp_path,
        MULTIMASS,
        replace={'"full.load.torque" = 201.0,': '"full.load.torqe" = 201.0, "nounit.x" = 1.0,'},
        append='\n[[connections]]\nfrom = "full.load.sped"\nto = "ghost.load.torque"\n',
    )
    with pytest.raises(SceneError) as caught:
        run_scene(path, tmp_path / "out", fmu_dir=fmu_dir, stop_time=0.1)
    problems = caught.value.problems
    only(problems, "nounit.x names no unit 'nounit'")
    only(problems, "full.load.torqe", "no variable 'load.torqe'")
    only(problems, "ghost.load.torque names no unit 'ghost'")
    only(problems, "full.load.sped", "no variable 'load.sped'")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ('\n[[events]]\ntime = 1.0\nsett = 5\nset = { "rope.break_segment" = 0 }\n', "'sett'"),
        ('\n[[connections]]\nfrm = "rope.tension_max"\nto = "cylinder.rod.force"\n', "'frm'"),
        (
            '\n[[plots]]\ntitle = "x"\ncolour = "red"\nvariables = ["rope.tension_max"]\n',
            "'colour'",
        ),
        ('\n[[plots]]\ntitle = 5\nvariables = ["rope.tension_max"]\n', "'title' must be text"),
        ('\n[[plots]]\ntitle = ""\nvariables = ["rope.tension_max"]\n', "1 to 100 characters"),
        ('\n[[plots]]\ntitle = "e"\nvariables = []\n', "at least one"),
        (
            '\n[[events]]\ntime = 1.0\nlabel = { a = 1 }\nset = { "rope.break_segment" = 0 }\n',
            "'label' must be text",
        ),
        ('\n[units."a -> b"]\nfmu = "Winch"\n', "a unit name is a letter"),
        ('\n[units.""]\nfmu = "Winch"\n', "a unit name is a letter"),
    ],
)
def test_typos_and_names_of_the_wrong_kind_are_named(tmp_path, fmu_dir, extra, words):
    problems = problems_of(variant(tmp_path, append=extra), fmu_dir)
    assert any(words in p for p in problems), problems


@pytest.mark.parametrize(
    ("line", "words"),
    [
        ('order = ["ghost"]', "run.order names 'ghost'"),
        ('order = ["rope", "rope"]', "more than once"),
        ("step = 1e-12", "nanoseconds"),
        ("stop_time = 1e300", "nanoseconds"),
    ],
)
def test_run_order_and_times_a_run_cannot_count_are_refused(tmp_path, fmu_dir, line, words):
    key = line.split(" =")[0]
    text = RISER.read_text(encoding="utf-8")
    replace = {m.group(0): "" for m in re.finditer(rf"^{key} = .*\n", text, flags=re.M)}
    problems = problems_of(variant(tmp_path, replace=replace, sections={"[run]": line}), fmu_dir)
    assert any(words in p for p in problems), problems


def test_an_integer_connection_is_refused_before_it_fails(tmp_path, fmu_dir):
    extra = '\n[[connections]]\nfrom = "rope.slack_spans"\nto = "rope.break_segment"\n'
    problems = problems_of(variant(tmp_path, append=extra), fmu_dir)
    assert any("connects a Integer to a Integer" in p for p in problems), problems


def test_thousands_of_chained_connections_need_no_recursion(tmp_path):
    """The algebraic-loop search recursed once per connection: 3000 gave a RecursionError."""
    from wire_fmu.master.scene import read_scene_data
    from wire_fmu.master.validate import Structure, feedthrough_loops

    chain = [{"from": f"a.x{i}", "to": f"a.x{i + 1}"} for i in range(5000)]
    chain.append({"from": "a.x5000", "to": "a.x0"})
    scene, _ = read_scene_data(
        {"units": {"a": {"fmu": "A.fmu"}}, "connections": chain}, base_dir=tmp_path
    )
    (loop,) = feedthrough_loops(scene, Structure({}, {}))
    assert len(loop) == 5002 and loop[0] == loop[-1]


@pytest.mark.parametrize(
    ("field", "value"), [("mass", "true"), ("mass", '"120000"'), ("damping", "[1.0]")]
)
def test_a_reeving_number_of_the_wrong_type_is_refused_not_cast(tmp_path, fmu_dir, field, value):
    """``mass = true`` was a 1 kg block (fast-line tension 0.98 N instead of 117.7 kN)."""
    text = DRAWWORKS.read_text(encoding="utf-8")
    match = re.search(rf"\b{field} = [0-9.e+]+", text)
    if match is None:
        pytest.skip(f"the drawworks reeving sets no {field}")
    path = variant(tmp_path, DRAWWORKS, replace={match.group(0): f"{field} = {value}"})
    problems = problems_of(path, fmu_dir)
    assert any(f"'{field}' must be a number" in p for p in problems), problems


def test_an_infinite_block_mass_is_named_by_check(tmp_path, fmu_dir):
    """It failed the run with "FloatingPointError: rope span 0 has no unstretched rope left"."""
    path = variant(tmp_path, DRAWWORKS, replace={"mass = 120000.0": "mass = inf"})
    problems = problems_of(path, fmu_dir)
    assert any("'mass' must be finite" in p for p in problems), problems
