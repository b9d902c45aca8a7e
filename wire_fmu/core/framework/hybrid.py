"""Integration of hybrid (mode-switching) ODEs over one communication step.

A :class:`HybridSystem` has a continuous state ``x`` and a discrete *mode*
(stick/slip flags, slack flags, broken ropes...). Inside one mode it is a
smooth ODE ``x' = f(t, x)``; *guards* ``g(t, x)`` watch for the mode's end.
The integrators here advance such a system to a target time, locate every
guard crossing to within a small time tolerance by re-stepping (regula falsi
with the Illinois modification), let the system switch mode there, and go on.

Solvers are small objects chosen by name from :data:`SOLVERS`:

``rk4``
    classical explicit Runge-Kutta, fixed step (order 4).
``ros2``
    two-stage linearly implicit Rosenbrock-W method of Verwer et al. (1999),
    L-stable, order 2 for any Jacobian approximation; the finite-difference
    Jacobian is reused within a communication step and refreshed after
    every event. Cheap and robust for stiff ropes and oil columns.
``radau``, ``bdf``, ``lsoda``, ``rk45``, ``dop853``
    SciPy's adaptive solvers with ``rtol``/``atol``, restarted at every
    communication step and every event.

The fixed-step solvers take ``ceil(H / max_step)`` equal steps per
communication step H, so the result never depends on how a master splits
time except through H itself.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.integrate import solve_ivp

__all__ = [
    "HybridSystem",
    "SolverSettings",
    "IntegrationError",
    "SOLVERS",
    "make_solver",
]


class HybridSystem(Protocol):
    """What an integrator needs from a model.

    Guards come in two kinds, told apart by :meth:`guard_directions`:
    ``-1`` fires when the guard goes from ``>= 0`` to ``< 0`` (leaving a
    mode), ``0`` fires on any change of sign (a kink such as a rope going
    slack, located for accuracy).
    """

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """Time derivative of the state in the current mode."""
        ...

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Guard function values in the current mode."""
        ...

    def guard_directions(self) -> np.ndarray:
        """Per guard: -1 (fires on a downward crossing) or 0 (any crossing)."""
        ...

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Switch mode after the guards ``fired``; return the (projected) state."""
        ...

    def project(self, x: np.ndarray) -> np.ndarray:
        """Enforce the current mode's algebraic invariants on ``x`` (exactly)."""
        ...


class IntegrationError(RuntimeError):
    """A step produced non-finite numbers or too many events."""


@dataclass(frozen=True)
class SolverSettings:
    """Choice and settings of the internal solver of a unit.

    Parameters
    ----------
    method : str
        A key of :data:`SOLVERS`.
    max_step : float
        Largest internal step, s (fixed-step methods take equal steps no
        longer than this; adaptive methods never exceed it).
    rtol, atol : float
        Tolerances of the adaptive SciPy methods.
    event_time_tolerance : float
        Guard crossings are located to within this time, s.
    """

    method: str = "ros2"
    max_step: float = 1e-3
    rtol: float = 1e-6
    atol: float = 1e-9
    event_time_tolerance: float = 1e-9

    def problems(self, known: Collection[str] = ()) -> list[str]:
        """Every problem with these settings, as sentences.

        ``known`` adds method names a unit offers beyond :data:`SOLVERS`
        (paper 004's energy-form integrator in the winch and the machine unit).
        """
        out = []
        names = set(SOLVERS) | set(known)
        if self.method not in names:
            out.append(f"solver {self.method!r} is unknown; choose one of {sorted(names)}")
        if not (self.max_step > 0 and math.isfinite(self.max_step)):
            out.append(f"solver_max_step must be a positive number of seconds, got {self.max_step}")
        if not (0 < self.rtol < 1):
            out.append(f"solver_rtol must lie in (0, 1), got {self.rtol}")
        if not (self.atol > 0):
            out.append(f"solver_atol must be positive, got {self.atol}")
        return out


RK4_STABILITY = 2.5
"""``|lambda| h`` below which classical RK4 is stable (its limit is 2.78 on the real
axis and 2.83 on the imaginary axis), with a margin."""


