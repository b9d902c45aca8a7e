"""Hostile FMI call sequences against our built FMUs, through fmpy.

Each case asserts the status the FMU answers (an invalid call is fmi2Error,
never fmi2Fatal or a crash; a step the unit cannot take is fmi2Discard), that
the logged reason names what was wrong, and that the instance stays usable:
after a refused call it still steps, or rolls back to a saved state.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent / "support"))

from fmi_test_tools import FmiLog, LoadedFmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import fmi2LastSuccessfulTime, fmi2Terminated  # noqa: E402

from wire_fmu.export.builder import build_fmu  # noqa: E402

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[1]
OK, DISCARD, ERROR, FATAL = 0, 2, 3, 4
RISER_LOAD = -1.424e6  # N on the rod: the shipped riser tensioner's start


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> dict[str, LoadedFmu]:
    out = tmp_path_factory.mktemp("hostile_fmi")
    return {
        name: LoadedFmu(build_fmu(ROOT / "models" / f"{name}.py", out))
        for name in ("hydraulics", "block_train", "winch")
    }


@pytest.fixture
def log() -> FmiLog:
    yield FmiLog()
    FmiLog.restore()


def _started(fmu: LoadedFmu, log: FmiLog, name: str = "u"):
    reals = {"rod.force": RISER_LOAD} if "rod.force" in _names(fmu) else {}
    return fmu.start(name, log, reals)


def _names(fmu: LoadedFmu) -> set[str]:
    return {v.name for v in fmu.model_description.modelVariables}


def _first_output(fmu: LoadedFmu) -> int:
    return next(
        v.valueReference
        for v in fmu.model_description.modelVariables
        if v.causality == "output" and v.type == "Real"
    )


def _status(call) -> int:
    try:
        call()
    except FMICallException as exc:
        return exc.status
    return OK


def _refused(log: FmiLog, call, *words: str, status: int = ERROR) -> str:
    log.records.clear()
    assert _status(call) == status
    said = " ".join(log.messages(status))
    for word in words:
        assert word in said, f"{word!r} not in {said!r}"
    assert not log.messages(FATAL)
    return said


UNITS = ("hydraulics", "block_train", "winch")


@pytest.mark.parametrize("unit", UNITS)
@pytest.mark.parametrize("step", [-0.5, 0.0, math.nan, math.inf, -math.inf])
def test_a_step_that_is_not_finite_and_positive_is_an_error(built, log, unit, step):
    fmu = _started(built[unit], log)
    _refused(log, lambda: fmu.doStep(0.0, step), "communication step", "finite and positive")
    fmu.doStep(0.0, 0.01)  # the clock did not move: the next step starts at 0
    fmu.doStep(0.01, 0.01)
    fmu.freeInstance()


@pytest.mark.parametrize("unit", UNITS)
@pytest.mark.parametrize("start", [0.5, -0.5, math.nan, 1e-3])
def test_a_step_that_does_not_start_at_the_units_time_is_an_error(built, log, unit, start):
    fmu = _started(built[unit], log)
    _refused(log, lambda: fmu.doStep(start, 0.01), "communication point", "t = 0.0 s")
    fmu.doStep(0.0, 0.01)
    fmu.freeInstance()


@pytest.mark.parametrize("unit", ["hydraulics", "block_train"])
def test_a_step_too_long_to_take_is_refused_at_once_and_the_unit_goes_on(built, log, unit):
    """A million seconds: the winch at rest takes it in one adaptive step; these two would
    need 1e9 internal steps and refuse it before starting (they used to run for hours)."""
    fmu = _started(built[unit], log)
    said = _refused(log, lambda: fmu.doStep(0.0, 1e6), "refused", status=DISCARD)
    assert "internal steps" in said and "take communication steps of at most" in said
    assert fmu.getBooleanStatus(fmi2Terminated)  # a plain master must stop here
    assert fmu.getRealStatus(fmi2LastSuccessfulTime) == 0.0
    fmu.doStep(0.0, 0.01)  # ... or retry shorter
    assert not fmu.getBooleanStatus(fmi2Terminated)
    fmu.freeInstance()


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_a_non_finite_input_is_refused_and_the_instance_reads_and_steps(built, log, value):
    fmu = built["hydraulics"]
    instance = _started(fmu, log)
    before = instance.getReal([_first_output(fmu)])
    _refused(
        log, lambda: instance.setReal([fmu.vr("rod.force")], [value]), "rod.force", "must be finite"
    )
    assert instance.getReal([_first_output(fmu)]) == before
    instance.doStep(0.0, 0.01)
    instance.freeInstance()


def test_a_non_finite_parameter_is_refused(built, log):
    fmu = built["hydraulics"]
    instance = fmu.instantiate("p", log)
    _refused(log, lambda: instance.setReal([fmu.vr("moving_mass")], [math.nan]), "moving_mass")
    instance.freeInstance()


@pytest.mark.parametrize("unit", UNITS)
def test_calls_out_of_order_are_errors_naming_the_phase(built, log, unit):
    fmu = built[unit]
    instance = fmu.instantiate("order", log)
    _refused(log, lambda: instance.doStep(0.0, 0.01), "fmi2DoStep", "instantiated")
    _refused(log, instance.exitInitializationMode, "fmi2ExitInitializationMode")
    instance.setupExperiment(startTime=0.0)
    instance.enterInitializationMode()
    _refused(log, instance.enterInitializationMode, "fmi2EnterInitializationMode")
    instance.exitInitializationMode()
    instance.doStep(0.0, 0.01)
    instance.freeInstance()


def test_an_unknown_value_reference_is_an_error_and_the_instance_lives_on(built, log):
    fmu = built["block_train"]
    instance = _started(fmu, log)
    unknown = "no variable has value reference 987654 or 4294967295; the unit's value references"
    said = _refused(log, lambda: instance.getReal([987654, 0, 2**32 - 1]), "fmi2GetReal", unknown)
    assert "unexpectedly" not in said
    said = _refused(log, lambda: instance.setReal([987654], [1.0]), "fmi2SetReal", "987654")
    assert "unexpectedly" not in said
    instance.doStep(0.0, 0.01)
    instance.freeInstance()


@pytest.mark.parametrize("unit", UNITS)
def test_a_get_before_initialisation_is_an_error_and_initialisation_goes_on(built, log, unit):
    fmu = built[unit]
    instance = fmu.instantiate("early", log)
    said = _refused(
        log, lambda: instance.getReal([_first_output(fmu)]), "fmi2GetReal", "'instantiated'"
    )
    assert "have values from fmi2EnterInitializationMode on" in said
    instance.setupExperiment(startTime=0.0)
    instance.enterInitializationMode()
    instance.getReal([_first_output(fmu)])
    instance.freeInstance()


def test_a_value_of_the_wrong_type_is_an_error(built, log):
    fmu = built["block_train"]
    instance = _started(fmu, log)
    real = _first_output(fmu)
    for call, name, kind in [
        (lambda: instance.getString([real]), "fmi2GetString", "String"),
        (lambda: instance.setBoolean([real], [True]), "fmi2SetBoolean", "Boolean"),
        (lambda: instance.getInteger([real]), "fmi2GetInteger", "Integer"),
    ]:
        said = _refused(log, call, name, f"value reference {real} is the Real variable")
        assert f"not a {kind}" in said or f"not an {kind}" in said
    instance.doStep(0.0, 0.01)
    instance.freeInstance()


def test_setting_an_output_is_an_error(built, log):
    fmu = built["hydraulics"]
    instance = _started(fmu, log)
    _refused(
        log,
        lambda: instance.setReal([fmu.vr("rod.position")], [1.0]),
        "rod.position",
        "cannot be set",
    )
    instance.freeInstance()


def test_a_fixed_parameter_after_initialisation_is_an_error(built, log):
    fmu = built["hydraulics"]
    instance = _started(fmu, log)
    _refused(log, lambda: instance.setReal([fmu.vr("moving_mass")], [1.0]), "moving_mass")
    instance.doStep(0.0, 0.01)
    instance.freeInstance()


def test_a_state_of_another_unit_type_is_refused(built, log):
    hydraulics = _started(built["hydraulics"], log, "h")
    rope = _started(built["block_train"], log, "r")
    state = rope.getFMUstate()
    _refused(log, lambda: hydraulics.setFMUstate(state), "fmi2SetFMUstate", "BlockTrain")
    hydraulics.doStep(0.0, 0.01)
    rope.freeFMUstate(state)
    for instance in (hydraulics, rope):
        instance.freeInstance()


def test_garbage_bytes_as_a_state_are_refused_when_set(built, log):
    fmu = built["winch"]
    instance = _started(fmu, log)
    state = instance.deSerializeFMUstate(b"\xff\x00 not a state")
    _refused(log, lambda: instance.setFMUstate(state), "fmi2SetFMUstate", "not an FMU state")
    instance.freeFMUstate(state)
    instance.doStep(0.0, 0.01)
    instance.freeInstance()


def test_rollback_after_an_error_restores_the_saved_state_exactly(built, log):
    fmu = built["hydraulics"]
    instance = _started(fmu, log)
    outputs = [
        v.valueReference
        for v in fmu.model_description.modelVariables
        if v.causality == "output" and v.type == "Real"
    ]
    instance.doStep(0.0, 0.01)
    saved, at_save = instance.getFMUstate(), instance.getReal(outputs)
    instance.doStep(0.01, 0.01)
    _refused(log, lambda: instance.doStep(0.0, 0.01), "communication point")
    instance.setFMUstate(saved)
    assert instance.getReal(outputs) == at_save
    instance.doStep(0.01, 0.01)  # the restored clock: 0.01 s
    serialised = instance.serializeFMUstate(saved)
    restored = instance.deSerializeFMUstate(serialised)
    instance.setFMUstate(restored)
    assert instance.getReal(outputs) == at_save
    for state in (saved, restored):
        instance.freeFMUstate(state)
    instance.freeInstance()


def test_unsupported_functions_are_errors_not_crashes(built, log):
    fmu = built["block_train"]
    instance = _started(fmu, log)
    vr = _first_output(fmu)
    _refused(
        log, lambda: instance.setRealInputDerivatives([vr], [1], [0.0]), "canInterpolateInputs"
    )
    _refused(log, lambda: instance.getRealOutputDerivatives([vr], [1]), "OutputDerivatives")
    _refused(log, instance.cancelStep, "fmi2CancelStep")
    instance.freeInstance()


def test_reset_gives_a_fresh_instance(built, log):
    fmu = built["hydraulics"]
    instance = _started(fmu, log)
    instance.doStep(0.0, 0.01)
    instance.reset()
    instance.setReal([fmu.vr("rod.force")], [RISER_LOAD])
    instance.setupExperiment(startTime=0.0)
    instance.enterInitializationMode()
    instance.exitInitializationMode()
    instance.doStep(0.0, 0.01)  # the clock starts again at 0
    instance.freeInstance()


def test_a_wrong_guid_or_model_exchange_is_refused_at_instantiation(built, log):
    import ctypes

    from fmpy.fmi2 import FMU2Slave

    fmu = built["winch"]
    md = fmu.model_description
    resources = (Path(fmu.unzipdir) / "resources").as_uri().encode()
    slave = FMU2Slave(
        guid=md.guid,
        unzipDirectory=fmu.unzipdir,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="g",
    )
    for guid, kind, words in (
        (b"{not-the-guid}", 1, "GUID"),
        (md.guid.encode(), 0, "co-simulation"),
    ):
        log.records.clear()
        handle = slave.fmi2Instantiate(
            b"g", kind, guid, resources, ctypes.byref(log.callbacks), 0, 1
        )
        assert not handle
        assert words in " ".join(m for _, _, m in log.records)
    slave.freeLibrary()


def test_freeing_without_terminate_and_many_instances_in_one_process(built, log):
    fmu = built["block_train"]
    for n in range(30):
        instance = _started(fmu, log, f"many{n}")
        instance.doStep(0.0, 0.01)
        if n % 3 == 0:
            _status(lambda inst=instance: inst.doStep(5.0, 0.01))  # an error on the way
        instance.freeInstance()


def test_setup_experiment_after_initialisation_is_an_error(built, log):
    fmu = built["winch"]
    instance = _started(fmu, log)
    _refused(log, lambda: instance.setupExperiment(startTime=5.0), "fmi2SetupExperiment")
    instance.doStep(0.0, 0.01)
    instance.freeInstance()


def test_a_state_with_a_time_that_is_not_finite_is_refused(built, log):
    """Such a state was accepted, and every step after it passed the time check (NaN)."""
    import json

    fmu = built["winch"]
    instance = _started(fmu, log)
    state = instance.getFMUstate()
    data = json.loads(bytes(instance.serializeFMUstate(state)).decode())
    data["time"] = float("nan")
    bad = instance.deSerializeFMUstate(json.dumps(data).encode())
    _refused(log, lambda: instance.setFMUstate(bad), "fmi2SetFMUstate", "not finite")
    _refused(log, lambda: instance.doStep(7.0, 0.01), "communication point")
    for s in (state, bad):
        instance.freeFMUstate(s)
    instance.freeInstance()
