"""The scenes of the hard cases (SPEC section 17, issue 7), as plain dicts.

Each is a scene as a TOML file would give it, naming our units
(``"fmu": "BlockTrain"``); :func:`~tests.hard_case_helpers.run_case` runs it on
the built FMUs. The hard-case tests check them against closed forms and the
monolithic reference; the kernel comparison (``tests/test_kernels.py``) runs
them with both kernels. The constants are the cases' physics, in SI units.
"""

from __future__ import annotations

import math

from wire_fmu.core.units.block_train.reevings import single_fall

from .hard_case_helpers import rigid_drum
from .hydraulics_helpers import constant_force_cylinder
from .winch_helpers import BRAKE

__all__ = [
    "brake_scene",
    "break_scene",
    "impact_scene",
    "snap_scene",
    "stiff_pulley_scene",
    "winch_and_fall_scene",
]

G = 9.81  # m/s^2

# =========================================================== 1. stiff rope
# --- inside one unit: a short, very stiff span on a light sheave -----------------
PULLEY_MASS, PULLEY_EA, PULLEY_RADIUS = 1000.0, 1.0e8, 0.05
RIM_MASS = 1.0  # kg: sheave inertia / radius^2
SHORT_SPAN, LONG_SPAN = 0.1, 10.0  # m: line end to sheave, sheave to hook
PULLEY_PRETENSION = 0.9 * PULLEY_MASS * G  # released off equilibrium: the hook oscillates


def stiff_pulley_scene(solver_max_step: float) -> dict:
    """A line end 0.1 m below a light sheave; the hook hangs 10 m below it.

    The short span (EA / 0.18 m = 5.6e8 N/m) on a 1 kg sheave rim is a mode of
    24000 rad/s; the hook mode (1000 kg on the spans in series) is 99 rad/s.
    """
    r = PULLEY_RADIUS
    reeving = {
        "rope": {"axial_stiffness": PULLEY_EA},
        "gravity": [0.0, -G, 0.0],
        "bodies": {
            "load": {
                "kind": "block",
                "mass": PULLEY_MASS,
                "direction": [0, 1, 0],
                "port": "block_a",
            }
        },
        "sheaves": {
            "pulley": {"centre": [0.0, LONG_SPAN, 0.0], "radius": r, "inertia": RIM_MASS * r * r}
        },
        "anchors": {"hook": {"body": "load", "point": [r, 0.0, 0.0]}},
        "path": [
            {"line_end": "line_a", "point": [-r, LONG_SPAN - SHORT_SPAN, 0.0]},
            {"sheave": "pulley", "wrap": "cw"},
            {"anchor": "hook"},
        ],
    }
    return {
        "name": "stiff_span",
        "run": {"stop_time": 0.5, "step": 2e-3},
        "units": {
            "rope": {
                "fmu": "BlockTrain",
                "effects": ["sheave_inertia"],
                "parameters": {
                    "reeving": reeving,
                    "solver": "ros2",
                    "solver_max_step": solver_max_step,
                    "initial_equilibrium": False,
                    "pretension": PULLEY_PRETENSION,
                },
            }
        },
        "outputs": {"variables": "all"},
    }


# --- across a unit boundary: rope stiffness between a light drum and the load -------
LOAD, FALL, LINE_EA, LINE_DAMPING = 1000.0, 10.0, 1.0e8, 4.0e4  # kg, m, N, N s
DRUM_INERTIA, DRUM_RADIUS = 10.0, 0.5  # kg m^2, m: 40 kg at the rope
HOLD = LOAD * G * DRUM_RADIUS  # N m: motor torque holding the load
WINCH_STOP = 0.2


def fast_line_bond() -> dict:
    """The rope bond of a winch (``winch``) and a single fall (``rope``): line end ``line_a``."""
    return {
        "name": "fast_line",
        "kind": "rope",
        "effort": "rope.line_a.tension -> winch.rope.tension",
        "flow": "winch.rope.payout_rate -> rope.line_a.payout_rate",
        "position": "winch.rope.payout -> rope.line_a.payout",
    }


