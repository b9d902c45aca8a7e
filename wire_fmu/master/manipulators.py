"""Manipulators: they set unit inputs, and never step anything.

:class:`DriverSet`
    applies the scene's drivers. Over a step ``[t, t + h]`` a driven input
    holds the driver's value at the step's midpoint (second order); a driven
    position with a ``rate_target`` gets its value at ``t`` and the rate
    input the step's mean rate, so a unit that advances the position with
    its rate lands exactly on the driver's value at ``t + h``.
:class:`ScheduledEvents`
    sets inputs to new values from scheduled times on (brake applied at
    12 s, rope breaks at 30 s); the master ends a macro step on each event
    time so the change happens exactly then.
"""

from __future__ import annotations

import logging
import math
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .drivers import make_driver
from .scene import DriverSpec, EventSpec, VarRef
from .step_size import _ns

__all__ = ["DriverSet", "ScheduledEvents"]

logger = logging.getLogger(__name__)


AHEAD = 64
"""Step ends a driver that can evaluate many times at once (``values_at``) is evaluated at
together: the ones of the step under way and of the next ``AHEAD - 1`` steps of its length."""


def _next_steps(t: float, h: float, count: int) -> tuple[list[float], list[float]]:
    """Starts and lengths of the ``count`` steps after ``[t, t + h]``, s.

    As :class:`~wire_fmu.master.simulation.Simulation` computes them: on the
    nanosecond grid of the step under way, each start ``n / 1e9`` and each length
    the next start minus it.
    """
    now, step = _ns(t), _ns(h)
    starts = [(now + j * step) / 1e9 for j in range(1, count + 2)]
    return starts[:-1], [b - a for a, b in zip(starts[:-1], starts[1:], strict=True)]


class _Values:
    """A driver's values over the steps, each computed once.

    Over a step ``[t, t + h]`` a driven position needs the driver's value at
    ``t`` and ``t + h``, and the next step starts at that ``t + h``: the last
    two answers are remembered. A driver that can evaluate many times at once
    (``values_at``: the sea state, a sum of some hundred cosines per value) is
    evaluated at the times the next :data:`AHEAD` steps will ask for, in one
    vectorised call. Drivers are functions of time alone: a remembered or
    precomputed value is the very number the driver gives at that time.
    """

    __slots__ = ("_value", "_values_at", "_last", "_before", "_ahead")

    def __init__(self, driver) -> None:
        self._value = driver.value
        self._values_at = getattr(driver, "values_at", None)
        self._last = self._before = (math.nan, 0.0)  # (time, value) pairs; NaN equals no time
        self._ahead: dict[float, float] = {}

    def at(self, t: float) -> float:
        """The driver's value at ``t`` (s), in the driven input's unit.

        A method, not ``__call__``: calling an instance goes through the type's call slot,
        some thousand machine instructions more than a method call, every step.
        """
        last = self._last
        if t == last[0]:
            return last[1]
        before = self._before
        if t == before[0]:
            return before[1]
        value = self._ahead.get(t)
        if value is None:
            value = self._value(t)
        self._before, self._last = last, (t, value)
        return value

    def step_end(self, t: float, h: float) -> float:
        """The value at the end of the step ``[t, t + h]`` (s); the next steps' ones ahead."""
        end = t + h
        if self._values_at is not None and end not in self._ahead and end != self._last[0]:
            starts, lengths = _next_steps(t, h, AHEAD - 1)
            times = [end, *starts, *(a + b for a, b in zip(starts, lengths, strict=True))]
            times = list(dict.fromkeys(times))  # a step's start is mostly the last one's end
            self._ahead = dict(zip(times, self._values_at(times), strict=True))
        return self.at(end)

    def midpoint(self, t: float, h: float) -> float:
        """The value at the middle of the step ``[t, t + h]`` (s); the next steps' ones ahead."""
        mid = t + 0.5 * h
        if self._values_at is not None and mid not in self._ahead and mid != self._last[0]:
            starts, lengths = _next_steps(t, h, AHEAD - 1)
            times = [mid, *(a + 0.5 * b for a, b in zip(starts, lengths, strict=True))]
            self._ahead = dict(zip(times, self._values_at(times), strict=True))
        return self.at(mid)


