"""The other three papers' systems as built FMUs and as shipped scenes run from the CLI.

ScissorJack (paper 003), MultiMassDrive (paper 002) and MachineUnit (paper 004):
each FMU validates with fmpy with no problem, restores a saved state bit for
bit (also through serialisation into another instance) and gives the core's
numbers bit for bit; each scene runs from ``wire-fmu run`` and writes its plots,
and its results reproduce the paper's numbers.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from fmi_test_tools import FmiLog, LoadedFmu  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from wire_fmu.cli import main  # noqa: E402
from wire_fmu.core.units.machine.unit import MachineDriveUnit  # noqa: E402
from wire_fmu.core.units.multimass_drive.unit import DriveUnit  # noqa: E402
from wire_fmu.core.units.scissor_jack.unit import ScissorJackUnit  # noqa: E402
from wire_fmu.export.builder import build_fmu  # noqa: E402
from wire_fmu.master.plots import read_results  # noqa: E402
from wire_fmu.master.run import find_scene  # noqa: E402
from wire_fmu.master.scene import load_scene  # noqa: E402
from wire_fmu.study.frequency_response import write_frequency_response  # noqa: E402

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[1]
STEP = 0.01
HOLDING_TORQUE = (0.002 / (2 * math.pi) + 0.01 * 0.1) * 3000.0 * math.sqrt(3.0)  # 6.850 N m


# ----------------------------------------------------------------------- each FMU's case
def jack_inputs(i: int) -> dict[str, float]:
    """A handle torque rising through breakaway (6.85 N m) at step 100."""
    return {"handle.torque_command": 6.0 + 0.0085 * i}


def drive_inputs(i: int) -> dict[str, float]:
    return {"motor.torque": 50.0 * math.sin(0.3 * i), "load.torque": 20.0 if i > 40 else 0.0}


def machine_inputs(i: int) -> dict[str, float]:
    return {"load.torque": 200.0 if i >= 60 else 0.0}


CASES = {
    "ScissorJack": (
        "scissor_jack.py",
        {"handle_drive": "torque", "effects": "thread_friction"},
        jack_inputs,
        ["load.height", "handle.speed", "thread.state", "energy_balance"],
        ScissorJackUnit,
    ),
    "MultiMassDrive": (
        "drive.py",
        {},
        drive_inputs,
        ["motor.speed", "load.speed", "shaft_2.torque", "energy_balance"],
        DriveUnit,
    ),
    "MachineUnit": (
        "machine_unit.py",
        {},
        machine_inputs,
        ["shaft.speed", "shaft.angle", "cycle.delta", "energy_balance"],
        MachineDriveUnit,
    ),
}


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, LoadedFmu]:
    folder = tmp_path_factory.mktemp("paper_fmus")
    return {
        name: LoadedFmu(build_fmu(ROOT / "models" / script, folder))
        for name, (script, *_) in CASES.items()
    }


@pytest.fixture(scope="module")
def fmu_dir(fmus) -> Path:
    return next(iter(fmus.values())).path.parent


def start(loaded: LoadedFmu, name: str, log: FmiLog, strings: dict[str, str]):
    fmu = loaded.instantiate(name, log)
    for key, value in strings.items():
        fmu.setString([loaded.vr(key)], [value])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu


def step(loaded: LoadedFmu, fmu, first: int, count: int, inputs, watch: list[str]):
    rows = []
    for i in range(first, first + count):
        for key, value in inputs(i).items():
            fmu.setReal([loaded.vr(key)], [value])
        fmu.doStep(currentCommunicationPoint=i * STEP, communicationStepSize=STEP)  # raises
        rows.append(fmu.getReal([loaded.vr(n) for n in watch if n != "thread.state"]))
    return rows


@pytest.mark.parametrize("name", list(CASES))
def test_model_description_is_complete(fmus, name):
    loaded = fmus[name]
    assert validate_fmu(str(loaded.path)) == []
    md = loaded.model_description
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert md.coSimulation.modelIdentifier == name
    deps = {o.variable.name: [d.name for d in o.dependencies] for o in md.outputs}
    state_output = {
        "ScissorJack": "load.height",
        "MultiMassDrive": "load.speed",
        "MachineUnit": "shaft.speed",
    }[name]
    assert deps[state_output] == []


@pytest.mark.parametrize("name", list(CASES))
def test_fmu_equals_the_core_and_restores_its_state_bit_for_bit(fmus, name):
    script, strings, inputs, watch, unit_class = CASES[name]
    loaded = fmus[name]
    log = FmiLog()
    fmu = start(loaded, "a", log, strings)
    step(loaded, fmu, 0, 80, inputs, watch)
    state = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(state)
    first = step(loaded, fmu, 80, 60, inputs, watch)  # the jack breaks away in here
    fmu.setFMUstate(state)
    again = step(loaded, fmu, 80, 60, inputs, watch)
    assert again == first
    other = start(loaded, "b", log, strings)
    other.setFMUstate(other.deSerializeFMUstate(serialized))
    assert step(loaded, other, 80, 60, inputs, watch) == first
    unit = unit_class("a")
    unit.values.update(strings)
    unit.configure()
    unit.initialize(0.0)
    for i in range(140):
        unit.values.update(inputs(i))
        assert unit.advance(i * STEP, STEP).success
    assert first[-1] == [unit.values[n] for n in watch if n != "thread.state"]
    assert all(math.isfinite(v) for row in first for v in row)
    fmu.freeFMUstate(state)
    for f in (fmu, other):
        f.terminate()
        f.freeInstance()


# ----------------------------------------------------------------------- the scenes
def run_cli(name: str, out: Path, fmu_dir: Path, stop_time: float) -> dict[str, np.ndarray]:
    code = main(
        [
            "--fmu-dir",
            str(fmu_dir),
            "run",
            name,
            "-o",
            str(out),
            "--stop-time",
            str(stop_time),
            "-q",
        ]
    )
    assert code == 0
    scene = load_scene(find_scene(name))
    for plot in scene.plots:
        slug = "".join(c if c.isalnum() else "_" for c in plot.title.lower()).strip("_")
        assert (out / f"{slug}.png").stat().st_size > 10_000, plot.title
    return read_results(out / "timeseries.csv")


def test_scissor_jack_scene_reproduces_the_paper(fmu_dir, tmp_path):
    columns = run_cli("scissor_jack", tmp_path, fmu_dir, 10.0)
    width0 = 2 * 0.13 * math.cos(math.radians(30.0))
    expected = math.sqrt(4 * 0.13**2 - (width0 - 0.040) ** 2)  # 20 turns of 2 mm
    assert columns["lift.load.height"][-1] == pytest.approx(expected, rel=1e-12)
    assert columns["lift.screw.displacement"][-1] == pytest.approx(0.020, rel=1e-12)
    assert columns["lift_friction.handle.torque"][0] == pytest.approx(HOLDING_TORQUE, rel=1e-3)
    held = columns["self_locking.thread.state"] == 2
    torque = columns["self_locking.handle.torque"]
    assert torque[held].max() < HOLDING_TORQUE <= torque[~held][1:].min()
    heights = columns["self_locking.load.height"]
    assert np.all(heights[held] == heights[0])  # no creep while held
    assert heights[-1] > heights[0] + 0.005
    for unit in ("lift", "lift_friction", "self_locking"):
        assert np.max(np.abs(columns[f"{unit}.energy_balance"])) < 1e-6


def test_multimass_drive_scene_and_its_frequency_response(fmu_dir, tmp_path):
    columns = run_cli("multimass_drive", tmp_path, fmu_dir, 1.5)
    full, reduced = columns["full.load.speed"], columns["reduced2.load.speed"]
    assert np.max(np.abs(full - reduced)) < 2e-3 * np.max(np.abs(full))
    assert columns["full.mode_1.frequency"][0] == pytest.approx(12.48, abs=0.01)
    first, second = (columns[f"two_motor.{m}.drive_torque"][-1] for m in ("motor", "motor2"))
    assert first == pytest.approx(second, rel=0.02)
    scene = load_scene(find_scene("multimass_drive"))
    png = write_frequency_response(scene, tmp_path, points=40, simulate=(13.0,))
    assert png.stat().st_size > 20_000


def test_machine_unit_scene_reports_delta_and_cost(fmu_dir, tmp_path):
    columns = run_cli("machine_unit", tmp_path, fmu_dir, 3.0)
    reference = columns["reference.cycle.delta"][-1]
    assert 0.03 < reference < 0.06
    assert abs(columns["paper.cycle.delta"][-1] - reference) < 1e-4
    assert abs(columns["paper_first_order.cycle.delta"][-1] - reference) < 2e-4
    speed_error = np.max(np.abs(columns["paper.shaft.speed"] - columns["reference.shaft.speed"]))
    assert speed_error < 1e-3
    assert columns["paper.solver.evaluations"][-1] < columns["reference.solver.evaluations"][-1]
