"""The winch's FMI variables: parameters, inputs and outputs, each with unit and description.

Ports, sign convention and solver choice: :mod:`wire_fmu.core.units.winch.unit`.
"""

from __future__ import annotations

import json

from wire_fmu.core.components.drive_train import default_drive_train
from wire_fmu.core.framework.energy_solver import ENERGY_SOLVERS
from wire_fmu.core.framework.interface_model import interface_input_names, interface_inputs
from wire_fmu.core.framework.solver_options import solver_parameters
from wire_fmu.core.framework.unit import input_, mode_change_time_output, output, parameter
from wire_fmu.core.units.winch.brake import BRAKE_FRICTION_MAX, BRAKE_WRAP_ANGLE_MAX
from wire_fmu.core.units.winch.model import WINCH_EFFECTS

__all__ = ["winch_parameters", "winch_inputs", "winch_outputs"]

_FEEDTHROUGH = (
    "rope.tension",
    *(name for name in interface_input_names("rope") if name != "rope.effort_rate"),
    "brake.lever_force",
    "motor.command",
)
"""What the outputs that depend on the rope's tension depend on: the tension, its interface
model's spring and damper with their reference motion (its rate acts from the time the
inputs are set on, not at that instant), the brake's lever and the motor's command."""
_INERTIA = ("drum_inertia",)
_BRAKE = ("band_brake",)
_LAYERS = ("rope_layers",)


def winch_parameters():
    """The winch's parameters: effects, solver, drive train, drum, brake and motor."""
    return (
        parameter(
            "effects",
            "",
            "",
            "Effects to include, comma separated: " + ", ".join(WINCH_EFFECTS.names),
            type=str,
        ),
        *solver_parameters(
            "rk4",
            1e-3,
            also=ENERGY_SOLVERS,
            note="energy, energy1: paper 004's energy form, rigid drive train only",
            acts_with=_INERTIA,
        ),
        parameter(
            "drive_train",
            json.dumps(default_drive_train()),
            "",
            "Drive train as JSON: masses (motor rotor .. drum) and shafts, each with its "
            "speed ratio to the drum (estimated 1500-2000 hp drawworks by default)",
            type=str,
        ),
        parameter(
            "drive_train_masses",
            0,
            "",
            "Masses kept with elastic_drive_train: 0 the "
            "full chain, 1 rigid, 2.. reduced by delta-star elimination",
            type=int,
            min=0,
            acts_with=("elastic_drive_train",),
        ),
        parameter(
            "drum_radius",
            0.42,
            "m",
            "Rope centreline radius on the first layer (32 in "
            "barrel with 1-3/8 in line, typical 1500-2000 hp drawworks; estimate)",
            min=0.0,
            min_exclusive=True,
        ),
        parameter(
            "rope_diameter",
            0.0349,
            "m",
            "Rope diameter: 1-3/8 in drilling line "
            "(API 9A size); the radius grows by one diameter per layer",
            min=0.0,
            min_exclusive=True,
            acts_with=_LAYERS,
        ),
        parameter(
            "rope_linear_mass",
            5.06,
            "kg/m",
            "Rope mass per metre on the drum, its inertia (1-3/8 in 6x19 IWRC, about 3.4 lb/ft)",
            min=0.0,
            acts_with=_LAYERS,
        ),
        parameter(
            "drum_wraps_per_layer",
            40,
            "",
            "Turns per layer (about 1.4 m barrel / rope diameter)",
            type=int,
            min=1,
            acts_with=_LAYERS,
        ),
        parameter(
            "drum_layers",
            4,
            "",
            "Layers the drum flanges allow",
            type=int,
            min=1,
            acts_with=_LAYERS,
        ),
        parameter(
            "rope_on_drum",
            150.0,
            "m",
            "Rope on the drum at the start, at most the drum's capacity with drum_layers",
            min=0.0,
            min_exclusive=True,
            acts_with=_LAYERS,
        ),
        parameter(
            "brake_rim_radius",
            0.62,
            "m",
            "Brake-rim radius r_f (about 49 in rims; estimate)",
            min=0.0,
            min_exclusive=True,
            acts_with=_BRAKE,
        ),
        parameter(
            "brake_lever_ratio",
            15.0,
            "1",
            "Lever ratio L/l of the brake handle linkage (estimate)",
            min=0.0,
            min_exclusive=True,
            acts_with=_BRAKE,
        ),
        parameter(
            "brake_efficiency",
            0.9,
            "1",
            "Efficiency eta of the brake linkage",
            min=0.0,
            max=1.0,
            min_exclusive=True,
            acts_with=_BRAKE,
        ),
        parameter(
            "brake_friction",
            0.4,
            "1",
            "Band friction coefficient mu (moulded lining on steel, 0.35-0.45; at most 1: "
            "brake linings lie below about 0.65)",
            min=0.0,
            max=BRAKE_FRICTION_MAX,
            min_exclusive=True,
            acts_with=_BRAKE,
        ),
        parameter(
            "brake_wrap_angle",
            5.24,
            "rad",
            "Band wrap angle alpha (about 300 deg; at most one turn, 2 pi: both band ends "
            "leave the drum)",
            min=0.0,
            max=BRAKE_WRAP_ANGLE_MAX,
            min_exclusive=True,
            acts_with=_BRAKE,
        ),
        parameter(
            "motor_slope",
            3.6e3,
            "N.m.s/rad",
            "Slope b of the motor characteristic at "
            "the motor shaft (1150 hp AC motor, 1.5 % slip at 1200 rpm; estimate)",
            min=0.0,
            acts_with=("motor_characteristic",),
        ),
        parameter(
            "initial_drum_speed",
            0.0,
            "rad/s",
            "Drum speed at the start (with drum_inertia; without, the drum starts at the "
            "speed command)",
            acts_with=_INERTIA,
        ),
    )


