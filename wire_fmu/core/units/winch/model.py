"""The winch (drawworks): drum, band brake, motor and drive train (SPEC sections 7-9).

Sign convention, stated once
----------------------------
Every angle, speed and torque of the winch is measured about one axis,
positive in the *paying-out* (lowering) sense: the drum angle ``phi`` grows
as rope leaves the drum, ``rope.payout`` grows with it and
``payout_rate = r(phi) omega``. The rope pulls the drum with ``+T r``
(paying out under tension drives the drum; power in ``T payout_rate``);
a hoisting motor gives a negative torque; the brake's torque opposes motion.

Effects (SPEC section 12)
-------------------------
=======================  ====================================================
``drum_inertia``         the drum (and drive train) has inertia:
                         ``J omega' = M_motor + T r + M_brake`` with the
                         signed torques above (the SPEC's ``J omega' = M -
                         T r_b - M_brake`` read with omega positive when
                         hoisting). Absent: kinetostatic (32), see below.
``band_brake``           dry friction band brake (34), direction dependent
``motor_characteristic`` ``M = a - b omega`` (004, eq. 6) with ``a`` the
                         command; absent: the command is the motor torque
``elastic_drive_train``  n-mass chain (002), reducible by delta-star
``rope_layers``          radius grows per layer, ``I(phi)`` (004)
=======================  ====================================================

Kinetostatic mode (no ``drum_inertia``)
---------------------------------------
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
and losses are exact for the held inputs.

Band brake (34)
---------------
Capacity against paying out (the self-energising direction of a drawworks
band, whose dead end is anchored so that a lowering load pulls the band
tighter): ``r_f F (L/l) eta (e^(mu alpha) - 1)``; against hauling in:
``r_f F (L/l) eta (1 - e^(-mu alpha))``. A lever force ``F <= 0`` releases
the brake (a band cannot push). While the drum is stopped the brake holds
it exactly (:class:`~wire_fmu.core.components.friction.StickSlip`, holding torque from
the known net torque), breaks away at capacity, slides with the capacity
of the direction of motion and re-sticks when the motion stops.

Energy
------
Stored: kinetic energy of every mass (the drum's with ``I(phi)``) plus
shaft strain energy. Dissipated: brake sliding, every viscous damper
(shafts and ground). External work: rope port (``T r omega_drum``) plus
the motor (its whole torque, ``a - b omega`` included: the characteristic
is a source whose losses are not the winch's). In kinetostatic mode the
motor work is what (32) requires and stored energy is zero.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numpy as np

from wire_fmu.core.components.drive_train import DriveChain
from wire_fmu.core.components.drum import Drum
from wire_fmu.core.components.friction import GROUND, FrictionLink, StickSlip
from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.energy_integrator import (
    ENERGY_SOLVERS,
    MachineUnit,
    StepWork,
    make_energy_solver,
)
from wire_fmu.core.framework.hybrid import RK4_STABILITY, SolverSettings, make_solver

__all__ = [
    "WINCH_EFFECTS",
    "BandBrake",
    "WinchInputs",
    "WinchConfig",
    "WinchReport",
    "WinchModel",
    "KinetostaticWinch",
    "build_winch",
    "fastest_rate",
    "RK4_STABILITY",
    "BRAKE_FREE",
    "BRAKE_SLIPPING",
    "BRAKE_HOLDING",
]

logger = logging.getLogger(__name__)

BRAKE_FREE, BRAKE_SLIPPING, BRAKE_HOLDING = 0, 1, 2
_BRAKE_WORDS = ("released", "slipping", "holding")  # indexed by brake state

WINCH_EFFECTS = EffectCatalogue(
    "winch",
    (
        Effect(
            "drum_inertia",
            "kinetostatic drum (eq. 32), speed commanded",
            "drum and drive-train inertia J",
        ),
        Effect("band_brake", "no brake", "band brake (eq. 34), dry friction, direction dependent"),
        Effect(
            "motor_characteristic",
            "motor torque input",
            "motor characteristic a - b omega",
            requires=("drum_inertia",),
        ),
        Effect(
            "elastic_drive_train",
            "rigid drive train",
            "n-mass elastic chain (paper 002)",
            requires=("drum_inertia",),
        ),
        Effect("rope_layers", "constant winding radius", "radius grows per layer, inertia I(phi)"),
    ),
)


@dataclass(frozen=True)
class BandBrake:
    """Band brake (eq. 34).

    Parameters
    ----------
    rim_radius : float
        Brake-rim radius ``r_f``, m.
    lever_ratio : float
        ``L/l``, the lever's force ratio (1).
    efficiency : float
        ``eta`` of the linkage (0, 1].
    friction : float
        Band friction coefficient ``mu`` (1).
    wrap_angle : float
        Band wrap angle ``alpha``, rad.
    """

    rim_radius: float = 0.62
    lever_ratio: float = 15.0
    efficiency: float = 0.9
    friction: float = 0.4
    wrap_angle: float = 5.24

    def band_tension(self, lever_force: float) -> float:
        """Tension the lever puts into the band's live end, N (0 if not pulled)."""
        return max(lever_force, 0.0) * self.lever_ratio * self.efficiency

    def capacities(self, lever_force: float) -> tuple[float, float]:
        """Torque capacities (against paying out, against hauling in), N m."""
        base = self.rim_radius * self.band_tension(lever_force)
        mu_alpha = self.friction * self.wrap_angle
        return base * math.expm1(mu_alpha), -base * math.expm1(-mu_alpha)

    def problems(self) -> list[str]:
        """Every problem with these parameters."""
        checks = (
            ("brake_rim_radius", self.rim_radius, self.rim_radius > 0, "> 0 m"),
            ("brake_lever_ratio", self.lever_ratio, self.lever_ratio > 0, "> 0"),
            ("brake_efficiency", self.efficiency, 0 < self.efficiency <= 1, "in (0, 1]"),
            ("brake_friction", self.friction, self.friction > 0, "> 0"),
            ("brake_wrap_angle", self.wrap_angle, self.wrap_angle > 0, "> 0 rad"),
        )
        return [
            f"parameter {name!r} must be {bound}, got {value}"
            for name, value, ok, bound in checks
            if not (ok and math.isfinite(value))
        ]


