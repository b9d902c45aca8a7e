"""``wire-fmu run SCENE --monolithic``: one ODE, the results folder of a normal run, true statuses.

The riser tensioner's first 0.5 s run both ways through the command line:
the same files, the same columns (less the bond channels that have no
counterpart in one ODE, named in the metadata) in the same units, and the
same key outputs. Then what is refused (``--step``, a unit given as an FMU
file) and how runs that do not finish end: stopped by the physics mid-run,
failed in initialisation, interrupted by Ctrl-C, each with its rows kept.
"""

from __future__ import annotations

import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.cli import main as cli
from wire_fmu.master.catalog import DEFAULT_FMU_DIR, ensure_built
from wire_fmu.master.plots import read_results
from wire_fmu.master.run import SCENE_DIR, read_results_frame
from wire_fmu.registry import BY_NAME
from wire_fmu.study.monolithic_run import output_times

pytestmark = pytest.mark.integration

RISER = SCENE_DIR / "riser_tensioner.toml"
WINDOW = "0.5"
"""Simulated seconds compared: the heave fades in over 10 s, and until 0.7 s the seal holds
the rod (measured: the co-simulated rod first moves at 0.70 s)."""

SEA_STATE = (
    'kind = "sea_state"\nsignificant_height = 6.0\npeak_period = 11.0\nspectrum = "jonswap"\n'
    "gamma = 3.3\nheave_rao = 0.3\nseed = 7\nramp_time = 10.0\n"
)
HEAVE_20_M = 'kind = "sine"\namplitude = 20.0\nperiod = 4.0\nramp_time = 0.5\n'

BOND_ONLY = {"bond.rod.energy_residual", "bond.rod.energy_carried"}
"""The riser's columns a co-simulated run records and a monolithic one cannot."""


def riser_variant(folder: Path, name: str, replace: dict[str, str]) -> Path:
    """A copy of the riser tensioner named ``name`` with text replaced."""
    text = RISER.read_text(encoding="utf-8").replace('name = "riser_tensioner"', f'name = "{name}"')
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def said(capsys) -> str:
    """What the command printed, checked to hold no traceback."""
    out = capsys.readouterr()
    assert "Traceback" not in out.out + out.err
    return out.out + out.err


@pytest.fixture(scope="module")
def riser_runs(tmp_path_factory) -> dict[str, Path]:
    """The riser's first 0.5 s, monolithic and co-simulated, through the command line."""
    folder = tmp_path_factory.mktemp("riser_runs")
    runs = {"monolithic": folder / "monolithic", "cosim": folder / "cosim"}
    for mode, out in runs.items():
        extra = ["--monolithic"] if mode == "monolithic" else []
        code = cli(["run", "-q", "--stop-time", WINDOW, *extra, "-o", str(out), "riser_tensioner"])
        assert code == 0, mode
    return runs


def metadata(folder: Path) -> dict:
    return json.loads((folder / "metadata.json").read_text())


# ------------------------------------------------------------------ the results folder
def test_a_monolithic_run_writes_the_files_of_a_normal_run(riser_runs):
    mono, cosim = riser_runs["monolithic"], riser_runs["cosim"]
    assert (mono / "timeseries.csv").is_file() and (mono / "metadata.json").is_file()
    plots = {p.name for p in cosim.glob("*.png")}
    assert plots >= {"riser_tension.png", "cylinder_stroke.png", "gas_pressure.png"}
    assert {p.name for p in mono.glob("*.png")} == plots
    meta = metadata(mono)
    assert meta["mode"] == "monolithic" and "mode" not in metadata(cosim)
    assert meta["result"]["status"] == "finished" and meta["result"]["message"] == ""
    assert meta["result"]["end_time"] == pytest.approx(0.5)
    assert meta["solver"]["method"] == "radau" and meta["result"]["steps"] > 0