def fastest_mode(system: HybridSystem, t: float, x: np.ndarray) -> float:
    """Largest ``|lambda|`` (1/s) of the system's Jacobian at ``(t, x)`` (finite differences)."""
    if x.size == 0:
        return 0.0
    return float(np.max(np.abs(np.linalg.eigvals(_finite_difference_jacobian(system, t, x)))))


_MAX_EVENTS_PER_STEP = 10_000
MAX_INTERNAL_STEPS = 100_000
"""Most internal steps one communication step may need; a longer one is refused
at once (its message says how long a step may be) rather than run for hours."""
_MAX_LOCATE_ITERATIONS = 60


def internal_steps(t0: float, t1: float, max_step: float) -> float:
    """How many steps of at most ``max_step`` (s) span ``[t0, t1]`` (s).

    Raises
    ------
    IntegrationError
        When that is more than :data:`MAX_INTERNAL_STEPS`, naming the longest
        communication step the unit takes.
    """
    count = (t1 - t0) / max_step
    if not count <= MAX_INTERNAL_STEPS:
        raise IntegrationError(
            f"a step of {t1 - t0:.6g} s needs {count:.3g} internal steps of at most "
            f"{max_step:.3g} s, more than the {MAX_INTERNAL_STEPS} one step may take; "
            f"take communication steps of at most {MAX_INTERNAL_STEPS * max_step:.6g} s"
        )
    return count


