"""Checks shared by the integration tests of our FMUs: built, run in fmpy and in libcosimpy.

Each helper asserts what every one of our FMUs must do (a complete model
description, a state that restores bit for bit, a foreign master that runs
it); the tests call them with their unit's inputs and add what is specific.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from fmi_test_tools import FmiLog, LoadedFmu  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from wire_fmu.export.builder import build_fmu  # noqa: E402

__all__ = [
    "FmiLog",
    "LoadedFmu",
    "built_fmu",
    "start_fmu",
    "output_dependencies",
    "assert_state_restores_bit_for_bit",
    "libcosim_last_values",
]

ROOT = Path(__file__).resolve().parents[1]


def built_fmu(model: str, tmp_path_factory) -> LoadedFmu:
    """``models/<model>.py`` built into a fresh folder and loaded with fmpy."""
    path = build_fmu(ROOT / "models" / f"{model}.py", tmp_path_factory.mktemp("fmu"))
    return LoadedFmu(path)


def start_fmu(loaded: LoadedFmu, name: str, log: FmiLog, effects: str):
    """An instance with ``effects``, initialised at t = 0 and ready to step."""
    fmu = loaded.instantiate(name, log)
    fmu.setString([loaded.vr("effects")], [effects])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu


def output_dependencies(loaded: LoadedFmu) -> dict[str, list[str]]:
    """Each output's declared dependencies, once fmpy validated the model description
    and it says the FMU can get, set and serialize its state."""
    assert validate_fmu(str(loaded.path)) == []
    md = loaded.model_description
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    return {o.variable.name: [d.name for d in o.dependencies] for o in md.outputs}


def assert_state_restores_bit_for_bit(
    loaded: LoadedFmu,
    effects: str,
    name: str,
    run_up: Callable[[Any], Any],
    run_on: Callable[[Any, Any], Sequence],
) -> Sequence:
    """Save a state, step on, restore it and step again; a second instance from the
    serialized state steps the same: all three bit for bit.

    ``run_up(fmu)`` steps an instance to the state to save and returns what
    ``run_on(fmu, that)`` needs to step on from there; ``run_on`` returns the
    rows compared. Returns the rows of the first run on.
    """
    log = FmiLog()
    fmu = start_fmu(loaded, name, log, effects)
    reached = run_up(fmu)
    state = fmu.getFMUstate()
    serialized = fmu.serializeFMUstate(state)
    first = run_on(fmu, reached)
    fmu.setFMUstate(state)
    again = run_on(fmu, reached)
    assert again == first
    other = start_fmu(loaded, f"{name}2", log, effects)
    other.setFMUstate(other.deSerializeFMUstate(serialized))
    copied = run_on(other, reached)
    assert copied == first
    fmu.freeFMUstate(state)
    for f in (fmu, other):
        f.terminate()
        f.freeInstance()
    return first


def libcosim_last_values(
    path: Path,
    instance: str,
    initial: Mapping[str, str | bool | float],
    watch: Sequence[str],
    step: float,
    stop_time: float,
) -> list[float]:
    """Run an FMU alone in libcosimpy (a master we did not write) from ``initial`` values
    (each accepted) and return the ``watch`` variables at ``stop_time`` (s)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_step_size(step_size=int(step * 1e9))
    slave = CosimLocalSlave(fmu_path=str(path), instance_name=instance)
    index = execution.add_local_slave(local_slave=slave)
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    for name, value in initial.items():
        if isinstance(value, str):
            assert execution.string_initial_value(index, refs[name], value)
        elif isinstance(value, bool):
            assert execution.boolean_initial_value(index, refs[name], value)
        else:
            assert execution.real_initial_value(index, refs[name], value)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    assert execution.simulate_until(target_time=int(stop_time * 1e9))
    return observer.last_real_values(index, [refs[n] for n in watch])
