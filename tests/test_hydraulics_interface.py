"""The cylinder on the flow side of an interface model (issue 17, SPEC section 15b).

Over a step from ``t0`` the rod is integrated against the effort side's local model
``F = E0 - K (d - d_ref) - D (v - v_ref) + R (t - t0)`` instead of a held ``E0``. The
checks are physics against physics: the held force again when ``K = D = R = 0``; a rod
on a linear spring-damper whose interface model is exact, in one long step and in many
short ones, against SciPy's solution of the same ODE and against the frequency
``sqrt((K + k_gas) / m)``; a stuck seal under a ramping force letting go where the force
reaches the breakaway force, inside the step; the energy ledger closing with the work of
the varying force; both kernels alike; the port's declarations; bad inputs refused by
name.
"""

from __future__ import annotations

import math
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled import KERNEL_ENV
from wire_fmu.core.framework.compiled_step import COMPILED_METHODS, STATUS_DONE
from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES, INTERFACE_UNITS
from wire_fmu.core.framework.unit import MODE_CHANGE_TIME
from wire_fmu.core.units.hydraulics import kernel
from wire_fmu.core.units.hydraulics.interface import INTERFACE_INPUTS, RodInterface
from wire_fmu.core.units.hydraulics.unit import DEFAULT_ROD_FORCE, HydraulicsUnit
from wire_fmu.export.model_description import patch_model_description

from .facade_checks import load_facade_class
from .hydraulics_helpers import (
    ALL_EFFECTS,
    AREA,
    F_EQ,
    MASS,
    P_EQ,
    V_EQ,
    balancing_force,
    constant_force_cylinder,
    make_unit,
    quiet_cylinder,
)

numba_only = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")

STEP = 0.01  # s, the communication step
K_ROPE = 1.0e6  # N/m, the spring on the rod
C_ROPE = 2.0e3  # N s/m, its damper
K_GAS = P_EQ * AREA**2 / V_EQ  # N/m, the isothermal gas spring of quiet_cylinder at rest
V_START = 0.1  # m/s, the rod's velocity at the start of the spring tests


def set_interface(unit: HydraulicsUnit, force: float, *values: float) -> None:
    """``rod.force`` and the interface model's inputs, in the order of ``INTERFACE_INPUTS``."""
    unit.values["rod.force"] = force
    unit.values.update(zip(INTERFACE_INPUTS, values, strict=True))


def swing(t: float, swing_: float = 0.1) -> float:
    """The rated rod force swinging by ``swing_`` at 1.5 and 7 Hz, N."""
    wave = 0.7 * math.sin(2.0 * math.pi * 1.5 * t) + 0.3 * math.sin(2.0 * math.pi * 7.0 * t)
    return DEFAULT_ROD_FORCE * (1.0 + swing_ * wave)


def real_outputs() -> tuple[str, ...]:
    """Every Real output of the unit."""
    return tuple(
        v.name
        for v in HydraulicsUnit.VARIABLES
        if v.causality.value == "output" and v.type is float
    )


# -- (a) no stiffness, damping or rate: the held force ------------------------------------------
@pytest.mark.parametrize("effects", ["", "seal_friction,end_stops", ALL_EFFECTS])
def test_without_stiffness_damping_or_rate_the_force_is_held_bit_for_bit(effects):
    """A reference point alone changes nothing: every output is the held force's, bit for bit,
    the state keeps its size and the work through the rod is ``sum E0 (x1 - x0)`` exactly."""
    plain = make_unit(effects, force=DEFAULT_ROD_FORCE)
    referenced = make_unit(effects, force=DEFAULT_ROD_FORCE)
    names, work = real_outputs(), 0.0
    for i in range(150):
        t, force = i * STEP, swing(i * STEP)
        plain.values["rod.force"] = force
        set_interface(referenced, force, 0.0, 0.0, 0.0, 0.37, -2.5)
        x0 = plain.values["rod.position"]
        assert plain.advance(t, STEP).success and referenced.advance(t, STEP).success
        work += force * (plain.values["rod.position"] - x0)
        assert [referenced.values[n] for n in names] == [plain.values[n] for n in names], i
    assert referenced.model.state.size == referenced.model.own_layout.size
    assert plain.values["external_work"] == work
    assert plain.values["mode_changes"] > 0 or "seal" not in effects  # the seal did switch


