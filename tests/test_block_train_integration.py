"""The built BlockTrain FMU in fmpy and in libcosimpy (a master we did not write)."""

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

from wire_fmu.core.units.block_train.reevings import drilling_block_train  # noqa: E402
from wire_fmu.export.builder import build_fmu  # noqa: E402

from .block_train_helpers import make_unit  # noqa: E402

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[1]
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
    path = build_fmu(ROOT / "models" / "block_train.py", tmp_path_factory.mktemp("fmu"))
    return LoadedFmu(path)


def lowering_rate(i: int) -> float:
    """Fast-line speed, m/s: lower for 0.3 s, then the drum stops hard."""
    return 0.8 if i < 30 else 0.0


def start(loaded: LoadedFmu, name: str, log: FmiLog, effects: str = EFFECTS):
    fmu = loaded.instantiate(name, log)
    fmu.setString([loaded.vr("effects")], [effects])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu


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
    assert validate_fmu(str(block_train_fmu.path)) == []
    md = block_train_fmu.model_description
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    deps = {o.variable.name: [d.name for d in o.dependencies] for o in md.outputs}
    assert deps["block_a.position"] == [] and "line_a.payout" in deps["line_a.tension"]


def test_fmu_in_fmpy_equals_the_core_and_holds_physics(block_train_fmu):
    log = FmiLog()
    fmu = start(block_train_fmu, "bt", log)
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
    log = FmiLog()
    loaded = block_train_fmu
    fmu = start(loaded, "bt", log)
    _, payout = step_fmu(loaded, fmu, 0, 25, 0.0)  # into the hard stop: friction modes change
    state = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(state)
    first, _ = step_fmu(loaded, fmu, 25, 20, payout)
    fmu.setFMUstate(state)
    again, _ = step_fmu(loaded, fmu, 25, 20, payout)
    assert again == first
    other = start(loaded, "bt2", log)
    other.setFMUstate(other.deSerializeFMUstate(serialized))
    copied, _ = step_fmu(loaded, other, 25, 20, payout)
    assert copied == first
    fmu.freeFMUstate(state)
    for f in (fmu, other):
        f.terminate()
        f.freeInstance()


def test_libcosimpy_steps_the_block_train(block_train_fmu):
    """A master we did not write runs our FMU unchanged and gets the core's numbers."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_step_size(step_size=int(STEP * 1e9))
    slave = CosimLocalSlave(fmu_path=str(block_train_fmu.path), instance_name="bt")
    index = execution.add_local_slave(local_slave=slave)
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    assert execution.string_initial_value(index, refs["effects"], "rope_damping")
    assert execution.boolean_initial_value(index, refs["initial_equilibrium"], False)
    assert execution.real_initial_value(index, refs["pretension"], 2.5e5)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    assert execution.simulate_until(target_time=int(0.5e9))
    got = observer.last_real_values(index, [refs[n] for n in WATCH])

    unit = make_unit(
        drilling_block_train(4), "rope_damping", initial_equilibrium=False, pretension=2.5e5
    )
    for i in range(50):
        assert unit.advance(i * STEP, STEP).success
    assert got == pytest.approx([unit.values[n] for n in WATCH], rel=1e-12, abs=1e-9)
    assert got[1] != pytest.approx(15.0, abs=1e-6)  # it moved: released off equilibrium
