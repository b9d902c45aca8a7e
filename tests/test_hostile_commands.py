"""Hostile command lines and files: refused with a message, never a traceback or a hang.

``check`` and ``run`` on the command line, ``draw`` of a reeving that is none,
scene, sweep and FMU paths that are devices, pipes or folders, sweeps of
absurdly many cases, study options out of range, a results folder that is a
file, and what the recorder and the plots make of odd outputs. The scene
variants come from :mod:`~tests.hostile_scene_helpers`, as in
``test_hostile_scenes``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from wire_fmu.cli import main as cli
from wire_fmu.master.run import run_scene

from .hostile_scene_helpers import RISER_ROD, only, problems_of, variant

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("hostile_scene_fmus")


def sweep_problems(path: Path) -> list[str]:
    """The problems loading the sweep spec at ``path`` is refused with (it must be)."""
    from wire_fmu.sweep import load_sweep_spec
    from wire_fmu.sweep.spec import SweepSpecError

    with pytest.raises(SweepSpecError) as caught:
        load_sweep_spec(path)
    return caught.value.problems


def test_a_shipped_scene_passes_check_through_the_command_line(fmu_dir, capsys):
    assert cli(["--fmu-dir", str(fmu_dir), "check", "riser_tensioner"]) == 0
    assert "no problems" in capsys.readouterr().out


@pytest.mark.parametrize("scene", ["rod_force", "bad_name", "stop_time"])
def test_check_on_the_command_line_exits_1_listing_the_problem(tmp_path, fmu_dir, capsys, scene):
    edits = {
        "rod_force": {"replace": {RISER_ROD: '"rod.force" = -5.0e6'}},
        "bad_name": {"replace": {}, "name": "ok"},
        "stop_time": {"replace": {"stop_time = 30.0": "stop_time = 1e300"}},
    }[scene]
    path = variant(tmp_path, **edits)
    if scene == "bad_name":
        path.write_text(path.read_text().replace('name = "ok"', 'name = "../../x"'))
    assert cli(["--fmu-dir", str(fmu_dir), "check", str(path)]) == 1
    out = capsys.readouterr()
    assert "error:" in out.out and "Traceback" not in out.out + out.err
    assert out.out.count("precharge_pressure") <= 1


def test_an_output_interval_below_the_step_records_every_step_quickly(tmp_path, fmu_dir):
    """The recorder added the interval to the next output time until it passed the time: two
    million additions a row at 1 ns (and for ever below the round-off, now refused with
    run.output_interval under 1 ns). The next output time is computed instead."""
    path = variant(
        tmp_path,
        replace={
            "output_interval = 0.004": "output_interval = 1e-9",
            "step = 0.004": "step = 0.002",
        },
    )
    outcome = run_scene(path, tmp_path / "out", fmu_dir=fmu_dir, stop_time=0.01, plots=False)
    assert outcome.result.status == "finished"
    rows = outcome.csv_path.read_text().splitlines()
    assert len(rows) == 1 + 1 + 5  # header, start, five steps of 2 ms
    tiny = variant(
        tmp_path, replace={"output_interval = 0.004": "output_interval = 1e-300"}, name="tiny"
    )
    only(problems_of(tiny, fmu_dir), "run.output_interval", "nanoseconds")


@pytest.mark.parametrize(
    ("reeving", "words"),
    [
        ('"{not json"', "is not JSON"),
        ("{ bodies = 5 }", "bodies: must be a mapping"),
    ],
)
def test_draw_of_a_reeving_that_is_not_one_names_the_problem(tmp_path, capsys, reeving, words):
    path = tmp_path / "draw.toml"
    path.write_text(
        f'name = "d"\n[units.r]\nfmu = "BlockTrain"\n[units.r.parameters]\nreeving = {reeving}\n'
    )
    assert cli(["draw", "-o", str(tmp_path / "out"), str(path)]) == 1
    out = capsys.readouterr().out
    assert "error:" in out and words in out and "Traceback" not in out


@pytest.mark.parametrize("kind", ["device", "pipe", "folder", "huge"])
def test_a_scene_path_that_is_no_scene_file_is_refused_without_reading_it(tmp_path, fmu_dir, kind):
    """``/dev/zero`` and a pipe used to hang the check (read to the end, which never comes)."""
    import os

    path = {
        "device": Path("/dev/zero"),
        "pipe": tmp_path / "pipe.toml",
        "folder": tmp_path / "folder.toml",
        "huge": tmp_path / "huge.toml",
    }[kind]
    if kind == "pipe":
        os.mkfifo(path)
    elif kind == "folder":
        path.mkdir()
    elif kind == "huge":
        with path.open("wb") as handle:  # sparse: 17 MiB that take no room
            handle.truncate(17 * 2**20)
    problems = problems_of(path, fmu_dir)
    words = {
        "device": "character device",
        "pipe": "a pipe",
        "folder": "a folder",
        "huge": "larger than 16 MiB",
    }[kind]
    only(problems, "cannot read the scene file", words)


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ('"../../evil"', "plain file name"),
        ('"/abs"', "plain file name"),
        ("5", "plain file name"),
    ],
)
def test_a_sweep_name_that_is_not_a_plain_file_name_is_refused(tmp_path, name, words):
    path = tmp_path / "sweep.toml"
    path.write_text(f"name = {name}\n")
    assert any(words in p and "'name'" in p for p in sweep_problems(path))


def test_a_sweep_spec_path_that_is_a_device_is_refused(tmp_path):
    from wire_fmu.sweep import load_sweep_spec
    from wire_fmu.sweep.spec import SweepSpecError

    with pytest.raises(SweepSpecError, match="character device"):
        load_sweep_spec(Path("/dev/zero"))


def test_an_fmu_path_that_is_a_pipe_is_refused_without_opening_it(tmp_path, fmu_dir):
    """A pipe named as a unit's FMU hung check (the model description reader waited)."""
    import os

    os.mkfifo(tmp_path / "unit.fmu")
    path = tmp_path / "pipe_fmu.toml"
    path.write_text('name = "p"\n[units.u]\nfmu = "unit.fmu"\n')
    only(problems_of(path, fmu_dir), "unit 'u'", "not a regular file")


