"""Sweeps on a local Dask cluster of two workers against serial runs.

The scene is the two-mass oscillator of ``test_master_convergence`` (two
small test FMUs, about 0.1-0.3 s per run). The reference for "results equal
those of serial runs" is each case run with ``run_scene`` in this process
and its key figures taken with numpy from its own time series, outside the
sweep machinery; the sweep's figures and time series must equal them bit
for bit.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from fmi_test_tools import FACADES  # noqa: E402

from wire_fmu.export.builder import build_fmu  # noqa: E402
from wire_fmu.master.plots import read_results  # noqa: E402
from wire_fmu.master.run import run_scene  # noqa: E402
from wire_fmu.master.scene import parse_scene  # noqa: E402
from wire_fmu.sweep import SweepError, apply_case, expand, parse_sweep_spec, run_sweep  # noqa: E402

pytestmark = pytest.mark.integration

FIGURES = {
    "peak_b": "max(b.position)",
    "low_a": "min(a.position)",
    "spread_a": "range(a.position)",
    "final_b": "final(b.position)",
    "mean_b": "mean(b.position)",
    "residual": "final(bond.spring.energy_residual)",
}


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


@pytest.fixture(scope="module")
def cluster(fmus):
    """A cluster of two single-thread worker processes, reached by its address."""
    from distributed import Client, LocalCluster

    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as local,
        Client(local) as client,
    ):
        yield client


def two_mass(fmus, stop_time=1.0, outputs=("a.position",)):
    return parse_scene(
        {
            "name": "two_mass",
            "run": {"stop_time": stop_time, "step": 0.01},
            "units": {
                "a": {
                    "fmu": str(fmus["osc"]),
                    "parameters": {
                        "mass": 1.0,
                        "stiffness": 40.0,
                        "damping": 0.0,
                        "x0": 0.1,
                        "substeps": 50,
                    },
                },
                "b": {
                    "fmu": str(fmus["mass"]),
                    "parameters": {
                        "mass": 2.0,
                        "stiffness": 60.0,
                        "damping": 0.0,
                        "x0": 0.0,
                        "substeps": 50,
                    },
                },
            },
            "bonds": [
                {
                    "name": "spring",
                    "kind": "translational",
                    "effort": "b.force_on_flange -> a.force",
                    "flow": "a.velocity -> b.flange.velocity",
                    "position": "a.position -> b.flange.position",
                }
            ],
            "outputs": {"variables": list(outputs)},  # the sweep adds what its figures read
        },
        base_dir=Path("."),
    )


def sweep_spec(masses=(1.0, 2.0), stiffnesses=(40.0, 80.0), samples=2, **axes):
    data = {
        "axes": [
            {"target": "units.b.parameters.mass", "values": list(masses)},
            {"target": "units.b.parameters.stiffness", "values": list(stiffnesses)},
            {
                "target": "units.b.parameters.damping",
                "distribution": "uniform",
                "low": 0.0,
                "high": 1.0,
            },
            *axes.values(),
        ],
        "sampling": {"samples": samples, "seed": 11},
        "figures": FIGURES,
    }
    return parse_sweep_spec(data)


def serial_reference(scene, spec, tmp_path) -> dict[str, tuple[dict, bytes]]:
    """Each case run by run_scene here; figures by numpy; and the time series' bytes."""
    out = {}
    for case in expand(spec):
        outcome = run_scene(apply_case(scene, case.values), tmp_path / case.case_id, plots=False)
        assert outcome.result.status == "finished", outcome.result.message
        c = read_results(outcome.csv_path)
        t, a, b = c["time"], c["a.position"], c["b.position"]
        figures = {
            "peak_b": np.max(b),
            "low_a": np.min(a),
            "spread_a": np.max(a) - np.min(a),
            "final_b": b[-1],
            "mean_b": np.trapezoid(b, t) / (t[-1] - t[0]),
            "residual": c["bond.spring.energy_residual"][-1],
        }
        out[case.case_id] = (
            {k: float(v) for k, v in figures.items()},
            outcome.csv_path.read_bytes(),
        )
    return out


def by_id(rows):
    return {r["case_id"]: r for r in rows}


def test_two_workers_equal_serial_runs_bit_for_bit(fmus, tmp_path):
    scene, spec = two_mass(fmus), sweep_spec()
    both = two_mass(fmus, outputs=("a.position", "b.position"))
    reference = serial_reference(both, spec, tmp_path / "reference")
    parallel = run_sweep(scene, spec, tmp_path / "parallel", workers=2, progress=False)
    assert parallel.executed == len(reference) == 8 and parallel.complete
    assert len({r["worker"] for r in parallel.rows} - {"local"}) == 2  # both workers ran cases
    for cid, row in by_id(parallel.rows).items():
        figures, csv = reference[cid]
        assert {k: row[k] for k in FIGURES} == figures  # exact, not approx
        assert (parallel.directory / "cases" / cid / "timeseries.csv").read_bytes() == csv
    table = pq.read_table(parallel.summary_path)
    assert table.num_rows == 8 and "units.b.parameters.damping" in table.column_names
    assert by_id(table.to_pylist()) == by_id(parallel.rows)
    assert sorted(p.name for p in parallel.plots) == sorted(f"{k}.png" for k in FIGURES)
    assert all(p.stat().st_size > 10_000 for p in parallel.plots)


