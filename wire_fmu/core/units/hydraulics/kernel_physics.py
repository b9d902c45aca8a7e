"""The cylinder's equations at one state, compiled: pressures, flow, forces, losses, energy.

The same arithmetic, operation for operation, as the readable reference
(:meth:`HydraulicsModel.evaluate <wire_fmu.core.units.hydraulics.model.HydraulicsModel.evaluate>`
and the components it calls). The tuple ``data = (parameters, layout, held)`` of
:mod:`~wire_fmu.core.units.hydraulics.kernel_arrays` is read once per call into a
:data:`Cylinder` of named scalars (:func:`cylinder`); everything here takes that and
the state's numbers and returns scalars or tuples of them. Nothing allocates, and no
array is handed from function to function: every array a compiled function holds costs
it reference counting at its entry and exits.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from wire_fmu.core.components.end_stops import EXTENDED, RETRACTED
from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.units.hydraulics.kernel_arrays import (
    H_COMPLIANCE,
    H_CONTACT,
    H_CUSHION,
    H_DAMPING,
    H_EFFORT_RATE,
    H_FORCE,
    H_GAS_PRESSURE,
    H_GAS_VOLUME,
    H_HELD_POSITION,
    H_OIL_CONSTANT,
    H_REFERENCE_EXTENSION,
    H_REFERENCE_VELOCITY,
    H_SEAL_MODE,
    H_STEP_START,
    H_STIFFNESS,
    H_TIME,
    L_CHAMBER_PRESSURE,
    L_COLUMN,
    L_CUSHIONS,
    L_DISSIPATED,
    L_FLOW,
    L_GAS_VOLUME,
    L_INTERFACE_WORK,
    L_OIL_FORM,
    L_SEAL,
    L_STOPS,
    P_AMBIENT,
    P_AREA,
    P_CAVITATION,
    P_CUSHION_COEFFICIENT,
    P_CUSHION_LENGTH,
    P_DEAD_VOLUME,
    P_EXPONENT,
    P_FULL_VOLUME,
    P_INERTANCE,
    P_LAMINAR,
    P_MASS,
    P_SA,
    P_SEAL_COULOMB,
    P_SEAL_STATIC,
    P_STOP_DAMPING,
    P_STOP_STIFFNESS,
    P_STRIBECK,
    P_STROKE,
    P_TURBULENT,
    P_VISCOUS,
    P_WEIGHT,
)
from wire_fmu.core.units.hydraulics.oil_side import (
    OIL_LOSSLESS_RIGID,
    OIL_ONE_NODE,
    OIL_RIGID,
)

jit = kernel_decorators(__file__).jit

__all__ = [
    "Cylinder",
    "Point",
    "accelerate",
    "chamber_pressure",
    "cylinder",
    "evaluate",
    "gas_pressure",
    "interface_power",
    "line_drop",
    "rod_force",
    "seal_stuck",
    "stored_energy",
]

Cylinder = namedtuple(
    "Cylinder",
    (
        # fixed, from ``parameters`` (SI units, see the P_* indices)
        "sa",
        "area",
        "mass",
        "weight",
        "ambient",
        "viscous",
        "laminar",
        "turbulent",
        "inertance",
        "exponent",
        "dead_volume",
        "full_volume",
        "cavitation",
        "stroke",
        "seal_static",
        "seal_coulomb",
        "stribeck",
        "stop_stiffness",
        "stop_damping",
        "cushion_length",
        "cushion_coefficient",
        # fixed, from ``layout`` (integers, see the L_* indices)
        "gas_index",
        "chamber_index",
        "flow_index",
        "dissipated_index",
        "oil_form",
        "seal",
        "stops",
        "cushions",
        "column",
        "interface_index",
        # per call, from ``held`` (see the H_* indices)
        "force",
        "seal_mode",
        "held_position",
        "contact_retracted",
        "contact_extended",
        "cushion_retracted",
        "cushion_extended",
        "reference_pressure",
        "reference_volume",
        "compliance",
        "oil_constant",
        "stiffness",
        "damping",
        "effort_rate",
        "reference_extension",
        "reference_velocity",
        "step_start",
        "time",
    ),
)
"""Everything the equations need, as named scalars (:func:`cylinder`)."""


@jit
def cylinder(data) -> Cylinder:
    """The :data:`Cylinder` the arrays of ``data`` hold.

    Parameters
    ----------
    data : tuple
        ``(parameters, layout, held)`` (see :mod:`.kernel_arrays`).
    """
    p, lay, held = data
    return Cylinder(
        p[P_SA],
        p[P_AREA],
        p[P_MASS],
        p[P_WEIGHT],
        p[P_AMBIENT],
        p[P_VISCOUS],
        p[P_LAMINAR],
        p[P_TURBULENT],
        p[P_INERTANCE],
        p[P_EXPONENT],
        p[P_DEAD_VOLUME],
        p[P_FULL_VOLUME],
        p[P_CAVITATION],
        p[P_STROKE],
        p[P_SEAL_STATIC],
        p[P_SEAL_COULOMB],
        p[P_STRIBECK],
        p[P_STOP_STIFFNESS],
        p[P_STOP_DAMPING],
        p[P_CUSHION_LENGTH],
        p[P_CUSHION_COEFFICIENT],
        lay[L_GAS_VOLUME],
        lay[L_CHAMBER_PRESSURE],
        lay[L_FLOW],
        lay[L_DISSIPATED],
        lay[L_OIL_FORM],
        lay[L_SEAL],
        lay[L_STOPS],
        lay[L_CUSHIONS],
        lay[L_COLUMN],
        lay[L_INTERFACE_WORK],
        held[H_FORCE],
        held[H_SEAL_MODE],
        held[H_HELD_POSITION],
        held[H_CONTACT + RETRACTED],
        held[H_CONTACT + EXTENDED],
        held[H_CUSHION + RETRACTED],
        held[H_CUSHION + EXTENDED],
        held[H_GAS_PRESSURE],
        held[H_GAS_VOLUME],
        held[H_COMPLIANCE],
        held[H_OIL_CONSTANT],
        held[H_STIFFNESS],
        held[H_DAMPING],
        held[H_EFFORT_RATE],
        held[H_REFERENCE_EXTENSION],
        held[H_REFERENCE_VELOCITY],
        held[H_STEP_START],
        held[H_TIME],
    )


Point = namedtuple(
    "Point",
    (
        "x",
        "v",
        "gas_volume",
        "gas_pressure",
        "chamber_pressure",
        "flow",
        "force",
        "stop_force",
        "depth_retracted",
        "depth_extended",
        "trial_retracted",
        "trial_extended",
        "loss",
        "stored",
        "interface_power",
    ),
)
"""The model at one state (see ``hydraulics.reference_physics._Point``; ``stored`` without
the gas, kinetic, pad and potential terms, which :func:`stored_energy` adds)."""


@jit
def gas_pressure(volume: float, c: Cylinder) -> float:
    """``p0 (V0 / V)^n``, Pa (see ``PolytropicGas.pressure``).

    Parameters
    ----------
    volume : float
        Gas volume, m^3.
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    ratio = c.reference_volume / volume
    return c.reference_pressure * ratio**c.exponent