@pytest.mark.parametrize(
    ("axis", "words"),
    [
        ("linspace = [100.0, 400.0, 30000]", "30000 cases, more than max_cases = 10000"),
        ("linspace = [100.0, 400.0, 10000000000]", "more than 100000"),
    ],
)
def test_a_sweep_of_absurdly_many_cases_is_refused_saying_how_to_allow_it(tmp_path, axis, words):
    from wire_fmu.sweep import load_sweep_spec
    from wire_fmu.sweep.spec import SweepSpecError

    path = tmp_path / "huge.toml"
    path.write_text(f'[[axes]]\ntarget = "units.j.parameters.load_mass"\n{axis}\n')
    problems = sweep_problems(path)
    assert any(words in p for p in problems), problems
    path.write_text("max_cases = 2\n" + path.read_text().replace("30000", "3"))
    if "30000]" in axis:
        with pytest.raises(SweepSpecError, match="3 cases, more than max_cases = 2"):
            load_sweep_spec(path)


def test_a_recorded_text_output_reads_as_nan_not_a_traceback(tmp_path):
    from wire_fmu.master.plots import read_results

    csv = tmp_path / "timeseries.csv"
    csv.write_text("time,j.load.height,j.solver\n0.0,1.5,rk4\n0.01,1.6,rk4\n")
    columns = read_results(csv)
    assert list(columns["j.load.height"]) == [1.5, 1.6]
    assert all(v != v for v in columns["j.solver"])


def test_a_results_folder_that_is_a_file_is_said_before_anything_runs(tmp_path, fmu_dir, capsys):
    (tmp_path / "taken").write_text("")
    code = cli(
        ["--fmu-dir", str(fmu_dir), "run", "-q", "-o", str(tmp_path / "taken"), "riser_tensioner"]
    )
    out = capsys.readouterr().out
    assert code == 1 and "cannot be the results folder" in out and "Traceback" not in out


