"""Small helpers shared by the winch tests: chains, a test brake, a configured unit, a run loop."""

from __future__ import annotations

import json
import math
from collections.abc import Callable

import numpy as np

from wire_fmu.core.units.winch.unit import WinchUnit

BRAKE = {
    "brake_rim_radius": 0.6,
    "brake_lever_ratio": 10.0,
    "brake_efficiency": 0.9,
    "brake_friction": 0.35,
    "brake_wrap_angle": 4.7,
}
"""A test band brake's parameters: capacity 22.6 N m per newton of lever force paying out,
4.36 hauling in."""


def capacities(lever_force: float) -> tuple[float, float]:
    """:data:`BRAKE`'s capacities paying out and hauling in, N m, at ``lever_force`` (N).

    Eq. (34) and its reverse, written out here.
    """
    base = 0.6 * lever_force * 10.0 * 0.9
    return base * (math.exp(0.35 * 4.7) - 1.0), base * (1.0 - math.exp(-0.35 * 4.7))


def one_mass(inertia: float, damping: float = 0.0, motor_ratio: float = 1.0) -> str:
    """A rigid drive train: the drum alone (motor acting on it through ``motor_ratio``)."""
    return json.dumps(
        {
            "masses": [{"name": "drum", "inertia": inertia, "damping": damping, "ratio": 1.0}],
            "shafts": [],
        }
    )


def two_mass(
    j_motor: float,
    j_drum: float,
    stiffness: float,
    damping: float = 0.0,
    ground: tuple[float, float] = (0.0, 0.0),
) -> str:
    """Motor rotor and drum on one shaft, both at drum speed (ratio 1)."""
    return json.dumps(
        {
            "masses": [
                {"name": "motor", "inertia": j_motor, "damping": ground[0]},
                {"name": "drum", "inertia": j_drum, "damping": ground[1]},
            ],
            "shafts": [{"name": "shaft", "stiffness": stiffness, "damping": damping}],
        }
    )


def make_unit(effects: str = "", **params) -> WinchUnit:
    """A configured, initialised winch unit.

    ``params`` are parameter or input values by name; ``__`` in a keyword
    stands for ``.`` (``brake__lever_force``), or pass dotted names with ``**{...}``.
    """
    unit = WinchUnit("test")
    unit.values["effects"] = effects
    for name, value in params.items():
        unit.values[name.replace("__", ".")] = value
    unit.configure()
    unit.initialize(0.0)
    return unit


def run(
    unit: WinchUnit,
    duration: float,
    step: float,
    drive: Callable[[float, WinchUnit], None] | None = None,
    record: tuple[str, ...] = ("drum.speed",),
    start: float = 0.0,
) -> dict[str, np.ndarray]:
    """Step ``unit`` for ``duration`` s; ``drive(t, unit)`` sets inputs before each step."""
    n = int(round(duration / step))
    out = {name: np.empty(n + 1) for name in ("time", *record)}
    out["time"][0] = start
    for name in record:
        out[name][0] = unit.values[name]
    for i in range(n):
        t = start + i * step
        if drive is not None:
            drive(t, unit)
        result = unit.advance(t, step)
        assert result.success, result.message
        out["time"][i + 1] = start + (i + 1) * step
        for name in record:
            out[name][i + 1] = unit.values[name]
    return out