# -- (b) a rod on a linear spring-damper -----------------------------------------------------------
def sprung_cylinder(**params) -> HydraulicsUnit:
    """quiet_cylinder's gas spring at 10 MPa, the rod balanced by ``F_EQ`` and moving at
    ``V_START``; no seals (the rod is free)."""
    return make_unit(
        "",
        force=F_EQ,
        **quiet_cylinder(
            initial_equilibrium=False,
            initial_gas_pressure=P_EQ,
            initial_velocity=V_START,
            **params,
        ),
    )


def spring_force(d: float, v: float, stiffness: float = K_ROPE, damping: float = C_ROPE) -> float:
    """The spring-damper on the rod: ``F_EQ`` at rest at the start, N."""
    return F_EQ - stiffness * d - damping * v


def exact_interface(unit, d_ref: float, v_ref: float, damping: float = C_ROPE) -> None:
    """The spring-damper's interface model about ``(d_ref, v_ref)``: exact, it is linear."""
    e0 = spring_force(d_ref, v_ref, K_ROPE, damping)
    set_interface(unit, e0, K_ROPE, damping, 0.0, d_ref, v_ref)


def ode_solution(duration: float, damping: float = C_ROPE) -> np.ndarray:
    """Displacement and velocity after ``duration`` (s) of ``m a = spring + gas`` (SciPy)."""

    def rhs(_t, y):
        d, v = y
        pressure = P_EQ * V_EQ / (V_EQ + AREA * d)  # isothermal gas, bore side
        return [v, (spring_force(d, v, K_ROPE, damping) + AREA * pressure) / MASS]

    solution = solve_ivp(rhs, (0.0, duration), [0.0, V_START], "DOP853", rtol=1e-12, atol=1e-14)
    return solution.y[:, -1]


@pytest.mark.parametrize(
    "solver",
    [
        dict(solver="radau", solver_rtol=1e-11, solver_atol=1e-14, solver_max_step=0.01),
        dict(solver="rk4", solver_max_step=1e-4),
    ],
    ids=["radau", "rk4"],
)
def test_one_long_step_on_a_spring_is_the_ode_of_rod_gas_and_spring(solver):
    """One step of 0.6 s (three periods) against the exact interface model of a spring-damper,
    about a reference point away from the rod (extrapolated): the rod's motion is SciPy's
    solution of ``m a = F_EQ - K d - D v + A p(V)``, to the solvers' tolerance."""
    unit = sprung_cylinder(**solver)
    exact_interface(unit, d_ref=0.004, v_ref=-0.05)
    result = unit.advance(0.0, 0.6)
    assert result.success, result.message
    d, v = ode_solution(0.6)
    amplitude = V_START / math.sqrt((K_ROPE + K_GAS) / MASS)
    assert unit.values["rod.displacement"] == pytest.approx(d, abs=1e-7 * amplitude)
    assert unit.values["rod.velocity"] == pytest.approx(v, abs=1e-7 * V_START)
    assert abs(d) > 0.1 * amplitude  # it has moved: the check is not of a rod at rest


def co_simulated(interface: bool, steps: int) -> np.ndarray:
    """Rod displacements of the spring (no damper) coupled at :data:`STEP`: each step the
    spring's effort side gives its force at the rod's motion, with (or without) its interface
    model about it; ROS2 at 0.1 ms inside the cylinder."""
    unit = sprung_cylinder(solver_max_step=1e-4)
    out = np.empty(steps + 1)
    out[0] = unit.values["rod.displacement"]
    for i in range(steps):
        d, v = unit.values["rod.displacement"], unit.values["rod.velocity"]
        if interface:
            exact_interface(unit, d, v, damping=0.0)
        else:
            unit.values["rod.force"] = spring_force(d, v, damping=0.0)
        assert unit.advance(i * STEP, STEP).success
        out[i + 1] = unit.values["rod.displacement"]
    return out