def winch_inputs():
    """The winch's inputs: rope tension and its interface model, brake lever force, motor and
    drum speed commands."""
    return (
        input_(
            "rope.tension",
            0.0,
            "N",
            "Rope tension at the drum: held over the step, or E0 of the interface model",
        ),
        *interface_inputs("rope", "rope", "rope.tension", "rope.payout", "rope.payout_rate"),
        input_(
            "brake.lever_force",
            0.0,
            "N",
            "Force on the brake lever (<= 0: released)",
            acts_with=_BRAKE,
        ),
        input_(
            "motor.command",
            0.0,
            "N.m",
            "Motor torque at the motor shaft, positive paying "
            "out; with motor_characteristic the zero-speed torque a of a - b omega",
        ),
        input_(
            "drum.speed_command",
            0.0,
            "rad/s",
            "Drum speed the drive imposes without "
            "drum_inertia (kinetostatic mode), positive paying out",
            acts_without=_INERTIA,
        ),
    )


def winch_outputs():
    """The winch's outputs: rope, drum, motor and brake quantities and the energy ledger."""
    deps = _FEEDTHROUGH
    return (
        output("rope.payout", "m", "Rope paid out since the start (unstretched)"),
        output("rope.payout_rate", "m/s", "Rate of rope paid out"),
        output("drum.speed", "rad/s", "Drum speed, positive paying out"),
        output("drum.angle", "rad", "Drum angle since the start, positive paying out"),
        output(
            "drum.layer",
            "",
            "Rope layer the rope leaves from (1 = on the barrel)",
            type=int,
            start=1,
        ),
        output("drum.radius", "m", "Winding radius where the rope leaves the drum"),
        output("motor.speed", "rad/s", "Motor shaft speed"),
        output("motor.torque", "N.m", "Motor torque at the motor shaft", depends_on=deps),
        output("brake.torque", "N.m", "Torque of the band brake on the drum", depends_on=deps),
        output(
            "brake.capacity",
            "N.m",
            "Brake capacity against paying out (eq. 34)",
            depends_on=("brake.lever_force",),
        ),
        output(
            "brake.state",
            "",
            "Band brake: 0 released, 1 slipping, 2 holding",
            type=int,
            depends_on=deps,
        ),
        output(
            "stored_energy",
            "J",
            "Kinetic energy of the drive train and drum plus shaft strain energy",
        ),
        output("dissipated_energy", "J", "Energy dissipated by the brake and dampers"),
        output("external_work", "J", "Work done on the winch by the rope and the motor"),
        output(
            "energy_balance", "J", "Ledger residual: stored change + dissipated - external work"
        ),
        mode_change_time_output("stick/slip, layer changes"),
        output(
            "mode_changes", "", "Number of mode events so far (stick/slip, layer changes)", type=int
        ),
    )
