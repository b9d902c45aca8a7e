"""What a scissor jack is built from, what it takes each step and what it reports."""

from __future__ import annotations

import math
from dataclasses import dataclass

from wire_fmu.core.components.screw_nut.thread import REGULARISATIONS, ScrewThread
from wire_fmu.core.units.scissor_jack.geometry import JackGeometry

__all__ = ["JackConfig", "JackInputs", "JackReport", "FRICTION_MODELS", "HANDLE_DRIVES"]

FRICTION_MODELS = ("none", "stick_slip", "linear", "tanh")
"""Thread friction models (:mod:`wire_fmu.core.units.scissor_jack.model`)."""

HANDLE_DRIVES = ("speed", "torque")
"""How the handle is driven: kinematically by a speed, or by a torque."""


@dataclass(frozen=True)
class JackConfig:
    """Everything a :class:`~wire_fmu.core.units.scissor_jack.model.ScissorJackModel` is built from.

    Parameters
    ----------
    geometry : JackGeometry
        Rods and travel.
    thread : ScrewThread
        Lead, mean radius and friction coefficient.
    load_mass : float
        Mass moving with the shoe, kg (paper: 306 kg).
    load_weight : float
        Weight acting on the shoe, N (paper: 3000 N).
    handle_inertia : float
        ``J_s`` of screw and handle about the screw axis, kg m^2.
    friction : str
        One of :data:`FRICTION_MODELS`.
    speed_scale : float
        ``w1`` of the regularised models, rad/s (paper: 1e-6).
    drive : str
        One of :data:`HANDLE_DRIVES`.
    initial_speed : float
        Handle speed at the start with a torque drive, rad/s.
    """

    geometry: JackGeometry
    thread: ScrewThread
    load_mass: float = 306.0
    load_weight: float = 3000.0
    handle_inertia: float = 5.0e-3
    friction: str = "stick_slip"
    speed_scale: float = 1.0e-6
    drive: str = "torque"
    initial_speed: float = 0.0

    @property
    def regularised(self) -> bool:
        """Whether the thread friction is one of the paper's regularised forms."""
        return self.friction in REGULARISATIONS

    def static_force(self, travel: float) -> float:
        """Axial force holding the load at rest, ``W cot(theta)``, N.

        Parameters
        ----------
        travel : float
            Screw travel through the nut since the start, m.
        """
        _, slope, _ = self.geometry.slopes(travel)
        return self.load_weight * slope

    def breakaway_torques(self, travel: float) -> tuple[float, float]:
        """Handle torques (N m) at which a stuck thread starts to lift / to lower.

        ``(h + r mu) F0`` and ``(h - r mu) F0`` with ``F0 = W cot(theta)``;
        a negative second value means the jack is self-locking (it holds the
        load with no handle torque and must be driven down).

        Parameters
        ----------
        travel : float
            Screw travel through the nut since the start, m.
        """
        force = self.static_force(travel)
        lead = self.thread.lead_torque(force)
        capacity = self.thread.friction_capacity(force)
        return lead + capacity, lead - capacity

    def effective_inertia(self, travel: float, direction: float) -> float:
        """``J_s + q m h^2 cot^2(theta)`` while sliding in ``direction``, kg m^2.

        Parameters
        ----------
        travel : float
            Screw travel through the nut since the start, m.
        direction : float
            Sliding direction of the handle, +1 lifting or -1 lowering.
        """
        _, slope, _ = self.geometry.slopes(travel)
        h = self.thread.lead_per_radian
        q = h + direction * self.thread.mean_radius * self.thread.friction
        return self.handle_inertia + q * self.load_mass * h * slope * slope

    def problems(self) -> list[str]:
        """Every problem with the configuration, as sentences."""
        out = self.geometry.problems() + self.thread.problems()
        for name in ("load_mass", "load_weight", "handle_inertia", "speed_scale"):
            value = getattr(self, name)
            if not (value > 0.0 and math.isfinite(value)):
                out.append(f"{name} must be a positive number, got {value}")
        if self.friction not in FRICTION_MODELS:
            out.append(
                f"thread friction model {self.friction!r} is unknown; choose one of "
                f"{', '.join(FRICTION_MODELS)}"
            )
        if self.drive not in HANDLE_DRIVES:
            out.append(
                f"handle drive {self.drive!r} is unknown; choose one of {', '.join(HANDLE_DRIVES)}"
            )
        if not math.isfinite(self.initial_speed):
            out.append(f"initial handle speed must be finite, got {self.initial_speed}")
        if out or self.friction == "none":
            return out
        lowest = self.geometry.travel_at_height(self.geometry.min_height)
        if self.effective_inertia(lowest, -1.0) <= 0.0:
            need = self.handle_inertia - self.effective_inertia(lowest, -1.0)
            out.append(
                f"handle_inertia {self.handle_inertia} kg m^2 is too light for lowering at "
                f"min_height {self.geometry.min_height} m: the effective inertia while the "
                f"thread slides down vanishes (Painleve's paradox of dry friction); use more "
                f"than {need:.4g} kg m^2 or raise min_height"
            )
        return out


@dataclass(frozen=True)
class JackInputs:
    """Handle commands held over a step.

    Attributes
    ----------
    speed_command : float
        Handle speed with a speed drive, rad/s (positive lifts).
    torque_command : float
        Handle torque with a torque drive, N m (positive lifts).
    """

    speed_command: float = 0.0
    torque_command: float = 0.0

    def problems(self) -> list[str]:
        """Non-finite commands."""
        return [
            f"input {name} is not finite ({value})"
            for name, value in (
                ("handle.speed_command", self.speed_command),
                ("handle.torque_command", self.torque_command),
            )
            if not math.isfinite(value)
        ]


@dataclass(frozen=True)
class JackReport:
    """Outputs of the jack at one instant (SI units), each named as its output (``_`` for ``.``)."""

    handle_angle: float
    handle_speed: float
    handle_torque: float
    screw_travel: float
    load_height: float
    load_velocity: float
    screw_displacement: float
    rod_angle: float
    screw_axial_force: float
    thread_lead_torque: float
    thread_friction_torque: float
    thread_state: int
    stored_energy: float
    dissipated_energy: float
    external_work: float