def angular_frequency(signal: np.ndarray) -> float:
    """``2 pi / period`` from the upward zero crossings of ``signal`` sampled at STEP, rad/s."""
    s = signal - 0.5 * (signal.max() + signal.min())
    idx = np.flatnonzero((s[:-1] < 0.0) & (s[1:] >= 0.0))
    crossings = (idx + s[idx] / (s[idx] - s[idx + 1])) * STEP
    return 2.0 * math.pi / float(np.mean(np.diff(crossings)))


def test_co_simulated_spring_oscillates_at_the_frequency_of_rope_and_gas():
    """Coupled every 10 ms (``omega h = 0.33``), the rod with the interface model swings at
    ``sqrt((K + k_gas) / m)`` as the ODE does, and as the same cylinder in one step of the
    whole run: the coupling adds nothing to the solver's own error. With the force held the
    explicit coupling of the stiff spring makes the swing grow."""
    steps = int(round(0.8 / STEP))
    omega = math.sqrt((K_ROPE + K_GAS) / MASS)
    amplitude = V_START / omega
    with_model = co_simulated(True, steps)
    assert angular_frequency(with_model) == pytest.approx(omega, rel=2e-3)
    exact = np.array([ode_solution(i * STEP, damping=0.0)[0] for i in range(1, steps + 1)])
    error_with_model = np.max(np.abs(with_model[1:] - exact))
    assert error_with_model < 5e-4 * amplitude  # ROS2's own error at 0.1 ms
    uncoupled = sprung_cylinder(solver_max_step=1e-4)
    exact_interface(uncoupled, 0.0, V_START, damping=0.0)
    assert uncoupled.advance(0.0, steps * STEP).success
    assert with_model[-1] == pytest.approx(
        uncoupled.values["rod.displacement"], abs=1e-8 * amplitude
    )
    held = co_simulated(False, steps)
    assert np.max(np.abs(held)) > 4.0 * amplitude  # grown sixfold in 0.8 s


# -- (c) the effort rate: breakaway inside the step ---------------------------------------------
@pytest.mark.parametrize("direction", [1.0, -1.0])
def test_a_stuck_seal_breaks_away_where_the_ramping_force_reaches_the_breakaway(direction):
    """A stuck rod, the gas force balanced, under ``E0 + R (t - t0)``: the seal lets go at
    ``t* = t0 + (F_static - |E0|) / |R|`` inside one 50 ms step, located to the event
    tolerance; held at ``E0`` it stays stuck."""
    static, offset, rate, t0 = 25.0e3, 5.0e3, 1.0e6, 0.3
    units = []
    for with_rate in (True, False):
        unit = HydraulicsUnit("test")
        unit.values["effects"] = "seal_friction"
        unit.values.update(constant_force_cylinder(seal_static_friction=static))
        unit.values["rod.force"] = balancing_force(unit)
        unit.configure()
        unit.initialize(t0)
        assert unit.values["seal.stuck"]
        unit.values["rod.force"] += direction * offset
        unit.values["rod.effort_rate"] = direction * rate if with_rate else 0.0
        assert unit.advance(t0, 0.05).success
        units.append(unit)
    ramped, held = units
    expected = t0 + (static - offset) / rate
    assert ramped.values[MODE_CHANGE_TIME] == pytest.approx(expected, abs=1e-8)
    assert not ramped.values["seal.stuck"]
    assert direction * ramped.values["rod.velocity"] > 0.0
    assert held.values["seal.stuck"] and held.values["rod.velocity"] == 0.0


# -- (d) the energy ledger ----------------------------------------------------------------------
def heave(t: float) -> tuple[float, float, float]:
    """Displacement (m), velocity and acceleration of the rope's far end (a heave), SI."""
    w1, w2 = 2.0 * math.pi * 0.2, 8.2
    d = 0.05 * math.sin(w1 * t) + 0.01 * math.sin(w2 * t)
    v = 0.05 * w1 * math.cos(w1 * t) + 0.01 * w2 * math.cos(w2 * t)
    a = -0.05 * w1**2 * math.sin(w1 * t) - 0.01 * w2**2 * math.sin(w2 * t)
    return d, v, a


