"""The band brake's modes in the winch with drum inertia: engaged or released, stuck or sliding.

:class:`DrumBrakeModes` is the part of
:class:`~wire_fmu.core.units.winch.drive.WinchModel` that makes the brake's
engagement and stick/slip mode fit the inputs, tells whether the compiled
one-call step may keep the mode, and gives the acceleration of the chain
locked rigid against the brake (for the start).
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.framework.compiled_step import CompiledFixedStep
from wire_fmu.core.units.winch import kernel
from wire_fmu.core.units.winch.brake import _BRAKE_WORDS, BRAKE_FREE, BRAKE_HOLDING, BRAKE_SLIPPING

__all__ = ["DrumBrakeModes"]


class DrumBrakeModes:
    """The brake's modes (a mixin of the model).

    The model provides ``n``, ``config``, ``engaged``, ``friction``, ``capacities``,
    ``compiled``, ``solver``, ``mode_changes``, ``_caps``, ``_held_angle``,
    ``kernel_data``, ``project``, ``_forces`` and ``_event``.
    """

    def brake_state(self) -> int:
        """0 released, 1 slipping, 2 holding."""
        if not self.engaged:
            return BRAKE_FREE
        return BRAKE_HOLDING if self.friction.mode[0] == 0 else BRAKE_SLIPPING

    def _mode_key(self) -> tuple[bool, int]:
        return self.engaged, int(self.friction.mode[0]) if self.friction.links else 0

    def _settle_modes(self, t: float, x: np.ndarray, fired: list[int] | None = None):
        """Make the brake's engagement and stick/slip mode fit the inputs at (t, x).

        Without a brake the capacities are zero: it stays released, nothing changes.
        """
        x = np.array(x, dtype=float)
        if fired is None and self.compiled and self._brake_mode_holds(t, x):
            self._held_angle = float(x[self.n - 1])
            return self.project(x)
        before = self._mode_key()
        n = self.n
        if min(self.capacities) <= 0.0:
            self.engaged = False
        else:
            if not self.engaged:
                self.friction.set_mode([int(np.sign(x[2 * n - 1]))])
                self.engaged = True
            forces = self._forces(x, t)
            x[n : 2 * n] = self.friction.switch(x[n : 2 * n], forces, self._caps, fired or [])
        if self._mode_key() != before or fired:
            self._event(t, f"brake {_BRAKE_WORDS[self.brake_state()]}")
            if fired is None:
                self.mode_changes += 1
        self._held_angle = float(x[n - 1])
        return self.project(x)

    def _brake_mode_holds(self, t: float, x: np.ndarray) -> bool:
        """Whether the brake's present mode fits the inputs at ``(t, x)`` (nothing to settle).

        Released and without capacity; or engaged with capacity, and sliding, or
        stuck with a holding margin left (the compiled kernel's stick guard).
        """
        if min(self.capacities) <= 0.0:
            return not self.engaged
        if not self.engaged:
            return False
        if self.friction.mode[0] != 0:
            return True
        return bool(kernel.guards(t, x, self.kernel_data())[0] >= 0.0)

    def _rigid_acceleration(self, torque: float, inertia: float, omega: float) -> float:
        """Acceleration of the chain locked rigid under ``torque`` (N m) and the brake."""
        plus, minus = self.capacities
        if min(plus, minus) <= 0.0:  # released, or no brake at all
            return torque / inertia
        if omega == 0.0:
            if -minus <= torque <= plus:  # the brake can hold
                return 0.0
            direction = 1.0 if torque > 0.0 else -1.0
        else:
            direction = 1.0 if omega > 0.0 else -1.0
        return (torque - direction * (plus if direction > 0 else minus)) / inertia

    def _kept_brake_mode(self, capacities: np.ndarray) -> tuple[bool, bool] | None:
        """How :func:`kernel.quiet_step` may keep the brake's mode, or None if it may not.

        ``(check_stick, hold_angle)``: a brake released without capacity (or no
        brake at all), or engaged and sliding, keeps its mode; one
        that holds the drum keeps it while it can (the kernel checks); anything
        else is settled by :meth:`_settle_modes`, in Python.

        Parameters
        ----------
        capacities : numpy.ndarray
            The brake's capacities for the step's lever force, shape (1, 2), N m.
        """
        if not (self.compiled and isinstance(self.solver, CompiledFixedStep)):
            return None
        plus, minus = capacities[0]
        if (minus if minus < plus else plus) <= 0.0:  # min(), without its keyword parse
            return None if self.engaged else (False, True)
        if not self.engaged:
            return None
        return self.friction.mode[0] == 0, True