@jit
def _gas_energy(volume: float, c: Cylinder) -> float:
    """Gas energy relative to the reference volume, J (see ``PolytropicGas.energy``)."""
    log_ratio = math.log(c.reference_volume / volume)
    m = c.exponent - 1.0
    constant = c.reference_pressure * c.reference_volume
    if m == 0.0:
        return constant * log_ratio
    return constant * math.expm1(m * log_ratio) / m


@jit
def line_drop(flow: float, c: Cylinder) -> float:
    """``(R_l + R_t |q|) q``, Pa (see ``HydraulicLine.pressure_drop``).

    Parameters
    ----------
    flow : float
        Line flow, m^3/s.
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    return (c.laminar + c.turbulent * abs(flow)) * flow


@jit
def _line_flow(drop: float, c: Cylinder) -> float:
    """The flow a pressure drop drives, m^3/s (see ``HydraulicLine.flow``)."""
    r_l, r_t = c.laminar, c.turbulent
    return 2.0 * drop / (r_l + math.sqrt(r_l * r_l + 4.0 * r_t * abs(drop)))


@jit
def _oil_side(vel, v_gas, p_g, p_c_state, flow_state, c: Cylinder):
    """Chamber pressure (Pa), line flow (m^3/s), line loss (W), oil and line energy (J).

    ``p_c_state`` and ``flow_state`` are the chamber pressure (Pa) and line flow (m^3/s)
    states where the form has them. See
    :class:`~wire_fmu.core.units.hydraulics.oil_side.OilSide` for the four forms.
    """
    form, sa = c.oil_form, c.sa
    if form == OIL_LOSSLESS_RIGID:
        return p_g, sa * vel, 0.0, 0.0
    if form == OIL_RIGID:
        flow = sa * vel
        drop = line_drop(flow, c)
        return p_g - drop, flow, drop * flow, 0.0
    compliance = c.compliance
    if form == OIL_ONE_NODE:
        c_gas = v_gas / (c.exponent * p_g)
        flow = sa * vel * c_gas / (c_gas + compliance)
        return p_g, flow, 0.0, 0.5 * compliance * p_g * p_g
    p_c = p_c_state
    stored = 0.5 * compliance * p_c * p_c
    if c.flow_index >= 0:
        flow = flow_state
        stored += 0.5 * c.inertance * flow * flow
    else:
        flow = _line_flow(p_g - p_c, c)
    drop = line_drop(flow, c)
    return p_c, flow, drop * flow, stored


@jit
def _stop_forces(pos: float, vel: float, c: Cylinder):
    """Force (N), pad depths (m), trial stop forces (N), loss (W), pad energy (J).

    See :meth:`EndStops.forces <wire_fmu.core.components.end_stops.EndStops.forces>`.
    """
    k, damping = c.stop_stiffness, c.stop_damping
    depth = (-pos, pos - c.stroke)
    inward = (-vel, vel)  # rate of penetration at each end
    trial = (k * depth[0] + damping * inward[0], k * depth[1] + damping * inward[1])
    contact = (c.contact_retracted, c.contact_extended)
    cushioned = (c.cushion_retracted, c.cushion_extended)
    force = loss = energy = 0.0
    for end in (RETRACTED, EXTENDED):
        direction = 1.0 if end == RETRACTED else -1.0
        if cushioned[end] != 0.0:
            speed = max(inward[end], 0.0)
            cushion = c.cushion_coefficient * speed * speed
            force += direction * cushion
            loss += cushion * speed
        if contact[end] != 0.0:  # smooth inside the mode, whatever the depth's sign
            energy += 0.5 * k * depth[end] ** 2
            force += direction * trial[end]
            loss += damping * inward[end] ** 2
        elif depth[end] > 0.0:  # the unloaded pad relaxes behind a rod that leaves faster
            energy += 0.5 * k * depth[end] ** 2
            loss -= k * depth[end] * inward[end]
    return force, depth[0], depth[1], trial[0], trial[1], loss, energy


@jit
def rod_force(t: float, pos: float, vel: float, c: Cylinder) -> float:
    """The external rod force ``F(x, v, t)`` over the step, N (``RodInterface.effort``).

    ``E0 - K (x - x_ref) - D (v - v_ref) + R (t - t0)``, each term added only when its
    coefficient is nonzero: without the interface model the held force, bit for bit.

    Parameters
    ----------
    t : float
        Time, s.
    pos, vel : float
        Rod extension (m) and velocity (m/s).
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    force = c.force
    if c.stiffness != 0.0:
        force = force - c.stiffness * (pos - c.reference_extension)
    if c.damping != 0.0:
        force = force - c.damping * (vel - c.reference_velocity)
    if c.effort_rate != 0.0:
        force = force + c.effort_rate * (t - c.step_start)
    return force


