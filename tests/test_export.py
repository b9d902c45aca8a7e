"""Export layer without building FMUs: facade, FMU state, model description, guard.

The facade is driven the way pythonfmu's C++ layer drives it (same method
names and arguments), against the test oscillator of ``tests/support``.
"""

from __future__ import annotations

import json
import logging
import math
import sys
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from pythonfmu import Boolean, Integer, Real, String
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from wire_fmu_test_units import (  # noqa: E402
    OscillatorUnit,
    SpringDamperUnit,
    oscillator_position,
)

from wire_fmu._fingerprint import bundled_files, fingerprint  # noqa: E402
from wire_fmu.core.errors import ConfigurationError  # noqa: E402
from wire_fmu.core.framework.unit import StepResult, Unit, input_, output, parameter  # noqa: E402
from wire_fmu.export.builder import BuildError, build_fmu, unique_module_name  # noqa: E402
from wire_fmu.export.facade import CoreFacade, FacadeError, Phase  # noqa: E402
from wire_fmu.export.guard import (  # noqa: E402
    BUILD_INFO_FILE,
    BuildInfo,
    CoreVersionError,
    check_core,
    imported_core,
)
from wire_fmu.export.model_description import patch_model_description  # noqa: E402
from wire_fmu.export.state import json_copy  # noqa: E402
from wire_fmu.export.units import UNITS  # noqa: E402


class Oscillator(CoreFacade):
    unit_class = OscillatorUnit


class SpringDamper(CoreFacade):
    unit_class = SpringDamperUnit


class DottedUnit(Unit):
    """Unit with dotted names, as the block train uses (``line_a.tension``)."""

    NAME = "Dotted"
    DESCRIPTION = "Dotted names"
    VARIABLES = (
        parameter("line_a.length", 2.0, "m", "Length of line a"),
        input_("drive.speed", 0.0, "m/s", "Drive speed"),
        output("line_a.tension", "N", "Tension in line a", depends_on=("drive.speed",)),
    )

    def configure(self) -> None:  # noqa: D102
        pass

    def initialize(self, start_time: float) -> None:  # noqa: D102
        pass

    def advance(self, time: float, step: float) -> StepResult:  # noqa: D102
        return StepResult(True)

    def get_state(self) -> dict:  # noqa: D102
        return {}

    def set_state(self, state) -> None:  # noqa: D102
        pass


class Dotted(CoreFacade):
    unit_class = DottedUnit


def make(facade_class=Oscillator, name="osc", **values) -> CoreFacade:
    """A facade instance as pythonfmu creates it, with ``values`` set directly."""
    facade = facade_class(instance_name=name, resources=None)
    facade.unit.values.update(values)
    return facade


def vr(facade: CoreFacade, name: str) -> int:
    return next(v.value_reference for v in facade.vars.values() if v.name == name)


def initialised(facade: CoreFacade, start_time: float = 0.0) -> CoreFacade:
    facade.setup_experiment(start_time)
    facade.enter_initialization_mode()
    facade.exit_initialization_mode()
    return facade


REAL_OUTPUTS = [
    v.name for v in OscillatorUnit.VARIABLES if v.causality == "output" and v.type is float
]


def run(facade: CoreFacade, t0: float, steps: int, h: float = 0.01) -> np.ndarray:
    """Step ``steps`` times; return every Real output after each step."""
    refs = [vr(facade, n) for n in REAL_OUTPUTS]
    rows = []
    for k in range(steps):
        assert facade.do_step(t0 + k * h, h)
        rows.append(facade.get_real(refs))
    return np.array(rows)


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and bool(np.all(a.view(np.int64) == b.view(np.int64)))


def log_entries(facade: CoreFacade, status: Fmi2Status) -> list[str]:
    return [m.msg for m in facade.log_queue if m.status == status]


# -- variables ------------------------------------------------------------------
def test_registers_one_variable_per_declaration():
    facade = make()
    kinds = {float: Real, int: Integer, bool: Boolean, str: String}
    initial = {
        "parameter": Fmi2Initial.exact,
        "input": None,
        "output": Fmi2Initial.calculated,
    }
    assert facade.modelName == "Oscillator"
    assert facade.description == OscillatorUnit.DESCRIPTION
    *declared, timing = facade.vars.values()
    assert (timing.name, timing.causality) == ("physics_seconds", Fmi2Causality.local)
    pairs = zip(declared, OscillatorUnit.VARIABLES, strict=True)
    for ref, (scalar, var) in enumerate(pairs):
        assert (scalar.name, scalar.value_reference) == (var.name, ref)
        assert isinstance(scalar, kinds[var.type])
        assert scalar.causality == Fmi2Causality[var.causality.value]
        assert scalar.variability == Fmi2Variability[var.variability.value]
        assert scalar.initial == initial[var.causality.value]
        assert scalar.description == var.description


