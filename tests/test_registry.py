"""One registry of unit types: every entry builds, validates, round-trips its state and can be
solved monolithically; every reader of unit types reads it."""

from __future__ import annotations

import importlib.util
import zipfile
from pathlib import Path

import pytest
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from wire_fmu.core.framework.unit import Causality, Unit
from wire_fmu.export.builder import build_fmu
from wire_fmu.master import catalog
from wire_fmu.registry import BY_NAME, MODELS_DIR, UNIT_TYPES, unit_type
from wire_fmu.study import monolithic

ROOT = Path(__file__).resolve().parents[1]
START = {"Hydraulics": {"rod.force": -1.424e6}}  # a load the default accumulator can carry


def test_the_catalogue_and_the_monolithic_reference_read_the_registry():
    assert list(catalog.OUR_FMUS) == [u.name for u in UNIT_TYPES]
    assert list(monolithic.CORE_UNITS) == [u.name for u in UNIT_TYPES]
    for u in UNIT_TYPES:
        assert catalog.OUR_FMUS[u.name] == u.facade and monolithic.CORE_UNITS[u.name] == u.core


def test_every_facade_script_in_models_is_registered_and_names_its_core_class():
    assert sorted(p.name for p in MODELS_DIR.glob("*.py") if not p.name.startswith("_")) == sorted(
        u.facade for u in UNIT_TYPES
    )
    for u in UNIT_TYPES:
        spec = importlib.util.spec_from_file_location(f"_registry_check_{u.name}", u.facade_path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        facades = [
            obj
            for obj in vars(module).values()
            if isinstance(obj, type)
            and getattr(obj, "unit_class", None) is not None
            and obj.__module__ == module.__name__
        ]
        assert [f.unit_class for f in facades] == [u.core_class()], u.name
        assert u.core_class().NAME == u.name


def test_an_unknown_unit_type_is_named_with_the_known_ones():
    with pytest.raises(KeyError, match="BlockTrain"):
        unit_type("Crane")
    assert unit_type("Winch") is BY_NAME["Winch"]


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("registry")
    return {u.name: build_fmu(u.facade_path, out) for u in UNIT_TYPES}


@pytest.mark.integration
@pytest.mark.parametrize("name", [u.name for u in UNIT_TYPES])
def test_every_registered_unit_builds_validates_and_round_trips_its_state(built, tmp_path, name):
    fmu = built[name]
    assert fmu.name == f"{name}.fmu"
    assert validate_fmu(str(fmu)) == []
    from fmpy import extract, read_model_description

    md = read_model_description(str(fmu))
    outputs = [
        v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"
    ]
    folder = extract(str(fmu), unzipdir=str(tmp_path / name))
    slave = FMU2Slave(
        guid=md.guid,
        unzipDirectory=folder,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    slave.instantiate()
    for key, value in START.get(name, {}).items():
        slave.setReal([next(v.valueReference for v in md.modelVariables if v.name == key)], [value])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    timing = next(v for v in md.modelVariables if v.name == "physics_seconds")
    assert (timing.causality, timing.unit) == ("local", "s")
    assert slave.getReal([timing.valueReference]) == [0.0]
    slave.doStep(0.0, 0.01)
    assert slave.getReal([timing.valueReference])[0] > 0.0  # the step's physics, timed
    state = slave.getFMUstate()
    saved = slave.getReal(outputs)
    slave.doStep(0.01, 0.01)
    slave.setFMUstate(slave.deSerializeFMUstate(slave.serializeFMUstate(state)))
    assert slave.getReal(outputs) == saved  # bit for bit
    slave.freeFMUstate(state)
    slave.terminate()
    slave.freeInstance()
    with zipfile.ZipFile(fmu) as archive:
        assert f"binaries/linux64/{name}.so" in archive.namelist()


@pytest.mark.parametrize("name", [u.name for u in UNIT_TYPES])
def test_every_registered_unit_offers_its_dynamics_to_the_monolithic_reference(name):
    cls = unit_type(name).core_class()
    assert issubclass(cls, Unit)
    assert cls.ode is not Unit.ode, f"{name} cannot be part of the monolithic reference"
    assert any(v.causality is Causality.output for v in cls.VARIABLES)


def test_build_fmus_refuses_a_facade_script_the_registry_does_not_list():
    spec = importlib.util.spec_from_file_location("_build_fmus", ROOT / "build_fmus.py")
    build_fmus = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(build_fmus)
    scripts = [u.facade_path for u in UNIT_TYPES]
    assert build_fmus.unregistered(scripts) == []
    (problem,) = build_fmus.unregistered([*scripts, MODELS_DIR / "crane.py"])
    assert "crane.py" in problem and "wire_fmu.registry" in problem