def test_its_columns_are_the_normal_runs_less_the_coupling_channels_in_the_same_units(
    riser_runs,
):
    mono, cosim = metadata(riser_runs["monolithic"]), metadata(riser_runs["cosim"])
    assert set(mono["omitted_columns"]) == BOND_ONLY
    assert all(len(reason) > 40 for reason in mono["omitted_columns"].values())
    assert mono["columns"] == [c for c in cosim["columns"] if c not in BOND_ONLY]
    assert mono["column_units"] == {c: cosim["column_units"][c] for c in mono["columns"]}
    assert mono["column_units"]["rope.path_end.tension"] == "N"
    assert mono["column_units"]["bond.rod.power"] == "W"
    assert mono["variables"] == cosim["variables"]
    frame = read_results_frame(riser_runs["monolithic"])  # read as any results folder
    assert list(frame.columns) == mono["columns"][1:]
    assert frame.attrs["status"] == "finished" and frame.attrs["complete"]
    assert frame.attrs["units"]["cylinder.gas.pressure"] == "Pa"


def test_in_static_equilibrium_it_agrees_with_the_co_simulation(riser_runs):
    """Until 0.7 s the seal's static friction holds the rod, in both runs.

    The rod then stands still: there is no coupling error in the rod's motion for the
    co-simulation to make, and the wire's tension is set by the heave (faded in, a few kN)
    through its stiffness, integrated by each run's own solver. Measured: tension within
    0.05 N (1.6e-5 of its 3.1 kN swing), gas pressure within 1.0 Pa (7e-8 of it, the two
    initial equilibria). Allowed: 1e-3 of the tension's swing (3 N; a stick-slip coupling
    error, 0.1-0.3 of the swing, is a hundred times more) and 1e-6 of the pressure. The
    rod must not move at all in either run (to 1 nm), or the premise is gone.
    """
    mono = read_results(riser_runs["monolithic"] / "timeseries.csv")
    cosim = read_results(riser_runs["cosim"] / "timeseries.csv")
    np.testing.assert_array_equal(mono["time"], cosim["time"])  # the same 126 record times
    assert len(mono["time"]) == 126
    for run in (mono, cosim):
        assert np.ptp(run["cylinder.rod.position"]) < 1e-9  # stuck
        assert np.max(np.abs(run["cylinder.rod.velocity"])) < 1e-9
    np.testing.assert_allclose(
        mono["cylinder.rod.position"], cosim["cylinder.rod.position"], rtol=0, atol=1e-9
    )
    tension, reference = mono["rope.path_end.tension"], cosim["rope.path_end.tension"]
    swing = np.ptp(reference)
    assert swing > 1e3  # the heave does stretch the wire in the window
    assert np.max(np.abs(tension - reference)) < 1e-3 * swing
    pressure = mono["cylinder.gas.pressure"]
    np.testing.assert_allclose(pressure, cosim["cylinder.gas.pressure"], rtol=1e-6)
    assert np.max(np.abs(mono["energy.units_balance"])) < 1e-3  # every ledger closes


def test_record_times_are_the_masters_and_end_at_the_stop_time():
    times = list(output_times(0.5, 0.01))
    assert len(times) == 50 and times[-1] == 0.5 and times[2] == 0.03
    odd = list(output_times(0.123, 0.01))
    assert len(odd) == 13 and odd[-2] == 0.12 and odd[-1] == 0.123


# ------------------------------------------------------------------------ refusals
def test_step_is_refused_with_monolithic_and_rtol_without_it(tmp_path, capsys):
    for args in (["--monolithic", "--step", "0.001"], ["--rtol", "1e-6"]):
        with pytest.raises(SystemExit) as stop:
            cli(["run", "-q", *args, "-o", str(tmp_path / "out"), "riser_tensioner"])
        assert stop.value.code == 2
        text = said(capsys)
        assert ("macro step" in text) if "--step" in args else ("--monolithic" in text)
    assert not (tmp_path / "out").exists()