@dataclass(frozen=True)
class WinchInputs:
    """Inputs held over one step.

    Attributes
    ----------
    tension : float
        Rope tension at the drum, N.
    lever_force : float
        Force on the brake lever, N.
    motor_command : float
        Motor torque (N m, at the motor shaft) or, with the motor
        characteristic, its zero-speed torque ``a``.
    speed_command : float
        Drum speed the drive imposes in kinetostatic mode, rad/s.
    """

    tension: float = 0.0
    lever_force: float = 0.0
    motor_command: float = 0.0
    speed_command: float = 0.0

    def problems(self) -> list[str]:
        """Names of non-finite inputs."""
        names = ("rope.tension", "brake.lever_force", "motor.command", "drum.speed_command")
        values = (self.tension, self.lever_force, self.motor_command, self.speed_command)
        return [
            f"input {n!r} is not finite ({v})"
            for n, v in zip(names, values, strict=True)
            if not math.isfinite(v)
        ]


@dataclass(frozen=True)
class WinchConfig:
    """Everything that defines a winch model.

    Parameters
    ----------
    effects : frozenset of str
        Validated by :data:`WINCH_EFFECTS`.
    drum : Drum
        Winding geometry (``layered`` set from the effects).
    chain : DriveChain
        Drive train reduced to the drum shaft, already reduced to the masses
        the model keeps (one mass when rigid).
    brake : BandBrake
        Used with ``band_brake``.
    motor_slope : float
        ``b`` of the characteristic at the motor shaft, N m s/rad.
    initial_speed : float
        Drum speed at the start (inertia modes), rad/s.
    """

    effects: frozenset[str]
    drum: Drum
    chain: DriveChain
    brake: BandBrake = field(default_factory=BandBrake)
    motor_slope: float = 0.0
    initial_speed: float = 0.0

    @property
    def has_brake(self) -> bool:
        """Whether the band brake is modelled."""
        return "band_brake" in self.effects


@dataclass(frozen=True)
class WinchReport:
    """Every output quantity of a winch at one instant (units as in the FMU).

    Each field feeds the unit's output of the same name, dots written as underscores.
    """

    rope_payout: float
    rope_payout_rate: float
    drum_speed: float
    drum_angle: float
    drum_layer: int
    drum_radius: float
    motor_speed: float
    motor_torque: float
    brake_torque: float
    brake_capacity: float
    brake_state: int
    stored_energy: float
    dissipated_energy: float
    external_work: float


