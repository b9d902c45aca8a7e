"""Keeping and restoring the state of the winch with drum inertia, and trying other inputs.

:class:`DriveSnapshots` is the part of
:class:`~wire_fmu.core.units.winch.drive.WinchModel` that saves its state as
plain data (FMI get and set state), keeps and undoes a step in this process,
and settles the brake for other inputs only while feedthrough outputs are read.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

from wire_fmu.core.units.winch.base import WinchInputs

__all__ = ["DriveSnapshots"]


class DriveSnapshots:
    """State keeping and trials (a mixin of the model).

    The model provides ``state``, ``time``, ``layer``, ``engaged``, ``friction``, ``inputs``,
    ``mode_changes``, ``last_events``, ``solver``, ``_held_angle``, ``set_inputs``,
    ``held_inputs``, ``restore_held_inputs``, ``_settle_modes`` and ``_forces``.
    """

    @contextmanager
    def trial(self, inputs: WinchInputs) -> Iterator[None]:
        """Modes settled for other inputs, undone on exit (for feedthrough outputs).

        Parameters
        ----------
        inputs : WinchInputs
            The inputs to read the outputs for.
        """
        saved = (
            self.inputs,
            self.engaged,
            self.friction.mode.copy(),
            self.mode_changes,
            list(self.last_events),
            self._held_angle,
            self.state.copy(),
        )
        try:
            self.set_inputs(inputs)
            self._settle_modes(self.time, self.state)
            self.mode_changes = saved[3]  # a trial is not an event
            yield
        finally:
            (
                inputs_,
                self.engaged,
                mode,
                self.mode_changes,
                self.last_events,
                self._held_angle,
                self.state,
            ) = saved
            self.friction.set_mode(mode)
            self.set_inputs(inputs_)
            self._forces(self.state, self.time)

    def get_state(self) -> dict:
        """Complete model state as plain data."""
        return {
            "x": [float(c) for c in self.state],
            "time": float(self.time),
            "layer": int(self.layer),
            "engaged": bool(self.engaged),
            "friction_mode": self.friction.get_mode(),
            "held_angle": float(self._held_angle),
            "mode_changes": int(self.mode_changes),
            "inputs": self.held_inputs(),
            "solver": {"rhs_calls": int(self.solver.rhs_calls), "steps": int(self.solver.steps)},
        }

    def snapshot(self) -> tuple:
        """What undoing a step needs, kept in this process (cheaper than :meth:`get_state`)."""
        return (
            self.state,  # never changed in place: every step makes a new array
            self.time,
            self.layer,
            self.engaged,
            self.friction.mode.copy(),
            self._held_angle,
            self.mode_changes,
            self.inputs,
            self.solver.rhs_calls,
            self.solver.steps,
        )

    def restore(self, saved: tuple) -> None:
        """Undo to what :meth:`snapshot` kept.

        Parameters
        ----------
        saved : tuple
            A snapshot of this model.
        """
        (self.state, self.time, self.layer, self.engaged, mode, self._held_angle,
         self.mode_changes, inputs, self.solver.rhs_calls, self.solver.steps) = saved  # fmt: skip
        self.friction.set_mode(mode)
        self.set_inputs(inputs)
        self._forces(self.state, self.time)

    def set_state(self, data: dict) -> None:
        """Restore a state from :meth:`get_state`.

        Parameters
        ----------
        data : dict
            A state from :meth:`get_state`.
        """
        self.state = np.array(data["x"], dtype=float)
        self.time = float(data["time"])
        self.layer = int(data["layer"])
        self.engaged = bool(data["engaged"])
        self.friction.set_mode(list(data["friction_mode"]))
        self._held_angle = float(data["held_angle"])
        self.mode_changes = int(data["mode_changes"])
        self.restore_held_inputs(data["inputs"])
        self.solver.rhs_calls = int(data["solver"]["rhs_calls"])
        self.solver.steps = int(data["solver"]["steps"])
        self._forces(self.state, self.time)