def rope_interface(unit, t: float, stiffness: float, damping: float) -> None:
    """The interface model of a rope ``F = F0 - K (d - u(t)) - D (v - u'(t))`` whose far end
    heaves by ``u(t)``, about the rod's motion extrapolated over one step (as an effort side
    that extrapolates its inputs would take it)."""
    d, v = unit.values["rod.displacement"], unit.values["rod.velocity"]
    d_ref, v_ref = d + v * STEP, v
    u, du, ddu = heave(t)
    e0 = DEFAULT_ROD_FORCE - stiffness * (d_ref - u) - damping * (v_ref - du)
    set_interface(unit, e0, stiffness, damping, stiffness * du + damping * ddu, d_ref, v_ref)


def ledger_run(effects: str, **solver) -> dict[str, np.ndarray]:
    """Ledger outputs over 3 s of the default cylinder on a 3e6 N/m rope with a 3e4 N s/m
    damper whose far end heaves (its interface model each step)."""
    unit = make_unit(effects, **solver)
    names = ("energy_balance", "external_work", "dissipated_energy")
    out = {name: np.empty(300) for name in names}
    for i in range(300):
        rope_interface(unit, i * STEP, 3.0e6, 3.0e4)
        result = unit.advance(i * STEP, STEP)
        assert result.success, result.message
        for name in names:
            out[name][i] = unit.values[name]
    return out


@pytest.mark.parametrize(
    "effects",
    [
        "",
        "polytropic_gas,line_losses,seal_friction",
        "oil_compressibility,line_losses,line_inertance",
        ALL_EFFECTS,
    ],
)
def test_the_ledger_closes_with_the_work_of_the_varying_force(effects):
    """Stored change plus losses equals the work of ``F(x, v, t)`` through the rod, to the
    tolerance the held force's ledger closes to, with a solver that resolves the rope's mode
    on the rod (29 rad/s; RK4 at 0.25 ms)."""
    out = ledger_run(effects, solver="rk4", solver_max_step=2.5e-4)
    work, dissipated = out["external_work"], out["dissipated_energy"]
    assert np.all(np.diff(dissipated) >= 0.0)
    assert np.max(np.abs(work)) > 1e4  # the rope did work on the rod
    tolerance = 1e-7 * np.max(np.abs(work)) + 3e-3 * dissipated[-1]
    assert np.max(np.abs(out["energy_balance"])) < tolerance


def test_with_ros2_the_ledger_residual_is_the_solvers_own():
    """ROS2, L-stable, damps the rope's mode a little (energy the ledger cannot see); its
    residual falls with its step (order 1.5 or more), so it is the solver's, not the
    booking's."""
    coarse = ledger_run("", solver="ros2", solver_max_step=5e-4)["energy_balance"]
    fine = ledger_run("", solver="ros2", solver_max_step=2.5e-4)["energy_balance"]
    assert np.max(np.abs(fine)) < np.max(np.abs(coarse)) / 2.0**1.5


def test_the_work_through_the_rod_is_that_of_the_force_it_saw():
    """One long step on the exact spring-damper: the work booked is the spring's energy given
    up plus the damper's loss, ``integral of F v dt``, from SciPy's solution."""
    unit = sprung_cylinder(solver="radau", solver_rtol=1e-11, solver_atol=1e-14)
    exact_interface(unit, d_ref=0.004, v_ref=-0.05)
    assert unit.advance(0.0, 0.6).success

    def rhs(_t, y):
        d, v, _ = y
        pressure = P_EQ * V_EQ / (V_EQ + AREA * d)
        force = spring_force(d, v)
        return [v, (force + AREA * pressure) / MASS, force * v]

    solution = solve_ivp(rhs, (0.0, 0.6), [0.0, V_START, 0.0], "DOP853", rtol=1e-12, atol=1e-14)
    work = solution.y[2, -1]
    scale = 0.5 * MASS * V_START**2
    assert unit.values["external_work"] == pytest.approx(work, abs=1e-7 * scale)
    assert abs(unit.values["energy_balance"]) < 1e-7 * scale


