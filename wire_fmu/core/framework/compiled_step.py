"""The fixed-step solvers of :mod:`~wire_fmu.core.framework.fixed_step`, compiled.

The same algorithm, step for step: ``ceil(H / max_step)`` equal steps of RK4 or
ROS2 (finite-difference Jacobian at the start of every interval, the
``(I - g h J)`` inverse kept while the step length stays), every guard crossing
located by Illinois regula falsi. What changes is where it runs: a unit's
compiled kernel gives plain functions

``rhs(t, x, data) -> x'``, ``guards(t, x, data) -> g``,
``rhs_guards(t, x, data) -> (x', g)`` (both from one evaluation of the model) and
``project(x, data) -> x``

over a tuple ``data`` of arrays (parameters, modes, held inputs), the linear
algebra of ROS2 (the ``dense_*`` functions here, or a structured set of its own
such as the block train's bordered band), and a cached entry point of its own
that calls :func:`advance_to_event` (dense) or :func:`advance_structured` with
them. The linear algebra is four functions:

``linearise(rhs, t, x, data) -> (J, evaluations)``, ``unlinearised(data) -> J``
(an empty ``J`` of the same type), ``factor(J, g h, data) -> F`` (empty for a NaN
``g h``) and ``solve(F, b, data) -> (I - g h J)^-1 b``.

Every state the loop reaches is evaluated once where it can be: the derivative and the
guards at the start come from one ``rhs_guards``, and so do the guards at the end of
a step and the first stage of the next (the guards alone at the end of the last step,
and a first stage of its own where ``t + h`` and the grid's ``t_next`` differ in their
last bit). The event location's trial steps start from that same first stage.

The compiled loop returns at the end of the step or at the first located event;
:class:`CompiledFixedStep` then lets the Python model switch its mode (and say
so in words) and calls the loop again. Nothing here allocates per step beyond
numpy temporaries inside the compiled code.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.framework.fixed_step import RK4, ROS2, FixedStepSolver
from wire_fmu.core.framework.step_limits import (
    MAX_EVENTS_PER_STEP,
    IntegrationError,
    internal_step_count,
)

jit, jit_inline = kernel_decorators(__file__)

if TYPE_CHECKING:
    from wire_fmu.core.framework.hybrid import SolverSettings

__all__ = [
    "COMPILED_METHODS",
    "CompiledFixedStep",
    "KernelModel",
    "STATUS_DONE",
    "STATUS_EVENT",
    "STATUS_NONFINITE",
    "STATUS_PYTHON",
    "advance_structured",
    "advance_to_event",
    "any_fired",
    "dense_factor",
    "dense_linearise",
    "dense_solve",
    "dense_unlinearised",
]

COMPILED_METHODS = {"rk4": 0, "ros2": 1}
"""Fixed-step methods the compiled loop offers, by name: their codes."""
_RK4, _ROS2 = COMPILED_METHODS["rk4"], COMPILED_METHODS["ros2"]
_GAMMA = ROS2.GAMMA
_MAX_LOCATE_ITERATIONS = 60

STATUS_DONE = 0
"""The loop reached the end of the communication step."""
STATUS_EVENT = 1
"""The loop stopped just after the first guard crossing it located."""
STATUS_NONFINITE = 2
"""A step gave a non-finite state; the loop returns the state it started that step from."""
STATUS_PYTHON = 3
"""A kernel's one-call ``quiet_step`` left the step to Python (a mode to settle first)."""


@jit
def _crossed(before: float, after: float, direction: float) -> bool:
    """Whether a guard crossed from ``before`` to ``after`` (see ``fixed_step._fired``):
    downwards through 0 from ``>= 0`` for direction -1, else a change of sign from nonzero."""
    if direction < 0:
        return before >= 0.0 and after < 0.0
    return np.sign(before) != np.sign(after) and before != 0.0


