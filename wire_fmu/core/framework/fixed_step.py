"""Fixed-step solvers of hybrid systems: the template with event location, RK4 and ROS2.

:class:`FixedStepSolver` takes ``ceil(H / max_step)`` equal steps per
communication step ``H``, locates every guard crossing by re-stepping
(regula falsi with the Illinois modification) and lets the system switch mode
there; a subclass gives one step (:meth:`FixedStepSolver._step`). The
solvers are chosen by name through :data:`wire_fmu.core.framework.hybrid.SOLVERS`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from wire_fmu.core.framework.step_limits import (
    MAX_EVENTS_PER_STEP,
    IntegrationError,
    internal_step_count,
)

if TYPE_CHECKING:
    from wire_fmu.core.framework.hybrid import HybridSystem, SolverSettings

__all__ = [
    "DenseLinearAlgebra",
    "FixedStepSolver",
    "LinearAlgebra",
    "RK4",
    "ROS2",
    "finite_difference_jacobian",
]

_MAX_LOCATE_ITERATIONS = 60


def _fired(g0: np.ndarray, g1: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Boolean mask of guards that crossed between two evaluations."""
    down = (g0 >= 0.0) & (g1 < 0.0)
    anyway = (np.sign(g0) != np.sign(g1)) & (g0 != 0.0)
    return np.where(directions < 0, down, anyway)


class FixedStepSolver:
    """Template for fixed-step methods: stepping, event location, bookkeeping."""

    def __init__(self, settings: SolverSettings) -> None:
        self.settings = settings
        self.rhs_calls = 0
        self.steps = 0

    # Subclasses implement one step of length h from (t, x).
    def _step(self, system: HybridSystem, t: float, x: np.ndarray, h: float) -> np.ndarray:
        raise NotImplementedError

    def _on_new_interval(self, system: HybridSystem, t: float, x: np.ndarray) -> None:
        """Hook: called at the start of a communication step and after events."""

    def advance(
        self, system: HybridSystem, t0: float, x0: np.ndarray, t1: float
    ) -> tuple[np.ndarray, int]:
        """Integrate from ``t0`` to ``t1``; return the state and the number of events.

        Parameters
        ----------
        system : HybridSystem
            The model.
        t0 : float
            Start time, s.
        x0 : ndarray
            State at ``t0``.
        t1 : float
            End time, s.
        """
        n = internal_step_count(t0, t1, self.settings.max_step)
        t, x = t0, np.array(x0, dtype=float)
        events = 0
        self._on_new_interval(system, t, x)
        directions = system.guard_directions()
        grid = [t0 + (t1 - t0) * i / n for i in range(n + 1)]
        k = 0
        g0 = system.guards(t, x)
        while k < n:
            t_next = grid[k + 1]
            x_next, g1, fired_at = self._step_with_events(system, t, x, t_next - t, directions, g0)
            if fired_at is None:
                t, x, g0 = t_next, x_next, g1
                k += 1
                continue
            t_event, fired = fired_at
            events += 1
            if events > MAX_EVENTS_PER_STEP:
                raise IntegrationError(f"more than {MAX_EVENTS_PER_STEP} events in one step")
            t = t_event
            x = system.handle_events(t, x_next, fired)
            self._on_new_interval(system, t, x)
            directions = system.guard_directions()
            if t >= t_next - self.settings.event_time_tolerance:
                t = t_next
                k += 1
            g0 = system.guards(t, x)
        return x, events

    def _checked_step(self, system, t, x, h):
        x1 = system.project(self._step(system, t, x, h))
        self.steps += 1
        if not np.all(np.isfinite(x1)):
            raise IntegrationError(f"non-finite state after a step of {h:.3g} s at t = {t:.6g} s")
        return x1

    def _step_with_events(self, system, t, x, h, directions, g0):
        """One step; if a guard fires inside it, stop just after the first crossing.

        Returns the new state, the guards there and ``None``, or the state
        just after the first crossing, ``None`` and ``(time, fired guards)``.
        """
        x1 = self._checked_step(system, t, x, h)
        if g0.size == 0:
            return x1, g0, None
        g1 = system.guards(t + h, x1)
        mask = _fired(g0, g1, directions)
        if not mask.any():
            return x1, g1, None
        x_event, fired_at = self._locate(system, t, x, h, g0, directions, x1, mask)
        return x_event, None, fired_at

    def _locate(self, system, t, x, h, g0, directions, x1, mask):
        """Illinois regula falsi on the step fraction, for the earliest crossing."""
        lo, hi = 0.0, 1.0
        x_hi = x1
        g_lo_all, g_hi_all = g0, system.guards(t + h, x1)
        tol = self.settings.event_time_tolerance / h
        side = 0
        for _ in range(_MAX_LOCATE_ITERATIONS):
            if hi - lo <= tol:
                break
            # earliest linear estimate among the guards that fired
            idx = np.flatnonzero(mask)
            est = []
            for i in idx:
                a, b = g_lo_all[i], g_hi_all[i]
                est.append(lo + (hi - lo) * a / (a - b) if a != b else 0.5 * (lo + hi))
            theta = min(est)
            theta = min(max(theta, lo + 0.05 * tol), hi - 0.05 * tol)
            x_mid = self._checked_step(system, t, x, theta * h)
            g_mid = system.guards(t + theta * h, x_mid)
            crossed = _fired(g0, g_mid, directions)
            if crossed.any():
                hi, x_hi, g_hi_all, mask = theta, x_mid, g_mid, crossed
                if side == 1:
                    g_lo_all = g_lo_all.copy()
                    g_lo_all[mask] *= 0.5
                side = 1
            else:
                lo, g_lo_all = theta, g_mid
                if side == -1:
                    g_hi_all = g_hi_all.copy()
                    g_hi_all[mask] *= 0.5
                side = -1
        return x_hi, (t + hi * h, [int(i) for i in np.flatnonzero(mask)])


