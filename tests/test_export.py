"""Export layer without building FMUs: the facade and its FMU state.

The facade is driven the way pythonfmu's C++ layer drives it (same method
names and arguments), against the test oscillator of ``tests/support``. The
model description, the builder's early checks and the core-version guard are in
``test_export_build``.
"""

from __future__ import annotations

import json
import logging
import math

import numpy as np
import pytest
from pythonfmu import Boolean, Integer, Real, String
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import StepResult, Unit, input_, output, parameter
from wire_fmu.export.facade import CoreFacade, FacadeError, Phase
from wire_fmu.export.state import json_copy

from .export_helpers import (
    Oscillator,
    OscillatorUnit,
    SpringDamper,
    oscillator_position,
)


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
    initialised(facade)  # a get before initialisation is refused
    values = facade.unit.values
    values["position"], values["moving_forward"] = 0.25, True
    assert facade.get_real([vr(facade, "position")]) == [0.25]
    assert facade.get_boolean([vr(facade, "moving_forward")]) == [True]
    assert facade.get_integer([vr(facade, "substeps")]) == [7]
    assert facade.get_string([vr(facade, "label")]) == ["crane 1"]


def test_a_get_of_an_output_before_initialisation_is_refused_saying_from_when():
    """An output has no value before the unit is initialised (the Oscillator's position
    would read 0, not its start x0); parameters and inputs read their start values."""
    facade = make(x0=0.3, substeps=7, flag=True, label="crane 1")
    outputs = {"real": vr(facade, "position"), "bool": vr(facade, "moving_forward")}
    for name, get in [
        ("fmi2GetReal", lambda: facade.get_real([vr(facade, "mass"), outputs["real"]])),
        ("fmi2GetBoolean", lambda: facade.get_boolean([outputs["bool"]])),
    ]:
        with pytest.raises(FacadeError, match=f"{name} of '.*' called in phase 'instantiated'"):
            get()
    said = log_entries(facade, Fmi2Status.error)
    assert len(said) == 2
    assert "'position'" in said[0] and "'mass'" not in said[0]
    assert all("have values from fmi2EnterInitializationMode on" in m for m in said)
    assert facade.get_real([vr(facade, "x0"), vr(facade, "force")]) == [0.3, 0.0]
    assert facade.get_integer([vr(facade, "substeps")]) == [7]
    assert facade.get_boolean([vr(facade, "flag")]) == [True]
    assert facade.get_string([vr(facade, "label")]) == ["crane 1"]
    facade.setup_experiment(0.0)
    facade.enter_initialization_mode()
    assert facade.get_real([outputs["real"]]) == [0.3]  # the value it starts with, not 0


def test_the_model_description_still_has_the_start_values_read_through_get():
    root = make(mass=2.5).to_xml()
    starts = {v.get("name"): v[0].get("start") for v in root.iter("ScalarVariable")}
    assert starts["mass"] == "2.5" and starts["label"] is not None


def test_value_references_no_variable_has_are_all_named():
    facade = initialised(make())
    count = len(facade.vars)
    for call, name in [
        (lambda: facade.get_real([9999, vr(facade, "position"), 12345, 9999]), "fmi2GetReal"),
        (lambda: facade.set_real([9999, 12345], [1.0, 2.0]), "fmi2SetReal"),
    ]:
        facade.log_queue.clear()
        with pytest.raises(FacadeError) as caught:
            call()
        assert str(caught.value) == (
            f"no variable has value reference 9999 or 12345; the unit's value references "
            f"are 0 to {count - 1}"
        )
        (message,) = log_entries(facade, Fmi2Status.error)
        assert message.startswith(f"Oscillator 'osc': {name} failed: no variable has")
    with pytest.raises(FacadeError, match="value reference 0 is the Real variable 'mass', not an"):
        facade.get_integer([0])
    with pytest.raises(FacadeError, match=r"value references 0 and 1 are not String variables"):
        facade.get_string([0, 1])
    assert not any("unexpectedly" in m.msg for m in facade.log_queue)


def test_dotted_names_are_plain_keys_not_attribute_paths():
    facade = make(Dotted)
    facade.set_real([vr(facade, "drive.speed")], [1.5])
    initialised(facade)  # a get before initialisation is refused
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