def _fired(g0: np.ndarray, g1: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Boolean mask of guards that crossed between two evaluations."""
    down = (g0 >= 0.0) & (g1 < 0.0)
    anyway = (np.sign(g0) != np.sign(g1)) & (g0 != 0.0)
    return np.where(directions < 0, down, anyway)


class _FixedStepSolver:
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
        """Integrate from ``t0`` to ``t1``; return the state and the number of events."""
        n = max(1, math.ceil(internal_steps(t0, t1, self.settings.max_step) - 1e-9))
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
            if events > _MAX_EVENTS_PER_STEP:
                raise IntegrationError(f"more than {_MAX_EVENTS_PER_STEP} events in one step")
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


class RK4(_FixedStepSolver):
    """Classical fourth-order Runge-Kutta with fixed steps."""

    def _step(self, system, t, x, h):
        f = system.rhs
        k1 = f(t, x)
        k2 = f(t + 0.5 * h, x + 0.5 * h * k1)
        k3 = f(t + 0.5 * h, x + 0.5 * h * k2)
        k4 = f(t + h, x + h * k3)
        self.rhs_calls += 4
        return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


class ROS2(_FixedStepSolver):
    """Verwer's ROS2: linearly implicit, L-stable, order 2 as a W-method.

    ``(I - g h J) k1 = f(t, x)``;
    ``(I - g h J) k2 = f(t + h, x + h k1) - 2 k1``;
    ``x+ = x + 1.5 h k1 + 0.5 h k2``, with ``g = 1 + 1/sqrt(2)``.
    """

    GAMMA = 1.0 + 1.0 / math.sqrt(2.0)

    def __init__(self, settings: SolverSettings) -> None:
        super().__init__(settings)
        self._jac: np.ndarray | None = None
        self._inverse_h: float | None = None
        self._inverse: np.ndarray | None = None

    def _on_new_interval(self, system, t, x):
        self._jac = _finite_difference_jacobian(system, t, x)
        self.rhs_calls += x.size + 1
        self._inverse_h = None

    def _w_inverse(self, h: float) -> np.ndarray:
        """``(I - g h J)^-1``, kept while ``h`` and the Jacobian stay.

        For the small systems of a unit, multiplying by the inverse costs a
        few microseconds where a LAPACK triangular solve through SciPy costs
        about twenty; the matrix is well conditioned for any ``h`` (its
        eigenvalues are ``1 - g h lambda`` with ``Re lambda <= 0``).
        """
        if self._inverse_h != h:
            n = self._jac.shape[0]
            self._inverse = np.linalg.inv(np.eye(n) - self.GAMMA * h * self._jac)
            self._inverse_h = h
        return self._inverse

    def _step(self, system, t, x, h):
        if x.size == 0:
            return x
        w_inv = self._w_inverse(h)
        k1 = w_inv @ system.rhs(t, x)
        k2 = w_inv @ (system.rhs(t + h, x + h * k1) - 2.0 * k1)
        self.rhs_calls += 2
        return x + h * (1.5 * k1 + 0.5 * k2)


def _finite_difference_jacobian(system: HybridSystem, t: float, x: np.ndarray) -> np.ndarray:
    """Forward-difference Jacobian of the current mode's right-hand side."""
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


class ScipySolver:
    """SciPy's ``solve_ivp`` per communication step, restarted at events.

    Like the fixed-step solvers, an event is taken just *after* the crossing
    (the dense output of the last step, ``event_time_tolerance`` past the
    located root), so the guard that fired is past its zero when the mode
    switches and cannot fire again at the restart.
    """

    def __init__(self, settings: SolverSettings, method: str) -> None:
        self.settings = settings
        self.method = method
        self.rhs_calls = 0
        self.steps = 0

    def advance(self, system, t0, x0, t1):
        internal_steps(t0, t1, self.settings.max_step)
        tol = self.settings.event_time_tolerance
        t, x = t0, np.array(x0, dtype=float)
        events = 0
        while t < t1 - tol:
            sol = solve_ivp(
                system.rhs,
                (t, t1),
                x,
                method=self.method,
                rtol=self.settings.rtol,
                atol=self.settings.atol,
                max_step=self.settings.max_step,
                events=self._event_functions(system) or None,
                dense_output=True,
            )
            self.rhs_calls += sol.nfev
            self.steps += max(0, sol.t.size - 1)
            if sol.status == -1:
                raise IntegrationError(f"{self.method}: {sol.message}")
            if sol.status == 0:
                return system.project(sol.y[:, -1]), events
            times = {i: float(te[0]) for i, te in enumerate(sol.t_events) if te.size}
            t_root = min(times.values())
            fired = [i for i, te in times.items() if te <= t_root + tol]
            t = min(t_root + tol, t1)
            x_after = sol.sol(t)
            if not np.all(np.isfinite(x_after)):
                raise IntegrationError(f"{self.method}: non-finite state at an event, t = {t}")
            events += 1
            if events > _MAX_EVENTS_PER_STEP:
                raise IntegrationError(f"more than {_MAX_EVENTS_PER_STEP} events in one step")
            x = system.handle_events(t, x_after, fired)
        return x, events

    @staticmethod
    def _event_functions(system):
        directions = system.guard_directions()
        cache: dict = {}

        def guards(t, x):
            key = (t, x.tobytes())
            if cache.get("key") != key:
                cache["key"], cache["g"] = key, system.guards(t, x)
            return cache["g"]

        functions = []
        for i, direction in enumerate(directions):

            def event(t, x, i=i):
                # our guards hold while >= 0 and fire when < 0; SciPy would also fire on
                # a guard resting at exactly 0 (a released brake), so a zero counts as +0
                g = guards(t, x)[i]
                return g if g != 0.0 else 1e-300

            event.terminal = True
            event.direction = float(direction)
            functions.append(event)
        return functions


SOLVERS = {
    "rk4": lambda s: RK4(s),
    "ros2": lambda s: ROS2(s),
    "radau": lambda s: ScipySolver(s, "Radau"),
    "bdf": lambda s: ScipySolver(s, "BDF"),
    "lsoda": lambda s: ScipySolver(s, "LSODA"),
    "rk45": lambda s: ScipySolver(s, "RK45"),
    "dop853": lambda s: ScipySolver(s, "DOP853"),
}


def make_solver(settings: SolverSettings):
    """A fresh solver object for ``settings`` (raises ValueError if unknown)."""
    try:
        factory = SOLVERS[settings.method]
    except KeyError:
        raise ValueError(
            f"solver {settings.method!r} is unknown; choose one of {sorted(SOLVERS)}"
        ) from None
    return factory(settings)