def test_physics_seconds_counts_the_time_spent_in_steps(monkeypatch):
    facade = initialised(make())
    timing = vr(facade, "physics_seconds")
    assert facade.get_real([timing]) == [0.0]
    clock = iter([10.0, 10.25, 20.0, 20.5])  # two steps: 0.25 s and 0.5 s in advance
    monkeypatch.setattr("wire_fmu.core.framework.unit.clock.perf_counter", lambda: next(clock))
    run(facade, 0.0, steps=2)
    assert facade.get_real([timing]) == [0.75]


def test_getters_and_setters_map_onto_unit_values():
    facade = make()
    facade.set_real([vr(facade, "mass")], [2.5])
    facade.set_integer([vr(facade, "substeps")], [7])
    facade.set_boolean([vr(facade, "flag")], [True])
    facade.set_string([vr(facade, "label")], ["crane 1"])
    values = facade.unit.values
    assert (values["mass"], values["substeps"], values["flag"]) == (2.5, 7, True)
    assert values["label"] == "crane 1"
    values["position"], values["moving_forward"] = 0.25, True
    assert facade.get_real([vr(facade, "position")]) == [0.25]
    assert facade.get_boolean([vr(facade, "moving_forward")]) == [True]
    assert facade.get_integer([vr(facade, "substeps")]) == [7]
    assert facade.get_string([vr(facade, "label")]) == ["crane 1"]


def test_dotted_names_are_plain_keys_not_attribute_paths():
    facade = make(Dotted)
    facade.set_real([vr(facade, "drive.speed")], [1.5])
    facade.unit.values["line_a.tension"] = 42.0
    assert facade.unit.values["drive.speed"] == 1.5
    assert facade.get_real([vr(facade, "line_a.tension"), vr(facade, "line_a.length")]) == [
        42.0,
        2.0,
    ]


def test_setting_an_output_is_refused_with_a_logged_reason():
    facade = make()
    with pytest.raises(FacadeError, match="position"):
        facade.set_real([vr(facade, "position")], [1.0])
    assert any("'position' cannot be set" in m for m in log_entries(facade, Fmi2Status.error))


def test_fixed_parameters_are_frozen_after_initialisation_tunable_are_not():
    facade = initialised(make())
    facade.set_boolean([vr(facade, "flag")], [True])  # tunable
    assert facade.unit.values["flag"] is True
    with pytest.raises(FacadeError, match="fixed parameter 'mass'"):
        facade.set_real([vr(facade, "mass")], [3.0])


# -- life cycle -------------------------------------------------------------------
def test_life_cycle_follows_the_closed_form_solution():
    facade = make(force=3.0, mass=2.0, x0=0.2, v0=-0.1)
    initialised(facade, start_time=1.0)
    assert facade.phase is Phase.step
    positions = run(facade, 1.0, 100)[:, REAL_OUTPUTS.index("position")]
    times = 0.01 * np.arange(1, 101)
    p = facade.unit.values
    expected = oscillator_position(
        times, p["mass"], p["stiffness"], p["damping"], p["x0"], p["v0"], p["force"]
    )
    np.testing.assert_allclose(positions, expected, rtol=0, atol=1e-10)


def test_parameter_set_in_initialisation_mode_rebuilds_the_unit():
    facade = make()
    facade.setup_experiment(0.0)
    facade.enter_initialization_mode()
    facade.set_real([vr(facade, "mass")], [4.0])
    facade.exit_initialization_mode()
    position = run(facade, 0.0, 50)[-1, REAL_OUTPUTS.index("position")]
    p = facade.unit.values
    expected = oscillator_position(np.array([0.5]), 4.0, p["stiffness"], p["damping"], 0.1, 0, 0)
    assert position == pytest.approx(expected[0], abs=1e-10)


def test_do_step_before_initialisation_is_refused():
    facade = make()
    with pytest.raises(FacadeError, match="fmi2DoStep called in phase 'instantiated'"):
        facade.do_step(0.0, 0.01)


def test_configuration_error_is_logged_with_every_problem(caplog):
    facade = make(mass=-1.0, stiffness=-2.0)
    facade.setup_experiment(0.0)
    with caplog.at_level(logging.DEBUG), pytest.raises(ConfigurationError):
        facade.enter_initialization_mode()
    (message,) = log_entries(facade, Fmi2Status.error)
    assert "fmi2EnterInitializationMode failed: mass = -1.0" in message
    assert "mass = -1.0 must be > 0" in message and "stiffness = -2.0 must be >= 0" in message
    # mirrored to the Python logger at debug level only: the master says it once
    mirrored = [r for r in caplog.records if "stiffness = -2.0" in r.getMessage()]
    assert mirrored and all(r.levelno == logging.DEBUG for r in mirrored)