@jit
def interface_power(t: float, vel: float, c: Cylinder) -> float:
    """Power of the interface model's damper and rate terms into the rod, W
    (``RodInterface.power``).

    Parameters
    ----------
    t : float
        Time, s.
    vel : float
        Rod velocity, m/s.
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    return (c.effort_rate * (t - c.step_start) - c.damping * (vel - c.reference_velocity)) * vel


@jit
def evaluate(t: float, x: np.ndarray, c: Cylinder) -> Point:
    """Pressures, flow, forces and losses at state ``x`` (``HydraulicsModel.evaluate``).

    Parameters
    ----------
    t : float
        Time, s (the rod force of the interface model varies with it).
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated, (interface work)]`` (m, m/s, m^3, Pa,
        m^3/s, J, J).
    c : Cylinder
        The cylinder (:func:`cylinder`).

    Returns
    -------
    Point
        The model at ``x``; ``stored`` holds only the oil and line energy (J).
    """
    pos, vel = x[0], x[1]
    sa = c.sa
    # the gas volume is a state with compressible oil, else tied to the rod
    v_gas = x[c.gas_index] if c.gas_index >= 0 else c.oil_constant + sa * pos
    p_c_state = x[c.chamber_index] if c.chamber_index >= 0 else 0.0
    flow_state = x[c.flow_index] if c.flow_index >= 0 else 0.0
    p_g = gas_pressure(max(v_gas, 0.5 * c.dead_volume), c)
    p_c, flow, loss, stored = _oil_side(vel, v_gas, p_g, p_c_state, flow_state, c)
    hydraulic = sa * (p_c - c.ambient)
    stop_force, depth_r, depth_e, trial_r, trial_e, stop_loss = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if c.stops:
        stop_force, depth_r, depth_e, trial_r, trial_e, stop_loss, _ = _stop_forces(pos, vel, c)
    viscous = c.viscous
    force = rod_force(t, pos, vel, c) + hydraulic + c.weight + stop_force - viscous * vel
    loss += stop_loss + viscous * vel * vel
    power = interface_power(t, vel, c) if c.interface_index >= 0 else 0.0
    return Point(
        pos,
        vel,
        v_gas,
        p_g,
        p_c,
        flow,
        force,
        stop_force,
        depth_r,
        depth_e,
        trial_r,
        trial_e,
        loss,
        stored,
        power,
    )


@jit
def _sliding_friction(vel: float, c: Cylinder) -> float:
    """Sliding seal friction at ``vel``, N (see ``SealSpec.sliding``)."""
    coulomb, stribeck = c.seal_coulomb, c.stribeck
    if stribeck <= 0.0:
        return coulomb
    decay = math.exp(-((vel / stribeck) ** 2))
    return coulomb + (c.seal_static - coulomb) * decay


@jit
def accelerate(point: Point, c: Cylinder):
    """Acceleration (m/s^2), seal friction force on the rod (N) and its loss (W).

    A stuck seal holds the rod (no acceleration) with whatever force that needs; a sliding
    one opposes the motion with its sliding force (``RodSeal.accelerate``).

    Parameters
    ----------
    point : Point
        The model at a state (:func:`evaluate`).
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    mass = c.mass
    if not c.seal:
        return point.force / mass, 0.0, 0.0
    sliding = _sliding_friction(point.v, c)
    mode = c.seal_mode
    if mode == 0.0:
        return 0.0, 0.0 - point.force, 0.0
    link = -mode * sliding
    return (point.force + link) / mass, link, 0.0 - link * point.v


