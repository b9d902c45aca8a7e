"""A communication step in which nothing happens, compiled in one call that makes its arrays once.

What :meth:`RefinedStepping._quiet_step
<wire_fmu.core.units.hydraulics.stepping.RefinedStepping._quiet_step>` asks of the
kernel: check the limits, settle the seal (project), integrate over ``[t0, t1]`` as
:class:`~wire_fmu.core.framework.compiled_step.CompiledFixedStep` would (``n`` equal
steps of RK4 or ROS2, ROS2's finite-difference Jacobian at the start and its
``(I - g h J)^-1`` made again whenever the step length changes), and report the end. As
soon as anything happens (a limit, a breakaway, a guard crossing, a non-finite step) it
gives up and leaves the step to the general path, which locates events.

The steps are those of :func:`~wire_fmu.core.framework.compiled_step.advance_to_event`,
with the same stage arithmetic element for element, but

* the arrays are made once per call and every stage writes into them;
* the few step lengths of the grid (``t_next - t`` differs between steps in its last
  bits) each get their ``(I - g h J)^-1`` once, kept while the call lasts, instead of
  once every time the length changes: the same matrices, made fewer times;
* every state is evaluated once: the guards at the end of a step, the first stage of the
  next and the report at the end of the communication step come from one evaluation, as
  do the limits, the Jacobian's base point, the first guards and the first stage at the
  start (the shared loop shares the first two and the start's guards and first stage
  too; where ``t + h`` and the grid's ``t_next`` differ in their last bit, both
  evaluate the next first stage again at ``t_next``: with the interface model's rate the
  right-hand side depends on time);
* the products with ``(I - g h J)^-1`` go into those arrays (the same BLAS ``gemv``).

The results are those of the shared loop to the last bit: the same numbers in the same
operations in the same order (the products and the inverse through the same BLAS and
LAPACK routines). That matters beyond rounding: the located events, and so everything
after the next event, depend on every bit of the state the quiet steps leave.
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.framework.compiled_step import COMPILED_METHODS, any_fired
from wire_fmu.core.framework.fixed_step import ROS2
from wire_fmu.core.units.hydraulics.kernel_arrays import (
    H_FORCE,
    H_REFERENCE_EXTENSION,
    H_STIFFNESS,
    L_DISSIPATED,
    L_INTERFACE_WORK,
    P_STROKE,
    QUIET_OUTPUTS,
    REPORT,
)
from wire_fmu.core.units.hydraulics.kernel_hybrid import (
    breaks_away,
    evaluate_into,
    first_limit,
    guard_count,
    hold,
    report_into,
    slope_into,
)
from wire_fmu.core.units.hydraulics.kernel_physics import (
    Cylinder,
    cylinder,
    seal_stuck,
)

jit = kernel_decorators(__file__).jit

__all__ = ["quiet_step", "quiet_step_outputs"]

_ROS2 = COMPILED_METHODS["ros2"]
_GAMMA = ROS2.GAMMA
_VECTORS = 7
"""Rows of the work vectors: state, next state, slope at the state, stage state and three
stage slopes (ROS2: ``k1``, ``f(stage) - 2 k1``, ``k2``; RK4: ``k2``, ``k3``, ``k4``)."""
_KEPT = 4
"""How many ``(I - g h J)^-1`` a call keeps, one per step length (the grid of a
communication step usually has two or three)."""


@jit
def _jacobian_into(jac, t, x, f0, probe, slope, c: Cylinder) -> None:
    """Forward-difference Jacobian at ``(t, x)`` with ``f0`` the slope there (``_jacobian``)."""
    n = x.size
    for j in range(n):
        dx = 1e-7 * max(1.0, abs(x[j]))
        probe[:] = x
        probe[j] += dx
        slope_into(t, probe, slope, c)
        for i in range(n):
            jac[i, j] = (slope[i] - f0[i]) / dx


@jit
def _w_inverse_into(w_inv, jac, h: float, w, identity) -> None:
    """``(I - g h J)^-1`` into ``w_inv`` as the shared loop makes it (``w``: work).

    LAPACK's ``gesv`` solves ``W X = I``, as ``compiled_step._w_inverse`` and numpy's
    ``inv`` do, so that the steps are the same to the last bit.
    """
    n = jac.shape[0]
    gh = _GAMMA * h
    for i in range(n):
        for j in range(n):
            w[i, j] = identity[i, j] - gh * jac[i, j]
    w_inv[:, :] = np.linalg.solve(w, identity)


@jit
def _kept(lengths: np.ndarray, h: float) -> int:
    """Which kept inverse is for the step length ``h`` (s), -1 if none."""
    for i in range(lengths.size):
        if lengths[i] == h:
            return i
    return -1


@jit
def _ros2_step(out, t, state, slope, h, w_inv, stage, k1, rest, k2, c: Cylinder) -> None:
    """One ROS2 step of length ``h`` from ``(t, state)`` (slope there: ``slope``) into ``out``."""
    n = state.size
    np.dot(w_inv, slope, k1)
    for i in range(n):
        stage[i] = state[i] + h * k1[i]
    slope_into(t + h, stage, rest, c)
    for i in range(n):
        rest[i] = rest[i] - 2.0 * k1[i]
    np.dot(w_inv, rest, k2)
    for i in range(n):
        out[i] = state[i] + h * (1.5 * k1[i] + 0.5 * k2[i])


@jit
def _rk4_step(out, t, state, slope, h, stage, k2, k3, k4, c: Cylinder) -> None:
    """One RK4 step of length ``h`` from ``(t, state)`` (slope there: ``slope``) into ``out``."""
    n = state.size
    half = 0.5 * h
    for i in range(n):
        stage[i] = state[i] + half * slope[i]
    slope_into(t + 0.5 * h, stage, k2, c)
    for i in range(n):
        stage[i] = state[i] + half * k2[i]
    slope_into(t + 0.5 * h, stage, k3, c)
    for i in range(n):
        stage[i] = state[i] + h * k3[i]
    slope_into(t + h, stage, k4, c)
    sixth = h / 6.0
    for i in range(n):
        out[i] = state[i] + sixth * (slope[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@jit
def _finite(x: np.ndarray) -> bool:
    for value in x:
        if not math.isfinite(value):
            return False
    return True


@jit
def quiet_step(method, t0, t1, n, x, directions, data):
    """A communication step in which nothing happens, in one call.

    Parameters
    ----------
    method : int
        A value of ``COMPILED_METHODS``.
    t0, t1 : float
        The communication step, s.
    n : int
        Number of equal internal steps over ``[t0, t1]``.
    x : numpy.ndarray
        State at ``t0`` (not changed).
    directions : numpy.ndarray
        Guard directions.
    data : tuple
        ``(parameters, layout, held)`` (see :mod:`.kernel_arrays`), the seal held where
        ``x`` is.

    Returns
    -------
    tuple
        ``(True, state at t1, report)`` (``kernel_hybrid.report``), or ``(False, x,
        empty)`` when a limit is reached, the seal lets go, a guard fires or a step is not
        finite.
    """
    nothing = np.empty(0)
    c = cylinder(data)
    size = x.size
    vectors = np.empty((_VECTORS, size))
    state, following, slope = vectors[0], vectors[1], vectors[2]
    stage, first, second, third = vectors[3], vectors[4], vectors[5], vectors[6]
    matrices = np.empty((2 + _KEPT, size, size))
    jac, w = matrices[0], matrices[1]
    identity = np.eye(size)
    lengths = np.full(_KEPT, math.nan)  # the step length each kept inverse is for, s
    made = 0
    values = np.empty((2, guard_count(data[1])))
    g0, g1 = values[0], values[1]
    point, acc, link = evaluate_into(t0, x, slope, g0, c)
    if first_limit(g0, c) >= 0 or breaks_away(point.force, c):
        return False, x, nothing
    state[:] = x
    if seal_stuck(c):  # the rod is held where it stuck, at rest: evaluate it there
        hold(state, c)
        point, acc, link = evaluate_into(t0, state, slope, g0, c)
    if method == _ROS2:
        _jacobian_into(jac, t0, state, slope, stage, first, c)
    t = t0
    for k in range(n):
        t_next = t0 + (t1 - t0) * (k + 1) / n
        h = t_next - t
        if method == _ROS2:
            kept = _kept(lengths, h)
            if kept < 0:
                kept = made % _KEPT
                _w_inverse_into(matrices[2 + kept], jac, h, w, identity)
                lengths[kept] = h
                made += 1
            w_inv = matrices[2 + kept]
            _ros2_step(following, t, state, slope, h, w_inv, stage, first, second, third, c)
        else:
            _rk4_step(following, t, state, slope, h, stage, first, second, third, c)
        hold(following, c)
        if not _finite(following):
            return False, x, nothing
        point, acc, link = evaluate_into(t + h, following, slope, g1, c)
        if any_fired(g0, g1, directions):
            return False, x, nothing
        if t + h != t_next:  # the shared loop's next first stage is at the grid's time
            slope_into(t_next, following, slope, c)
        state, following = following, state
        g0, g1 = g1, g0
        t = t_next
    out = np.empty(len(REPORT))
    report_into(out, point, acc, link, c)
    return True, state.copy(), out


@jit
def quiet_step_outputs(
    method, t0, t1, n, x, directions, data, external_work, initial_energy, initial_position
):
    """:func:`quiet_step` from the model's own state, with the rod's work and every output
    a step without events changes (:data:`~.kernel_arrays.QUIET_OUTPUTS`).

    With the interface model (``data``'s layout has its work state) the work state is
    appended at 0 J, integrated with the rest and taken off again; the work through the
    rod is then ``E0 (x1 - x0)``, the spring's exactly and the damper's and rate's as
    integrated (``RefinedStepping._interface_work``), else ``E0 (x1 - x0)``: the
    operations of the Python model, in its order.

    Parameters
    ----------
    method, t0, t1, n, directions, data
        As :func:`quiet_step` takes them.
    x : numpy.ndarray
        The model's own state at ``t0`` (not changed).
    external_work : float
        Work done on the rod since the start, before the step, J.
    initial_energy : float
        Stored energy at the start of the ledger, J.
    initial_position : float
        The rod's extension at the start, where its displacement is 0, m.

    Returns
    -------
    tuple
        ``(taken, state at t1, outputs, finite)``: ``outputs`` in the order of
        ``QUIET_OUTPUTS``, ``finite`` whether all are; ``(False, x, empty, False)`` when
        the step is not quiet (see :func:`quiet_step`).
    """
    parameters, layout, held = data
    work = layout[L_INTERFACE_WORK]
    start = x
    if work >= 0:  # the interface model's work, J, starts at 0
        start = np.zeros(x.size + 1)
        start[: x.size] = x
    taken, state, report = quiet_step(method, t0, t1, n, start, directions, data)
    if not taken:
        return False, x, report, False
    x0, x1 = x[0], state[0]
    if work >= 0:
        varying = state[work]
        state = state[:work].copy()
        x_ref = held[H_REFERENCE_EXTENSION]
        elastic = -0.5 * held[H_STIFFNESS] * (x1 - x0) * ((x1 - x_ref) + (x0 - x_ref))
        external_work += held[H_FORCE] * (x1 - x0) + elastic + varying
    else:
        external_work += held[H_FORCE] * (x1 - x0)
    size = len(REPORT)
    out = np.empty(len(QUIET_OUTPUTS))
    out[:size] = report
    position, stored, dissipated = report[0], report[size - 1], state[layout[L_DISSIPATED]]
    out[size] = position - initial_position
    out[size + 1] = position / parameters[P_STROKE]
    out[size + 2] = dissipated
    out[size + 3] = external_work
    out[size + 4] = stored - initial_energy + dissipated - external_work
    return True, state, out, _finite(out)
