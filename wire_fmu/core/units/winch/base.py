"""What both winch models share: inputs, configuration, report, drum and layer bookkeeping.

Sign convention and energy: :mod:`wire_fmu.core.units.winch.model`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import astuple, dataclass

import numpy as np

from wire_fmu.core.components.drive_train import DriveChain
from wire_fmu.core.components.drum import Drum
from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.interface_model import EffortModel, interface_input_names
from wire_fmu.core.framework.interface_model import inputs_taken as interface_inputs_taken
from wire_fmu.core.units.winch.brake import BandBrake

__all__ = [
    "FLAT_INPUTS",
    "NO_ROPE_MODEL",
    "ROPE_MODEL_INPUTS",
    "WinchConfig",
    "WinchInputs",
    "WinchReport",
    "inputs_taken",
]

ROPE_MODEL_INPUTS = interface_input_names("rope")
"""The unit's inputs of the rope's interface model, in :class:`EffortModel`'s order."""
NO_ROPE_MODEL = EffortModel()
"""The held tension: no interface model."""
FLAT_INPUTS = (
    "rope.tension",
    "brake.lever_force",
    "motor.command",
    "drum.speed_command",
    *ROPE_MODEL_INPUTS,
)
"""The unit's inputs, in the order :func:`inputs_taken` and the compiled quiet step
(:meth:`~wire_fmu.core.units.winch.drive.WinchModel.quiet_step_outputs`) take them."""
_ROPE_STIFFNESS_AT = FLAT_INPUTS.index(ROPE_MODEL_INPUTS[0])

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class WinchInputs:
    """Inputs held over one step.

    Attributes
    ----------
    tension : float
        Rope tension at the drum, N: held over the step, or the block train's
        tension ``E0`` at the step's start about which ``rope_model`` is taken.
    lever_force : float
        Force on the brake lever, N.
    motor_command : float
        Motor torque (N m, at the motor shaft) or, with the motor
        characteristic, its zero-speed torque ``a``.
    speed_command : float
        Drum speed the drive imposes in kinetostatic mode, rad/s.
    rope_model : EffortModel
        The block train's interface model of the tension about the step's start
        (:mod:`~wire_fmu.core.framework.interface_model`; position ``rope.payout``,
        velocity ``rope.payout_rate``); :data:`NO_ROPE_MODEL` holds the tension.
    """

    tension: float = 0.0
    lever_force: float = 0.0
    motor_command: float = 0.0
    speed_command: float = 0.0
    rope_model: EffortModel = NO_ROPE_MODEL

    def tension_at(self, t: float, payout: float, payout_rate: float) -> float:
        """Rope tension at time ``t`` with the drum at ``payout`` and ``payout_rate``, N.

        The held ``tension`` without an interface model; with one, its local model
        ``E0 - K (payout - x_ref) - D (payout_rate - v_ref) + R (t - t0)``, and at
        least 0: a rope cannot push (a model that would is a rope gone slack).

        Parameters
        ----------
        t : float
            Time, s.
        payout : float
            Rope paid out, m.
        payout_rate : float
            Its rate, m/s.
        """
        model = self.rope_model
        if not model.active:
            return self.tension
        tension = model.effort(self.tension, t, payout, payout_rate, model.reference_position)
        return tension if tension > 0.0 else 0.0

    def problems(self) -> list[str]:
        """Non-finite inputs and a rope model's spring or damper of the wrong sign, named.

        Checked before every step: the names are put together only for a bad input."""
        rope = self.rope_model
        values = (
            self.tension,
            self.lever_force,
            self.motor_command,
            self.speed_command,
            rope.stiffness,
            rope.damping,
            rope.effort_rate,
            rope.reference_position,
            rope.reference_velocity,
        )
        if inputs_taken(values):
            return []
        out = [
            f"input {n!r} is not finite ({v})"
            for n, v in zip(FLAT_INPUTS, values, strict=True)
            if not math.isfinite(v)
        ]
        return out + rope.problems("rope")


def inputs_taken(values: tuple[float, ...]) -> bool:
    """Whether the winch takes these inputs: all finite, the rope model's spring and damper
    not negative.

    Parameters
    ----------
    values : tuple of float
        The values of :data:`FLAT_INPUTS`: tension (N), lever force (N), motor command
        (N m), speed command (rad/s), then the rope model's K (N/m), D (N s/m), R (N/s),
        reference payout (m) and rate (m/s).
    """
    return interface_inputs_taken(values, _ROPE_STIFFNESS_AT)


@dataclass(frozen=True)
class WinchConfig:
    """Everything that defines a winch model.

    Parameters
    ----------
    effects : frozenset of str
        Validated by :data:`WINCH_EFFECTS`.
    drum : Drum
        Winding geometry: a :class:`~wire_fmu.core.components.drum.LayeredDrum`
        with ``rope_layers``.
    chain : DriveChain
        Drive train reduced to the drum shaft, already reduced to the masses
        the model keeps (one mass when rigid).
    brake : BandBrake or None
        The band brake with ``band_brake``; None (no brake at all) without it.
    motor_slope : float
        ``b`` of the characteristic at the motor shaft, N m s/rad.
    initial_speed : float
        Drum speed at the start (inertia modes), rad/s.
    """

    effects: frozenset[str]
    drum: Drum
    chain: DriveChain
    brake: BandBrake | None = None
    motor_slope: float = 0.0
    initial_speed: float = 0.0


@dataclass(slots=True)
class WinchReport:
    """Every output quantity of a winch at one instant (units as in the FMU).

    Each field feeds the unit's output of the same name, dots written as underscores.
    Made once per step and only read (not frozen: a frozen dataclass of 14 fields
    costs twice as much to make).
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


_NO_CAPACITY = np.zeros((1, 2))
_NO_CAPACITY.flags.writeable = False  # shared by every winch without a brake


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
        self.first_event_time = math.inf  # of the last step's located events, s
        self.time = 0.0  # of the state, s: where the rope model's tension is taken
        self._caps = _NO_CAPACITY

    def set_inputs(self, inputs: WinchInputs) -> None:
        """Hold ``inputs`` from now on.

        Parameters
        ----------
        inputs : WinchInputs
            Inputs held from now on.
        """
        self._caps = self._capacities_for(inputs.lever_force)
        self.inputs = inputs
        self._step_summary = None  # outputs a compiled step computed are for other inputs

    def _capacities_for(self, lever_force: float) -> np.ndarray:
        """The brake's capacities for ``lever_force`` (N), shape (1, 2), N m: the array
        held now while the lever force is the same; else a new one, never changed in place
        (snapshots and kernel data keep the old one)."""
        if self.brake is None or (
            lever_force == self.inputs.lever_force and self._caps is not _NO_CAPACITY
        ):
            return self._caps
        return np.array([self.brake.capacities(lever_force)])

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
            "rope_model": list(astuple(i.rope_model)),
        }

    def restore_held_inputs(self, data: dict[str, float]) -> None:
        """Restore inputs saved by :meth:`held_inputs`.

        Parameters
        ----------
        data : dict
            Tension (N), lever force (N), motor command (N m), speed command
            (rad/s) and the rope model's fields as from :meth:`held_inputs`.
        """
        data = dict(data)
        fields = data.pop("rope_model", None)
        model = NO_ROPE_MODEL if fields is None else EffortModel(*map(float, fields))
        inputs = WinchInputs(**{k: float(v) for k, v in data.items()}, rope_model=model)
        self.set_inputs(inputs)