def test_a_misspelt_kernel_choice_names_the_variable_through_the_units(
    tmp_path, fmu_dir, capsys, monkeypatch
):
    """The units read ``WIRE_FMU_KERNEL`` inside the FMUs; the run's error still names it."""
    monkeypatch.setenv("WIRE_FMU_KERNEL", "numba")
    args = ["run", "-q", "--stop-time", "0.004", "-o", str(tmp_path / "out"), "riser_tensioner"]
    code = cli(["--fmu-dir", str(fmu_dir), *args])
    out = capsys.readouterr().out
    assert code == 1 and "Traceback" not in out
    assert "WIRE_FMU_KERNEL='numba' is not a kernel: expected one of compiled, python" in out


def test_plot_files_never_overwrite_each_other_or_the_energy_plot():
    from wire_fmu.master.plots import _file_names

    assert _file_names(["Energy", "energy", "Tension", ""], taken={"energy"}) == [
        "energy_2",
        "energy_3",
        "tension",
        "plot",
    ]


@pytest.mark.parametrize(
    "args", [["--repeats", "0"], ["--repeats", "-1"], ["--stop-time", "-1"], ["--stop-time", "nan"]]
)
def test_study_options_out_of_range_are_refused_by_the_command_line(args, capsys):
    with pytest.raises(SystemExit) as caught:
        cli(["study", "effects", "--quick", *args, "scissor_jack"])
    assert caught.value.code == 2
    assert "expected" in capsys.readouterr().err


SWEEP_SPEC_WITH_EVERY_KIND_OF_PROBLEM = """\
name = "bad"
max_cases = "many"
[[axes]]
target = "units.nosuch.parameters.x"
linspace = [1.0, 2.0, -3]
[[axes]]
target = "units.lift.parameters.load_mass"
values = []
[figures]
peak = "maximum(lift.load.height)"
h = "max(lift.load.heigth)"
"""


def test_a_sweep_spec_s_own_problems_and_the_scene_s_are_said_at_once(tmp_path, fmu_dir, capsys):
    spec = tmp_path / "bad.toml"
    spec.write_text(SWEEP_SPEC_WITH_EVERY_KIND_OF_PROBLEM)
    out = tmp_path / "out"
    args = ["--fmu-dir", str(fmu_dir), "sweep", "scissor_jack", str(spec), "-o", str(out)]
    assert cli([*args, "--workers", "0", "-q"]) == 1
    said = capsys.readouterr().out
    assert said.startswith("error: sweep spec 'bad' for scene 'scissor_jack': 6 problems:")
    for words in (
        "'linspace' must be [start, stop, count]",
        "'values' must be a non-empty list",
        "unknown function 'maximum'",
        "'max_cases' must be a whole number >= 1, got 'many'",
        "the scene has no unit 'nosuch'",
        "unit 'lift' has no variable 'load.heigth'",
    ):
        assert words in said, words
    assert "unexpected" not in said and not out.exists()


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--workers", "-1"], "--workers: expected a whole number >= 1, or 0 to run"),
        (["--workers", "two"], "--workers: expected a whole number >= 1, or 0 to run"),
        (["--scheduler", "notaurl"], "expected PROTOCOL://HOST:PORT, e.g. tcp://10.0.0.5:8786"),
        (["--scheduler", "foo://host:8786"], "unknown protocol 'foo'"),
    ],
)
def test_sweep_options_out_of_range_are_refused_by_the_command_line(tmp_path, capsys, args, words):
    with pytest.raises(SystemExit) as caught:
        cli(["sweep", "scissor_jack", str(tmp_path / "spec.toml"), *args])
    assert caught.value.code == 2
    assert words in capsys.readouterr().err


def test_a_sweep_of_negative_workers_is_refused_before_anything_runs(tmp_path):
    from wire_fmu.sweep import SweepError, run_sweep

    with pytest.raises(SweepError, match=r"workers = -1: expected .*; scheduler: expected"):
        run_sweep("scissor_jack", tmp_path / "none.toml", tmp_path / "out", -1, "notaurl")
    assert not (tmp_path / "out").exists()
