"""How a unit's refusal or failure reaches the master: the exceptions its FMI calls raise."""

from __future__ import annotations

__all__ = ["StepRefusedError", "UnitFailedError"]


class _UnitError(RuntimeError):
    """A unit's answer; ``unit`` names it."""

    def __init__(self, message: str, unit: str | None = None) -> None:
        super().__init__(message)
        self.unit = unit


class StepRefusedError(_UnitError):
    """A unit answered a step with fmi2Discard (a physical or numerical stop)."""


class UnitFailedError(_UnitError):
    """A unit answered with fmi2Error or fmi2Fatal."""
