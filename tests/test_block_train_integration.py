"""The built BlockTrain FMU in fmpy and in libcosimpy (a master we did not write)."""

from __future__ import annotations

import math

import pytest

from wire_fmu.core.units.block_train.reevings import drilling_block_train

from .block_train_helpers import make_unit
from .fmu_checks import (
    FmiLog,
    LoadedFmu,
    assert_state_restores_bit_for_bit,
    built_fmu,
    libcosim_last_values,
    output_dependencies,
    start_fmu,
)

pytestmark = pytest.mark.integration

EFFECTS = "rope_damping,sheave_inertia,bearing_friction,rope_slip"
WATCH = [
    "line_a.tension",
    "block_a.position",
    "block_a.velocity",
    "energy_balance",
    "dissipated_energy",
]
STEP = 0.01


@pytest.fixture(scope="module")
def block_train_fmu(tmp_path_factory) -> LoadedFmu:
    return built_fmu("block_train", tmp_path_factory)


def lowering_rate(i: int) -> float:
    """Fast-line speed, m/s: lower for 0.3 s, then the drum stops hard."""
    return 0.8 if i < 30 else 0.0


def step_fmu(loaded, fmu, first: int, count: int, payout: float):
    rows = []
    for i in range(first, first + count):
        rate = lowering_rate(i)
        fmu.setReal([loaded.vr("line_a.payout"), loaded.vr("line_a.payout_rate")], [payout, rate])
        fmu.doStep(currentCommunicationPoint=i * STEP, communicationStepSize=STEP)
        payout += rate * STEP
        rows.append(fmu.getReal([loaded.vr(n) for n in WATCH]))
    return rows, payout


def test_model_description_is_complete(block_train_fmu):
    deps = output_dependencies(block_train_fmu)
    assert deps["block_a.position"] == [] and "line_a.payout" in deps["line_a.tension"]


def test_fmu_in_fmpy_equals_the_core_and_holds_physics(block_train_fmu):
    log = FmiLog()
    fmu = start_fmu(block_train_fmu, "bt", log, EFFECTS)
    (initial,) = fmu.getReal([block_train_fmu.vr("line_a.tension")])
    rows, _ = step_fmu(block_train_fmu, fmu, 0, 60, 0.0)
    fmu.terminate()
    fmu.freeInstance()
    unit = make_unit(drilling_block_train(4), EFFECTS)
    payout = 0.0
    for i in range(60):
        unit.values["line_a.payout"], unit.values["line_a.payout_rate"] = payout, lowering_rate(i)
        assert unit.advance(i * STEP, STEP).success
        payout += lowering_rate(i) * STEP
    assert rows[-1] == [unit.values[n] for n in WATCH]  # bit for bit
    # at the start the hook hangs in equilibrium on 4 lines
    assert initial == pytest.approx(1.2e5 * 9.81 / 4, rel=1e-12)
    assert all(math.isfinite(v) for row in rows for v in row)
    assert abs(rows[-1][3]) < 1e-3 * rows[-1][4]  # the ledger closes


def test_fmu_state_restores_bit_for_bit(block_train_fmu):
    loaded = block_train_fmu
    assert_state_restores_bit_for_bit(
        loaded,
        EFFECTS,
        "bt",
        # into the hard stop: friction modes change
        lambda fmu: step_fmu(loaded, fmu, 0, 25, 0.0)[1],
        lambda fmu, payout: step_fmu(loaded, fmu, 25, 20, payout)[0],
    )


def test_libcosimpy_steps_the_block_train(block_train_fmu):
    """A master we did not write runs our FMU unchanged and gets the core's numbers."""
    initial = {"effects": "rope_damping", "initial_equilibrium": False, "pretension": 2.5e5}
    got = libcosim_last_values(block_train_fmu.path, "bt", initial, WATCH, STEP, 0.5)

    unit = make_unit(
        drilling_block_train(4), "rope_damping", initial_equilibrium=False, pretension=2.5e5
    )
    for i in range(50):
        assert unit.advance(i * STEP, STEP).success
    assert got == pytest.approx([unit.values[n] for n in WATCH], rel=1e-12, abs=1e-9)
    assert got[1] != pytest.approx(15.0, abs=1e-6)  # it moved: released off equilibrium