class _WinchBase:
    """What both winch models share: drum, brake, inputs, events, layer bookkeeping."""

    def __init__(self, config: WinchConfig) -> None:
        self.config = config
        self.drum = config.drum
        self.brake = config.brake
        self.chain = config.chain
        self.motor_ratio = config.chain.motor_ratio
        self.layer = self.drum.initial_layer()
        self.inputs = WinchInputs()
        self.mode_changes = 0
        self.last_events: list[tuple[float, str]] = []
        self._caps = np.zeros((1, 2))

    def set_inputs(self, inputs: WinchInputs) -> None:
        """Hold ``inputs`` from now on."""
        self.inputs = inputs
        if self.config.has_brake:
            self._caps = np.array([self.brake.capacities(inputs.lever_force)])
        else:
            self._caps = np.zeros((1, 2))

    @property
    def capacities(self) -> tuple[float, float]:
        """Brake capacities (against paying out, against hauling in) now, N m."""
        return float(self._caps[0, 0]), float(self._caps[0, 1])

    def _event(self, t: float, text: str) -> None:
        self.last_events.append((t, text))
        logger.debug("winch event at t = %.9g s: %s", t, text)

    def _change_layer(self, t: float, step: int) -> None:
        """Move to the next (+1, winding in) or previous (-1, paying out) layer."""
        new = self.layer + step
        if new < 0:
            raise ModelError(
                "the rope would run off the drum: all rope on the drum has been paid out "
                f"(rope_on_drum = {self.drum.initial_rope} m)"
            )
        if new >= self.drum.max_layers:
            raise ModelError(
                f"the drum is full: winding in beyond {self.drum.max_layers} layers "
                "(drum_layers) would spool rope over the flanges"
            )
        self.layer = new
        verb = "winds onto" if step > 0 else "pays out from"
        self._event(t, f"rope {verb} layer {new + 1} (radius {self.drum.layer_radius(new):.6g} m)")

    def held_inputs(self) -> dict[str, float]:
        """The held inputs as plain data."""
        i = self.inputs
        return {
            "tension": i.tension,
            "lever_force": i.lever_force,
            "motor_command": i.motor_command,
            "speed_command": i.speed_command,
        }

    def restore_held_inputs(self, data: dict[str, float]) -> None:
        """Restore inputs saved by :meth:`held_inputs`."""
        self.set_inputs(WinchInputs(**{k: float(v) for k, v in data.items()}))


