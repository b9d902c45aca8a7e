"""Helpers for tests that load the test FMUs with fmpy.

fmpy pitfall handled here: ``fmpy.logging.addLoggerProxy`` stores the logger
of the callbacks it is given in one *global* of a native library, and every
FMU message (also of FMUs instantiated with fmpy's default callbacks) goes
through it. ``simulate_fmu(logger=f)`` registers a callback object that is
freed when the call returns, so the next FMU message jumps to freed memory
and the process segfaults. :class:`FmiLog` registers a collector whose
callbacks live for the whole session, and :meth:`FmiLog.restore` points the
proxy back at fmpy's printer. Never pass ``logger=`` to ``simulate_fmu``.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass, field
from pathlib import Path

from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi1 import printLogMessage
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.logging import addLoggerProxy

SUPPORT = Path(__file__).resolve().parent
FACADES = SUPPORT / "facades"
UNITS_MODULE = SUPPORT / "wire_fmu_test_units.py"

_KEEP_ALIVE: list[object] = []  # callbacks the native proxy may still point at


def _callbacks(logger) -> fmi2CallbackFunctions:
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    addLoggerProxy(ctypes.byref(callbacks))
    _KEEP_ALIVE.append(callbacks)
    return callbacks


@dataclass
class FmiLog:
    """Collects FMU log messages as ``(status, category, message)``."""

    records: list[tuple[int, str, str]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.callbacks = _callbacks(self._collect)

    def _collect(self, env, instance, status, category, message) -> None:
        text = message.decode("utf-8", "replace") if message else ""
        self.records.append((status, (category or b"").decode(), text))

    def messages(self, status: int | None = None) -> list[str]:
        """Messages, optionally only those of one status."""
        return [m for s, _, m in self.records if status is None or s == status]

    @staticmethod
    def restore() -> None:
        """Point fmpy's proxy at its default printer again."""
        _callbacks(printLogMessage)


@dataclass
class LoadedFmu:
    """An extracted FMU and its model description."""

    path: Path
    model_description: object = field(init=False)
    unzipdir: str = field(init=False)

    def __post_init__(self) -> None:
        self.model_description = read_model_description(str(self.path))
        self.unzipdir = extract(str(self.path))

    def vr(self, name: str) -> int:
        """Value reference of variable ``name``."""
        for var in self.model_description.modelVariables:
            if var.name == name:
                return var.valueReference
        raise KeyError(name)

    def instantiate(self, name: str, log: FmiLog) -> FMU2Slave:
        """A new instance logging into ``log``."""
        fmu = FMU2Slave(
            guid=self.model_description.guid,
            unzipDirectory=self.unzipdir,
            modelIdentifier=self.model_description.coSimulation.modelIdentifier,
            instanceName=name,
        )
        fmu.instantiate(callbacks=log.callbacks, loggingOn=True)
        return fmu

    def start(self, name: str, log: FmiLog, reals: dict[str, float] | None = None) -> FMU2Slave:
        """Instantiate, set ``reals`` and initialise at t = 0."""
        fmu = self.instantiate(name, log)
        for key, value in (reals or {}).items():
            fmu.setReal([self.vr(key)], [value])
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        return fmu