class RK4(FixedStepSolver):
    """Classical fourth-order Runge-Kutta with fixed steps."""

    def _step(self, system, t, x, h):
        f = system.rhs
        k1 = f(t, x)
        k2 = f(t + 0.5 * h, x + 0.5 * h * k1)
        k3 = f(t + 0.5 * h, x + 0.5 * h * k2)
        k4 = f(t + h, x + h * k3)
        self.rhs_calls += 4
        return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


class ROS2(FixedStepSolver):
    """Verwer's ROS2: linearly implicit, L-stable, order 2 as a W-method.

    ``(I - g h J) k1 = f(t, x)``;
    ``(I - g h J) k2 = f(t + h, x + h k1) - 2 k1``;
    ``x+ = x + 1.5 h k1 + 0.5 h k2``, with ``g = 1 + 1/sqrt(2)``.

    ``J`` is taken at the start of every internal interval from the system's
    ``linear_algebra()`` where it offers one (a structured Jacobian, see
    :class:`LinearAlgebra`), else by forward differences of every state.
    """

    GAMMA = 1.0 + 1.0 / math.sqrt(2.0)

    def __init__(self, settings: SolverSettings) -> None:
        super().__init__(settings)
        self._linear: LinearAlgebra = DenseLinearAlgebra(None)
        self._jac = None
        self._inverse_h: float | None = None
        self._inverse = None

    def _on_new_interval(self, system, t, x):
        make = getattr(system, "linear_algebra", None)
        self._linear = make() if make is not None else DenseLinearAlgebra(system)
        self._jac, evaluations = self._linear.linearise(t, x)
        self.rhs_calls += evaluations
        self._inverse_h = None

    def _w_inverse(self, h: float):
        """The factors of ``I - g h J``, kept while ``h`` and the Jacobian stay."""
        if self._inverse_h != h:
            self._inverse = self._linear.factor(self._jac, self.GAMMA * h)
            self._inverse_h = h
        return self._inverse

    def _step(self, system, t, x, h):
        if x.size == 0:
            return x
        w_inv = self._w_inverse(h)
        solve = self._linear.solve
        k1 = solve(w_inv, system.rhs(t, x))
        k2 = solve(w_inv, system.rhs(t + h, x + h * k1) - 2.0 * k1)
        self.rhs_calls += 2
        return x + h * (1.5 * k1 + 0.5 * k2)


class LinearAlgebra(Protocol):
    """ROS2's Jacobian and ``(I - g h J)`` solves, as a system offers them.

    A system with a structured Jacobian returns one from ``linear_algebra()``;
    others get :class:`DenseLinearAlgebra`.
    """

    def linearise(self, t: float, x: np.ndarray) -> tuple[Any, int]:
        """The Jacobian at ``(t, x)`` in the form :meth:`factor` takes, and the
        right-hand sides evaluated for it."""

    def factor(self, jac: Any, gh: float) -> Any:
        """Factors of ``I - gh J`` (``gh`` in s)."""

    def solve(self, factors: Any, b: np.ndarray) -> np.ndarray:
        """``(I - gh J)^-1 b``."""


class DenseLinearAlgebra:
    """Every state differenced, ``I - g h J`` inverted.

    For the small systems of a unit, multiplying by the inverse costs a few
    microseconds where a LAPACK triangular solve through SciPy costs about twenty;
    the matrix is well conditioned for any ``h`` (its eigenvalues are
    ``1 - g h lambda`` with ``Re lambda <= 0``).

    Parameters
    ----------
    system : HybridSystem
        The model, in its current mode.
    """

    def __init__(self, system: HybridSystem | None) -> None:
        self.system = system

    def linearise(self, t: float, x: np.ndarray) -> tuple[np.ndarray, int]:
        """:func:`finite_difference_jacobian` and its ``x.size + 1`` evaluations."""
        return finite_difference_jacobian(self.system, t, x), x.size + 1

    def factor(self, jac: np.ndarray, gh: float) -> np.ndarray:
        """``(I - gh J)^-1``."""
        return np.linalg.inv(np.eye(jac.shape[0]) - gh * jac)

    def solve(self, factors: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``factors @ b``."""
        return factors @ b


def finite_difference_jacobian(system: HybridSystem, t: float, x: np.ndarray) -> np.ndarray:
    """Forward-difference Jacobian of the current mode's right-hand side.

    Parameters
    ----------
    system : HybridSystem
        The model, in its current mode.
    t : float
        Time, s.
    x : ndarray
        Continuous state of the model.

    Returns
    -------
    ndarray, shape (n, n)
        ``d rhs / d x`` at ``(t, x)``.
    """
    n = x.size
    jac = np.zeros((n, n))
    if n == 0:
        return jac
    f0 = system.rhs(t, x)
    for j in range(n):
        dx = 1e-7 * max(1.0, abs(x[j]))
        xp = x.copy()
        xp[j] += dx
        jac[:, j] = (system.rhs(t, xp) - f0) / dx
    return jac