def test_refused_step_is_logged_as_discard_before_returning_false():
    facade = initialised(make(max_position=0.05))
    assert facade.do_step(0.0, 0.01) is False
    (message,) = log_entries(facade, Fmi2Status.discard)
    assert "refused" in message and "max_position" in message and "t = 0.0 s" in message
    assert facade.unit.values["position"] == 0.1  # state at the start of the step


def test_unexpected_exception_is_one_error_line_and_a_debug_traceback(monkeypatch, caplog):
    facade = initialised(make())

    def broken(time, step):
        return 1 / 0

    monkeypatch.setattr(facade.unit, "advance", broken)
    with (
        caplog.at_level("DEBUG", logger="wire_fmu.export.facade"),
        pytest.raises(ZeroDivisionError),
    ):
        facade.do_step(0.0, 0.01)
    (message,) = log_entries(facade, Fmi2Status.error)
    assert "fmi2DoStep failed unexpectedly: ZeroDivisionError" in message
    assert "Traceback" not in message and "\n" not in message
    assert not log_entries(facade, Fmi2Status.fatal)
    debug = [r.getMessage() for r in caplog.records if r.levelname == "DEBUG"]
    assert any("Traceback" in m and "broken" in m for m in debug)


def test_feedthrough_output_follows_a_new_input_without_a_step():
    facade = initialised(make())
    run(facade, 0.0, 3)
    before = facade.get_real([vr(facade, "position"), vr(facade, "acceleration")])
    facade.set_real([vr(facade, "force")], [5.0])
    after = facade.get_real([vr(facade, "position"), vr(facade, "acceleration")])
    assert after[0] == before[0]
    assert after[1] == pytest.approx(before[1] + 5.0 / facade.unit.values["mass"], abs=1e-12)


# -- FMU state ----------------------------------------------------------------
def _contains_array(data) -> bool:
    if isinstance(data, dict):
        return any(_contains_array(v) for v in data.values())
    if isinstance(data, list):
        return any(_contains_array(v) for v in data)
    return not isinstance(data, (str, int, float, bool, type(None)))


def test_state_is_plain_json_and_restores_bit_identically():
    facade = initialised(make(force=1.5))
    run(facade, 0.0, 30)
    state = facade._get_fmu_state()
    assert not _contains_array(state)
    assert json.loads(json.dumps(state)) == state
    first = run(facade, 0.3, 30)
    facade._set_fmu_state(state)
    again = run(facade, 0.3, 30)
    assert same_bits(first, again)


def test_serialised_state_restores_into_a_fresh_instance():
    facade = initialised(make(force=-2.0, damping=0.9))
    run(facade, 0.0, 20)
    data = Oscillator._fmu_state_to_bytes(facade._get_fmu_state())
    first = run(facade, 0.2, 20)
    fresh = make(name="fresh")
    fresh._set_fmu_state(Oscillator._fmu_state_from_bytes(data))
    assert fresh.phase is Phase.step
    assert same_bits(first, run(fresh, 0.2, 20))


def test_state_does_not_alias_the_running_unit():
    facade = initialised(make())
    run(facade, 0.0, 5)
    state = facade._get_fmu_state()
    frozen = json.loads(json.dumps(state))
    run(facade, 0.05, 5)
    assert state == frozen


def test_state_taken_in_initialisation_mode_restores():
    facade = make(force=0.5)
    facade.setup_experiment(0.0)
    facade.enter_initialization_mode()
    state = facade._get_fmu_state()
    facade.exit_initialization_mode()
    first = run(facade, 0.0, 10)
    other = make(name="other")
    other._set_fmu_state(state)
    assert other.phase is Phase.initialization
    other.exit_initialization_mode()
    assert same_bits(first, run(other, 0.0, 10))


def test_unreadable_serialised_state_is_refused_with_a_logged_reason():
    facade = initialised(make())
    state = Oscillator._fmu_state_from_bytes(b"\xff not json")
    with pytest.raises(FacadeError, match="not a serialised wire_fmu state"):
        facade._set_fmu_state(state)
    assert any("fmi2SetFMUstate" in m for m in log_entries(facade, Fmi2Status.error))


def test_state_of_another_unit_is_refused():
    spring = initialised(make(SpringDamper))
    with pytest.raises(FacadeError, match="belongs to unit 'SpringDamper'"):
        make()._set_fmu_state(spring._get_fmu_state())


def test_json_copy_converts_arrays_and_keeps_every_bit():
    data = {"y": np.array([0.1, -0.0, math.inf]), "n": np.int64(3), "t": (1.0, np.nan)}
    copied = json_copy(data)
    assert copied["y"] == [0.1, -0.0, math.inf] and math.copysign(1, copied["y"][1]) < 0
    assert copied["n"] == 3 and type(copied["n"]) is int
    assert copied["t"][0] == 1.0 and math.isnan(copied["t"][1])
    with pytest.raises(TypeError, match="object"):
        json_copy({"bad": object()})


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
