"""Paper 004's energy-form integrator against SciPy at tight tolerance.

The machine has every ingredient of the paper: I(phi), M_d = a - b omega,
M_c(phi) with an exact work integral, a non-linear M_c(omega) (so the
tangent and secant lines of eqs. 7 and 10 differ) and M_c(t). References
come from ``solve_ivp`` (DOP853, rtol 1e-13) on the Lagrange equation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from wire_fmu.core.framework.energy_integrator import EnergyFormBreakdownError, EnergyFormIntegrator
from wire_fmu.core.framework.machine_unit import MachineUnit

TIGHT = {"method": "DOP853", "rtol": 1e-13, "atol": 1e-13}


def loom_like(a: float = 100.0) -> MachineUnit:
    """A machine unit with variable inertia and all three kinds of resistance."""
    return MachineUnit(
        inertia=lambda p: 2.0 + 0.5 * math.sin(p),
        inertia_slope=lambda p: 0.5 * math.cos(p),
        a=a,
        b=2.0,
        resistance_angle=lambda p: 10.0 + 5.0 * math.cos(2 * p),
        resistance_angle_work=lambda p0, p1: (
            10 * (p1 - p0) + 2.5 * (math.sin(2 * p1) - math.sin(2 * p0))
        ),
        resistance_speed=lambda w: 0.05 * w * w,
        resistance_speed_slope=lambda w: 0.1 * w,
        resistance_time=lambda t: 3.0 * math.sin(5.0 * t),
    )


def observed_orders(errors: list[float]) -> np.ndarray:
    e = np.asarray(errors)
    return np.log2(e[:-1] / e[1:])


def by_angle(integrator, machine, omega0, span, n):
    t, phi, omega = 0.0, 0.0, omega0
    for _ in range(n):
        step = integrator.step_angle(machine, t, phi, omega, span / n)
        t, phi, omega = step.time, step.phi, step.omega
    return omega, t


def by_time(integrator, machine, omega0, span, n):
    t, phi, omega = 0.0, 0.0, omega0
    forms = set()
    for _ in range(n):
        step = integrator.step_time(machine, t, phi, omega, span / n)
        t, phi, omega = step.time, step.phi, step.omega
        forms.add(step.form)
    return omega, phi, forms


@pytest.mark.parametrize(
    "refinements, order",
    [(0, 1), (1, 2), (None, 2)],
    ids=["first-order (9, 15)", "one correction (12, 18)", "refined"],
)
def test_angle_steps_converge_with_the_claimed_order(refinements, order):
    machine, span = loom_like(), 10.0
    ref = solve_ivp(machine.rhs_angle, (0, span), [20.0, 0.0], **TIGHT)
    omega_ref, t_ref = ref.y[:, -1]
    integrator = EnergyFormIntegrator(refinements)
    assert integrator.order == order
    results = [by_angle(integrator, machine, 20.0, span, n) for n in (50, 100, 200, 400)]
    speed = observed_orders([abs(w - omega_ref) for w, _ in results])
    time = observed_orders([abs(t - t_ref) for _, t in results])
    np.testing.assert_allclose(speed, order, atol=0.05)
    np.testing.assert_allclose(time, order, atol=0.05)
    assert abs(results[-1][0] - omega_ref) < (2e-2 if order == 1 else 3e-5)


@pytest.mark.parametrize("refinements, order", [(0, 1), (None, 2)])
def test_time_steps_converge_with_the_claimed_order(refinements, order):
    machine, span = loom_like(), 0.5
    ref = solve_ivp(machine.rhs_time, (0, span), [0.0, 20.0], **TIGHT)
    phi_ref, omega_ref = ref.y[:, -1]
    integrator = EnergyFormIntegrator(refinements)
    results = [by_time(integrator, machine, 20.0, span, n) for n in (100, 200, 400, 800)]
    assert all(forms == {"energy"} for *_, forms in results)
    np.testing.assert_allclose(
        observed_orders([abs(w - omega_ref) for w, _, _ in results]), order, atol=0.1
    )
    np.testing.assert_allclose(
        observed_orders([abs(p - phi_ref) for _, p, _ in results]), order, atol=0.1
    )


def test_without_torques_i_omega_squared_is_kept_exactly():
    """E = I(phi) omega^2 / 2 with no work done: the energy form keeps it at any step size."""
    machine = MachineUnit(inertia=lambda p: 3.0 + math.cos(p), inertia_slope=lambda p: -math.sin(p))
    integrator = EnergyFormIntegrator(None)
    t, phi, omega = 0.0, 0.0, 5.0
    invariant = machine.inertia(phi) * omega**2
    for _ in range(40):
        step = integrator.step_angle(machine, t, phi, omega, 0.3)
        t, phi, omega = step.time, step.phi, step.omega
        assert machine.inertia(phi) * omega**2 == pytest.approx(invariant, rel=1e-12)
    # and the speed follows I(phi): omega = omega0 sqrt(I(0) / I(phi))
    assert omega == pytest.approx(5.0 * math.sqrt(4.0 / (3.0 + math.cos(phi))), rel=1e-12)


def test_works_close_the_energy_balance_of_each_step():
    machine, integrator = loom_like(), EnergyFormIntegrator(None)
    step = integrator.step_angle(machine, 0.0, 0.0, 20.0, 0.1)
    before = machine.kinetic_energy(0.0, 20.0)
    after = machine.kinetic_energy(step.phi, step.omega)
    assert after - before == pytest.approx(step.work.net, rel=1e-10)
    assert step.refinements >= 1


def test_energy_form_breaks_down_at_rest():
    """A machine at rest cannot take an angle step: dt = dphi / omega."""
    with pytest.raises(EnergyFormBreakdownError, match="dt = dphi/omega"):
        EnergyFormIntegrator(None).step_angle(loom_like(), 0.0, 0.0, 0.0, 0.01)
    with pytest.raises(EnergyFormBreakdownError):
        EnergyFormIntegrator(None).step_angle(loom_like(), 0.0, 0.0, 1.0, -0.01)


def test_time_steps_start_from_rest_in_time_form_and_keep_order_two():
    machine, span = loom_like(), 0.3
    ref = solve_ivp(machine.rhs_time, (0, span), [0.0, 0.0], **TIGHT)
    integrator = EnergyFormIntegrator(None)
    results = [by_time(integrator, machine, 0.0, span, n) for n in (100, 200, 400, 800)]
    assert all(forms == {"energy", "time"} for *_, forms in results)
    orders = observed_orders([abs(w - ref.y[1, -1]) for w, _, _ in results])
    assert orders.min() > 1.8


def test_time_steps_through_a_reversal_fall_back_to_time_form():
    """A machine braked through omega = 0 (sign lost in E): the time form takes over."""
    machine = MachineUnit(inertia=lambda p: 2.0, a=-50.0)
    integrator = EnergyFormIntegrator(None)
    omega, phi, forms = by_time(integrator, machine, 1.0, 0.1, 50)
    assert "time" in forms
    assert omega == pytest.approx(1.0 - 25.0 * 0.1, rel=1e-9)
    assert phi == pytest.approx(0.1 - 12.5 * 0.1**2, rel=1e-9)
