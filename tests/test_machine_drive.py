"""Paper 004's machine unit in steady motion: the unit, its laws and the paper's claimed orders.

References are independent: the crank-slider's slider position differentiated
numerically, quadrature of the Fourier works, and SciPy's DOP853 at
rtol 1e-12 on the Lagrange equation for the motion (via
:mod:`wire_fmu.study.steady_motion`, which builds it from the laws, not the unit).
"""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import Causality
from wire_fmu.core.units.machine.cycle_statistics import CycleStatistics
from wire_fmu.core.units.machine.laws import CrankSliderInertia, FourierSeries
from wire_fmu.core.units.machine.spec import crank_press, parse_machine
from wire_fmu.core.units.machine.unit import MachineDriveUnit
from wire_fmu.study.steady_motion import (
    compare,
    last_delta,
    reference_trajectory,
    steady_motion_study,
    unit_trajectory,
)

ROOT = Path(__file__).resolve().parents[1]


def slider_position(phi: float, r: float = 0.1, rod: float = 0.5) -> float:
    return r * math.cos(phi) + math.sqrt(rod * rod - (r * math.sin(phi)) ** 2)


def test_crank_slider_inertia_is_m_times_slider_speed_squared():
    law = CrankSliderInertia(50.0, 0.1, 0.5, 200.0)
    d = 1e-5
    for phi in np.linspace(0.0, 2 * math.pi, 13):
        speed = (slider_position(phi + d) - slider_position(phi - d)) / (2 * d)
        assert law(phi) == pytest.approx(50.0 + 200.0 * speed**2, rel=1e-9)
        slope = (law(phi + d) - law(phi - d)) / (2 * d)
        assert law.derivative(phi) == pytest.approx(slope, abs=1e-6)
    assert law(0.0) == law(math.pi) == 50.0  # dead centres
    assert CrankSliderInertia(50.0, 0.6, 0.5, 1.0).problems()


def test_fourier_work_is_exact():
    series = FourierSeries(550.0, (450.0, 150.0), (30.0,))
    exact, _ = quad(series, 0.3, 2.9, epsabs=1e-13)
    assert series.integral(0.3, 2.9) == pytest.approx(exact, rel=1e-12)
    d = 1e-6
    assert series.derivative(1.1) == pytest.approx(
        (series(1.1 + d) - series(1.1 - d)) / (2 * d), rel=1e-7
    )


def test_cycle_statistics_of_a_uniform_rotation():
    stats = CycleStatistics()
    stats.start(0.0, 0.0, 3.0)
    h = 0.013
    for i in range(1, 2000):
        stats.update((i - 1) * h, (3.0 * (i - 1) * h, 3.0), i * h, (3.0 * i * h, 3.0))
    assert stats.count == int(3.0 * 1999 * h / (2 * math.pi))
    assert stats.last["period"] == pytest.approx(2 * math.pi / 3.0, rel=1e-12)
    assert stats.last["delta"] == 0.0


# ================================================================= the paper's orders
@pytest.fixture(scope="module")
def reference():
    """DOP853 at rtol 1e-12, sampled every 10 ms over 3 s."""
    return reference_trajectory(0.01 * np.arange(301))


@pytest.mark.parametrize(
    "solver, order, steps",
    [
        ("energy1", 1, (1.25e-3, 6.25e-4, 3.125e-4)),
        ("energy", 2, (1e-2, 5e-3, 2.5e-3)),
    ],
    ids=["first-order step (9, 15): order 1", "successive refinement (12, 18): order 2"],
)
def test_paper_method_converges_with_the_claimed_order(reference, solver, order, steps):
    runs = compare(solver, steps, stop_time=3.0, step=0.01, reference=reference)
    orders = [r.order for r in runs[1:]]
    np.testing.assert_allclose(orders, order, atol=0.1)
    assert runs[-1].speed_error < 1e-4


def test_paper_method_reports_the_steady_non_uniformity(reference):
    """Delta of the last revolution: the refined method within 2e-5 of the reference at 5 ms."""
    ref = last_delta(reference)
    assert 0.03 < ref < 0.06  # a crank press with a stiff induction motor
    paper = unit_trajectory("energy", 5e-3, stop_time=3.0, step=0.01)
    assert abs(last_delta(paper) - ref) < 2e-5
    assert paper.evaluations > 0


