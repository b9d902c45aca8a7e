"""The block train's interface model in its compiled kernel: every port in one call.

The same forward differences as
:func:`~wire_fmu.core.units.block_train.interface.port_linearisations` (the readable
reference, which says what they mean), in the same order and with the same
arithmetic, over :func:`.kernel.summary`: one base evaluation and four per port, at
every step's end, without a crossing back to Python between them.

A port is one row of ``slots``:

=====  ============  =======================================================
index  name          contents
=====  ============  =======================================================
0      ``position``  index of the port's position in the held-input vector
1      ``rate``      index of its rate there
2      ``sign``      held value = sign x the port's own variable
3      ``tension``   span whose tension is the effort, or -1
4      ``body``      body whose force is the effort, or -1
5      ``ramp``      index of its rate's acceleration there
=====  ============  =======================================================
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.units.block_train.kernel import summary

jit = kernel_decorators(__file__).jit

__all__ = ["port_linearisations"]


@jit
def _pick(values: np.ndarray, n_spans: int, slot: np.ndarray) -> float:
    """The port's effort (N) among :func:`.kernel.summary`'s ``values``; NaN if the
    model could not be evaluated."""
    if not math.isfinite(values[0]):
        return math.nan
    span, body = int(slot[3]), int(slot[4])
    return values[2 + span] if span >= 0 else values[2 + n_spans + body]


@jit
def _effort(t: float, x: np.ndarray, data, held: np.ndarray, slot: np.ndarray) -> float:
    """The port's effort (N) at ``(t, x)`` with held inputs ``held`` (see :func:`_pick`)."""
    return _pick(summary(t, x, data[:11] + (held,) + data[12:]), data[3].size, slot)


@jit
def port_linearisations(
    t: float,
    x: np.ndarray,
    data,
    slots: np.ndarray,
    relative_step: float,
    time_step: float,
) -> np.ndarray:
    """Every port's effort linearised at ``(t, x)``.

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State; left as it is.
    data : tuple
        See :mod:`.kernel`; its held inputs are those of the last step.
    slots : numpy.ndarray
        One row a port (see the module docstring).
    relative_step : float
        Differencing step of a position or velocity, relative to ``max(1, |value|)``.
    time_step : float
        Differencing step of the time, s.

    Returns
    -------
    numpy.ndarray
        One row a port: stiffness (N/m), damping (N s/m), effort rate (N/s),
        reference position (m), reference velocity (m/s); NaN everywhere when an
        evaluation failed (the Python reference then names why).
    """
    held = data[11]
    out = np.empty((slots.shape[0], 5))
    elapsed = t - held[0]
    base = summary(t, x, data)
    n = data[0][0]
    moved = x.copy()  # the coordinates moved on at their velocities
    moved[:n] += time_step * x[n : 2 * n]
    for p in range(slots.shape[0]):
        slot = slots[p]
        position_at, rate_at, sign, ramp_at = int(slot[0]), int(slot[1]), slot[2], int(slot[5])
        acceleration = held[ramp_at]
        rate = held[rate_at] + acceleration * elapsed  # the held rate at t
        effort = _pick(base, data[3].size, slot)
        # d/d position: the held position moves, so the position at t does too
        travel = (held[rate_at] + 0.5 * acceleration * elapsed) * elapsed
        position = sign * (held[position_at] + travel)
        step = relative_step * max(1.0, abs(position))
        up = held.copy()
        up[position_at] += sign * step
        d_position = (_effort(t, x, data, up, slot) - effort) / step
        # d/d velocity at the same position at t
        step = relative_step * max(1.0, abs(rate))
        up = held.copy()
        up[rate_at] += sign * step
        up[position_at] -= sign * step * elapsed
        d_velocity = (_effort(t, x, data, up, slot) - effort) / step
        # d/d t with this port still where it is at t
        still = held.copy()
        still[position_at] += travel
        still[rate_at] = 0.0
        still[ramp_at] = 0.0
        later = _effort(t + time_step, moved, data, still, slot) - effort
        now = _effort(t, x, data, still, slot) - effort
        out[p, 0] = -d_position
        out[p, 1] = -d_velocity
        out[p, 2] = (later - now) / time_step
        out[p, 3] = position
        out[p, 4] = sign * rate
        if not math.isfinite(effort + d_position + d_velocity + later + now):
            out[:] = math.nan
            return out
    return out
