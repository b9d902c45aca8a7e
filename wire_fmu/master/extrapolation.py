"""What value a connection holds over a macro step.

FMUs made with pythonfmu cannot take input derivatives, so every input is
held constant over a step. The held value is the *average over the step*
of a polynomial through the source's recent values: holding that average
(the step's midpoint value, for a line) is what makes linear extrapolation
second order (SPEC section 15).

``constant``
    the source's value at the start of the step (order 1); in a
    Gauss-Seidel sweep after the source has stepped, its newest value.
``linear``
    the line through the last two values, averaged over the step, i.e.
    held at the midpoint (order 2); with the source's new value known
    (Gauss-Seidel), the average of the old and new values.
``quadratic``
    the parabola through the last three values (or two and the new one),
    averaged over the step by Simpson's rule, exact for a parabola.

With fewer past values than a scheme needs (at the start, after a reset)
the order drops accordingly; so it does where the past values are closer together
than half the step (:data:`MIN_SPACING`: after a step shortened to a mode change),
which a polynomial through them would turn into a wild extrapolation.

A ramped flow (a bond wired with ``run.ramped_flows``, :func:`ramp`) is not held:
the effort side takes its value at the step's start and its slope over the step,
the same polynomial's change from the step's start to its end divided by the step,
with the start chosen so that the ramp's average over the step is the held value
above. The position the effort side integrates from the flow therefore ends the step
where a held flow would take it, and the flow itself ends it at the polynomial's end
value (exactly, for a line): a feedthrough output that depends on the flow (a rope's
damper) no longer sees the step's average at the step's end.

An interface model's links (a port's stiffness, damping, effort rate and
reference motion) and the effort of their bond are never extrapolated: the
scene holds them ``constant`` whatever the run's scheme
(:data:`~wire_fmu.master.scene.data.HELD`), since they are the coefficients
of a model the flow side integrates its step against, taken about one
instant; a trend extrapolated on top would count the model's own rate twice.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping

__all__ = ["History", "held_value", "push_all", "ramp", "SCHEME_POINTS"]

SCHEME_POINTS = {"constant": 1, "linear": 2, "quadratic": 3}
MIN_SPACING = 0.5
"""Past values closer together than this many steps are not extrapolated from: a line
through two values ``d`` apart carried over a step ``H`` multiplies their difference by
``H / d`` (after a step shortened to a unit's mode change, ``d`` may be microseconds)."""


class History:
    """The last values of one source output at accepted macro-step times."""

    def __init__(self, size: int = 3) -> None:
        self.points: deque[tuple[float, float]] = deque(maxlen=size)
        """Oldest first; changed in place, never replaced (input plans keep it)."""

    def push(self, t: float, value: float) -> None:
        """Record the value at an accepted step end.

        Parameters
        ----------
        t : float
            Time of the step end, s; a time not after the newest replaces it.
        value : float
            The output's value there, in its unit.
        """
        push_all({"": self}, {"": value}, t)

    def reset(self) -> None:
        """Forget all but the latest value (after a mode change or an event)."""
        while len(self.points) > 1:
            self.points.popleft()

    @property
    def latest(self) -> float:
        """The newest value."""
        return self.points[-1][1]


def push_all(histories: Mapping[str, History], values: Mapping[str, float], t: float) -> None:
    """:meth:`History.push` of each history's new value, all at ``t``.

    The master calls this at every accepted step, so the loop is written out here
    once rather than as a method call per source.

    Parameters
    ----------
    histories : mapping of str to History
        Histories by source key (``"unit.variable"``).
    values : mapping of str to float
        New values by source key, in their units; a history whose key is not among
        them is left as it is.
    t : float
        Time of the step end, s; a time not after a history's newest replaces it.
    """
    for key, history in histories.items():
        value = values.get(key)
        if value is None:
            continue
        points = history.points
        if points and t <= points[-1][0]:
            points[-1] = (t, value)
        else:
            points.append((t, value))


def _lagrange(points: list[tuple[float, float]], t: float) -> float:
    total = 0.0
    for i, (ti, yi) in enumerate(points):
        weight = 1.0
        for j, (tj, _) in enumerate(points):
            if j != i:
                weight *= (t - tj) / (ti - tj)
        total += weight * yi
    return total


def _line(t0: float, y0: float, t1: float, y1: float, t: float) -> float:
    """:func:`_lagrange` through two points, operation for operation (the same bits)."""
    return 0.0 + (t - t1) / (t0 - t1) * y0 + (t - t0) / (t1 - t0) * y1


def held_value(
    history: History, t: float, step: float, scheme: str, fresh: float | None = None
) -> float:
    """The value to hold over ``[t, t + step]``.

    Parameters
    ----------
    history : History
        Past values of the source; its latest is at ``t``.
    t, step : float
        Step start and length, s.
    scheme : str
        ``"constant"``, ``"linear"`` or ``"quadratic"``.
    fresh : float, optional
        The source's value at ``t + step`` when it has already stepped
        (Gauss-Seidel, iteration).

    Returns
    -------
    float
        The value to hold, in the source's unit.
    """
    need = SCHEME_POINTS[scheme]
    points = history.points
    if need == 1 and points:  # the two common cases first: called for every link and step
        return points[-1][1] if fresh is None else fresh
    if need == 2 and points:
        if fresh is not None:
            t0, y0 = points[-1]
            return _line(t0, y0, t + step, fresh, t + 0.5 * step)
        if len(points) == 1:
            return points[-1][1]
        (t0, y0), (t1, y1) = points[-2], points[-1]
        if t1 - t0 >= MIN_SPACING * step:
            return _line(t0, y0, t1, y1, t + 0.5 * step)
    if fresh is not None and scheme == "constant":
        return fresh
    pts = _polynomial(history, t, step, scheme, fresh)
    if len(pts) == 1:
        return pts[0][1]
    if len(pts) == 2:
        return _lagrange(pts, t + 0.5 * step)
    return (
        _lagrange(pts, t) + 4.0 * _lagrange(pts, t + 0.5 * step) + _lagrange(pts, t + step)
    ) / 6.0


def _polynomial(
    history: History, t: float, step: float, scheme: str, fresh: float | None
) -> list[tuple[float, float]]:
    """The points the scheme's polynomial over ``[t, t + step]`` goes through, oldest first:
    the newest (``fresh`` at ``t + step`` when given), then going back each point at least
    :data:`MIN_SPACING` steps before the one after it."""
    need = SCHEME_POINTS[scheme]
    chosen = [(t + step, fresh)] if fresh is not None else []
    for point in reversed(history.points):
        if len(chosen) == need:
            break
        if not chosen or chosen[-1][0] - point[0] >= MIN_SPACING * step:
            chosen.append(point)
    return chosen[::-1]


def ramp(
    history: History, t: float, step: float, scheme: str, fresh: float | None = None
) -> tuple[float, float]:
    """The ramp to set over ``[t, t + step]``: its value at ``t`` and its slope.

    The slope is the scheme's polynomial's change over the step divided by the step;
    the value at ``t`` is :func:`held_value` less half the change, so that the ramp's
    average over the step is the held value (see the module docstring). ``constant``
    gives a slope of 0 and the held value.

    Parameters
    ----------
    history, t, step, scheme, fresh
        As for :func:`held_value`.

    Returns
    -------
    start : float
        The value at ``t``, in the source's unit.
    slope : float
        Its rate of change over the step, in the source's unit per second.
    """
    points = history.points
    if scheme == "linear" and points and points[-1][0] == t:  # the common case, every step:
        t1, y1 = points[-1]  # held_value's line through the same points, written out here
        if fresh is not None:
            slope = (fresh - y1) / step
            average = _line(t1, y1, t + step, fresh, t + 0.5 * step)
            return average - 0.5 * slope * step, slope
        if len(points) > 1 and t - points[-2][0] >= MIN_SPACING * step:
            t0, y0 = points[-2]
            slope = (y1 - y0) / (t - t0)
            average = _line(t0, y0, t1, y1, t + 0.5 * step)
            return average - 0.5 * slope * step, slope
    average = held_value(history, t, step, scheme, fresh)
    points = _polynomial(history, t, step, scheme, fresh)
    if len(points) < 2 or step <= 0.0:
        return average, 0.0
    change = _lagrange(points, t + step) - _lagrange(points, t)
    return average - 0.5 * change, change / step
