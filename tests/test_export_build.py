"""Export layer without building FMUs: model description, builder checks, core-version guard.

The model description the facade writes, as the builder patches it (units,
dependencies, initial unknowns); the builder's checks that stop before
pythonfmu; the fingerprint of the bundled core and the guard that refuses an
FMU built from another one. Against the test oscillator of ``tests/support``,
as in ``test_export``.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

from wire_fmu._fingerprint import bundled_files, fingerprint
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import output
from wire_fmu.export.builder import BuildError, build_fmu, unique_module_name
from wire_fmu.export.facade import CoreFacade
from wire_fmu.export.guard import (
    BUILD_INFO_FILE,
    BuildInfo,
    CoreVersionError,
    check_core,
    imported_core,
)
from wire_fmu.export.model_description import patch_model_description
from wire_fmu.export.units import UNITS

from .export_helpers import SUPPORT, Oscillator, OscillatorUnit


# -- model description ------------------------------------------------------------
def patched(facade_class=Oscillator) -> ET.Element:
    facade = facade_class(instance_name="xml", resources=None)
    raw = ET.tostring(facade.to_xml(), encoding="UTF-8")
    return ET.fromstring(patch_model_description(raw, facade_class.unit_class, "test"))


def test_every_real_has_a_defined_unit_and_every_variable_a_description():
    root = patched()
    defined = {u.get("name"): u.find("BaseUnit").attrib for u in root.iter("Unit")}
    assert defined["N.s/m"] == {"kg": "1", "s": "-1"}
    for node in root.find("ModelVariables"):
        assert node.get("description")
        real = node.find("Real")
        if real is not None:
            assert real.get("unit") in defined
    stiffness = root.find("ModelVariables/ScalarVariable[@name='stiffness']/Real")
    assert float(stiffness.get("start")) == 4 * math.pi**2  # round-trips
    assert stiffness.get("min") == "0.0"


def test_outputs_declare_their_direct_dependencies():
    root = patched()
    index = {n.get("name"): str(i + 1) for i, n in enumerate(root.find("ModelVariables"))}
    outputs = {u.get("index"): u.attrib for u in root.find("ModelStructure/Outputs")}
    assert outputs[index["position"]] == {"index": index["position"], "dependencies": ""}
    assert outputs[index["acceleration"]]["dependencies"] == index["force"]
    assert outputs[index["acceleration"]]["dependenciesKind"] == "dependent"


def test_initial_unknowns_list_every_output_with_known_dependencies():
    root = patched()
    nodes = list(root.find("ModelVariables"))
    outputs = [str(i + 1) for i, n in enumerate(nodes) if n.get("causality") == "output"]
    knowns = {
        str(i + 1) for i, n in enumerate(nodes) if n.get("causality") in ("parameter", "input")
    }
    unknowns = list(root.find("ModelStructure/InitialUnknowns"))
    assert [u.get("index") for u in unknowns] == outputs
    for unknown in unknowns:
        assert set(unknown.get("dependencies").split()) == knowns


def test_initial_dependencies_can_be_narrowed_by_the_unit():
    class Narrow(OscillatorUnit):
        INITIAL_DEPENDS_ON = {"position": ()}

    class NarrowFacade(CoreFacade):
        unit_class = Narrow

    root = patched(NarrowFacade)
    names = [n.get("name") for n in root.find("ModelVariables")]
    position = next(
        u
        for u in root.find("ModelStructure/InitialUnknowns")
        if names[int(u.get("index")) - 1] == "position"
    )
    assert str(names.index("force") + 1) not in position.get("dependencies").split()


def test_unknown_unit_is_an_error_naming_the_variable():
    class Odd(OscillatorUnit):
        NAME = "Odd"
        VARIABLES = (*OscillatorUnit.VARIABLES, output("reach", "furlong", "Reach"))

    class OddFacade(CoreFacade):
        unit_class = Odd

    with pytest.raises(ConfigurationError, match=r"Odd\.reach: unit 'furlong'"):
        patched(OddFacade)


def test_unit_table_is_dimensionally_consistent():
    def dims(name):
        return {k: v for k, v in UNITS[name].exponents.items() if v}

    assert dims("J") == dims("N.m") == {"kg": 1, "m": 2, "s": -2}
    assert dims("W") == {"kg": 1, "m": 2, "s": -3}
    assert dims("Pa") == dims("bar") and UNITS["bar"].factor == 1e5
    assert dims("N.s/m") == {"kg": 1, "s": -1}


# -- builder checks that stop before pythonfmu --------------------------------------
FACADE_HEADER = "from wire_fmu.export.facade import CoreFacade\n"
UNIT_IMPORT = "from wire_fmu_test_units import OscillatorUnit\n"


def test_script_without_a_facade_class_is_rejected_by_name(tmp_path):
    script = tmp_path / "empty_model.py"
    script.write_text(FACADE_HEADER)
    with pytest.raises(BuildError, match=r"(?s)empty_model\.py.*exactly one CoreFacade subclass"):
        build_fmu(script, tmp_path / "out")


def test_script_with_two_facade_classes_is_rejected(tmp_path):
    script = tmp_path / "twice.py"
    body = "class A(CoreFacade):\n    unit_class = OscillatorUnit\n\n\nclass B(A):\n    pass\n"
    script.write_text(FACADE_HEADER + UNIT_IMPORT + body)
    with pytest.raises(BuildError, match=r"(?s)twice\.py.*\['A', 'B'\]"):
        build_fmu(script, tmp_path / "out")


def test_build_refuses_sources_changed_since_they_were_loaded(tmp_path, monkeypatch):
    import wire_fmu.export.builder as builder

    version, _, root = imported_core()
    monkeypatch.setattr(builder, "imported_core", lambda: (version, "e" * 64, root))
    with pytest.raises(BuildError, match="changed after this process loaded them"):
        build_fmu(SUPPORT / "facades" / "oscillator.py", tmp_path)


def test_module_name_is_unique_per_script_and_core(tmp_path):
    script = tmp_path / "block train.py"
    script.write_text("# one\n")
    first = unique_module_name(script, "core-a")
    assert first.startswith("wire_fmu_block_train_") and first.isidentifier()
    assert unique_module_name(script, "core-b") != first
    script.write_text("# two\n")
    assert unique_module_name(script, "core-a") != first


# -- fingerprint and core-version guard ---------------------------------------------
def test_fingerprint_covers_sources_only(tmp_path):
    root = tmp_path / "wire_fmu"
    for name in ("__init__.py", "core/a.py", "master/m.py", "cli.py", "core/__pycache__/a.pyc"):
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(name)
    assert [p.as_posix() for p in bundled_files(root)] == ["__init__.py", "core/a.py"]
    before = fingerprint(root)
    (root / "master" / "m.py").write_text("changed")
    (root / "core" / "b.swp").write_text("editor")
    assert fingerprint(root) == before
    (root / "core" / "a.py").write_text("changed")
    assert fingerprint(root) != before


def write_record(folder: Path, fingerprint_: str) -> None:
    version, _, _ = imported_core()
    BuildInfo("Oscillator", "wire_fmu_oscillator_0", version, fingerprint_).write(
        folder / BUILD_INFO_FILE
    )


def test_guard_accepts_the_imported_core(tmp_path):
    write_record(tmp_path, imported_core()[1])
    check_core(tmp_path, "Oscillator", "osc")


def test_guard_names_fmu_versions_paths_and_remedy(tmp_path):
    write_record(tmp_path, "f" * 64)
    with pytest.raises(CoreVersionError) as caught:
        check_core(tmp_path, "Oscillator", "osc")
    text = str(caught.value)
    for part in ("'Oscillator'", "'osc'", "ffffffffffff", imported_core()[1][:12]):
        assert part in text
    assert str(imported_core()[2]) in text and str(tmp_path / "wire_fmu") in text
    assert "Rebuild all FMUs" in text and "separate processes" in text


def test_guard_refuses_an_fmu_without_build_record(tmp_path):
    with pytest.raises(CoreVersionError, match="not built with wire_fmu.export.builder"):
        check_core(tmp_path, "Oscillator", "osc")


def test_instantiation_fails_on_core_mismatch(tmp_path, caplog):
    write_record(tmp_path, "0" * 64)
    with caplog.at_level(logging.ERROR), pytest.raises(CoreVersionError):
        Oscillator(instance_name="osc", resources=str(tmp_path))
    assert any("was built with wire_fmu" in r.getMessage() for r in caplog.records)


# -- an FMU replaced whole ------------------------------------------------------------
def test_a_build_that_fails_leaves_the_fmu_before_it_and_nothing_else(tmp_path, monkeypatch):
    import wire_fmu.export.builder as builder

    fmu = build_fmu(SUPPORT / "facades" / "oscillator.py", tmp_path)
    before = fmu.read_bytes()

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(builder, "_finish", broken)
    with pytest.raises(OSError, match="disk full"):
        build_fmu(SUPPORT / "facades" / "oscillator.py", tmp_path)
    assert fmu.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [fmu.name]


@pytest.mark.integration
def test_two_builds_into_one_folder_at_once_leave_one_whole_fmu(tmp_path):
    import subprocess
    import sys
    import zipfile

    code = (
        "import sys; from pathlib import Path; sys.path.insert(0, sys.argv[3]); "
        "from wire_fmu.export.builder import build_fmu; "
        "build_fmu(Path(sys.argv[1]), Path(sys.argv[2]), extra_modules=[Path(sys.argv[4])])"
    )
    script, out = SUPPORT / "facades" / "oscillator.py", tmp_path / "out"
    units = SUPPORT / "wire_fmu_test_units.py"
    arguments = [str(script), str(out), str(SUPPORT), str(units)]
    builds = [subprocess.Popen([sys.executable, "-c", code, *arguments]) for _ in range(2)]
    assert [b.wait(timeout=300) for b in builds] == [0, 0]
    (fmu,) = out.iterdir()  # no partial file left beside it
    with zipfile.ZipFile(fmu) as archive:
        assert archive.testzip() is None
        assert "modelDescription.xml" in archive.namelist()


def test_a_rewrite_of_an_archive_that_fails_leaves_it_as_it_was(tmp_path):
    import zipfile

    from wire_fmu.export.fmu_archive import rewrite_zip

    archive = tmp_path / "unit.fmu"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("modelDescription.xml", b"<fmiModelDescription/>")
    before = archive.read_bytes()
    with pytest.raises(TypeError):
        rewrite_zip(archive, {"resources/a.txt": b"a", "resources/b.txt": object()})
    assert archive.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["unit.fmu"]
    rewrite_zip(archive, {"resources/a.txt": b"a"})
    with zipfile.ZipFile(archive) as zf:
        assert zf.read("resources/a.txt") == b"a" and zf.testzip() is None
    assert [p.name for p in tmp_path.iterdir()] == ["unit.fmu"]