def test_a_unit_given_as_an_fmu_file_is_refused_naming_it(tmp_path, capsys):
    built = ensure_built("Hydraulics", BY_NAME["Hydraulics"].facade_path, DEFAULT_FMU_DIR)
    shutil.copy(built, tmp_path / "cylinder.fmu")
    scene = riser_variant(tmp_path, "foreign", {'fmu = "Hydraulics"': 'fmu = "cylinder.fmu"'})
    out = tmp_path / "out"
    assert cli(["run", "-q", "--monolithic", "-o", str(out), str(scene)]) == 1
    text = said(capsys)
    assert text.startswith("error: scene 'foreign' cannot run monolithically")
    assert "unit 'cylinder'" in text and "'cylinder.fmu' is an FMU" in text
    assert "without --monolithic" in text and "unit 'rope'" not in text
    assert not out.exists()


# --------------------------------------------------------------- runs that do not finish
def test_a_run_the_physics_stops_keeps_its_rows_and_says_why(tmp_path, capsys):
    """Without end stops, a 20 m heave pulls the rod past the end of its stroke at 0.3407 s
    (the co-simulation at 2 ms stops there too)."""
    scene = riser_variant(
        tmp_path,
        "overstroke",
        {'"seal_friction", "end_stops"]': '"seal_friction"]', SEA_STATE: HEAVE_20_M},
    )
    out = tmp_path / "out"
    assert cli(["run", "-q", "--monolithic", "--stop-time", "2", "-o", str(out), str(scene)]) == 1
    text = said(capsys)
    assert "run stopped: after t = 0.34 s" in text and "add the effect 'end_stops'" in text
    result = metadata(out)["result"]
    assert result["status"] == "stopped" and "rod extension" in result["message"]
    assert result["end_time"] == pytest.approx(0.34)
    rows = read_results(out / "timeseries.csv")
    assert len(rows["time"]) == 86 and rows["time"][-1] == pytest.approx(0.34)
    assert rows["cylinder.rod.position"][-1] < 0.05  # nearly at the end of its stroke
    # the bond's power: the rope's force on the rod times the rod's velocity, at each row
    power = rows["rope.mover_a.force"] * rows["cylinder.rod.velocity"]
    assert np.max(np.abs(power)) > 1e5
    np.testing.assert_allclose(rows["bond.rod.power"], power, rtol=1e-12, atol=1e-6)


def test_a_failed_initialisation_ends_failed_with_the_reason(tmp_path, capsys):
    scene = riser_variant(tmp_path, "failing", {'"rod.force" = -1.424e6': '"rod.force" = -5.0e6'})
    out = tmp_path / "out"
    assert cli(["run", "-q", "--monolithic", "-o", str(out), str(scene)]) == 1
    assert "run failed: initialisation failed" in said(capsys)
    result = metadata(out)["result"]
    assert result["status"] == "failed" and "precharge_pressure" in result["message"]
    assert not (out / "timeseries.csv").exists()  # nothing was computed, nothing recorded


def test_ctrl_c_ends_a_monolithic_run_interrupted_with_its_rows(tmp_path):
    out = tmp_path / "interrupted"
    process = subprocess.Popen(
        [sys.executable, "-m", "wire_fmu.cli", "run", "-q", "--monolithic", "-o", str(out)]
        + ["riser_tensioner"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    csv = out / "timeseries.csv"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and (not csv.exists() or csv.stat().st_size < 20_000):
        time.sleep(0.05)  # well inside the 30 s run: rows are being written
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stdout + stderr
    assert "run interrupted" in stdout and "Traceback" not in stdout + stderr
    result = metadata(out)["result"]
    assert result["status"] == "interrupted"
    rows = read_results(csv)["time"]
    assert len(rows) > 10 and rows[-1] == pytest.approx(result["end_time"])
    assert result["end_time"] < 30.0
