"""The benchmark commands: what they are asked to run, and refusals of what they cannot.

Figures are not checked here (benchmarks measure, tests assert correctness): only
that ``--scenes`` picks the scenes measured, and that bad options are refused
with a message naming them.
"""

from __future__ import annotations

import pytest

from wire_fmu.bench import bytecodes as bench_bytecodes
from wire_fmu.bench import libcosim as bench_libcosim
from wire_fmu.bench import master as bench_master
from wire_fmu.bench import scenes as bench_scenes


@pytest.mark.integration
def test_the_master_benchmark_measures_only_the_scenes_named(tmp_path):
    out = tmp_path / "master.md"
    bench_master.main(
        ["--scenes", "riser_tensioner", "--stop-time", "0.02", "--repeats", "1", "--out", str(out)]
    )
    rows = [line for line in out.read_text().splitlines() if line.startswith("| ")]
    assert [row.split("|")[1].strip() for row in rows[1:]] == ["riser_tensioner"]
    cells = [cell.strip() for cell in rows[1].split("|")[1:-1]]
    assert cells[1:4] == ["2", "5", "0.02"]  # two units, five steps of 4 ms


@pytest.mark.integration
def test_the_libcosim_benchmark_runs_both_masters_on_the_scenes_named(tmp_path):
    out = tmp_path / "libcosim.md"
    bench_libcosim.main(
        ["--scenes", "riser_tensioner", "--stop-time", "0.02", "--repeats", "1", "--out", str(out)]
    )
    rows = [line for line in out.read_text().splitlines() if line.startswith("| ")]
    assert [row.split("|")[1].strip() for row in rows[1:]] == ["riser_tensioner"]
    cells = [cell.strip() for cell in rows[1].split("|")[1:-1]]
    assert cells[1:3] == ["2", "5"]  # two units, five steps of 4 ms
    assert float(cells[3]) > 0.0 and float(cells[4]) > 0.0  # each master stepped


def test_the_libcosim_benchmark_runs_libcosims_algorithm():
    scene = bench_libcosim.jacobi_scene("drawworks", 1.0)
    run = scene.run
    settings = (run.algorithm, run.extrapolation, run.iterations, run.adaptive, run.ramped_flows)
    assert settings == ("jacobi", "constant", 1, False, False)
    assert run.stop_time == 1.0


@pytest.mark.parametrize("command", [bench_master.main, bench_scenes.main, bench_libcosim.main])
@pytest.mark.parametrize(
    ("options", "named"),
    [(["--scenes", "no_such_scene"], "--scenes"), (["--repeats", "0"], "--repeats")],
)
def test_a_benchmark_refuses_bad_options_naming_them(command, options, named, capsys):
    with pytest.raises(SystemExit) as stopped:
        command(options)
    assert stopped.value.code == 2
    assert named in capsys.readouterr().err


def test_the_libcosim_benchmark_refuses_a_stop_time_not_above_zero(capsys):
    with pytest.raises(SystemExit) as stopped:
        bench_libcosim.main(["--stop-time", "0"])
    assert stopped.value.code == 2
    assert "--stop-time" in capsys.readouterr().err


@pytest.mark.integration
def test_the_bytecode_benchmark_counts_the_same_in_every_run(tmp_path):
    # riser_tensioner in 4 ms steps: counting starts after the step that ends at 0.02 s
    first = bench_bytecodes.measure("riser_tensioner", 0.04, 0.02, tmp_path / "first")
    second = bench_bytecodes.measure("riser_tensioner", 0.04, 0.02, tmp_path / "second")
    assert (first.units, first.steps) == (2, 5)
    assert first.by_layer == second.by_layer
    assert first.by_function == second.by_function
    assert first.by_layer["master"] > 0 and first.by_layer["FMU side"] > 0
    assert first.by_function["wire_fmu/master/exchange.py:set_inputs (master)"] > 0
    assert first.by_function["wire_fmu/export/facade.py:do_step (FMU side)"] > 0


def test_code_counts_to_the_layer_it_lives_in():
    layer_of = bench_bytecodes.layer_of
    assert layer_of("/site/wire_fmu/master/exchange.py") == "master"
    assert layer_of("/site/wire_fmu/export/facade.py") == "FMU side"
    assert layer_of("/site/wire_fmu/core/units/winch/drive.py") == "FMU side"
    assert layer_of("/site/wire_fmu/bench/master.py") == "other"
    assert layer_of("/usr/lib/python3.11/dataclasses.py") is None
    short = bench_bytecodes.short_file
    assert short("/venv/lib/python3.11/site-packages/numpy/_core/_methods.py") == (
        "numpy/_core/_methods.py"
    )
    assert short("/src/wire_fmu/master/exchange.py") == "wire_fmu/master/exchange.py"
    assert short("/usr/lib/python3.11/dataclasses.py") == "dataclasses.py"


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--scenes", "no_such_scene"], "--scenes"),
        (["--stop-time", "0"], "--stop-time"),
        (["--warm-up", "1"], "--warm-up"),
        (["--top", "-1"], "--top"),
    ],
)
def test_the_bytecode_benchmark_refuses_bad_options_naming_them(options, named, capsys):
    with pytest.raises(SystemExit) as stopped:
        bench_bytecodes.main(options)
    assert stopped.value.code == 2
    assert named in capsys.readouterr().err


def test_the_bytecode_benchmark_reports_every_bad_option_at_once(capsys):
    with pytest.raises(SystemExit) as stopped:
        bench_bytecodes.main(["--stop-time", "-1", "--warm-up", "2", "--top", "-3"])
    assert stopped.value.code == 2
    err = capsys.readouterr().err
    assert "--stop-time" in err and "--warm-up" in err and "--top" in err
