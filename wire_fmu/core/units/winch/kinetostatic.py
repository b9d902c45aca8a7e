"""The winch without inertia (eq. 32): a speed-commanded drive, stepped exactly.

Paper 000's winch (32) ``T r + M + M_f = 0`` has no inertia, so the motion
cannot follow from the torques: the drive is *speed commanded*. The drum
turns at ``drum.speed_command`` (rad/s) and the motor torque follows from
(32) with the drive train's viscous losses: ``M = beta omega - T r -
M_brake``. With the command at zero the drum is held (paper's braking
mode): the brake takes the holding torque up to its capacity and the motor
the rest. The drive takes up a new command at the start of a step and
holds it over the step; the speed outputs report the speed over the step
just finished (their left limit), so the payout outputs depend on no input
in this mode either. Without inertia nothing is integrated: payout, work
and losses are exact for the held inputs. With the rope's interface model the
tension varies over the step (the motion does not: it is commanded); the rope's
work is the trapezoid of the model's tension at the step's ends times the rope
paid out, exact while the rope stays taut and on one layer.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

from wire_fmu.core.units.winch.base import WinchConfig, WinchInputs, WinchReport, _WinchBase
from wire_fmu.core.units.winch.brake import _BRAKE_WORDS, BRAKE_FREE, BRAKE_HOLDING, BRAKE_SLIPPING

__all__ = ["KinetostaticWinch"]


class KinetostaticWinch(_WinchBase):
    """Winch without inertia (eq. 32): a speed-commanded drive, stepped exactly.

    State ``[phi, omega over the last step, dissipated, external work]``.
    The rules are in the module docstring.
    """

    def __init__(self, config: WinchConfig) -> None:
        super().__init__(config)
        self.beta = float(math.fsum(config.chain.dampings))
        self.state = np.zeros(4)
        self._brake_state = BRAKE_FREE
        self.solver = None

    def initialize(self, t0: float, inputs: WinchInputs) -> None:
        """At rest at ``phi = 0``, turning at the speed command from the start.

        Parameters
        ----------
        t0 : float
            Start time, s.
        inputs : WinchInputs
            Inputs at the start.
        """
        self.set_inputs(inputs)
        self.time = float(t0)
        self.layer = self.drum.initial_layer()
        self.state = np.array([0.0, inputs.speed_command, 0.0, 0.0])
        self._brake_state = self._brake_state_for(inputs.speed_command)
        self.mode_changes = 0
        self.last_events = []

    def _brake_state_for(self, omega: float) -> int:
        if min(self.capacities) <= 0.0:  # released, or no brake at all
            return BRAKE_FREE
        return BRAKE_SLIPPING if omega != 0.0 else BRAKE_HOLDING

    def _tension(self, t: float, phi: float, omega: float, layer: int | None = None) -> float:
        """Rope tension at time ``t`` (s), drum angle ``phi`` (rad), speed ``omega`` (rad/s)
        with the rope leaving ``layer`` (default: the present one), N."""
        k = self.layer if layer is None else layer
        return self.inputs.tension_at(
            t, self.drum.payout(phi, k), self.drum.layer_radius(k) * omega
        )

    def _brake_and_motor(self, omega: float, tension: float) -> tuple[float, float]:
        """(brake torque, motor torque) on the drum shaft by (32) under ``tension`` (N), N m."""
        rope = tension * self.drum.layer_radius(self.layer)
        plus, minus = self.capacities
        if omega > 0.0:
            brake = -plus
        elif omega < 0.0:
            brake = minus
        else:  # held: the brake takes what it can of the holding torque -rope
            brake = max(-rope, -plus) if rope > 0.0 else min(-rope, minus)
        return brake, self.beta * omega - rope - brake

    def advance(self, t: float, h: float, inputs: WinchInputs) -> int:
        """Turn at the commanded speed for ``h``; exact payout, work and losses.

        Parameters
        ----------
        t : float
            Start of the step, s.
        h : float
            Step length, s.
        inputs : WinchInputs
            Inputs held over the step.

        Returns
        -------
        int
            The number of events (layer changes, brake changes).
        """
        self.last_events = []
        self.first_event_time = math.inf
        self.set_inputs(inputs)
        omega = inputs.speed_command
        phi0, k0 = float(self.state[0]), self.layer
        phi1 = phi0 + omega * h
        self._cross_layers(t, h, phi0, phi1)
        state = self._brake_state_for(omega)
        if state != self._brake_state:
            self._brake_state = state
            self.mode_changes += 1
            self._event(t, f"brake {_BRAKE_WORDS[state]}")
        paid = self.drum.payout(phi1, self.layer) - self.drum.payout(phi0, k0)
        tension = self._tension(t + h, phi1, omega)
        brake = self._brake_and_motor(omega, tension)[0]
        dissipated = -brake * (phi1 - phi0) + self.beta * omega * omega * h
        if inputs.rope_model.active:  # the trapezoid of a tension linear in time
            tension = 0.5 * (self._tension(t, phi0, omega, k0) + tension)
        rope_work = tension * paid
        motor_work = dissipated - rope_work  # what (32) makes the motor do
        self.state = np.array(
            [phi1, omega, self.state[2] + dissipated, self.state[3] + rope_work + motor_work]
        )
        self.time = t + h
        return len(self.last_events)

    def _cross_layers(self, t: float, h: float, phi0: float, phi1: float) -> None:
        """Change layer for every boundary between ``phi0`` and ``phi1``."""
        speed = (phi1 - phi0) / h if h else 0.0
        for _ in range(self.drum.max_layers + 1):
            low, high = self.drum.phi_bounds(self.layer)
            if phi1 < low:
                edge, step = low, +1
            elif phi1 > high:
                edge, step = high, -1
            else:
                return
            crossing = t + (edge - phi0) / speed
            self.first_event_time = min(self.first_event_time, crossing)
            self._change_layer(crossing, step)
            self.mode_changes += 1

    def stored_energy(self) -> float:
        """No inertia, no springs: 0 J."""
        return 0.0

    # ------------------------------ HybridSystem protocol (monolithic models)
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[phi', 0, dissipated', external work']`` at the commanded speed.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[phi (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        omega = self.inputs.speed_command
        tension = self._tension(t, x[0], omega)
        brake, motor = self._brake_and_motor(omega, tension)
        rope = tension * self.drum.layer_radius(self.layer)
        loss = -brake * omega + self.beta * omega * omega
        return np.array([omega, 0.0, loss, (rope + motor) * omega])

    def guard_directions(self) -> np.ndarray:
        """The layer's two edges fire on a downward crossing."""
        return -np.ones(self.drum.layer_guard_count)

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """The layer's two edges (none without layers).

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[phi (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        return self.drum.layer_guards(x[0], self.layer)

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """The rope changes layer.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[phi (rad), omega (rad/s), dissipated (J), external work (J)]``.
        fired : list of int
            Indices of the guards that crossed.
        """
        for i in fired:
            self._change_layer(t, +1 if i == 0 else -1)
        self.mode_changes += 1
        return np.array(x, dtype=float)

    def project(self, x: np.ndarray) -> np.ndarray:
        """No invariants.

        Parameters
        ----------
        x : ndarray
            State, returned as it is.
        """
        return x

    def report(self) -> WinchReport:
        """Outputs for the drum speed of the last step and the held inputs."""
        phi, omega = float(self.state[0]), float(self.state[1])
        radius = self.drum.layer_radius(self.layer)
        brake, motor = self._brake_and_motor(omega, self._tension(self.time, phi, omega))
        return WinchReport(
            rope_payout=self.drum.payout(phi, self.layer),
            rope_payout_rate=radius * omega,
            drum_speed=omega,
            drum_angle=phi,
            drum_layer=self.layer + 1,
            drum_radius=radius,
            motor_speed=self.motor_ratio * omega,
            motor_torque=motor / self.motor_ratio,
            brake_torque=brake + 0.0,
            brake_capacity=self.capacities[0],
            brake_state=self._brake_state_for(omega),
            stored_energy=0.0,
            dissipated_energy=float(self.state[2]),
            external_work=float(self.state[3]),
        )

    @contextmanager
    def trial(self, inputs: WinchInputs) -> Iterator[None]:
        """Other inputs for reading feedthrough outputs, undone on exit.

        Parameters
        ----------
        inputs : WinchInputs
            The inputs to read the outputs for.
        """
        saved = self.inputs
        try:
            self.set_inputs(inputs)
            yield
        finally:
            self.set_inputs(saved)

    def get_state(self) -> dict:
        """Complete model state as plain data."""
        return {
            "x": [float(c) for c in self.state],
            "time": float(self.time),
            "layer": int(self.layer),
            "brake_state": int(self._brake_state),
            "mode_changes": int(self.mode_changes),
            "inputs": self.held_inputs(),
        }

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
        self._brake_state = int(data["brake_state"])
        self.mode_changes = int(data["mode_changes"])
        self.restore_held_inputs(data["inputs"])
