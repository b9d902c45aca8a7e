"""An FMU configured by its start values (:mod:`wire_fmu.export.start_values`).

What an SSP package carries for each unit, so that a host that applies no parameter
binding or sets no String (FMPy's SSP runner) runs the unit as the scene set it: the
model description says the values, the facade sets them at instantiation, the GUID is
its own. Errors name every bad value at once.
"""

from __future__ import annotations

import json
import logging
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

from wire_fmu.export.fmu_archive import FACADE_FILE, MODEL_DESCRIPTION
from wire_fmu.export.guard import imported_core
from wire_fmu.export.start_values import (
    START_VALUES_FILE,
    StartValuesError,
    read_start_values,
    write_configured_fmu,
)

from .export_helpers import Oscillator
from .interop_helpers import build_test_fmus
from .test_export_build import write_record

VALUES = {"mass": 2.5, "label": 'a <label> & "text"', "substeps": 7, "flag": True}


@pytest.fixture(scope="module")
def oscillator(tmp_path_factory) -> Path:
    return build_test_fmus(tmp_path_factory.mktemp("fmus"))["osc"]


def _description(fmu: Path) -> ET.Element:
    with zipfile.ZipFile(fmu) as archive:
        return ET.fromstring(archive.read(MODEL_DESCRIPTION))


def _starts(root: ET.Element) -> dict[str, str]:
    return {v.get("name"): v[0].get("start") for v in root.iter("ScalarVariable")}


def test_the_model_description_states_the_values_and_a_guid_of_its_own(oscillator, tmp_path):
    configured = write_configured_fmu(oscillator, VALUES, tmp_path / "osc.fmu")
    before, after = _description(oscillator), _description(configured)
    starts = _starts(after)
    assert starts["mass"] == "2.5" and starts["substeps"] == "7" and starts["flag"] == "true"
    assert starts["label"] == VALUES["label"]
    unchanged = set(_starts(before)) - set(VALUES)
    assert all(_starts(before)[n] == starts[n] for n in unchanged)
    assert after.get("guid") != before.get("guid")
    with zipfile.ZipFile(configured) as archive:
        assert archive.read(FACADE_FILE).decode().splitlines()[2] == after.get("guid")
        assert json.loads(archive.read(f"resources/{START_VALUES_FILE}")) == VALUES
    again = write_configured_fmu(oscillator, VALUES, tmp_path / "again.fmu")
    assert _description(again).get("guid") == after.get("guid")  # same values, same GUID
    other = write_configured_fmu(oscillator, {"mass": 3.0}, tmp_path / "other.fmu")
    assert _description(other).get("guid") not in (after.get("guid"), before.get("guid"))


def test_a_configured_fmu_passes_fmpys_validation_and_starts_with_its_values(oscillator, tmp_path):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.validation import validate_fmu

    configured = write_configured_fmu(oscillator, VALUES, tmp_path / "osc.fmu")
    assert validate_fmu(str(configured)) == []
    model = read_model_description(str(configured))
    refs = {v.name: v.valueReference for v in model.modelVariables}
    slave = FMU2Slave(
        guid=model.guid,
        unzipDirectory=extract(str(configured)),
        modelIdentifier=model.coSimulation.modelIdentifier,
        instanceName="osc",
    )
    slave.instantiate()
    try:
        assert slave.getReal([refs["mass"]]) == [2.5]
        assert slave.getInteger([refs["substeps"]]) == [7]
        assert slave.getBoolean([refs["flag"]]) == [True]
        assert slave.getString([refs["label"]])[0].decode() == VALUES["label"]
        slave.setReal([refs["mass"]], [4.0])  # a host may still set another value
        assert slave.getReal([refs["mass"]]) == [4.0]
    finally:
        slave.freeInstance()


def test_no_values_copy_the_fmu_as_it_is(oscillator, tmp_path):
    copy = write_configured_fmu(oscillator, {}, tmp_path / "osc.fmu")
    assert copy.read_bytes() == oscillator.read_bytes()


def test_values_that_are_no_parameter_or_of_the_wrong_type_are_refused_naming_each(
    oscillator, tmp_path
):
    bad = {"nope": 1.0, "position": 0.0, "label": 3.0, "mass": "heavy"}
    with pytest.raises(StartValuesError) as caught:
        write_configured_fmu(oscillator, bad, tmp_path / "osc.fmu")
    problems = caught.value.problems
    assert len(problems) == 4
    for name, words in (
        ("nope", "no such variable"),
        ("position", "output"),
        ("label", "String"),
        ("mass", "Real"),
    ):
        assert any(p.startswith(repr(name)) and words in p for p in problems), (name, problems)
    assert not (tmp_path / "osc.fmu").exists()


def _resources(tmp_path: Path, values: object) -> Path:
    write_record(tmp_path, imported_core()[1])
    (tmp_path / START_VALUES_FILE).write_text(json.dumps(values))
    return tmp_path


def test_the_facade_sets_the_values_as_a_host_would_before_initialisation(tmp_path):
    facade = Oscillator(instance_name="osc", resources=str(_resources(tmp_path, VALUES)))
    assert {name: facade.unit.values[name] for name in VALUES} == VALUES


def test_the_facade_refuses_a_start_values_file_naming_every_problem(tmp_path, caplog):
    values = {"nope": 1.0, "velocity": 0.0, "label": 2, "x0": float("nan")}
    with caplog.at_level(logging.ERROR), pytest.raises(StartValuesError) as caught:
        Oscillator(instance_name="osc", resources=str(_resources(tmp_path, values)))
    text = str(caught.value)
    assert "Oscillator 'osc'" in text and START_VALUES_FILE in text
    assert len(caught.value.problems) == 4
    assert "'nope'" in text and "'velocity'" in text and "expected a str" in text
    assert "'x0' = nan: must be finite" in text
    assert any("'nope'" in r.getMessage() for r in caplog.records)


def test_an_unreadable_start_values_file_is_named(tmp_path):
    (tmp_path / START_VALUES_FILE).write_text("{not json")
    with pytest.raises(StartValuesError, match="cannot be read as JSON"):
        read_start_values(tmp_path)
    (tmp_path / START_VALUES_FILE).write_text('{"mass": [1, 2], "x0": null}')
    with pytest.raises(StartValuesError) as caught:
        read_start_values(tmp_path)
    assert len(caught.value.problems) == 2
    assert read_start_values(tmp_path / "missing") == {}
