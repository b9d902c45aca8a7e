"""The cylinder's hybrid system, compiled: derivative, guards, projection, limits and report.

Each quantity is written from one evaluation of the model at a state
(:func:`~wire_fmu.core.units.hydraulics.kernel_physics.evaluate` and
:func:`~wire_fmu.core.units.hydraulics.kernel_physics.accelerate`) into an array the
caller gives (:func:`derivative_into`, :func:`guards_into`, :func:`report_into`), so that
a loop holding its own arrays evaluates each state once and allocates nothing. They take
the :data:`~wire_fmu.core.units.hydraulics.kernel_physics.Cylinder` read from the
kernel's arrays once. The functions of the hybrid protocol (:func:`rhs`, :func:`guards`,
:func:`project`, as :func:`~wire_fmu.core.framework.compiled_step.advance_to_event`
calls them) and the one-off :func:`limits_and_force` and :func:`report` take the
arrays, ``data = (parameters, layout, held)`` of
:mod:`~wire_fmu.core.units.hydraulics.kernel_arrays`, and wrap them.

The guards come in the order of :meth:`HydraulicsModel.guards
<wire_fmu.core.units.hydraulics.model.HydraulicsModel.guards>`: the seal (if any);
gas dead volume, gas empty, cavitation; then per end (retracted, extended) stop
contact, pad kink and cushion zone (with stops) or the two ends of the stroke
(without).
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.components.end_stops import EXTENDED, RETRACTED
from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.units.hydraulics.kernel_arrays import L_CUSHIONS, L_SEAL, L_STOPS, REPORT
from wire_fmu.core.units.hydraulics.kernel_physics import (
    Cylinder,
    Point,
    accelerate,
    chamber_pressure,
    cylinder,
    evaluate,
    gas_pressure,
    line_drop,
    seal_stuck,
    stored_energy,
)

jit = kernel_decorators(__file__).jit

__all__ = [
    "breaks_away",
    "derivative_into",
    "evaluate_into",
    "first_limit",
    "guard_count",
    "guards",
    "guards_into",
    "hold",
    "limits_and_force",
    "project",
    "report",
    "report_into",
    "rhs",
    "rhs_guards",
    "slope_into",
]


@jit
def derivative_into(out: np.ndarray, point: Point, acc: float, friction_loss: float, c: Cylinder):
    """Write the state derivative ``[x', v', (V_g', p_c', q'), dissipated']`` into ``out``.

    Parameters
    ----------
    out : numpy.ndarray
        One entry per state.
    point : Point
        The model at the state (``kernel_physics.evaluate``).
    acc, friction_loss : float
        Rod acceleration (m/s^2) and seal friction loss (W) there
        (``kernel_physics.accelerate``).
    c : Cylinder
        The cylinder (``kernel_physics.cylinder``).
    """
    stuck = seal_stuck(c)
    out[0] = 0.0 if stuck else point.v
    out[1] = 0.0 if stuck else acc
    if c.gas_index >= 0:
        out[c.gas_index] = point.flow
    if c.chamber_index >= 0:
        rate = (point.flow - c.sa * point.v) / c.compliance
        out[c.chamber_index] = rate
    if c.flow_index >= 0:
        drop = line_drop(point.flow, c)
        pressure = point.gas_pressure - point.chamber_pressure - drop
        out[c.flow_index] = pressure / c.inertance
    out[c.dissipated_index] = point.loss + friction_loss
    if c.interface_index >= 0:
        out[c.interface_index] = 0.0 if stuck else point.interface_power


@jit
def rhs(t: float, x: np.ndarray, data) -> np.ndarray:
    """State derivative ``[x', v', (V_g', p_c', q'), dissipated']``.

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        ``(parameters, layout, held)`` (see :mod:`.kernel_arrays`).
    """
    out = np.empty_like(x)
    slope_into(t, x, out, cylinder(data))
    return out


@jit
def rhs_guards(t: float, x: np.ndarray, data) -> tuple:
    """:func:`rhs` and :func:`guards` at ``(t, x)`` from one evaluation (:func:`evaluate_into`).

    Parameters
    ----------
    t, x, data
        As :func:`rhs` takes them.
    """
    out = np.empty_like(x)
    values = np.empty(guard_count(data[1]))
    evaluate_into(t, x, out, values, cylinder(data))
    return out, values


@jit
def slope_into(t: float, x: np.ndarray, out: np.ndarray, c: Cylinder) -> None:
    """The state derivative at ``(t, x)`` into ``out`` (what :func:`rhs` returns)."""
    point = evaluate(t, x, c)
    acc, _, friction_loss = accelerate(point, c)
    derivative_into(out, point, acc, friction_loss, c)


@jit
def evaluate_into(t: float, x: np.ndarray, slope: np.ndarray, values: np.ndarray, c: Cylinder):
    """Evaluate at ``(t, x)`` once: its derivative into ``slope``, its guards into ``values``.

    Returns the point, the acceleration (m/s^2) and the seal force (N), for the report.
    """
    point = evaluate(t, x, c)
    acc, link, friction_loss = accelerate(point, c)
    derivative_into(slope, point, acc, friction_loss, c)
    guards_into(values, point, acc, link, c)
    return point, acc, link


@jit
def guard_count(layout: np.ndarray) -> int:
    """Number of guards (see the module docstring).

    Parameters
    ----------
    layout : numpy.ndarray
        The ``L_*`` array.
    """
    per_end = 2 + layout[L_CUSHIONS] if layout[L_STOPS] else 1
    return layout[L_SEAL] + 3 + 2 * per_end


@jit
def _stop_guards(out: np.ndarray, first: int, point: Point, c: Cylinder) -> None:
    """Contact, pad and cushion guards of both ends into ``out`` from ``first`` on.

    See :meth:`EndStops.guard <wire_fmu.core.components.end_stops.EndStops.guard>`.
    """
    depths = (point.depth_retracted, point.depth_extended)
    trials = (point.trial_retracted, point.trial_extended)
    contact = (c.contact_retracted, c.contact_extended)
    cushioned = (c.cushion_retracted, c.cushion_extended)
    length, stroke = c.cushion_length, c.stroke
    i = first
    for end in (RETRACTED, EXTENDED):
        if contact[end] != 0.0:
            out[i] = trials[end]
        else:
            out[i] = max(-c.stop_stiffness * depths[end], -trials[end])
        out[i + 1] = -depths[end]
        i += 2
        if c.cushions:
            boundary = length if end == RETRACTED else stroke - length
            inside = point.x - boundary if end == EXTENDED else boundary - point.x
            out[i] = inside if cushioned[end] != 0.0 else -inside
            i += 1


@jit
def guards_into(out: np.ndarray, point: Point, acc: float, link: float, c: Cylinder) -> None:
    """Write the guards at ``point`` into ``out`` (>= 0 inside the mode).

    Parameters
    ----------
    out : numpy.ndarray
        :func:`guard_count` entries, in the order of the module docstring.
    point : Point
        The model at the state (``kernel_physics.evaluate``).
    acc, link : float
        Rod acceleration (m/s^2) and seal force on the rod (N) there
        (``kernel_physics.accelerate``).
    c : Cylinder
        The cylinder (``kernel_physics.cylinder``).
    """
    i = 0
    if c.seal:
        mode = c.seal_mode
        out[0] = c.seal_static - abs(link) if mode == 0.0 else mode * point.v
        i = 1
    out[i] = point.gas_volume - c.dead_volume
    out[i + 1] = c.full_volume - point.gas_volume
    out[i + 2] = chamber_pressure(point, acc, c) - c.cavitation
    if c.stops:
        _stop_guards(out, i + 3, point, c)
    else:
        out[i + 3] = point.x
        out[i + 4] = c.stroke - point.x


@jit
def guards(t: float, x: np.ndarray, data) -> np.ndarray:
    """Seal stick/slip, limits, stop contact and cushion zones (>= 0 inside the mode).

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        ``(parameters, layout, held)`` (see :mod:`.kernel_arrays`).

    Returns
    -------
    numpy.ndarray
        One value per guard, in the order of the module docstring.
    """
    c = cylinder(data)
    point = evaluate(t, x, c)
    acc, link, _ = accelerate(point, c)
    out = np.empty(guard_count(data[1]))
    guards_into(out, point, acc, link, c)
    return out


@jit
def first_limit(values: np.ndarray, c: Cylinder) -> int:
    """The first limit guard below zero among the guard ``values`` (-1: none).

    The limits are the gas volume's two ends, cavitation and (without stops) the stroke.

    Parameters
    ----------
    values : numpy.ndarray
        The guards (:func:`guards_into`).
    c : Cylinder
        The cylinder (``kernel_physics.cylinder``).
    """
    first = c.seal
    last = first + (3 if c.stops else 5)
    for i in range(first, last):
        if values[i] < 0.0:
            return i
    return -1


@jit
def limits_and_force(x: np.ndarray, data) -> tuple[int, float]:
    """The first limit guard already below zero at ``x`` (-1: none) and the force on the rod.

    The force is every force on the rod but seal friction and the column's inertia, N, at
    the time ``data`` holds (``H_TIME``: the step's start, or an event's time).

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        ``(parameters, layout, held)`` (see :mod:`.kernel_arrays`).
    """
    c = cylinder(data)
    point = evaluate(c.time, x, c)
    acc, link, _ = accelerate(point, c)
    values = np.empty(guard_count(data[1]))
    guards_into(values, point, acc, link, c)
    return first_limit(values, c), point.force


@jit
def breaks_away(force: float, c: Cylinder) -> bool:
    """Whether a stuck seal lets go under ``force`` (N) (``RodSeal.settle``).

    Parameters
    ----------
    force : float
        Every force on the rod but seal friction, N.
    c : Cylinder
        The cylinder (``kernel_physics.cylinder``).
    """
    return seal_stuck(c) and abs(force) > c.seal_static


@jit
def hold(x: np.ndarray, c: Cylinder) -> None:
    """Hold a stuck rod exactly where it stuck, at rest (``x`` changed in place).

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    c : Cylinder
        The cylinder (``kernel_physics.cylinder``).
    """
    if seal_stuck(c):
        x[0] = c.held_position
        x[1] = 0.0


@jit
def project(x: np.ndarray, data) -> np.ndarray:
    """Hold a stuck rod exactly where it stuck, at rest (``x`` changed in place).

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        ``(parameters, layout, held)`` (see :mod:`.kernel_arrays`).
    """
    hold(x, cylinder(data))
    return x


@jit
def report_into(out: np.ndarray, point: Point, acc: float, link: float, c: Cylinder) -> None:
    """Write the quantities of ``REPORT`` at ``point`` into ``out``.

    Parameters
    ----------
    out : numpy.ndarray
        ``len(REPORT)`` entries: position (m), velocity (m/s), acceleration (m/s^2),
        chamber pressure (Pa), hydraulic force (N), gas pressure (Pa) and volume (m^3),
        line flow (m^3/s), oil in the accumulator (m^3), stiffness (N/m), stop force
        (N), seal friction force (N), stored energy (J).
    point : Point
        The model at the state (``kernel_physics.evaluate``).
    acc, link : float
        Rod acceleration (m/s^2) and seal force on the rod (N) there
        (``kernel_physics.accelerate``).
    c : Cylinder
        The cylinder (``kernel_physics.cylinder``).
    """
    if seal_stuck(c):
        acc = 0.0
    p_c = chamber_pressure(point, acc, c)
    gas_compliance = point.gas_volume / (c.exponent * gas_pressure(point.gas_volume, c))
    if c.gas_index >= 0:  # compressible oil
        gas_compliance += c.compliance
    area = c.area
    out[0], out[1], out[2], out[3] = point.x, point.v, acc, p_c
    out[4] = c.sa * (p_c - c.ambient)
    out[5], out[6], out[7] = point.gas_pressure, point.gas_volume, point.flow
    out[8] = c.full_volume - point.gas_volume
    out[9] = area**2 / gas_compliance
    out[10] = point.stop_force
    out[11] = link - c.viscous * point.v
    out[12] = stored_energy(point, c)


@jit
def report(x: np.ndarray, data) -> np.ndarray:
    """The quantities of ``REPORT`` at ``x``, in one array (one crossing back to Python).

    Evaluated at the time ``data`` holds (``H_TIME``), which the interface model's rod
    force depends on.

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        ``(parameters, layout, held)`` (see :mod:`.kernel_arrays`).

    Returns
    -------
    numpy.ndarray
        See :func:`report_into`.
    """
    c = cylinder(data)
    point = evaluate(c.time, x, c)
    acc, link, _ = accelerate(point, c)
    out = np.empty(len(REPORT))
    report_into(out, point, acc, link, c)
    return out
