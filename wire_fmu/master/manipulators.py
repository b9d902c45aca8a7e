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
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .drivers import make_driver
from .scene import DriverSpec, EventSpec, VarRef

__all__ = ["DriverSet", "ScheduledEvents"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class _Driven:
    driver: Any
    target: VarRef
    rate: VarRef | None


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


class ScheduledEvents:
    """Input values that change at scheduled times and then stay."""

    def __init__(self, events: tuple[EventSpec, ...]) -> None:
        self._pending = sorted(events, key=lambda e: e.time)
        self._active: dict[VarRef, Any] = {}

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
