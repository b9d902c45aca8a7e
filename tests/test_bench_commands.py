"""The benchmark commands: what they are asked to run, and refusals of what they cannot.

Figures are not checked here (benchmarks measure, tests assert correctness): only
that ``--scenes`` picks the scenes measured, and that bad options are refused
with a message naming them.
"""

from __future__ import annotations

import pytest

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