@jit
def chamber_pressure(point: Point, acceleration: float, c: Cylinder) -> float:
    """Pressure at the cylinder port, Pa (``HydraulicsModel.chamber_pressure``).

    Parameters
    ----------
    point : Point
        The model at a state (:func:`evaluate`).
    acceleration : float
        Rod acceleration, m/s^2.
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    if c.column:
        return point.chamber_pressure - c.inertance * c.sa * acceleration
    return point.chamber_pressure


@jit
def seal_stuck(c: Cylinder) -> bool:
    """Whether there is a seal and it holds the rod.

    Parameters
    ----------
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    return c.seal != 0 and c.seal_mode == 0.0


@jit
def stored_energy(point: Point, c: Cylinder) -> float:
    """Stored energy at ``point``, J (see the package docstring, Energy).

    Parameters
    ----------
    point : Point
        The model at a state (:func:`evaluate`).
    c : Cylinder
        The cylinder (:func:`cylinder`).
    """
    pos, vel = point.x, point.v
    pad_energy = 0.0
    if c.stops:
        pad_energy = _stop_forces(pos, vel, c)[6]
    weight = c.weight
    gas_volume = max(point.gas_volume, 0.5 * c.dead_volume)
    return point.stored + (
        0.5 * c.mass * vel * vel
        + _gas_energy(gas_volume, c)
        + pad_energy
        + c.sa * c.ambient * pos
        - weight * pos
    )
