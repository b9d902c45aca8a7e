"""The built Hydraulics FMU in fmpy and in libcosimpy (a master we did not write)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from fmi_test_tools import FmiLog, LoadedFmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from wire_fmu.export.builder import build_fmu  # noqa: E402

from .hydraulics_helpers import ALL_EFFECTS, make_unit, quiet_cylinder  # noqa: E402

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[1]
WATCH = [
    "rod.position",
    "rod.velocity",
    "chamber.pressure",
    "gas.pressure",
    "gas.volume",
    "seal.friction_force",
    "end_stop.force",
    "energy_balance",
    "dissipated_energy",
]
STEP = 0.01
F0 = -4 * 356.0e3


@pytest.fixture(scope="module")
def hydraulics_fmu(tmp_path_factory) -> LoadedFmu:
    path = build_fmu(ROOT / "models" / "hydraulics.py", tmp_path_factory.mktemp("fmu"))
    return LoadedFmu(path)


def rope_force(i: int) -> float:
    """Heave on the rope for 0.4 s (the seals stick and slip), then 15 % of the load
    is lost: the rod runs through the cushion onto the extension stop and sticks there."""
    return F0 * (1 + 0.02 * math.sin(0.5 * i)) if i < 40 else 0.85 * F0


def start(loaded: LoadedFmu, name: str, log: FmiLog, effects: str = ALL_EFFECTS):
    fmu = loaded.instantiate(name, log)
    fmu.setString([loaded.vr("effects")], [effects])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu


def step_fmu(loaded: LoadedFmu, fmu, first: int, count: int) -> list[list[float]]:
    rows = []
    for i in range(first, first + count):
        fmu.setReal([loaded.vr("rod.force")], [rope_force(i)])
        fmu.doStep(currentCommunicationPoint=i * STEP, communicationStepSize=STEP)
        rows.append(fmu.getReal([loaded.vr(n) for n in WATCH]))
    return rows


def flags(loaded: LoadedFmu, fmu) -> tuple[bool, bool]:
    stuck, contact = fmu.getBoolean([loaded.vr("seal.stuck"), loaded.vr("end_stop.contact")])
    return bool(stuck), bool(contact)


def test_model_description_is_complete(hydraulics_fmu):
    assert validate_fmu(str(hydraulics_fmu.path)) == []
    md = hydraulics_fmu.model_description
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    deps = {o.variable.name: [d.name for d in o.dependencies] for o in md.outputs}
    assert deps["rod.position"] == [] and deps["rod.velocity"] == []
    # the force now, held or its interface model restarted at the present time
    assert deps["chamber.pressure"] == ["rod.force", *(f"rod.{q}" for q in INTERFACE_QUANTITIES)]
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["gas.pressure"] == "Pa" and units["cushion_coefficient"] == "N.s2/m2"


def test_fmu_in_fmpy_equals_the_core_bit_for_bit(hydraulics_fmu):
    log = FmiLog()
    fmu = start(hydraulics_fmu, "hyd", log)
    rows = step_fmu(hydraulics_fmu, fmu, 0, 130)
    (changes,) = fmu.getInteger([hydraulics_fmu.vr("mode_changes")])
    assert changes >= 10  # stick/slip, cushion, stop
    fmu.terminate()
    fmu.freeInstance()
    unit = make_unit(ALL_EFFECTS)
    for i in range(130):
        unit.values["rod.force"] = rope_force(i)
        assert unit.advance(i * STEP, STEP).success
    assert rows[-1] == [unit.values[n] for n in WATCH]
    assert all(math.isfinite(v) for row in rows for v in row)
    assert abs(rows[-1][7]) < 2e-3 * rows[-1][8]  # the ledger closes


@pytest.mark.parametrize(("at", "expected"), [(22, (True, False)), (123, (False, True))])
def test_fmu_state_restores_bit_for_bit_in_stick_and_contact(hydraulics_fmu, at, expected):
    log = FmiLog()
    loaded = hydraulics_fmu
    fmu = start(loaded, "hyd", log)
    step_fmu(loaded, fmu, 0, at)
    assert flags(loaded, fmu) == expected
    state = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(state)
    first = step_fmu(loaded, fmu, at, 15)
    fmu.setFMUstate(state)
    assert step_fmu(loaded, fmu, at, 15) == first
    other = start(loaded, "hyd2", log)
    other.setFMUstate(other.deSerializeFMUstate(serialized))
    assert step_fmu(loaded, other, at, 15) == first
    fmu.freeFMUstate(state)
    for f in (fmu, other):
        f.terminate()
        f.freeInstance()


def test_zero_gas_volume_is_a_logged_discard(hydraulics_fmu):
    log = FmiLog()
    loaded = hydraulics_fmu
    fmu = loaded.instantiate("hyd", log)
    params = quiet_cylinder(accumulator_volume=0.05, accumulator_dead_volume=0.005)
    fmu.setReal([loaded.vr(k) for k in params], list(params.values()))
    area = math.pi * 0.2**2 / 4
    fmu.setReal([loaded.vr("rod.force")], [-1.0e7 * area])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([loaded.vr("rod.force")], [-1.0e7 * area - 3.0e6])
    with pytest.raises(FMICallException) as refused:
        for i in range(200):
            fmu.doStep(currentCommunicationPoint=i * STEP, communicationStepSize=STEP)
    assert refused.value.status == 2  # fmi2Discard
    messages = " ".join(log.messages())
    assert "refused" in messages and "dead volume 0.005 m3" in messages
    (volume,) = fmu.getReal([loaded.vr("gas.volume")])
    assert 0.005 < volume  # the state of the last accepted step, never negative
    fmu.terminate()
    fmu.freeInstance()


def test_libcosimpy_steps_the_hydraulics(hydraulics_fmu):
    """A master we did not write runs our FMU unchanged and gets the core's numbers."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_step_size(step_size=int(STEP * 1e9))
    slave = CosimLocalSlave(fmu_path=str(hydraulics_fmu.path), instance_name="hyd")
    index = execution.add_local_slave(local_slave=slave)
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    effects = "polytropic_gas,line_losses,seal_friction"
    assert execution.string_initial_value(index, refs["effects"], effects)
    assert execution.boolean_initial_value(index, refs["initial_equilibrium"], False)
    assert execution.real_initial_value(index, refs["initial_gas_pressure"], 1.45e7)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    assert execution.simulate_until(target_time=int(0.5e9))
    got = observer.last_real_values(index, [refs[n] for n in WATCH])

    unit = make_unit(effects, initial_equilibrium=False, initial_gas_pressure=1.45e7)
    for i in range(50):
        assert unit.advance(i * STEP, STEP).success
    expected = [unit.values[n] for n in WATCH]
    balance = WATCH.index("energy_balance")  # a small difference of MJ-sized energies
    assert got[balance] == pytest.approx(expected.pop(balance), abs=1e-6)
    got.pop(balance)
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-9)
    assert got[0] != pytest.approx(1.905, abs=1e-6)  # it moved: released off equilibrium