def test_a_case_that_raises_is_recorded_and_the_rest_complete(fmus, cluster, tmp_path):
    spec = parse_sweep_spec(
        {
            "axes": [
                {"target": "units.a.parameters.mass", "values": [1.0, -1.0]},  # -1: refused
                {"target": "units.a.parameters.max_position", "values": [1e3, 0.05]},  # 0.05: stops
                {"target": "run.step", "values": [0.01, -0.01]},  # -0.01: not a valid setting
            ],
            "figures": FIGURES,
        }
    )
    result = run_sweep(
        two_mass(fmus), spec, tmp_path / "out", scheduler=cluster.scheduler.address, progress=False
    )
    rows = {
        (r["units.a.parameters.mass"], r["units.a.parameters.max_position"], r["run.step"]): r
        for r in result.rows
    }
    assert result.counts == {"finished": 1, "stopped": 1, "failed": 6}
    assert rows[1.0, 1e3, 0.01]["status"] == "finished"
    stopped = rows[1.0, 0.05, 0.01]
    assert stopped["status"] == "stopped" and "refused the step" in stopped["error"]
    assert stopped["end_time"] == 0.0 and stopped["peak_b"] == 0.0  # what was recorded
    for key in ((-1.0, 1e3, 0.01), (-1.0, 0.05, 0.01)):
        assert rows[key]["status"] == "failed"
        assert "mass = -1.0 must be > 0" in rows[key]["error"]
        assert rows[key]["peak_b"] is None
    for row in result.rows:
        if row["run.step"] < 0:
            assert row["status"] == "failed" and "run.step must be a positive" in row["error"]


def test_a_worker_killed_mid_sweep_loses_no_case(fmus, cluster, tmp_path):
    scene, spec = two_mass(fmus, stop_time=2.0), sweep_spec()
    pids = cluster.run(os.getpid)
    killed: dict[str, object] = {}

    def kill_the_other_worker(row):
        if killed:
            return
        victim = next(a for a in pids if a != row["worker"])
        for _ in range(100):  # between two cases the scheduler may not have assigned one yet
            killed["running"] = cluster.processing([victim])[victim]
            if killed["running"]:
                break
            time.sleep(0.05)
        killed["address"] = victim
        os.kill(pids[victim], signal.SIGKILL)

    result = run_sweep(
        scene,
        spec,
        tmp_path / "out",
        scheduler=cluster.scheduler.address,
        progress=False,
        on_case=kill_the_other_worker,
    )
    assert killed["running"], "the worker killed was running a case"
    assert killed["address"] not in cluster.scheduler_info()["workers"]
    assert result.complete and result.executed == 8
    serial = run_sweep(scene, spec, tmp_path / "serial", workers=0, progress=False)
    assert serial.complete and {r["worker"] for r in serial.rows} == {"local"}
    reference = by_id(serial.rows)
    for cid, row in by_id(result.rows).items():
        assert {k: row[k] for k in FIGURES} == {k: reference[cid][k] for k in FIGURES}


class SimulatedInterruptError(Exception):
    """Stands for Ctrl-C or a lost client."""


def test_second_invocation_runs_only_what_is_missing(fmus, cluster, tmp_path):
    scene, spec, out = two_mass(fmus), sweep_spec(), tmp_path / "out"
    address = cluster.scheduler.address
    seen = []

    def stop_after_three(row):
        seen.append(row["case_id"])
        if len(seen) == 3:
            raise SimulatedInterruptError

    with pytest.raises(SimulatedInterruptError):
        run_sweep(scene, spec, out, scheduler=address, progress=False, on_case=stop_after_three)
    on_disk = {p.stem for p in (out / "records").glob("*.parquet")}
    assert on_disk == set(seen)
    summary = pq.read_table(out / "summary.parquet").to_pylist()
    assert sorted(r["status"] for r in summary) == ["finished"] * 3 + ["pending"] * 5
    first = {r["case_id"]: r["finished_at"] for r in summary if r["status"] == "finished"}

    again = run_sweep(scene, spec, out, scheduler=address, progress=False)
    assert (again.executed, again.reused) == (5, 3) and again.complete
    assert {cid: by_id(again.rows)[cid]["finished_at"] for cid in first} == first

    third = run_sweep(scene, spec, out, scheduler=address, progress=False)
    assert (third.executed, third.reused, third.startup_time) == (0, 8, 0.0)

    with pytest.raises(SweepError, match="choose another output folder"):
        run_sweep(two_mass(fmus, stop_time=3.0), spec, out, workers=0, progress=False)


def test_a_grown_spec_runs_only_new_cases_and_adds_figures_from_stored_series(fmus, tmp_path):
    scene, out = two_mass(fmus), tmp_path / "out"
    axis = {"target": "units.b.parameters.mass", "values": [1.0, 2.0]}
    first = run_sweep(
        scene,
        parse_sweep_spec({"axes": [axis], "figures": {"peak_b": FIGURES["peak_b"]}}),
        out,
        workers=0,
        progress=False,
        plots=False,
    )
    grown = parse_sweep_spec(
        {
            "axes": [{**axis, "values": [1.0, 2.0, 3.0]}],
            "figures": {"peak_b": FIGURES["peak_b"], "low_a": FIGURES["low_a"]},
        }
    )
    second = run_sweep(scene, grown, out, workers=0, progress=False, plots=False)
    assert (first.executed, second.executed, second.reused) == (2, 1, 2)
    for row in second.rows:
        columns = read_results(out / "cases" / row["case_id"] / "timeseries.csv")
        assert row["low_a"] == float(np.min(columns["a.position"]))
    assert pq.read_table(out / "records").num_rows == 3  # one schema again
