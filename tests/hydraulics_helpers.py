"""Small helpers shared by the hydraulics tests: make a unit, a gas spring at rest, run it, find
periods."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit

ALL_EFFECTS = (
    "polytropic_gas,line_losses,line_inertance,oil_compressibility,seal_friction,end_stops"
)


def make_unit(effects: str = "", *, force: float | None = None, **params) -> HydraulicsUnit:
    """A configured, initialised hydraulics unit (``force``: initial ``rod.force``)."""
    unit = HydraulicsUnit("test")
    unit.values["effects"] = effects
    unit.values.update(params)
    if force is not None:
        unit.values["rod.force"] = force
    unit.configure()
    unit.initialize(0.0)
    return unit


def quiet_cylinder(**params) -> dict:
    """Parameters of a horizontal cylinder without ambient pressure or gravity.

    Bore 0.2 m, 4 m stroke, 1000 kg, a 0.2 m^3 accumulator (no gas bank)
    pre-charged to 8 MPa: simple numbers for closed forms.
    """
    base = dict(
        bore_diameter=0.2,
        rod_diameter=0.1,
        stroke=4.0,
        moving_mass=1000.0,
        gravity_along_rod=0.0,
        ambient_pressure=0.0,
        accumulator_volume=0.2,
        gas_bank_volume=0.0,
        accumulator_dead_volume=0.002,
        precharge_pressure=8.0e6,
        initial_position=2.0,
    )
    base.update(params)
    return base


AREA = math.pi * 0.2**2 / 4  # bore of quiet_cylinder, m^2
P_EQ = 1.0e7  # Pa, working pressure of the gas-spring tests
F_EQ = -P_EQ * AREA  # rod force that P_EQ holds, N
V_EQ = 0.2 * 8.0e6 / P_EQ  # gas volume after charging from 8 MPa (Boyle), m^3
MASS = 1000.0
DAMPED_LINE = dict(
    line_diameter=0.028,
    line_length=5.0,
    oil_viscosity=0.025,
    line_friction_factor=0.0,
    line_loss_coefficient=0.0,
)
"""A laminar line giving the gas spring about half its critical damping."""


def gas_spring(effects: str = "", **params) -> HydraulicsUnit:
    """quiet_cylinder at rest in equilibrium at 10 MPa."""
    return make_unit(effects, force=F_EQ, **quiet_cylinder(**params))


def settled_displacement(n: float, extra_force: float) -> float:
    """Exact static displacement after the rod force changes by ``extra_force`` (N), m."""
    p1 = P_EQ - extra_force / AREA
    v1 = V_EQ * (P_EQ / p1) ** (1.0 / n)
    return (v1 - V_EQ) / AREA


def constant_force_cylinder(**params) -> dict:
    """A rod whose gas force hardly changes with position (a huge accumulator).

    The gas spring rate ``p A^2 / V`` is 0.01 N/m with these numbers, so a rod
    started with ``initial_gas_pressure`` balanced by ``rod.force`` moves
    freely: a free mass for cushion, stop and line tests.
    """
    return quiet_cylinder(
        accumulator_volume=1.0e6,
        accumulator_dead_volume=1.0,
        precharge_pressure=1.0e6,
        initial_equilibrium=False,
        initial_gas_pressure=2.0e6,
        **params,
    )


def balancing_force(unit: HydraulicsUnit) -> float:
    """Rod force that balances the oil force of ``unit``'s initial gas pressure, N."""
    cyl = unit.spec().cylinder
    pressure = float(unit.values["initial_gas_pressure"])
    return -cyl.sign * cyl.working_area * (pressure - cyl.ambient_pressure)


def make_free_rod(effects: str, velocity: float, **params) -> HydraulicsUnit:
    """A rod in :func:`constant_force_cylinder`, forces balanced, moving at ``velocity``."""
    unit = HydraulicsUnit("test")
    unit.values["effects"] = effects
    unit.values.update(constant_force_cylinder(initial_velocity=velocity, **params))
    unit.values["rod.force"] = balancing_force(unit)
    unit.configure()
    unit.initialize(0.0)
    return unit


def run(
    unit: HydraulicsUnit,
    duration: float,
    step: float,
    force: Callable[[float], float] | None = None,
    record: tuple[str, ...] = ("rod.position", "rod.velocity"),
    start: float = 0.0,
) -> dict[str, np.ndarray]:
    """Step ``unit`` for ``duration`` seconds; ``force(t)`` sets ``rod.force`` each step."""
    n = int(round(duration / step))
    out = {name: np.empty(n + 1) for name in ("time", *record)}
    out["time"][0] = start
    for name in record:
        out[name][0] = unit.values[name]
    for i in range(n):
        t = start + i * step
        if force is not None:
            unit.values["rod.force"] = force(t)
        result = unit.advance(t, step)
        assert result.success, result.message
        out["time"][i + 1] = start + (i + 1) * step
        for name in record:
            out[name][i + 1] = unit.values[name]
    return out


def crossing_times(time: np.ndarray, signal: np.ndarray, level: float = 0.0) -> np.ndarray:
    """Times where ``signal`` crosses ``level`` upwards (linear interpolation), s."""
    s = signal - level
    idx = np.flatnonzero((s[:-1] < 0.0) & (s[1:] >= 0.0))
    frac = s[idx] / (s[idx] - s[idx + 1])
    return time[idx] + frac * (time[idx + 1] - time[idx])


def period(time: np.ndarray, signal: np.ndarray) -> float:
    """Mean period of an oscillation about its mean, from upward crossings, s."""
    level = 0.5 * (signal.max() + signal.min())
    crossings = crossing_times(time, signal, level)
    assert crossings.size >= 3, "fewer than three crossings"
    return float(np.mean(np.diff(crossings)))
