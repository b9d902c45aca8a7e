"""The winch with drum inertia: a hybrid ODE of drum, drive train, motor and band brake.

The equations, sign convention and energy ledger are in :mod:`wire_fmu.core.units.winch.model`.
The brake's modes are in :mod:`~wire_fmu.core.units.winch.drive_brake_modes`, keeping
and restoring the state in :mod:`~wire_fmu.core.units.winch.drive_snapshots`.
"""

from __future__ import annotations

import math
from dataclasses import astuple

import numpy as np

from wire_fmu.core.components.friction import GROUND, FrictionLink, StickSlip
from wire_fmu.core.framework.compiled import use_compiled
from wire_fmu.core.framework.compiled_step import (
    COMPILED_METHODS,
    STATUS_DONE,
    STATUS_PYTHON,
    KernelModel,
)
from wire_fmu.core.framework.energy_solver import ENERGY_SOLVERS, make_energy_solver
from wire_fmu.core.framework.hybrid import SolverSettings
from wire_fmu.core.framework.interface_model import EffortModel
from wire_fmu.core.framework.machine_unit import MachineUnit, StepWork
from wire_fmu.core.framework.step_limits import IntegrationError
from wire_fmu.core.units.winch import kernel
from wire_fmu.core.units.winch.base import (
    NO_ROPE_MODEL,
    WinchConfig,
    WinchInputs,
    WinchReport,
    _WinchBase,
    inputs_taken,
)
from wire_fmu.core.units.winch.drive_brake_modes import DrumBrakeModes
from wire_fmu.core.units.winch.drive_snapshots import DriveSnapshots

__all__ = ["WinchModel"]

_NO_ROPE_FIELDS = astuple(NO_ROPE_MODEL)