def winch_and_fall_scene(step: float, *, stop: float = WINCH_STOP, **run) -> dict:
    """A light rigid drum hoists a 1000 kg load on 10 m of stiff, slightly damped rope.

    The drum (40 kg at the rope) and the load on the rope (1e7 N/m) form a mode of
    510 rad/s that lives across the bond: explicit coupling holds only for omega H
    below about 0.05-0.1 (SPEC section 15). Held at first, the motor torque rises
    by 30 % at 0.05 s.
    """
    return {
        "name": "winch_and_fall",
        "run": {"stop_time": stop, "step": step, **run},
        "units": {
            "winch": {
                "fmu": "Winch",
                "effects": ["drum_inertia"],
                "parameters": {
                    "drive_train": rigid_drum(DRUM_INERTIA),
                    "drum_radius": DRUM_RADIUS,
                    "motor.command": -HOLD,
                    "solver": "ros2",
                    "solver_max_step": 5e-4,
                },
            },
            "rope": {
                "fmu": "BlockTrain",
                "effects": ["rope_damping"],
                "parameters": {
                    "reeving": single_fall(
                        mass=LOAD, length=FALL, axial_stiffness=LINE_EA, damping=LINE_DAMPING
                    ),
                    "solver_max_step": 5e-4,
                },
            },
        },
        "bonds": [fast_line_bond()],
        "events": [{"time": 0.05, "label": "hoist", "set": {"winch.motor.command": -1.3 * HOLD}}],
        "outputs": {"variables": "all"},
    }


# ================================================== 2. band brake stick and slip
BRAKE_DRUM, BRAKE_RADIUS, LEVER = 1000.0, 0.5, 1000.0  # kg m^2, m, N
RAMP_END, APPLY = 0.4, 0.5  # s: the load stops rising; the lever force doubles


def brake_capacity(lever_force: float) -> float:
    """Eq. (34) written out: r_f F (L/l) eta (e^(mu alpha) - 1), N m (paying out)."""
    b = BRAKE
    return (
        b["brake_rim_radius"]
        * lever_force
        * b["brake_lever_ratio"]
        * b["brake_efficiency"]
        * math.expm1(b["brake_friction"] * b["brake_wrap_angle"])
    )


CAPACITY = brake_capacity(LEVER)
T_CAP = CAPACITY / BRAKE_RADIUS  # rope tension at which the held drum breaks away
T_START, T_END = 0.79 * T_CAP, 1.2 * T_CAP


def brake_scene(step: float) -> dict:
    """A rigid drum held by the band brake while the rope tension ramps up past its capacity;
    at 0.5 s the driller doubles the lever force and the drum stops again."""
    return {
        "name": "band_brake",
        "run": {"stop_time": 0.8, "step": step},
        "units": {
            "winch": {
                "fmu": "Winch",
                "effects": ["drum_inertia", "band_brake"],
                "parameters": {
                    "drive_train": rigid_drum(BRAKE_DRUM),
                    "drum_radius": BRAKE_RADIUS,
                    **BRAKE,
                    "brake.lever_force": LEVER,
                },
            }
        },
        "drivers": [
            {
                "target": "winch.rope.tension",
                "kind": "ramp",
                "points": [[0.0, T_START], [RAMP_END, T_END]],
            }
        ],
        "events": [
            {
                "time": APPLY,
                "label": "brake applied harder",
                "set": {"winch.brake.lever_force": 2 * LEVER},
            }
        ],
        "outputs": {"variables": "all"},
    }


# ================================================ 3. slack rope and snap load
SNAP_MASS, SNAP_LENGTH, SNAP_EA, DROP = 1000.0, 10.0, 1.0e7, 0.05  # kg, m, N, m


