"""Energy ledgers inside the internal solvers: dissipated energy never decreases.

A damped oscillator ``m x'' = -k x - c x'`` with its dissipated energy
``D' = c x'^2`` as a trailing ledger state. ROS2 is linearly implicit: run
through ``(I - g h J)^-1`` the ledger picks up ``-g h dP/dx`` terms and can go
down in a step where the velocity changes sign; integrated by quadrature of
its (never negative) power it cannot. The mechanical states must not notice
(beyond round-off: the inverse of a different matrix).
"""

from __future__ import annotations

import numpy as np
import pytest

from wire_fmu.core.hybrid import SolverSettings, make_solver

MASS, STIFFNESS, DAMPING, X0 = 1.0, 1.0e6, 200.0, 0.01  # kg, N/m, N s/m, m: 1000 rad/s


class DampedOscillator:
    """State ``[x, v, dissipated]``; no guards."""

    def __init__(self, ledger_states: int) -> None:
        self.ledger_states = ledger_states

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        v = x[1]
        return np.array([v, (-STIFFNESS * x[0] - DAMPING * v) / MASS, DAMPING * v * v])

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        return np.zeros(0)

    def guard_directions(self) -> np.ndarray:
        return np.zeros(0)

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        return x

    def project(self, x: np.ndarray) -> np.ndarray:
        return x


def trajectory(ledger_states: int, step: float, stop: float = 0.02) -> np.ndarray:
    """States at every internal step of ROS2, one row each."""
    system = DampedOscillator(ledger_states)
    solver = make_solver(SolverSettings("ros2", max_step=step))
    x = np.array([X0, 0.0, 0.0])
    rows = [x]
    for k in range(round(stop / step)):
        x, _ = solver.advance(system, k * step, x, (k + 1) * step)
        rows.append(x)
    return np.array(rows)


def mechanical_energy(rows: np.ndarray) -> np.ndarray:
    return 0.5 * STIFFNESS * rows[:, 0] ** 2 + 0.5 * MASS * rows[:, 1] ** 2


@pytest.mark.parametrize("step", [2e-3, 2e-4])  # omega h = 2 (stiff) and 0.2
def test_ros2_ledger_never_decreases_and_the_mechanics_do_not_notice(step):
    """With the ledger declared, dissipated energy rises monotonically and x, v are the
    same as without, to round-off; undeclared (the Jacobian row kept), the same run takes
    the ledger down in some step: the protection this test checks."""
    declared, undeclared = trajectory(1, step), trajectory(0, step)
    np.testing.assert_allclose(declared[:, :2], undeclared[:, :2], rtol=1e-8, atol=1e-14)
    assert np.all(np.diff(declared[:, 2]) >= 0.0)
    assert np.min(np.diff(undeclared[:, 2])) < 0.0


def test_ros2_ledger_closes_at_second_order():
    """Dissipated energy against the oscillator's energy loss along the same trajectory:
    the ledger residual E(0) - E(t) - D(t) shrinks fourfold as the step halves (0.4 % of
    E(0) at omega h = 0.025)."""
    residuals = []
    for step in (1e-4, 5e-5, 2.5e-5):
        rows = trajectory(1, step)
        energy = mechanical_energy(rows)
        residuals.append(float(np.max(np.abs(energy[0] - energy - rows[:, 2]))) / energy[0])
    orders = np.log2(np.array(residuals[:-1]) / np.array(residuals[1:]))
    assert residuals[-1] < 1e-2, residuals
    assert np.all(orders > 1.8), (residuals, orders)
