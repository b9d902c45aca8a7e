"""The built Winch FMU in fmpy and in libcosimpy (a master we did not write)."""

from __future__ import annotations

import math

import pytest

from .fmu_checks import (
    FmiLog,
    LoadedFmu,
    assert_state_restores_bit_for_bit,
    built_fmu,
    libcosim_last_values,
    output_dependencies,
    start_fmu,
)
from .winch_helpers import make_unit

pytestmark = pytest.mark.integration

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
    return built_fmu("winch", tmp_path_factory)


def inputs(i: int) -> dict[str, float]:
    """Lower under load, brake to a stop (hold), release a little, hold again."""
    lever = 0.0 if i < 20 else (2500.0 if i < 60 else (300.0 if i < 70 else 2500.0))
    return {"rope.tension": 1.2e5, "brake.lever_force": lever, "motor.command": -300.0}


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
    deps = output_dependencies(winch_fmu)
    assert deps["rope.payout"] == [] and deps["rope.payout_rate"] == []
    assert "motor.command" in deps["motor.torque"]
    units = {v.name: v.unit for v in winch_fmu.model_description.modelVariables}
    assert units["rope.tension"] == "N" and units["motor_slope"] == "N.m.s/rad"


def test_fmu_in_fmpy_equals_the_core_and_holds_physics(winch_fmu):
    log = FmiLog()
    fmu = start_fmu(winch_fmu, "winch", log, EFFECTS)
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
    loaded = winch_fmu

    def run_up(fmu) -> None:
        rows = step_fmu(loaded, fmu, 0, 55)
        assert rows[-1][len(WATCH)] == 2  # the brake holds the drum here

    first = assert_state_restores_bit_for_bit(
        loaded, EFFECTS, "winch", run_up, lambda fmu, _: step_fmu(loaded, fmu, 55, 30)
    )
    # released to slipping, then held again
    assert {row[len(WATCH)] for row in first} >= {1, 2}


def test_libcosimpy_steps_the_winch(winch_fmu):
    """A master we did not write runs our FMU unchanged and gets the core's numbers."""
    initial = {
        "effects": "drum_inertia,band_brake",
        "initial_drum_speed": 8.0,
        "brake.lever_force": 1500.0,
        "rope.tension": 5.0e4,
    }
    got = libcosim_last_values(winch_fmu.path, "winch", initial, WATCH, STEP, 0.5)

    unit = make_unit(
        "drum_inertia,band_brake",
        initial_drum_speed=8.0,
        **{"brake.lever_force": 1500.0, "rope.tension": 5.0e4},
    )
    for i in range(50):
        assert unit.advance(i * STEP, STEP).success
    assert got == pytest.approx([unit.values[n] for n in WATCH], rel=1e-12, abs=1e-9)
    assert got[0] > 0.1  # it paid out before the brake stopped it