def snap_scene(step: float) -> dict:
    """A 1000 kg block on 10 m of rope without pretension; at t = 0 the line end pays out
    5 cm at once: the rope is slack, the block falls 5 cm and snaps it taut."""
    return {
        "name": "snap",
        "run": {"stop_time": 0.3, "step": step},
        "units": {
            "rope": {
                "fmu": "BlockTrain",
                "parameters": {
                    "reeving": single_fall(
                        mass=SNAP_MASS, length=SNAP_LENGTH, axial_stiffness=SNAP_EA
                    ),
                    "initial_equilibrium": False,
                    "pretension": 0.0,
                    "solver_max_step": step,
                },
            }
        },
        "events": [{"time": 0.0, "label": "payout step", "set": {"rope.line_a.payout": DROP}}],
        "outputs": {"variables": "all"},
    }


# ============================================================= 4. rope break
BREAK_EA, BREAK_DRUM, BREAKING_LOAD = 1.0e7, 100.0, 1.5e4  # N, kg m^2, N
BREAK_STOP = 0.2


def break_scene(step: float, how: str) -> dict:
    """A drum holding a 1000 kg load on 10 m of rope; the rope breaks.

    ``breaking_load``: at 0.05 s the motor hoists with twice the holding torque
    and the snatch takes the tension past the 15 kN breaking load (a mode event
    inside the BlockTrain). ``commanded``: the scene breaks the rope at 0.1 s.
    """
    reeving = single_fall(mass=LOAD, length=FALL, axial_stiffness=BREAK_EA)
    if how == "breaking_load":
        reeving["rope"]["breaking_load"] = BREAKING_LOAD
        event = {"time": 0.05, "label": "hoist hard", "set": {"winch.motor.command": -2 * HOLD}}
    else:
        event = {"time": 0.1, "label": "rope cut", "set": {"rope.break_segment": 1}}
    watch = [
        "rope.line_a.tension",
        "rope.tension_max",
        "rope.block_a.position",
        "rope.block_a.velocity",
        "rope.broken",
        "rope.mode_changes",
        "rope.stored_energy",
        "rope.dissipated_energy",
        "rope.external_work",
        "winch.rope.tension",
        "winch.drum.speed",
        "winch.motor.torque",
        "winch.stored_energy",
        "winch.dissipated_energy",
        "winch.external_work",
    ]
    return {
        "name": "rope_break",
        "run": {"stop_time": BREAK_STOP, "step": step},
        "units": {
            "winch": {
                "fmu": "Winch",
                "effects": ["drum_inertia"],
                "parameters": {
                    "drive_train": rigid_drum(BREAK_DRUM),
                    "drum_radius": DRUM_RADIUS,
                    "motor.command": -HOLD,
                    "solver": "ros2",
                },
            },
            "rope": {"fmu": "BlockTrain", "parameters": {"reeving": reeving}},
        },
        "bonds": [fast_line_bond()],
        "events": [event],
        "outputs": {"variables": watch},
    }


# ===================================================== 5. cylinder end-stop impact
ROD_MASS, STROKE, STOP_STIFFNESS, RESTITUTION, IMPACT_SPEED = 1000.0, 4.0, 1e8, 0.3, 0.5
GAS_PRESSURE = 2.0e6  # Pa: a huge accumulator, so the rod is a free mass
BORE_AREA = math.pi * 0.2**2 / 4


def impact_scene(step: float, solver_max_step: float) -> dict:
    """A free rod (its oil force balanced by rod.force) runs at 0.5 m/s onto the extension
    stop, 1e8 N/m with restitution 0.3, no cushion; contact begins at 0.08 s."""
    params = constant_force_cylinder(
        initial_velocity=IMPACT_SPEED,
        initial_position=3.96,
        cushion_length=0.0,
        stop_stiffness=STOP_STIFFNESS,
        stop_restitution=RESTITUTION,
        solver_max_step=solver_max_step,
    )
    params["rod.force"] = -BORE_AREA * GAS_PRESSURE
    return {
        "name": "end_stop",
        "run": {"stop_time": 0.15, "step": step},
        "units": {"cyl": {"fmu": "Hydraulics", "effects": ["end_stops"], "parameters": params}},
        "outputs": {"variables": "all"},
    }