# -- (e) both kernels ---------------------------------------------------------------------------
def run_kernel(monkeypatch, choice: str, effects: str) -> dict[str, np.ndarray]:
    """Real outputs per step of the default cylinder on a heaving rope, kernel ``choice``."""
    monkeypatch.setenv(KERNEL_ENV, choice)
    unit = make_unit(effects, initial_position=1.0)
    assert unit.model.compiled == (choice == "compiled")
    names = real_outputs()
    rows = [[unit.values[n] for n in names]]
    for i in range(150):
        rope_interface(unit, i * 0.002, 3.07e7, 3.0e5)
        unit.values["rod.force"] += swing(i * 0.002, 0.2) - DEFAULT_ROD_FORCE
        result = unit.advance(i * 0.002, 0.002)
        assert result.success, result.message
        rows.append([unit.values[n] for n in names])
    table = np.array(rows)
    return {name: table[:, k] for k, name in enumerate(names)}


@numba_only
@pytest.mark.parametrize(
    "effects",
    ["", "seal_friction", "oil_compressibility,line_losses,line_inertance", ALL_EFFECTS],
    ids=lambda e: e or "none",
)
def test_both_kernels_give_the_same_numbers_with_an_interface_model(monkeypatch, effects):
    """A stiff rope's interface model (``16 EA / L``) with damping, heave and a swinging
    force: every Real output agrees to a relative 1e-10 of its scale."""
    from .test_hydraulics_kernel import RELATIVE, differences

    python = run_kernel(monkeypatch, "python", effects)
    fast = run_kernel(monkeypatch, "compiled", effects)
    worst = differences(python, fast, make_unit(effects).model.mass)
    bad = {name: value for name, value in worst.items() if not value <= RELATIVE}
    assert not bad, f"outputs differ by more than {RELATIVE:g} of their scale: {bad}"


@numba_only
@pytest.mark.parametrize("method", sorted(COMPILED_METHODS))
def test_quiet_step_gives_the_shared_loop_with_the_work_state(monkeypatch, method):
    """With the interface model (its work a state, its rate making the right-hand side depend
    on time, so that every stage must be evaluated at the shared loop's times) the one-call
    quiet step still gives the shared loop's numbers to the last bit."""
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    unit = make_unit("polytropic_gas,line_losses", solver=method, solver_max_step=7e-4)
    model, code, taken = unit.model, COMPILED_METHODS[method], 0
    model.use_layout(model.interface_layout)
    for i in range(40):
        t0, t1 = 0.1 + i * 0.0137, 0.1 + (i + 1) * 0.0137
        model.force = swing(t0)
        model.interface = RodInterface(3.0e7, 3.0e5, -4.0e6 * (-1) ** i, 0.001, 0.02, start=t0)
        x = np.append(model.state, 0.0)
        data, directions = model.kernel_data(), model.guard_directions()
        n = model.solver.internal_count(t0, t1)
        quiet, end, _ = kernel.quiet_step(code, t0, t1, n, x, directions, data)
        shared = kernel.advance(code, t0, t1, n, 0, t0, x.copy(), directions, 1e-9, data)
        assert shared[0] == STATUS_DONE
        assert quiet, i
        assert end.tobytes() == shared[1].tobytes(), i
        taken += 1
        model.state = end[:-1]
    assert taken == 40


# -- (g) declarations ---------------------------------------------------------------------------
def test_the_rod_port_declares_the_interface_model_as_inputs():
    """The framework's check passes; the built model description marks the rod port as
    carrying the interface model (no switch: the flow side always integrates against it), its
    five quantities inputs in their units with start 0."""
    assert HydraulicsUnit.check_declarations() == []
    facade = load_facade_class("hydraulics", "Hydraulics")(instance_name="xml", resources=None)
    raw = ET.tostring(facade.to_xml(), encoding="UTF-8")
    root = ET.fromstring(patch_model_description(raw, HydraulicsUnit, "test"))
    (port,) = root.findall("VendorAnnotations/Tool/Ports/Port")
    assert (port.get("name"), port.get("side"), port.get("position")) == (
        "rod",
        "flow",
        "rod.displacement",
    )
    assert port.get("interface") == "true" and port.get("interface_switch") is None
    variables = {v.get("name"): v for v in root.find("ModelVariables")}
    units = INTERFACE_UNITS["translational"]
    for quantity, unit in zip(INTERFACE_QUANTITIES, units, strict=True):
        variable = variables[f"rod.{quantity}"]
        assert variable.get("causality") == "input"
        assert variable.find("Real").get("unit") == unit
        assert float(variable.find("Real").get("start")) == 0.0
    assert "hydraulic_stiffness" in variables