def test_unit_reports_delta_per_revolution_like_the_samples():
    unit = MachineDriveUnit("m")
    unit.configure()
    unit.initialize(0.0)
    phi, omega = [0.0], [unit.values["shaft.speed"]]
    for i in range(300):
        assert unit.advance(i * 0.01, 0.01).success
        phi.append(unit.values["shaft.angle"])
        omega.append(unit.values["shaft.speed"])
    assert unit.values["cycle.count"] == math.floor(phi[-1] / (2 * math.pi))
    from wire_fmu.study.steady_motion import Trajectory

    samples = Trajectory(0.01 * np.arange(301), np.array(phi), np.array(omega))
    assert unit.values["cycle.delta"] == last_delta(samples)
    assert unit.values["cycle.omega_mean"] == pytest.approx(np.mean(omega[-60:]), rel=2e-2)


@pytest.mark.parametrize("solver", ["energy", "rk4", "radau"])
def test_energy_ledger_closes(solver):
    unit = MachineDriveUnit("m")
    unit.values["solver"] = solver
    unit.configure()
    unit.initialize(0.0)
    for i in range(200):
        assert unit.advance(i * 0.01, 0.01).success
    assert abs(unit.values["energy_balance"]) < 1e-6 * unit.values["dissipated_energy"]


def test_study_writes_its_table_and_plot(tmp_path):
    study = steady_motion_study(
        tmp_path, stop_time=1.0, max_steps=(5e-3, 2.5e-3), solvers=("energy1", "energy")
    )
    for path in study["files"].values():
        assert path.exists() and path.stat().st_size > 0
    assert "| energy | 2 |" in study["files"]["md"].read_text()


# ================================================================= configuration and facade
def test_configuration_problems_are_all_reported():
    unit = MachineDriveUnit("m")
    machine = crank_press()
    machine["inertia"]["crank"] = 0.9
    machine["resistance_speed"] = {"coefficients": "fast"}
    unit.values.update({"machine": json.dumps(machine), "solver": "euler"})
    with pytest.raises(ConfigurationError) as info:
        unit.configure()
    text = str(info.value)
    for word in ("euler", "coefficients"):
        assert word in text
    assert parse_machine({"inertia": {"kind": "fourier", "mean": 1.0, "cos": [2.0]}})[1]


def test_declarations_and_feedthrough():
    assert MachineDriveUnit.check_declarations() == []
    unit = MachineDriveUnit("m")
    unit.configure()
    unit.initialize(0.0)
    unit.advance(0.0, 0.01)
    outputs = [v for v in MachineDriveUnit.VARIABLES if v.causality is Causality.output]
    for name in ("motor.command", "load.torque"):
        before = dict(unit.values)
        unit.values[name] += 100.0
        unit.evaluate_outputs()
        after = dict(unit.values)
        unit.values[name] -= 100.0
        unit.evaluate_outputs()
        for var in outputs:
            if name not in var.depends_on:
                assert after[var.name] == before[var.name], (name, var.name)


def test_facade_steps_like_the_core():
    spec = importlib.util.spec_from_file_location(
        "machine_facade", ROOT / "models" / "machine_unit.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    facade = module.MachineUnit(instance_name="m", resources=None)
    refs = {v.name: v.value_reference for v in facade.vars.values()}
    facade.setup_experiment(0.0, None, None)
    facade.enter_initialization_mode()
    facade.exit_initialization_mode()
    unit = MachineDriveUnit("m")
    unit.configure()
    unit.initialize(0.0)
    for i in range(30):
        facade.set_real([refs["load.torque"]], [10.0 * i])
        facade.do_step(i * 0.01, 0.01)
        unit.values["load.torque"] = 10.0 * i
        unit.advance(i * 0.01, 0.01)
    names = ["shaft.speed", "shaft.angle", "energy_balance", "cycle.delta"]
    assert facade.get_real([refs[n] for n in names]) == [unit.values[n] for n in names]