@jit
def _fired(g0: np.ndarray, g1: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Guards that crossed between two evaluations (:func:`_crossed`, one per guard)."""
    out = np.zeros(g0.size, dtype=np.bool_)
    for i in range(g0.size):
        out[i] = _crossed(g0[i], g1[i], directions[i])
    return out


@jit
def any_fired(g0: np.ndarray, g1: np.ndarray, directions: np.ndarray) -> bool:
    """Whether any guard crossed between two evaluations (:func:`_fired`, no array made).

    Parameters
    ----------
    g0, g1 : numpy.ndarray
        The guards at the start and the end of a step.
    directions : numpy.ndarray
        Guard directions (-1 fires downwards, 0 on any crossing).
    """
    for i in range(g0.size):
        if _crossed(g0[i], g1[i], directions[i]):
            return True
    return False


@jit_inline
def _jacobian(rhs, t: float, x: np.ndarray, data) -> np.ndarray:
    """Forward-difference Jacobian (see ``fixed_step.finite_difference_jacobian``)."""
    n = x.size
    jac = np.zeros((n, n))
    if n == 0:
        return jac
    f0 = rhs(t, x, data)
    for j in range(n):
        dx = 1e-7 * max(1.0, abs(x[j]))
        xp = x.copy()
        xp[j] += dx
        fj = rhs(t, xp, data)
        for i in range(n):
            jac[i, j] = (fj[i] - f0[i]) / dx
    return jac


@jit_inline
def dense_linearise(rhs, t: float, x: np.ndarray, data):
    """The forward-difference Jacobian of every state and the evaluations it took."""
    return _jacobian(rhs, t, x, data), x.size + 1


@jit
def dense_unlinearised(data) -> np.ndarray:
    """No Jacobian yet (an empty matrix)."""
    return np.zeros((0, 0))


@jit
def dense_factor(jac: np.ndarray, gh: float, data) -> np.ndarray:
    """``(I - gh J)^-1`` (empty for a NaN ``gh`` or an empty ``J``)."""
    n = jac.shape[0]
    if n == 0 or math.isnan(gh):
        return np.zeros((0, 0))
    # numpy's inv solves W X = I (LAPACK gesv); so does this, for the same numbers
    return np.ascontiguousarray(np.linalg.solve(np.eye(n) - gh * jac, np.eye(n)))


@jit
def dense_solve(w_inv: np.ndarray, b: np.ndarray, data) -> np.ndarray:
    """``W^-1 b`` with the inverse of :func:`dense_factor`."""
    return w_inv @ b


@jit_inline
def _step(rhs, solve, method: int, t: float, x: np.ndarray, h: float, fac, data, f0):
    """One RK4 step, or one ROS2 step with the factors ``fac`` of ``I - g h J``, from
    ``(t, x)`` where the derivative is ``f0`` (``rhs(t, x, data)``, evaluated already)."""
    if method == _RK4:
        # the stages' states written into one array (numpy's operations, element by
        # element: three arrays fewer to make per step)
        stage = np.empty_like(x)
        half = 0.5 * h
        k1 = f0
        for i in range(x.size):
            stage[i] = x[i] + half * k1[i]
        k2 = rhs(t + 0.5 * h, stage, data)
        for i in range(x.size):
            stage[i] = x[i] + half * k2[i]
        k3 = rhs(t + 0.5 * h, stage, data)
        for i in range(x.size):
            stage[i] = x[i] + h * k3[i]
        k4 = rhs(t + h, stage, data)
        sixth = h / 6.0
        for i in range(x.size):
            stage[i] = x[i] + sixth * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        return stage
    if x.size == 0:
        return x
    k1 = solve(fac, f0, data)
    k2 = solve(fac, rhs(t + h, x + h * k1, data) - 2.0 * k1, data)
    return x + h * (1.5 * k1 + 0.5 * k2)


@jit_inline
def _refactor(factor, method: int, jac, h: float, w_h: float, fac, data):
    """Factors of ``I - g h J`` for ``h``, reusing ``fac`` if it was made for the same ``h``."""
    if method != _ROS2 or h == w_h:
        return fac, w_h
    return factor(jac, _GAMMA * h, data), h


@jit
def _all_finite(x: np.ndarray) -> bool:
    for value in x:
        if not math.isfinite(value):
            return False
    return True


@jit
def _stage_calls(method: int, x: np.ndarray) -> int:
    """Right-hand-side evaluations one step makes (as the Python solvers count them)."""
    if method == _RK4:
        return 4
    return 0 if x.size == 0 else 2


@jit_inline
def advance_to_event(
    rhs, guards, rhs_guards, project, method, t0, t1, n, k, t, x, directions, tol, data
):
    """:func:`advance_structured` with the ``dense_*`` linear algebra (every state
    differenced, ``I - g h J`` inverted): for the units of a few states."""
    return advance_structured(
        rhs,
        guards,
        rhs_guards,
        project,
        dense_linearise,
        dense_unlinearised,
        dense_factor,
        dense_solve,
        method,
        t0,
        t1,
        n,
        k,
        t,
        x,
        directions,
        tol,
        data,
    )


@jit_inline
def advance_structured(
    rhs,
    guards,
    rhs_guards,
    project,
    linearise,
    unlinearised,
    factor,
    solve,
    method,
    t0,
    t1,
    n,
    k,
    t,
    x,
    directions,
    tol,
    data,
):
    """Integrate from ``(t, x)`` on interval ``k`` of ``n`` equal steps of ``[t0, t1]``.

    Parameters
    ----------
    rhs, guards, rhs_guards, project : compiled functions
        The unit's kernel (see the module docstring).
    linearise, unlinearised, factor, solve : compiled functions
        ROS2's linear algebra (see the module docstring), e.g. the ``dense_*`` functions.
    method : int
        A value of :data:`COMPILED_METHODS`.
    t0, t1 : float
        The communication step, s.
    n : int
        Number of equal internal steps over ``[t0, t1]``.
    k : int
        Index of the internal step ``t`` lies in (``t`` may be an event time inside it).
    t : float
        Time to start from, s.
    x : numpy.ndarray
        State at ``t``.
    directions : numpy.ndarray
        Guard directions (-1 fires downwards, 0 on any crossing).
    tol : float
        Event time tolerance, s.
    data : tuple
        The unit's parameters, modes and held inputs.

    Returns
    -------
    tuple
        ``(status, x, t, k, fired, steps, rhs_calls, h)``: a ``STATUS_*`` code; the
        state and time reached (just after the event, or where a non-finite step
        started); the interval index; the fired guards (bool mask); the steps taken
        and right-hand sides evaluated; the length of the last step tried, s.
    """
    steps = 0
    calls = 0
    jac = unlinearised(data)
    if method == _ROS2:
        jac, evaluations = linearise(rhs, t, x, data)
        calls += evaluations
    w_h = math.nan
    fac = factor(jac, w_h, data)
    f0, g0 = rhs_guards(t, x, data)  # the first stage and the guards: one evaluation
    no_fire = np.zeros(g0.size, dtype=np.bool_)
    while k < n:
        t_next = t0 + (t1 - t0) * (k + 1) / n
        h = t_next - t
        fac, w_h = _refactor(factor, method, jac, h, w_h, fac, data)
        x1 = project(_step(rhs, solve, method, t, x, h, fac, data, f0), data)
        steps += 1
        calls += _stage_calls(method, x)
        if not _all_finite(x1):
            return STATUS_NONFINITE, x, t, k, no_fire, steps, calls, h
        if g0.size == 0:
            t, x = t_next, x1
            k += 1
            if k < n:
                f0 = rhs(t, x, data)
            continue
        # the guards at the step's end and the next step's first stage: one evaluation,
        # unless there is no next step or the grid's time differs from t + h
        fused = k + 1 < n and t + h == t_next
        if fused:
            f1, g1 = rhs_guards(t + h, x1, data)
        else:
            f1, g1 = f0, guards(t + h, x1, data)
        if not any_fired(g0, g1, directions):
            t, x, g0 = t_next, x1, g1
            k += 1
            if k < n:
                f0 = f1 if fused else rhs(t, x, data)
            continue
        mask = _fired(g0, g1, directions)
        # Illinois regula falsi on the step fraction, for the earliest crossing
        lo, hi = 0.0, 1.0
        x_hi = x1
        g_lo, g_hi = g0, g1
        frac_tol = tol / h
        side = 0
        for _ in range(_MAX_LOCATE_ITERATIONS):
            if hi - lo <= frac_tol:
                break
            theta = math.inf
            for i in range(mask.size):
                if mask[i]:
                    a, b = g_lo[i], g_hi[i]
                    est = lo + (hi - lo) * a / (a - b) if a != b else 0.5 * (lo + hi)
                    theta = min(theta, est)
            theta = min(max(theta, lo + 0.05 * frac_tol), hi - 0.05 * frac_tol)
            fac, w_h = _refactor(factor, method, jac, theta * h, w_h, fac, data)
            x_mid = project(_step(rhs, solve, method, t, x, theta * h, fac, data, f0), data)
            steps += 1
            calls += _stage_calls(method, x)
            if not _all_finite(x_mid):
                return STATUS_NONFINITE, x, t, k, no_fire, steps, calls, theta * h
            g_mid = guards(t + theta * h, x_mid, data)
            crossed = _fired(g0, g_mid, directions)
            if crossed.any():
                hi, x_hi, g_hi, mask = theta, x_mid, g_mid, crossed
                if side == 1:
                    g_lo = g_lo.copy()
                    for i in range(mask.size):
                        if mask[i]:
                            g_lo[i] *= 0.5
                side = 1
            else:
                lo, g_lo = theta, g_mid
                if side == -1:
                    g_hi = g_hi.copy()
                    for i in range(mask.size):
                        if mask[i]:
                            g_hi[i] *= 0.5
                side = -1
        return STATUS_EVENT, x_hi, t + hi * h, k, mask, steps, calls, hi * h
    return STATUS_DONE, x, t, k, no_fire, steps, calls, 0.0


class CompiledFixedStep(FixedStepSolver):
    """RK4 or ROS2 over a unit's compiled kernel, with events handled by the Python model.

    Parameters
    ----------
    settings : SolverSettings
        ``method`` a key of :data:`COMPILED_METHODS`.
    entry : callable
        The unit's compiled entry point: :func:`advance_to_event` with its kernel
        bound, called as ``entry(method, t0, t1, n, k, t, x, directions, tol, data)``.
    """

    def __init__(self, settings: SolverSettings, entry: Callable[..., Any]) -> None:
        super().__init__(settings)
        self.entry = entry
        self.method = COMPILED_METHODS[settings.method]
        self._python = RK4(settings) if settings.method == "rk4" else ROS2(settings)

    def internal_count(self, t0: float, t1: float) -> int:
        """The number of equal internal steps the loop takes over ``[t0, t1]`` (s)."""
        return internal_step_count(t0, t1, self.settings.max_step)

    def advance(
        self, system, t0: float, x0: np.ndarray, t1: float, first: tuple | None = None
    ) -> tuple[np.ndarray, int]:
        """Integrate from ``t0`` to ``t1``; return the state and the number of events.

        Implements :meth:`FixedStepSolver.advance`; ``system`` also offers
        ``kernel_data()``, the tuple its compiled functions take.

        Parameters
        ----------
        system : HybridSystem
            The model, with its compiled kernel.
        t0, t1 : float
            The communication step, s.
        x0 : numpy.ndarray
            State at ``t0``.
        first : tuple, optional
            What a kernel's one-call step already returned for the first stretch
            from ``(t0, x0)`` (the entry point's answer): the loop goes on from there.
        """
        n = self.internal_count(t0, t1)
        tol = self.settings.event_time_tolerance
        t, x, k, events = t0, np.array(x0, dtype=float), 0, 0
        directions = np.asarray(system.guard_directions(), dtype=float)
        while k < n:
            if first is not None:
                (status, x, t_hit, k, mask, steps, calls, h), first = first, None
            else:
                status, x, t_hit, k, mask, steps, calls, h = self.entry(
                    self.method, t0, t1, n, k, t, x, directions, tol, system.kernel_data()
                )
            self.steps += steps
            self.rhs_calls += calls
            if status == STATUS_DONE:
                break
            if status == STATUS_NONFINITE:
                self._explain_nonfinite(system, t_hit, x, h)
            events += 1
            if events > MAX_EVENTS_PER_STEP:
                raise IntegrationError(f"more than {MAX_EVENTS_PER_STEP} events in one step")
            x = system.handle_events(t_hit, x, [int(i) for i in np.flatnonzero(mask)])
            directions = np.asarray(system.guard_directions(), dtype=float)
            t_next = t0 + (t1 - t0) * (k + 1) / n
            t = t_hit
            if t >= t_next - tol:
                t, k = t_next, k + 1
            if k >= n and self.method == COMPILED_METHODS["ros2"]:
                # the Python solver's Jacobian after the last event
                self.rhs_calls += system.jacobian_evaluations(x)
        return x, events

    def preload(self, system, t: float, x: np.ndarray) -> None:
        """Load the compiled loop now, by a call that takes no step (interval 1 of 1).

        The first call of a compiled function loads it from the on-disk cache (tens of
        milliseconds for a kernel's loop); made at initialisation, that cost is part of
        the start, not of the first step.

        Parameters
        ----------
        system : HybridSystem
            The model, with its compiled kernel.
        t : float
            The present time, s.
        x : numpy.ndarray
            The present state (not changed).
        """
        directions = np.asarray(system.guard_directions(), dtype=float)
        tol = self.settings.event_time_tolerance
        self.entry(self.method, t, t, 1, 1, t, x, directions, tol, system.kernel_data())

    def finish_quiet_step(
        self, system, t0: float, x0: np.ndarray, t1: float, result: tuple
    ) -> tuple[np.ndarray, int, np.ndarray | None]:
        """Book what a kernel's one-call ``quiet_step`` returned; go on from its event, if any.

        Call it once the model holds the step's inputs and modes (the status is not
        :data:`STATUS_PYTHON`).

        Parameters
        ----------
        system : HybridSystem
            The model, with its compiled kernel.
        t0, t1 : float
            The communication step, s.
        x0 : numpy.ndarray
            State at ``t0``.
        result : tuple
            ``quiet_step``'s answer: the loop's ``(status, x, t, k, fired, steps,
            rhs_calls, h)`` and the values the outputs need at ``t1``.

        Returns
        -------
        tuple
            The state at ``t1``, the number of events and the outputs' values (None
            after an event: the model computes them).
        """
        if result[0] == STATUS_DONE:
            self.steps += result[5]
            self.rhs_calls += result[6]
            return result[1], 0, result[8]
        x, events = self.advance(system, t0, x0, t1, result[:8])
        return x, events, None

    def _explain_nonfinite(self, system, t: float, x: np.ndarray, h: float) -> None:
        """Re-take the failed step with the Python kernel, which raises the error it names."""
        with system.python_kernel():
            self._python._on_new_interval(system, t, x)
            self._python._checked_step(system, t, x, h)
        raise IntegrationError(f"non-finite state after a step of {h:.3g} s at t = {t:.6g} s")


class KernelModel:
    """What a model with a compiled kernel shares (a mixin).

    The model sets :attr:`compiled` when it is built and names its kernel module
    in :attr:`KERNEL` (which offers ``kernel_data(model)`` and the entry point
    ``resume``, the loop of :func:`advance_structured` going on from an event, called
    as ``advance`` is); its ``rhs``/``guards`` hand over to the kernel while
    :attr:`compiled` is True.
    """

    KERNEL: ModuleType
    compiled: bool = False

    def kernel_data(self) -> tuple:
        """The tuple of arrays the compiled kernel takes, for the present modes and inputs."""
        return self.KERNEL.kernel_data(self)

    def preload_kernel(self, t: float) -> None:
        """Load the compiled step from the cache now rather than in the first step
        (:meth:`CompiledFixedStep.preload`); nothing without one.

        Parameters
        ----------
        t : float
            The present time, s.
        """
        solver = getattr(self, "solver", None)
        if isinstance(solver, CompiledFixedStep):
            solver.preload(self, t, self.state)

    def jacobian_evaluations(self, x: np.ndarray) -> int:
        """Right-hand sides ROS2 evaluates for one Jacobian at state ``x`` (all differenced)."""
        return x.size + 1

    @contextmanager
    def python_kernel(self) -> Iterator[None]:
        """Evaluate with the Python kernel inside the ``with`` block."""
        compiled, self.compiled = self.compiled, False
        try:
            yield
        finally:
            self.compiled = compiled

    def resume_entry(self) -> Callable[..., tuple]:
        """What :class:`CompiledFixedStep` calls to go on after an event: the kernel's
        ``resume`` (a model whose kernel has one entry point for all it does passes
        through that instead)."""
        return self.KERNEL.resume

    def kernel_solver(self, settings: SolverSettings):
        """The compiled fixed-step loop over the kernel when compiled and the method has one,
        else the Python solver.

        Parameters
        ----------
        settings : SolverSettings
            The solver's settings.
        """
        from wire_fmu.core.framework.hybrid import make_solver

        if self.compiled and settings.method in COMPILED_METHODS:
            return CompiledFixedStep(settings, self.resume_entry())
        return make_solver(settings)