# -- (h) bad inputs -----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("name", "value", "said"),
    [
        ("rod.stiffness", -1.0e6, "input 'rod.stiffness' must be >= 0 N/m"),
        ("rod.damping", -5.0, "input 'rod.damping' must be >= 0 N.s/m"),
        ("rod.stiffness", math.nan, "inputs ['rod.stiffness'] are not finite"),
        ("rod.effort_rate", math.inf, "inputs ['rod.effort_rate'] are not finite"),
        ("rod.reference_position", -math.inf, "inputs ['rod.reference_position'] are not finite"),
        ("rod.reference_velocity", math.nan, "inputs ['rod.reference_velocity'] are not finite"),
    ],
)
def test_a_bad_interface_input_refuses_the_step_naming_it(name, value, said):
    """The step is refused with the unit, the time and the input named; nothing moves."""
    unit = make_unit("seal_friction")
    before = unit.get_state()
    unit.values[name] = value
    result = unit.advance(0.0, STEP)
    assert not result.success
    assert result.message.startswith("Hydraulics 'test' at t = 0 s: step refused: ")
    assert said in result.message
    assert unit.get_state() == before
    unit.values[name] = 0.0
    assert unit.advance(0.0, STEP).success


def test_a_bad_interface_input_at_the_start_is_a_configuration_error():
    """Set before initialisation, a negative stiffness stops the start, naming the input."""
    from wire_fmu.core.errors import ConfigurationError

    with pytest.raises(ConfigurationError, match="'rod.stiffness' must be >= 0 N/m"):
        make_unit("", **{"rod.stiffness": -1.0})


# -- state ---------------------------------------------------------------------------------------
def test_a_limit_refused_with_the_interface_model_leaves_the_unit_as_it_was():
    """Driven into the gas's dead volume against a spring: the step is refused at the limit
    and the state, its size and the outputs are those before it; so is the next refusal."""
    unit = make_unit(
        "",
        force=F_EQ,
        **quiet_cylinder(
            accumulator_volume=0.05, accumulator_dead_volume=0.005, precharge_pressure=8.0e6
        ),
    )
    set_interface(unit, F_EQ - 3.0e6, 1.0e5, 2.0e3, -1.0e6, 0.0, 0.0)
    t, refused = 0.0, None
    for _ in range(200):
        before, state = dict(unit.values), unit.get_state()
        result = unit.advance(t, STEP)
        if not result.success:
            refused = result
            break
        set_interface(unit, F_EQ - 3.0e6, 1.0e5, 2.0e3, -1.0e6, unit.values["rod.displacement"], 0)
        t += STEP
    assert refused is not None and "dead volume" in refused.message
    assert unit.values == before and unit.get_state() == state
    assert unit.model.state.size == unit.model.own_layout.size == len(state["x"])
    assert unit.model.layout is unit.model.own_layout
    assert not unit.advance(t, STEP).success


def test_state_round_trip_with_the_interface_model_is_bit_identical():
    """Saved mid-run and restored into a fresh unit, the next steps give the same bits."""
    units = [make_unit(ALL_EFFECTS) for _ in range(2)]
    first, second = units
    for i in range(30):
        rope_interface(first, i * STEP, 3.0e6, 3.0e4)
        assert first.advance(i * STEP, STEP).success
    second.set_state(first.get_state())
    second.values.update({n: first.values[n] for n in ("rod.force", *INTERFACE_INPUTS)})
    second.values[MODE_CHANGE_TIME] = first.values[MODE_CHANGE_TIME]  # of the last step only
    assert second.values == first.values
    for i in range(30, 40):
        for unit in units:
            rope_interface(unit, i * STEP, 3.0e6, 3.0e4)
            assert unit.advance(i * STEP, STEP).success
        assert second.values == first.values, i
