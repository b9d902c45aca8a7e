"""How a run ended: :class:`RunResult`, its statuses, and the error that stops a run."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["RunResult", "SimulationStoppedError", "STATUSES"]

STATUSES = ("finished", "stopped", "failed", "interrupted")
"""How a run ends: ``finished`` at the stop time; ``stopped`` by the physics or the
numerics with a message (a unit refused a step, the energy guard, a diverging
iteration); ``failed``, a unit answered with an error (also in initialisation) or
something unexpected happened; ``interrupted`` by Ctrl-C (SIGINT) or SIGTERM."""


class SimulationStoppedError(RuntimeError):
    """A unit stopped the run; the message says which, when and why."""


@dataclass
class RunResult:
    """Outcome of :meth:`Simulation.run`."""

    status: str  # one of STATUSES
    message: str = ""
    end_time: float = 0.0
    wall_time: float = 0.0
    steps: int = 0
    rejected: int = 0
    iterations: int = 0
    synchronised: int = 0  # steps shortened to a unit's mode change (synchronise_events)
    bond_residual: dict[str, float] = field(default_factory=dict)
    bond_carried: dict[str, float] = field(default_factory=dict)
    bond_error: dict[str, float] = field(default_factory=dict)
    stepping_wall_time: float = 0.0
    """Wall time of the stepping loop alone (no instantiation, initialisation or clean-up), s."""
    stepping_fmi_time: float = 0.0
    """Time inside the FMI calls made by the stepping loop, s."""

    def summary(self) -> dict[str, Any]:
        """How the run ended, as ``metadata.json`` gives it (every kind of run alike).

        Returns
        -------
        dict
            Status and message, simulated end time (s), wall time (s), real-time
            factor (None before any wall time) and accepted macro steps.
        """
        return {
            "status": self.status,
            "message": self.message,
            "end_time": self.end_time,
            "wall_time": self.wall_time,
            "real_time_factor": self.end_time / self.wall_time if self.wall_time else None,
            "steps": self.steps,
        }
