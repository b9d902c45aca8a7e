"""The built Winch FMU in fmpy and in libcosimpy (a master we did not write)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from fmi_test_tools import FmiLog, LoadedFmu  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from wire_fmu.export.builder import build_fmu  # noqa: E402

from .winch_helpers import make_unit  # noqa: E402

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[1]
EFFECTS = "drum_inertia,band_brake,motor_characteristic,elastic_drive_train,rope_layers"
WATCH = [
    "rope.payout",
    "rope.payout_rate",
    "drum.speed",
    "brake.torque",
    "motor.torque",
    "energy_balance",
    "dissipated_energy",
]
INTEGERS = ["brake.state", "mode_changes", "drum.layer"]
STEP = 0.01


@pytest.fixture(scope="module")
def winch_fmu(tmp_path_factory) -> LoadedFmu:
    path = build_fmu(ROOT / "models" / "winch.py", tmp_path_factory.mktemp("fmu"))
    return LoadedFmu(path)


def inputs(i: int) -> dict[str, float]:
    """Lower under load, brake to a stop (hold), release a little, hold again."""
    lever = 0.0 if i < 20 else (2500.0 if i < 60 else (300.0 if i < 70 else 2500.0))
    return {"rope.tension": 1.2e5, "brake.lever_force": lever, "motor.command": -300.0}


def start(loaded: LoadedFmu, name: str, log: FmiLog):
    fmu = loaded.instantiate(name, log)
    fmu.setString([loaded.vr("effects")], [EFFECTS])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu


def step_fmu(loaded, fmu, first: int, count: int):
    rows = []
    for i in range(first, first + count):
        values = inputs(i)
        fmu.setReal([loaded.vr(k) for k in values], list(values.values()))
        fmu.doStep(currentCommunicationPoint=i * STEP, communicationStepSize=STEP)
        rows.append(
            fmu.getReal([loaded.vr(n) for n in WATCH])
            + fmu.getInteger([loaded.vr(n) for n in INTEGERS])
        )
    return rows


def test_model_description_is_complete(winch_fmu):
    assert validate_fmu(str(winch_fmu.path)) == []
    md = winch_fmu.model_description
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    deps = {o.variable.name: [d.name for d in o.dependencies] for o in md.outputs}
    assert deps["rope.payout"] == [] and deps["rope.payout_rate"] == []
    assert "motor.command" in deps["motor.torque"]
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["rope.tension"] == "N" and units["motor_slope"] == "N.m.s/rad"


def test_fmu_in_fmpy_equals_the_core_and_holds_physics(winch_fmu):
    log = FmiLog()
    fmu = start(winch_fmu, "winch", log)
    rows = step_fmu(winch_fmu, fmu, 0, 80)
    fmu.terminate()
    fmu.freeInstance()
    unit = make_unit(EFFECTS)
    for i in range(80):
        unit.values.update(inputs(i))
        assert unit.advance(i * STEP, STEP).success
    assert rows[-1] == [unit.values[n] for n in WATCH + INTEGERS]  # bit for bit
    assert all(math.isfinite(v) for row in rows for v in row)
    states = [row[len(WATCH)] for row in rows]
    assert states[0] == 0 and 2 in states and 1 in states  # released, slipping, holding
    assert abs(rows[-1][5]) < 2e-5 * rows[-1][6]  # the ledger closes (rk4, 1 ms)


def test_fmu_state_restores_bit_for_bit_including_the_brake_hold(winch_fmu):
    log = FmiLog()
    loaded = winch_fmu
    fmu = start(loaded, "winch", log)
    rows = step_fmu(loaded, fmu, 0, 55)
    assert rows[-1][len(WATCH)] == 2  # the brake holds the drum here
    state = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(state)
    first = step_fmu(loaded, fmu, 55, 30)  # released to slipping, then held again
    assert {row[len(WATCH)] for row in first} >= {1, 2}
    fmu.setFMUstate(state)
    again = step_fmu(loaded, fmu, 55, 30)
    assert again == first
    other = start(loaded, "winch2", log)
    other.setFMUstate(other.deSerializeFMUstate(serialized))
    copied = step_fmu(loaded, other, 55, 30)
    assert copied == first
    fmu.freeFMUstate(state)
    for f in (fmu, other):
        f.terminate()
        f.freeInstance()


def test_libcosimpy_steps_the_winch(winch_fmu):
    """A master we did not write runs our FMU unchanged and gets the core's numbers."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_step_size(step_size=int(STEP * 1e9))
    slave = CosimLocalSlave(fmu_path=str(winch_fmu.path), instance_name="winch")
    index = execution.add_local_slave(local_slave=slave)
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    assert execution.string_initial_value(index, refs["effects"], "drum_inertia,band_brake")
    assert execution.real_initial_value(index, refs["initial_drum_speed"], 8.0)
    assert execution.real_initial_value(index, refs["brake.lever_force"], 1500.0)
    assert execution.real_initial_value(index, refs["rope.tension"], 5.0e4)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    assert execution.simulate_until(target_time=int(0.5e9))
    got = observer.last_real_values(index, [refs[n] for n in WATCH])

    unit = make_unit(
        "drum_inertia,band_brake",
        initial_drum_speed=8.0,
        **{"brake.lever_force": 1500.0, "rope.tension": 5.0e4},
    )
    for i in range(50):
        assert unit.advance(i * STEP, STEP).success
    assert got == pytest.approx([unit.values[n] for n in WATCH], rel=1e-12, abs=1e-9)
    assert got[0] > 0.1  # it paid out before the brake stopped it