# ====================================================================== inertia
class WinchModel(_WinchBase):
    """Winch with drum inertia: a hybrid ODE (see the module docstring).

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

    def __init__(self, config: WinchConfig, solver: SolverSettings) -> None:
        super().__init__(config)
        chain = config.chain
        self.n = chain.n
        self.base_inertia = np.array(chain.inertias, dtype=float)
        self.stiffness = chain.stiffness_matrix()
        self.damping = chain.damping_matrix()
        links = (FrictionLink("band brake", self.n - 1, GROUND),) if config.has_brake else ()
        self.friction = StickSlip(self.base_inertia.copy(), links)
        self.masses = self.friction.masses  # the drum's entry follows I(phi)
        self.characteristic = "motor_characteristic" in config.effects
        self.motor_b = config.motor_slope * self.motor_ratio**2 if self.characteristic else 0.0
        self.engaged = False
        self.state = np.zeros(2 * self.n + 2)
        self._held_angle = 0.0
        self._n_brake_guards = 2 if config.has_brake else 0
        self._guard_dirs = -np.ones(self._n_brake_guards + 2 * int(self.drum.layered))
        self.settings = solver
        if solver.method in ENERGY_SOLVERS:
            if self.n != 1:
                raise ValueError("the energy-form solver needs a rigid drive train (one mass)")
            self.solver = make_energy_solver(solver)
        else:
            self.solver = make_solver(solver)

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
        """Motor torque at the motor shaft, N m, at real motor speed (rad/s)."""
        if self.characteristic:
            return self.inputs.motor_command - self.config.motor_slope * motor_speed
        return self.inputs.motor_command

    def _motor_reduced(self, omega0: float) -> float:
        """Motor torque reduced to the drum shaft at reduced speed ``omega0``."""
        return self.motor_ratio * self.inputs.motor_command - self.motor_b * omega0

    def _forces(self, x: np.ndarray) -> np.ndarray:
        """All torques except the brake's on every mass (reduced), N m; updates I(phi)."""
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
            self.inputs.tension * drum.layer_radius(k) - 0.5 * drum.rope_inertia_slope(k) * w * w
        )
        self.masses[n - 1] = self.base_inertia[n - 1] + drum.rope_inertia(phi, k)
        return forces

    def _dynamics(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Accelerations and brake torque (shape (0,) or (1,)) in the current mode."""
        forces = self._forces(x)
        if self.engaged:
            return self.friction.accelerations(forces, self._caps)
        return forces / self.masses, np.zeros(len(self.friction.links))

    def drum_held(self) -> bool:
        """Whether the brake holds the drum at rest."""
        return self.engaged and self.friction.mode[0] == 0

    # ------------------------------------------------ HybridSystem protocol
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[theta', omega', dissipated', external work']``."""
        n = self.n
        omega = x[n : 2 * n]
        acc, link = self._dynamics(x)
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
            self._motor_reduced(omega[0]) * omega[0] + self.inputs.tension * r * omega[n - 1]
        )
        return out

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
        """
        out = []
        if self.config.has_brake:
            if self.engaged:
                _, link = self._dynamics(x)
                out.extend(self.friction.guards(x[self.n : 2 * self.n], link, self._caps))
                out.append(self.inputs.lever_force)
            else:
                out += [1.0, -self.inputs.lever_force]
        if self.drum.layered:
            low, high = self.drum.phi_bounds(self.layer)
            phi = x[self.n - 1]
            out += [phi - low, high - phi]
        return np.array(out, dtype=float)

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Brake stick/slip, or the rope changing layer."""
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
        """A held drum stays exactly where it stuck, at rest."""
        if self.drum_held():
            x[self.n - 1] = self._held_angle
            x[2 * self.n - 1] = 0.0
        return x

    # ------------------------------------------ RigidMachineSystem protocol
    def machine(self, t: float, x: np.ndarray) -> MachineUnit | None:
        """Paper 004's machine unit of the current mode (rigid chain only)."""
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
        """Brake and dampers dissipate; motor and rope are external."""
        return work.speed, work.driving - work.angle

    # ---------------------------------------------------------- modes
    def brake_state(self) -> int:
        """0 released, 1 slipping, 2 holding."""
        if not self.engaged:
            return BRAKE_FREE
        return BRAKE_HOLDING if self.friction.mode[0] == 0 else BRAKE_SLIPPING

    def _mode_key(self) -> tuple[bool, int]:
        return self.engaged, int(self.friction.mode[0]) if self.friction.links else 0

    def _settle_modes(self, t: float, x: np.ndarray, fired: list[int] | None = None):
        """Make the brake's engagement and stick/slip mode fit the inputs at (t, x)."""
        if not self.config.has_brake:
            return x
        x = np.array(x, dtype=float)
        before = self._mode_key()
        n = self.n
        if min(self.capacities) <= 0.0:
            self.engaged = False
        else:
            if not self.engaged:
                self.friction.set_mode([int(np.sign(x[2 * n - 1]))])
                self.engaged = True
            forces = self._forces(x)
            x[n : 2 * n] = self.friction.switch(x[n : 2 * n], forces, self._caps, fired or [])
        if self._mode_key() != before or fired:
            self._event(t, f"brake {_BRAKE_WORDS[self.brake_state()]}")
            if fired is None:
                self.mode_changes += 1
        self._held_angle = float(x[n - 1])
        return self.project(x)

    # ---------------------------------------------------------- life cycle
    def initialize(self, t0: float, inputs: WinchInputs) -> None:
        """Start at the configured speed with the shafts already carrying their torques.

        The shafts are twisted as in quasi-static motion: every mass has the
        acceleration the chain would have if it were rigid (zero when the
        brake holds), so the start causes no shaft vibration.
        """
        self.set_inputs(inputs)
        self.layer = self.drum.initial_layer()
        n = self.n
        x = np.zeros(2 * n + 2)
        x[n : 2 * n] = self.config.initial_speed
        forces = self._forces(x)
        acc = self._rigid_acceleration(float(forces.sum()), float(self.masses.sum()), x[2 * n - 1])
        twists = np.cumsum(forces[:-1] - self.masses[:-1] * acc) / np.asarray(
            self.chain.stiffnesses, dtype=float
        )
        x[: n - 1] = np.cumsum(twists[::-1])[::-1]  # angles relative to the drum's 0
        self.engaged = False
        self.mode_changes = 0
        self.last_events = []
        self.state = self._settle_modes(t0, x, [])
        self._forces(self.state)

    def _rigid_acceleration(self, torque: float, inertia: float, omega: float) -> float:
        """Acceleration of the chain locked rigid under ``torque`` (N m) and the brake."""
        plus, minus = self.capacities
        if not self.config.has_brake or min(plus, minus) <= 0.0:
            return torque / inertia
        if omega == 0.0:
            if -minus <= torque <= plus:  # the brake can hold
                return 0.0
            direction = 1.0 if torque > 0.0 else -1.0
        else:
            direction = 1.0 if omega > 0.0 else -1.0
        return (torque - direction * (plus if direction > 0 else minus)) / inertia

    def advance(self, t: float, h: float, inputs: WinchInputs) -> int:
        """Advance by ``h`` with ``inputs`` held; return the number of events."""
        self.last_events = []
        self.set_inputs(inputs)
        self.state = self._settle_modes(t, self.state)
        x, events = self.solver.advance(self, t, self.state, t + h)
        self.state = x
        self._forces(x)
        return events

    # ---------------------------------------------------------- outputs
    def stored_energy(self, x: np.ndarray | None = None) -> float:
        """Kinetic energy of every mass plus shaft strain energy, J."""
        x = self.state if x is None else x
        n = self.n
        theta, omega = x[:n], x[n : 2 * n]
        self._forces(x)
        return 0.5 * float(self.masses @ omega**2) + 0.5 * float(theta @ self.stiffness @ theta)

    def report(self) -> WinchReport:
        """Outputs at the current state for the held inputs (state untouched)."""
        x = self.state
        n = self.n
        _, link = self._dynamics(x)
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
            brake_torque=float(link[0]) + 0.0 if self.engaged else 0.0,
            brake_capacity=self.capacities[0],
            brake_state=self.brake_state(),
            stored_energy=self.stored_energy(),
            dissipated_energy=float(x[2 * n]),
            external_work=float(x[2 * n + 1]),
        )

    @contextmanager
    def trial(self, inputs: WinchInputs) -> Iterator[None]:
        """Modes settled for other inputs, undone on exit (for feedthrough outputs)."""
        saved = (
            self.inputs,
            self.engaged,
            self.friction.get_mode(),
            self.mode_changes,
            list(self.last_events),
            self._held_angle,
            self.state.copy(),
        )
        try:
            self.set_inputs(inputs)
            self._settle_modes(0.0, self.state)
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
            self._forces(self.state)

    def get_state(self) -> dict:
        """Complete model state as plain data."""
        return {
            "x": [float(c) for c in self.state],
            "layer": int(self.layer),
            "engaged": bool(self.engaged),
            "friction_mode": self.friction.get_mode(),
            "held_angle": float(self._held_angle),
            "mode_changes": int(self.mode_changes),
            "inputs": self.held_inputs(),
            "solver": {"rhs_calls": int(self.solver.rhs_calls), "steps": int(self.solver.steps)},
        }

    def set_state(self, data: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.state = np.array(data["x"], dtype=float)
        self.layer = int(data["layer"])
        self.engaged = bool(data["engaged"])
        self.friction.set_mode(list(data["friction_mode"]))
        self._held_angle = float(data["held_angle"])
        self.mode_changes = int(data["mode_changes"])
        self.restore_held_inputs(data["inputs"])
        self.solver.rhs_calls = int(data["solver"]["rhs_calls"])
        self.solver.steps = int(data["solver"]["steps"])
        self._forces(self.state)


# ================================================================ kinetostatic
class KinetostaticWinch(_WinchBase):
    """Winch without inertia (eq. 32): a speed-commanded drive, stepped exactly.

    State ``[phi, omega over the last step, dissipated, external work]``.
    See the module docstring for the rules.
    """

    def __init__(self, config: WinchConfig) -> None:
        super().__init__(config)
        self.beta = float(math.fsum(config.chain.dampings))
        self.state = np.zeros(4)
        self._brake_state = BRAKE_FREE
        self.solver = None

    def initialize(self, t0: float, inputs: WinchInputs) -> None:
        """At rest at ``phi = 0``, turning at the speed command from the start."""
        self.set_inputs(inputs)
        self.layer = self.drum.initial_layer()
        self.state = np.array([0.0, inputs.speed_command, 0.0, 0.0])
        self._brake_state = self._brake_state_for(inputs.speed_command)
        self.mode_changes = 0
        self.last_events = []

    def _brake_state_for(self, omega: float) -> int:
        if not self.config.has_brake or min(self.capacities) <= 0.0:
            return BRAKE_FREE
        return BRAKE_SLIPPING if omega != 0.0 else BRAKE_HOLDING

    def _brake_and_motor(self, omega: float) -> tuple[float, float]:
        """(brake torque, motor torque) on the drum shaft by (32), N m."""
        rope = self.inputs.tension * self.drum.layer_radius(self.layer)
        plus, minus = self.capacities
        if omega > 0.0:
            brake = -plus
        elif omega < 0.0:
            brake = minus
        else:  # held: the brake takes what it can of the holding torque -rope
            brake = max(-rope, -plus) if rope > 0.0 else min(-rope, minus)
        return brake, self.beta * omega - rope - brake

    def advance(self, t: float, h: float, inputs: WinchInputs) -> int:
        """Turn at the commanded speed for ``h``; exact payout, work and losses."""
        self.last_events = []
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
        brake = self._brake_and_motor(omega)[0]
        dissipated = -brake * (phi1 - phi0) + self.beta * omega * omega * h
        rope_work = inputs.tension * paid
        motor_work = dissipated - rope_work  # what (32) makes the motor do
        self.state = np.array(
            [phi1, omega, self.state[2] + dissipated, self.state[3] + rope_work + motor_work]
        )
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
            self._change_layer(t + (edge - phi0) / speed, step)
            self.mode_changes += 1

    def stored_energy(self) -> float:
        """No inertia, no springs: 0 J."""
        return 0.0

    # ------------------------------ HybridSystem protocol (monolithic models)
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[phi', 0, dissipated', external work']`` at the commanded speed."""
        omega = self.inputs.speed_command
        brake, motor = self._brake_and_motor(omega)
        rope = self.inputs.tension * self.drum.layer_radius(self.layer)
        loss = -brake * omega + self.beta * omega * omega
        return np.array([omega, 0.0, loss, (rope + motor) * omega])

    def guard_directions(self) -> np.ndarray:
        """The layer's two edges fire on a downward crossing."""
        return -np.ones(2 if self.drum.layered else 0)

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """The layer's two edges (none without layers)."""
        if not self.drum.layered:
            return np.zeros(0)
        low, high = self.drum.phi_bounds(self.layer)
        return np.array([x[0] - low, high - x[0]])

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """The rope changes layer."""
        for i in fired:
            self._change_layer(t, +1 if i == 0 else -1)
        self.mode_changes += 1
        return np.array(x, dtype=float)

    def project(self, x: np.ndarray) -> np.ndarray:
        """No invariants."""
        return x

    def report(self) -> WinchReport:
        """Outputs for the drum speed of the last step and the held inputs."""
        phi, omega = float(self.state[0]), float(self.state[1])
        radius = self.drum.layer_radius(self.layer)
        brake, motor = self._brake_and_motor(omega)
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
        """Other inputs for reading feedthrough outputs, undone on exit."""
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
            "layer": int(self.layer),
            "brake_state": int(self._brake_state),
            "mode_changes": int(self.mode_changes),
            "inputs": self.held_inputs(),
        }

    def set_state(self, data: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.state = np.array(data["x"], dtype=float)
        self.layer = int(data["layer"])
        self._brake_state = int(data["brake_state"])
        self.mode_changes = int(data["mode_changes"])
        self.restore_held_inputs(data["inputs"])


def fastest_rate(chain: DriveChain, motor_slope: float = 0.0) -> float:
    """Largest ``|lambda|`` (1/s) of the chain with the motor characteristic, brake released.

    The eigenvalues of ``[[0, I], [-M^-1 K, -M^-1 (B + b_red e0 e0^T)]]`` with the
    chain's own inertias (rope on the drum only adds inertia, lowering them).

    Parameters
    ----------
    chain : DriveChain
        Reduced to the drum shaft.
    motor_slope : float
        ``b`` of the motor characteristic at the motor shaft, N m s/rad (0: torque input).
    """
    n = chain.n
    damping = chain.damping_matrix()
    damping[0, 0] += motor_slope * chain.motor_ratio**2
    inv_mass = 1.0 / np.asarray(chain.inertias, dtype=float)
    system = np.block(
        [
            [np.zeros((n, n)), np.eye(n)],
            [-inv_mass[:, None] * chain.stiffness_matrix(), -inv_mass[:, None] * damping],
        ]
    )
    return float(np.abs(np.linalg.eigvals(system)).max())


def build_winch(config: WinchConfig, solver: SolverSettings) -> WinchModel | KinetostaticWinch:
    """The model the effects call for: with ``drum_inertia`` a hybrid ODE, else kinetostatic."""
    drum = replace(config.drum, layered="rope_layers" in config.effects)
    config = replace(config, drum=drum)
    if "drum_inertia" in config.effects:
        return WinchModel(config, solver)
    return KinetostaticWinch(config)
