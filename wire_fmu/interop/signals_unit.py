"""Runtime of the generated signals FMU: a scene's drivers and events as outputs.

This module is copied into a signals FMU under a unique module name (it
imports only the bundled core and the driver module handed to
:func:`make_unit_class`), so it must stay free of master imports.

Outputs are *look-ahead*: after a step that ends at ``t`` each output holds
the value our master sets on its target for the next step ``[t, t + h]``
(``h`` the ``step`` parameter), so a host that transfers outputs at ``t``
and holds them over the step (libcosim's fixed-step algorithm) applies
exactly what :class:`~wire_fmu.master.manipulators.DriverSet` and
:class:`~wire_fmu.master.manipulators.ScheduledEvents` apply:

``midpoint``
    a driven input: the driver's value at ``t + h/2``;
``start``
    a driven position with a rate input: its value at ``t``;
``mean_rate``
    that rate input: ``(value(t + h) - value(t)) / h``;
``events``
    an input set by scheduled events: the value of the last event at or
    before ``t``, the target's start value before the first.

In initialisation mode (before ``fmi2ExitInitializationMode``) the outputs
are the values our master sets at initialisation: ``value(t0)``,
``rate(t0)`` and the target's start value.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from wire_fmu.core.framework.unit import STEP_TAKEN, StepResult, Unit, output, parameter

__all__ = ["make_unit_class", "MODES", "EVENT_TOLERANCE"]

MODES = ("midpoint", "start", "mean_rate", "events")
EVENT_TOLERANCE = 1e-12
"""An event at ``time`` applies from any step start ``t >= time - EVENT_TOLERANCE``
(the master's rule)."""

_TYPES = {"Real": float, "Integer": int, "Boolean": bool, "String": str}


@dataclass(frozen=True)
class _Signal:
    """One output: a driver in one of :data:`MODES`, or an event schedule."""

    name: str
    mode: str
    driver: Any = None
    start: Any = 0.0
    events: tuple[tuple[float, Any], ...] = ()

    def initial(self, t: float) -> Any:
        """Value during initialisation at ``t``.

        Parameters
        ----------
        t : float
            Start time, s.
        """
        if self.mode == "events":
            return self.start
        if self.mode == "mean_rate":
            return float(self.driver.rate(t))
        return float(self.driver.value(t))

    def for_step(self, t: float, h: float) -> Any:
        """Value to hold over ``[t, t + h]``.

        Parameters
        ----------
        t : float
            Start of the step, s.
        h : float
            The host's macro step, s.
        """
        if self.mode == "events":
            value = self.start
            for when, new in self.events:
                if when <= t + EVENT_TOLERANCE:
                    value = new
            return value
        if self.mode == "midpoint":
            return float(self.driver.value(t + 0.5 * h))
        if self.mode == "start":
            return float(self.driver.value(t))
        return float((self.driver.value(t + h) - self.driver.value(t)) / h)


def _signal(entry: Mapping[str, Any], make_driver: Callable) -> _Signal:
    mode = entry["mode"]
    if mode == "events":
        kind = _TYPES[entry["type"]]
        events = tuple((float(t), kind(v)) for t, v in entry["events"])
        return _Signal(entry["name"], mode, start=kind(entry["start"]), events=events)
    driver, problems = make_driver(entry["driver"], where=f"signal {entry['name']}", base_dir=".")
    if problems:
        raise ValueError("; ".join(problems))
    return _Signal(entry["name"], mode, driver=driver)


class SignalsUnit(Unit):
    """Base of the generated signals units (see the module docstring)."""

    PROGRAM: ClassVar[Mapping[str, Any]] = {}
    MAKE_DRIVER: ClassVar[Callable | None] = None

    def __init__(self, instance_name: str = "unit") -> None:
        super().__init__(instance_name)
        self._signals: list[_Signal] = []

    def configure(self) -> None:
        """Build the drivers; publish the initialisation values."""
        make = type(self).MAKE_DRIVER
        self._signals = [_signal(entry, make) for entry in self.PROGRAM["signals"]]
        t0 = float(self.PROGRAM.get("start_time", 0.0))
        for s in self._signals:
            self.values[s.name] = s.initial(t0)

    def initialize(self, start_time: float) -> None:
        """Publish the values for the first step.

        Parameters as in :meth:`wire_fmu.core.framework.unit.Unit.initialize`.
        """
        self._publish(start_time)

    def advance(self, time: float, step: float) -> StepResult:
        """Publish the values for the step that starts where this one ends.

        Parameters as in :meth:`wire_fmu.core.framework.unit.Unit.advance`.
        """
        self._publish(time + step)
        return STEP_TAKEN

    def _publish(self, t: float) -> None:
        h = float(self.values["step"])
        for s in self._signals:
            self.values[s.name] = s.for_step(t, h)

    def get_state(self) -> dict[str, Any]:
        """No hidden state: the outputs are functions of time."""
        return {}

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Nothing to restore.

        Parameters as in :meth:`wire_fmu.core.framework.unit.Unit.set_state`.
        """


def _variables(program: Mapping[str, Any]) -> tuple:
    out = [
        parameter(
            "step",
            float(program["step"]),
            "s",
            "Macro step the host takes; outputs hold for one step of this length",
            min=0.0,
        )
    ]
    for entry in program["signals"]:
        kind = _TYPES[entry["type"]]
        out.append(
            output(
                entry["name"],
                entry["unit"] if kind is float else "",
                entry["description"],
                type=kind,
            )
        )
    return tuple(out)


def make_unit_class(program: Mapping[str, Any], make_driver: Callable) -> type[Unit]:
    """The signals unit class described by ``program``.

    Parameters
    ----------
    program : mapping
        ``model_name``, ``description``, ``step`` (s), ``start_time`` (s) and
        ``signals``: entries with ``name``, ``type``, ``unit``,
        ``description``, ``mode`` and either ``driver`` (a driver table) or
        ``start`` and ``events`` (``[[time, value], ...]``).
    make_driver : callable
        :func:`wire_fmu.master.drivers.make_driver` (from the copy bundled
        in the FMU).
    """
    attrs = {
        "NAME": program["model_name"],
        "DESCRIPTION": program["description"],
        "VARIABLES": _variables(program),
        "PROGRAM": program,
        "MAKE_DRIVER": staticmethod(make_driver),
        "__module__": __name__,
    }
    return type(program["model_name"], (SignalsUnit,), attrs)