@dataclass(frozen=True)
class _Driven:
    driver: Any
    target: VarRef
    rate: VarRef | None
    value: _Values = field(init=False, compare=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "value", _Values(self.driver))


class DriverSet:
    """The scene's drivers, grouped by unit."""

    def __init__(self, specs: tuple[DriverSpec, ...], base_dir: Path) -> None:
        self._by_unit: dict[str, list[_Driven]] = defaultdict(list)
        for i, d in enumerate(specs):
            driver, problems = make_driver(
                d.spec, where=f"driver {i} ({d.target})", base_dir=base_dir
            )
            if problems:
                raise ValueError("; ".join(problems))
            self._by_unit[d.target.unit].append(_Driven(driver, d.target, d.rate_target))

    def values(self, unit: str, t: float, h: float | None) -> dict[str, float]:
        """Input values of ``unit`` for the step ``[t, t + h]`` (``h`` None: at ``t``).

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        t : float
            Start of the step, s.
        h : float or None
            The step, s; None (or 0) gives the values and rates at ``t``.

        Returns
        -------
        dict of str to float
            Value of each driven input by variable name, in its unit: a
            driver's value at the step's midpoint, or, with a rate input, the
            value at ``t`` and the step's mean rate.
        """
        out = {}
        for d in self._by_unit.get(unit, ()):
            if d.rate is None:
                out[d.target.variable] = d.driver.value(t if h is None else t + 0.5 * h)
            else:
                out[d.target.variable] = d.driver.value(t)
                out[d.rate.variable] = (
                    d.driver.rate(t) if not h else (d.driver.value(t + h) - d.driver.value(t)) / h
                )
        return out

    def targets(self, unit: str) -> list[str]:
        """The inputs of ``unit`` that :meth:`step_values` gives values for, in its order.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.

        Returns
        -------
        list of str
            Variable names; a driven position is followed by its rate input.
        """
        names = []
        for d in self._by_unit.get(unit, ()):
            names.append(d.target.variable)
            if d.rate is not None:
                names.append(d.rate.variable)
        return names

    def step_values(self, unit: str, t: float, h: float) -> list[float]:
        """:meth:`values` for a step of ``h`` > 0 as a list, in the order of :meth:`targets`.

        Called for every unit and macro step: each driver value is computed once
        (a driven position's value at ``t + h`` is the next step's value at its
        start), a sea state's for many steps at once (see :data:`AHEAD`).

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        t : float
            Start of the step, s.
        h : float
            The step, s (> 0).

        Returns
        -------
        list of float
            The values of :meth:`values`, in the driven inputs' units.
        """
        out = []
        for d in self._by_unit.get(unit, ()):
            if d.rate is None:
                out.append(d.value.midpoint(t, h))
            else:
                start = d.value.at(t)
                out.append(start)
                out.append((d.value.step_end(t, h) - start) / h)
        return out


class ScheduledEvents:
    """Input values that change at scheduled times and then stay."""

    def __init__(self, events: tuple[EventSpec, ...]) -> None:
        self._pending = sorted(events, key=lambda e: e.time)
        self._active: dict[VarRef, Any] = {}
        self.fired = 0
        """How many events have fired so far (what :meth:`values` gives changes with it)."""
        self.units = frozenset(ref.unit for e in events for ref in e.values)
        """Units some event sets an input of."""

    @property
    def next_time(self) -> float | None:
        """Time of the next event, or None."""
        return self._pending[0].time if self._pending else None

    def fire_due(self, t: float) -> list[str]:
        """Apply every event due at or before ``t``; return their labels.

        Parameters
        ----------
        t : float
            Time reached, s.
        """
        fired = []
        while self._pending and self._pending[0].time <= t + 1e-12:
            event = self._pending.pop(0)
            self._active.update(event.values)
            self.fired += 1
            fired.append(event.label)
            logger.info("t = %.6g s: %s", t, event.label)
        return fired

    def values(self, unit: str) -> dict[str, Any]:
        """Input values the events so far impose on ``unit``.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.

        Returns
        -------
        dict of str to object
            Value by variable name (a number, a boolean or text).
        """
        return {ref.variable: v for ref, v in self._active.items() if ref.unit == unit}