class WinchModel(KernelModel, DrumBrakeModes, DriveSnapshots, _WinchBase):
    """Winch with drum inertia: a hybrid ODE (:mod:`wire_fmu.core.units.winch.model`).

    State ``[theta_0..theta_{n-1}, omega_0..omega_{n-1}, dissipated,
    external work]``: angles (rad) and speeds (rad/s) of the chain's masses
    reduced to the drum shaft, mass 0 the motor rotor, mass ``n - 1`` the
    drum (``theta_{n-1} = phi``). Modes: the brake's engagement and
    stick/slip mode, the rope layer.

    Parameters
    ----------
    config : WinchConfig
        The winch.
    solver : SolverSettings
        Internal solver; ``"energy"``/``"energy1"`` (paper 004) only for a
        rigid drive train (one mass).
    """

    KERNEL = kernel

    def __init__(self, config: WinchConfig, solver: SolverSettings) -> None:
        super().__init__(config)
        chain = config.chain
        self.n = chain.n
        self.base_inertia = np.array(chain.inertias, dtype=float)
        self.stiffness = chain.stiffness_matrix()
        self.damping = chain.damping_matrix()
        brake = () if config.brake is None else (FrictionLink("band brake", self.n - 1, GROUND),)
        self.friction = StickSlip(self.base_inertia.copy(), brake)
        self.masses = self.friction.masses  # the drum's entry follows I(phi)
        self.characteristic = "motor_characteristic" in config.effects
        self.motor_b = config.motor_slope * self.motor_ratio**2 if self.characteristic else 0.0
        self.kernel_constants = (
            self.motor_ratio,
            config.motor_slope if self.characteristic else math.nan,
            1.0 if self.drum.layer_guard_count else 0.0,
        )
        """The motor ratio and slope (NaN without the characteristic) and whether the drum
        is layered, as the kernel's ``held`` array ends (:data:`kernel.HELD`)."""
        self.engaged = False
        self.state = np.zeros(2 * self.n + 2)
        self._held_angle = 0.0
        self._step_summary: tuple[np.ndarray, np.ndarray] | None = None  # (x, kernel.OUTPUTS there)
        self._kernel_layer: tuple | None = None  # (layer, its constants), by kernel_data
        self._kernel_modes: tuple | None = None  # (brake modes, their array), by kernel_data
        self._n_brake_guards = 2 * len(brake)
        self._guard_dirs = -np.ones(self._n_brake_guards + self.drum.layer_guard_count)
        self.settings = solver
        self.compiled = solver.method in COMPILED_METHODS and use_compiled("winch")
        if solver.method in ENERGY_SOLVERS:
            if self.n != 1:
                raise ValueError("the energy-form solver needs a rigid drive train (one mass)")
            self.solver = make_energy_solver(solver)
        else:
            self.solver = self.kernel_solver(solver)

    # ---------------------------------------------------------- state views
    @property
    def phi(self) -> float:
        """Drum angle, rad."""
        return float(self.state[self.n - 1])

    @property
    def omega(self) -> np.ndarray:
        """Speeds of the masses reduced to the drum shaft, rad/s."""
        return self.state[self.n : 2 * self.n]

    # ---------------------------------------------------------- torques
    def motor_torque(self, motor_speed: float) -> float:
        """Motor torque at the motor shaft, N m, at real motor speed (rad/s).

        Parameters
        ----------
        motor_speed : float
            Motor shaft speed, rad/s.
        """
        if self.characteristic:
            return self.inputs.motor_command - self.config.motor_slope * motor_speed
        return self.inputs.motor_command

    def _motor_reduced(self, omega0: float) -> float:
        """Motor torque reduced to the drum shaft at reduced speed ``omega0``."""
        return self.motor_ratio * self.inputs.motor_command - self.motor_b * omega0

    def rope_tension(self, t: float, x: np.ndarray) -> float:
        """Rope tension at ``(t, x)``: held, or the rope's interface model, N.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[theta (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        n, k = self.n, self.layer
        phi, w = x[n - 1], x[2 * n - 1]
        return self.inputs.tension_at(t, self.drum.payout(phi, k), self.drum.layer_radius(k) * w)

    def _forces(self, x: np.ndarray, t: float) -> np.ndarray:
        """All torques except the brake's on every mass (reduced) at time ``t`` (s), N m;
        updates I(phi)."""
        n = self.n
        theta, omega = x[:n], x[n : 2 * n]
        if n > 1:
            forces = -(self.stiffness @ theta) - self.damping @ omega
        else:
            forces = np.array([-self.damping[0, 0] * omega[0]])
        forces[0] += self._motor_reduced(omega[0])
        phi, w = theta[n - 1], omega[n - 1]
        drum, k = self.drum, self.layer
        forces[n - 1] += (
            self.rope_tension(t, x) * drum.layer_radius(k)
            - 0.5 * drum.rope_inertia_slope(k) * w * w
        )
        self.masses[n - 1] = self.base_inertia[n - 1] + drum.rope_inertia(phi, k)
        return forces

    def _dynamics(self, x: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Accelerations and brake torque (shape (0,) or (1,)) in the current mode at ``t``."""
        forces = self._forces(x, t)
        if self.engaged:
            return self.friction.accelerations(forces, self._caps)
        return forces / self.masses, np.zeros(len(self.friction.links))

    def drum_held(self) -> bool:
        """Whether the brake holds the drum at rest."""
        return self.engaged and self.friction.mode[0] == 0

    # ------------------------------------------------ HybridSystem protocol
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[theta', omega', dissipated', external work']``.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[theta (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        if self.compiled:
            return kernel.rhs(t, x, self.kernel_data())
        n = self.n
        omega = x[n : 2 * n]
        acc, link = self._dynamics(x, t)
        out = np.empty_like(x)
        out[:n] = omega
        out[n : 2 * n] = acc
        loss = float(omega @ self.damping @ omega)
        if self.engaged:
            loss += self.friction.loss_power(omega, link)
            if self.friction.mode[0] == 0:
                out[n - 1] = 0.0
        r = self.drum.layer_radius(self.layer)
        out[2 * n] = loss
        out[2 * n + 1] = (
            self._motor_reduced(omega[0]) * omega[0] + self.rope_tension(t, x) * r * omega[n - 1]
        )
        return out

    @property
    def guard_counts(self) -> tuple[int, int]:
        """Guards of the brake (0 without one, else 2) and of the layer (0 or 2)."""
        return self._n_brake_guards, self.drum.layer_guard_count

    def guard_directions(self) -> np.ndarray:
        """All guards fire on a downward crossing."""
        return self._guard_dirs

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Brake stick/slip, brake engagement, then the layer's two edges.

        Stick/slip: the holding margin (held) or direction * speed (sliding).
        Engagement: ``-F`` while released, ``F`` while applied (``F`` the
        lever force); it can only fire when the lever force varies within a
        step, as in a monolithic model -- held inputs are settled at the
        start of every step.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[theta (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        if self.compiled:
            return kernel.guards(t, x, self.kernel_data())
        layer = self.drum.layer_guards(x[self.n - 1], self.layer)
        if not self.friction.links:
            return layer
        return np.concatenate((self._brake_guards(x, t), layer))

    def _brake_guards(self, x: np.ndarray, t: float) -> list[float]:
        """Stick/slip and engagement guards of the brake at ``(t, x)``."""
        if not self.engaged:
            return [1.0, -self.inputs.lever_force]
        _, link = self._dynamics(x, t)
        stick_slip = self.friction.guards(x[self.n : 2 * self.n], link, self._caps)
        return [*stick_slip, self.inputs.lever_force]

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Brake stick/slip, or the rope changing layer.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[theta (rad), omega (rad/s), dissipated (J), external work (J)]``.
        fired : list of int
            Indices of the guards that crossed.
        """
        self.first_event_time = min(self.first_event_time, t)
        x = np.array(x, dtype=float)
        n_brake = self._n_brake_guards
        for i in fired:
            if i >= n_brake:
                self._change_layer_keeping_energy(t, x, +1 if i == n_brake else -1)
        x = self._settle_modes(t, x, [0] if 0 in fired and n_brake else [])
        self.mode_changes += 1
        return self.project(x)

    def _change_layer_keeping_energy(self, t: float, x: np.ndarray, step: int) -> None:
        """Change layer; rescale the drum speed so its kinetic energy is continuous.

        The event is located just past the edge, where the old layer's
        inertia law has been extrapolated by at most the event tolerance;
        the rescaling (a relative change of that order) keeps the ledger exact.
        """
        n, phi = self.n, x[self.n - 1]
        before = self.base_inertia[n - 1] + self.drum.rope_inertia(phi, self.layer)
        self._change_layer(t, step)
        after = self.base_inertia[n - 1] + self.drum.rope_inertia(phi, self.layer)
        x[2 * n - 1] *= math.sqrt(before / after)

    def project(self, x: np.ndarray) -> np.ndarray:
        """A held drum stays exactly where it stuck, at rest.

        Parameters
        ----------
        x : ndarray
            State, changed in place and returned.
        """
        if self.drum_held():
            x[self.n - 1] = self._held_angle
            x[2 * self.n - 1] = 0.0
        return x

    # ------------------------------------------ RigidMachineSystem protocol
    def machine(self, t: float, x: np.ndarray) -> MachineUnit | None:
        """Paper 004's machine unit of the current mode (rigid chain only).

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[theta (rad), omega (rad/s), dissipated (J), external work (J)]``.

        Returns
        -------
        MachineUnit or None
            None while the brake holds the drum.
        """
        if self.drum_held():
            return None
        sliding = 0.0
        if self.engaged:
            mode = int(self.friction.mode[0])
            sliding = mode * (self._caps[0, 0] if mode > 0 else self._caps[0, 1])
        drum, k, base = self.drum, self.layer, float(self.base_inertia[0])
        rope_torque = self.inputs.tension * drum.layer_radius(k)
        beta = float(self.damping[0, 0])
        return MachineUnit(
            inertia=lambda phi: base + drum.rope_inertia(phi, k),
            inertia_slope=lambda phi: drum.rope_inertia_slope(k),
            a=self.motor_ratio * self.inputs.motor_command,
            b=self.motor_b,
            resistance_angle=lambda phi: -rope_torque,
            resistance_angle_work=lambda p0, p1: -rope_torque * (p1 - p0),
            resistance_speed=lambda w: sliding + beta * w,
            resistance_speed_slope=lambda w: beta,
        )

    def book(self, work: StepWork) -> tuple[float, float]:
        """Brake and dampers dissipate; motor and rope are external.

        Parameters
        ----------
        work : StepWork
            The works of the step, J.

        Returns
        -------
        tuple of float
            (dissipated, external work), J.
        """
        return work.speed, work.driving - work.angle

    # ---------------------------------------------------------- life cycle
    def initialize(self, t0: float, inputs: WinchInputs) -> None:
        """Start at the configured speed with the shafts already carrying their torques.

        The shafts are twisted as in quasi-static motion: every mass has the
        acceleration the chain would have if it were rigid (zero when the
        brake holds), so the start causes no shaft vibration.

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
        n = self.n
        x = np.zeros(2 * n + 2)
        x[n : 2 * n] = self.config.initial_speed
        forces = self._forces(x, t0)
        acc = self._rigid_acceleration(float(forces.sum()), float(self.masses.sum()), x[2 * n - 1])
        twists = np.cumsum(forces[:-1] - self.masses[:-1] * acc) / np.asarray(
            self.chain.stiffnesses, dtype=float
        )
        x[: n - 1] = np.cumsum(twists[::-1])[::-1]  # angles relative to the drum's 0
        self.engaged = False
        self.mode_changes = 0
        self.last_events = []
        self.state = self._settle_modes(t0, x, [])
        self._forces(self.state, t0)
        self.preload_kernel(t0)

    def advance(self, t: float, h: float, inputs: WinchInputs) -> int:
        """Advance by ``h`` with ``inputs`` held; return the number of events.

        Parameters
        ----------
        t : float
            Start of the step, s.
        h : float
            Step length, s.
        inputs : WinchInputs
            Inputs held over the step.
        """
        self.last_events = []
        self.first_event_time = math.inf
        self.set_inputs(inputs)
        kept = self._kept_brake_mode(self._caps)
        if kept is not None and self._quiet_step(t, h, *kept):
            self.time = t + h
            return self._quiet_events
        self.state = self._settle_modes(t, self.state)
        x, events = self.solver.advance(self, t, self.state, t + h)
        self.state = x
        self.time = t + h
        self._forces(x, self.time)
        return events

    def _quiet_step(self, t: float, h: float, check_stick: bool, hold_angle: bool) -> bool:
        """The step in one compiled call (:func:`kernel.quiet_step`); False if it is Python's."""
        solver = self.solver
        t1 = t + h
        count = solver.internal_count(t, t1)
        # the ledger's start 0: only the brake torque and stored energy are read
        result = self._kernel_quiet_step(t, t1, count, self.kernel_data(), hold_angle, check_stick)
        if result[0] == STATUS_PYTHON:
            return False
        if hold_angle:
            self._held_angle = float(self.state[self.n - 1])
        x, self._quiet_events, values = solver.finish_quiet_step(self, t, self.state, t1, result)
        if values is not None:
            self._step_summary = (x, values)
        self.state = x
        if values is None:  # after an event; else the outputs come from the kernel's summary
            self._forces(x, t1)
        return True

    def quiet_step_outputs(
        self, t: float, h: float, flat: tuple[float, ...], initial_energy: float
    ) -> list[float] | None:
        """A step in which nothing happens, with its outputs, in one compiled call.

        What :meth:`advance` and then the unit's outputs do for such a step, with the same
        arithmetic, to the last bit (:func:`kernel.quiet_step`), without the Python
        between. When anything happens in the step -- inputs the winch cannot take, a
        brake mode to settle, an event, an output that is not finite -- it changes nothing
        and answers None: the step is then taken the general way, which names what
        happened.

        Parameters
        ----------
        t, h : float
            Start and length of the step, s.
        flat : tuple of float
            The inputs at ``t``, in the order of :data:`~.base.FLAT_INPUTS`.
        initial_energy : float
            Stored energy at the start of the ledger, J.

        Returns
        -------
        list of float or None
            The values of :data:`kernel.OUTPUTS`, in their units; None if the step was
            not taken.
        """
        if not inputs_taken(flat):
            return None  # WinchInputs.problems names them
        tension, lever_force, command, speed_command, stiffness, damping, rate, *reference = flat
        capacities = self._capacities_for(lever_force)
        kept = self._kept_brake_mode(capacities)
        if kept is None:
            return None
        solver, t1 = self.solver, t + h
        try:
            count = solver.internal_count(t, t1)
        except IntegrationError:  # a step too long: refused the general way, with the reason
            return None
        active = stiffness != 0.0 or damping != 0.0 or rate != 0.0
        rope = (stiffness, damping, rate, *reference, self.time) if active else _NO_ROPE_FIELDS
        held = kernel.held_array(self, command, tension, lever_force, capacities, rope)
        data = (kernel._modes(self), self.base_inertia, self.stiffness, self.damping, held)
        check_stick, hold_angle = kept
        status, x, _, _, _, steps, rhs_calls, _, values, finite = self._kernel_quiet_step(
            t, t1, count, data, hold_angle, check_stick, initial_energy
        )
        if status != STATUS_DONE or not finite:
            return None
        rope_model = EffortModel(*rope) if active else NO_ROPE_MODEL
        self.inputs = WinchInputs(tension, lever_force, command, speed_command, rope_model)
        self._caps = capacities
        self.last_events = []
        self.first_event_time = math.inf
        if hold_angle:
            self._held_angle = float(self.state[self.n - 1])
        self.state = x
        self.time = t1
        self._step_summary = (x, values)
        solver.steps += steps
        solver.rhs_calls += rhs_calls
        return values.tolist()

    def _kernel_quiet_step(
        self,
        t: float,
        t1: float,
        count: int,
        data: tuple,
        hold_angle: bool,
        check_stick: bool,
        initial_energy: float = 0.0,
    ) -> tuple:
        """:func:`kernel.quiet_step` from the present state over ``[t, t1]`` (s) in
        ``count`` internal steps, with the kernel ``data`` of the step's inputs, the
        brake's mode kept as :meth:`_kept_brake_mode` says, the ledger from
        ``initial_energy`` (J)."""
        return kernel.quiet_step(
            self.solver.method,
            t,
            t1,
            count,
            self.settings.event_time_tolerance,
            self.state,
            self._guard_dirs,
            data,
            check_stick,
            hold_angle,
            0,
            t,
            False,
            initial_energy,
        )

    # ---------------------------------------------------------- outputs
    def stored_energy(self, x: np.ndarray | None = None) -> float:
        """Kinetic energy of every mass plus shaft strain energy, J.

        Parameters
        ----------
        x : ndarray, optional
            State (default: the current one).
        """
        x = self.state if x is None else x
        if self.compiled:
            return float(kernel.summary(self.time, x, self.kernel_data())[1])
        n = self.n
        theta, omega = x[:n], x[n : 2 * n]
        self._forces(x, self.time)
        return 0.5 * float(self.masses @ omega**2) + 0.5 * float(theta @ self.stiffness @ theta)

    def report(self) -> WinchReport:
        """Outputs at the current state for the held inputs (state untouched)."""
        x = self.state
        n = self.n
        if self.compiled:
            done = self._step_summary
            if done is not None and done[0] is x:  # the outputs the step's kernel computed
                brake = float(done[1][kernel.BRAKE_TORQUE])
                stored = float(done[1][kernel.STORED_ENERGY])
            else:
                brake, stored = kernel.summary(self.time, x, self.kernel_data()).tolist()
        else:
            brake = float(self._dynamics(x, self.time)[1][0]) if self.engaged else 0.0
            stored = None
        w, k = float(x[2 * n - 1]), self.layer
        radius = self.drum.layer_radius(k)
        motor_speed = self.motor_ratio * float(x[n])
        return WinchReport(
            rope_payout=self.drum.payout(self.phi, k),
            rope_payout_rate=radius * w,
            drum_speed=w,
            drum_angle=self.phi,
            drum_layer=k + 1,
            drum_radius=radius,
            motor_speed=motor_speed,
            motor_torque=self.motor_torque(motor_speed),
            brake_torque=brake + 0.0 if self.engaged else 0.0,
            brake_capacity=self.capacities[0],
            brake_state=self.brake_state(),
            stored_energy=self.stored_energy() if stored is None else stored,
            dissipated_energy=float(x[2 * n]),
            external_work=float(x[2 * n + 1]),
        )
