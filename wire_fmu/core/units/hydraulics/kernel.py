"""The hydraulic cylinder's compiled kernel: its equations as plain functions over flat arrays.

The same physics as :class:`~wire_fmu.core.units.hydraulics.model.HydraulicsModel`
(``evaluate``, ``rhs``, ``guards``, ``project``, ``report``: the readable
reference), for every effect set of the package. Everything a function needs is
in one tuple ``data = (parameters, layout, held)`` of three arrays, built by
:func:`kernel_data`:

==============  =====  ===============================================================
array           type   contents
==============  =====  ===============================================================
``parameters``  float  fixed when the model is built (``P_*`` indices): areas, masses,
                       line resistances and inertance, gas exponent and volume limits,
                       cavitation pressure, stroke, seal and stop parameters
``layout``      int    fixed when the model is built (``L_*`` indices): where the
                       optional states are (-1 when absent), the oil side's form and
                       which parts (seal, stops, cushions, oil column) there are
``held``        float  what changes between calls (``H_*`` indices): the rod force
                       held over the step, the seal's mode and held position, the
                       stops' contact and cushion modes, the gas reference state,
                       the oil compliance and the oil constant
==============  =====  ===============================================================

The guards come in the order of :meth:`HydraulicsModel.guards
<wire_fmu.core.units.hydraulics.model.HydraulicsModel.guards>`: the seal (if any);
gas dead volume, gas empty, cavitation; then per end (retracted, extended) stop
contact, pad kink and cushion zone (with stops) or the two ends of the stroke
(without).

What Python calls: :func:`rhs` and :func:`guards` (the hybrid protocol, for the
SciPy solvers and a monolithic model), :func:`limits_and_force` (at the start of a
step), :func:`report` (the outputs), :func:`advance` (the entry point of
:class:`~wire_fmu.core.framework.compiled_step.CompiledFixedStep`) and
:func:`quiet_step` (a whole step in which nothing happens). Events, their words and
the reasons of refused steps stay in Python.
"""

from __future__ import annotations

import math
from collections import namedtuple
from typing import TYPE_CHECKING

import numpy as np

from wire_fmu.core.components.end_stops import EXTENDED, RETRACTED
from wire_fmu.core.framework.compiled import jit
from wire_fmu.core.framework.compiled_step import STATUS_DONE, advance_to_event
from wire_fmu.core.units.hydraulics.oil_side import (
    OIL_LOSSLESS_RIGID,
    OIL_ONE_NODE,
    OIL_RIGID,
)

if TYPE_CHECKING:
    from wire_fmu.core.units.hydraulics.model import HydraulicsModel

__all__ = [
    "REPORT",
    "advance",
    "guard_count",
    "guards",
    "kernel_data",
    "kernel_layout",
    "kernel_parameters",
    "limits_and_force",
    "project",
    "quiet_step",
    "report",
    "rhs",
]

# ------------------------------------------------------------ parameters (fixed)
P_SA = 0  # signed working area s A, m^2
P_AREA = 1  # working area A, m^2
P_MASS = 2  # rod mass with the oil column it carries, kg
P_WEIGHT = 3  # gravity along the rod on the moving mass, N
P_AMBIENT = 4  # ambient pressure, Pa
P_VISCOUS = 5  # viscous seal coefficient, N s/m
P_LAMINAR = 6  # laminar line resistance R_l, Pa s/m^3
P_TURBULENT = 7  # turbulent line resistance R_t, Pa s^2/m^6
P_INERTANCE = 8  # line inertance L, Pa s^2/m^3
P_EXPONENT = 9  # polytropic exponent n, 1
P_DEAD_VOLUME = 10  # gas volume of a full accumulator, m^3
P_FULL_VOLUME = 11  # gas volume of an empty accumulator, m^3
P_CAVITATION = 12  # cavitation pressure, Pa
P_STROKE = 13  # stroke, m
P_SEAL_STATIC = 14  # breakaway force, N
P_SEAL_COULOMB = 15  # Coulomb force, N
P_STRIBECK = 16  # Stribeck velocity, m/s
P_STOP_STIFFNESS = 17  # stop spring, N/m
P_STOP_DAMPING = 18  # stop dashpot, N s/m
P_CUSHION_LENGTH = 19  # cushion zone length, m
P_CUSHION_COEFFICIENT = 20  # cushion c in c v^2, N s^2/m^2
N_PARAMETERS = 21

# ---------------------------------------------------------------- layout (fixed)
L_GAS_VOLUME = 0  # index of the gas volume state, or -1
L_CHAMBER_PRESSURE = 1  # index of the chamber pressure state, or -1
L_FLOW = 2  # index of the line flow state, or -1
L_DISSIPATED = 3  # index of the dissipated energy state
L_OIL_FORM = 4  # the oil side's form (an OIL_* code of oil_side)
L_SEAL = 5  # 1 with seal friction
L_STOPS = 6  # 1 with end stops
L_CUSHIONS = 7  # 1 with cushion zones (end stops with cushion_length > 0)
L_COLUMN = 8  # 1 when the line's oil column moves with the rod (inertance, rigid oil)
N_LAYOUT = 9

# ------------------------------------------------------------ held (per call)
H_FORCE = 0  # external rod force held over the step, N
H_SEAL_MODE = 1  # 0 stuck, +1/-1 sliding direction
H_HELD_POSITION = 2  # where a stuck rod is held, m
H_CONTACT = 3  # on the retracted stop, on the extended stop (2 entries)
H_CUSHION = 5  # in the retracted cushion, in the extended cushion (2 entries)
H_GAS_PRESSURE = 7  # gas reference pressure p0, Pa
H_GAS_VOLUME = 8  # gas reference volume V0, m^3
H_COMPLIANCE = 9  # oil compliance C, m^3/Pa
H_OIL_CONSTANT = 10  # gas volume minus s A x (rigid oil), m^3
N_HELD = 11

REPORT = (
    "position",
    "velocity",
    "acceleration",
    "chamber_pressure",
    "hydraulic_force",
    "gas_pressure",
    "gas_volume",
    "flow",
    "oil_in_accumulator",
    "stiffness",
    "stop_force",
    "friction_force",
    "stored_energy",
)
"""What :func:`report` gives, in order (the keys of ``HydraulicsModel.report``)."""


# ----------------------------------------------------------------- from the model
def kernel_parameters(model: HydraulicsModel) -> np.ndarray:
    """The fixed parameters (``P_*``) of ``model``, built once.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder, with its seal and stops built.
    """
    cyl, acc, spec = model.cyl, model.spec.accumulator, model.spec
    out = np.zeros(N_PARAMETERS)
    out[P_SA], out[P_AREA], out[P_MASS] = model.sa, model.area, model.mass
    out[P_WEIGHT] = cyl.moving_mass * cyl.gravity_along_rod
    out[P_AMBIENT] = cyl.ambient_pressure
    out[P_LAMINAR], out[P_TURBULENT], out[P_INERTANCE] = model.r_l, model.r_t, model.inertance
    out[P_EXPONENT] = model.exponent
    out[P_DEAD_VOLUME], out[P_FULL_VOLUME] = acc.dead_volume, acc.full_volume
    out[P_CAVITATION], out[P_STROKE] = spec.oil.cavitation_pressure, cyl.stroke
    if model.seal is not None:
        seal = model.seal.spec
        out[P_SEAL_STATIC], out[P_SEAL_COULOMB] = seal.static, seal.coulomb
        out[P_STRIBECK], out[P_VISCOUS] = seal.stribeck_velocity, seal.viscous
    if model.stops is not None:
        stops = model.stops
        out[P_STOP_STIFFNESS], out[P_STOP_DAMPING] = stops.spec.stiffness, stops.damping
        out[P_CUSHION_LENGTH] = stops.spec.cushion_length
        out[P_CUSHION_COEFFICIENT] = stops.spec.cushion_coefficient
    return out


def kernel_layout(model: HydraulicsModel) -> np.ndarray:
    """The fixed layout (``L_*``) of ``model``, built once.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder, with its seal and stops built.
    """
    lay = model.layout
    out = np.zeros(N_LAYOUT, dtype=np.int64)
    out[L_GAS_VOLUME], out[L_CHAMBER_PRESSURE] = lay.gas_volume, lay.chamber_pressure
    out[L_FLOW], out[L_DISSIPATED] = lay.flow, lay.dissipated
    out[L_OIL_FORM] = model.oil_form()
    out[L_SEAL] = model.seal is not None
    out[L_STOPS] = model.stops is not None
    out[L_CUSHIONS] = model.stops is not None and model.stops.spec.cushion_length > 0.0
    out[L_COLUMN] = model.has_inertance and not model.compressible
    return out


def kernel_data(model: HydraulicsModel) -> tuple:
    """The tuple of arrays the kernel functions take, from ``model``'s present values.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder (see the module docstring).
    """
    seal, stops, gas = model.seal, model.stops, model.gas
    seal_mode, held_position = (0, 0.0) if seal is None else (seal.mode, seal.held_position)
    contact, cushion = _NO_STOPS if stops is None else (stops.contact, stops.in_cushion)
    held = (
        model.force,
        seal_mode,
        held_position,
        contact[RETRACTED],
        contact[EXTENDED],
        cushion[RETRACTED],
        cushion[EXTENDED],
        gas.reference_pressure,
        gas.reference_volume,
        model.compliance,
        model.oil_constant,
    )
    return model.kernel_parameters, model.kernel_layout, np.array(held, dtype=np.float64)


_NO_STOPS = ((False, False), (False, False))
"""Contact and cushion modes without the effect."""


# ------------------------------------------------------------------- the physics
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
    ),
)
"""The model at one state (see ``hydraulics.model._Point``; ``stored`` without the gas,
kinetic, pad and potential terms, which :func:`_stored_energy` adds)."""


@jit
def _gas_pressure(volume: float, held: np.ndarray, parameters: np.ndarray) -> float:
    """``p0 (V0 / V)^n``, Pa (see ``PolytropicGas.pressure``)."""
    ratio = held[H_GAS_VOLUME] / volume
    return held[H_GAS_PRESSURE] * ratio ** parameters[P_EXPONENT]


@jit
def _gas_energy(volume: float, held: np.ndarray, parameters: np.ndarray) -> float:
    """Gas energy relative to the reference volume, J (see ``PolytropicGas.energy``)."""
    log_ratio = math.log(held[H_GAS_VOLUME] / volume)
    m = parameters[P_EXPONENT] - 1.0
    constant = held[H_GAS_PRESSURE] * held[H_GAS_VOLUME]
    if m == 0.0:
        return constant * log_ratio
    return constant * math.expm1(m * log_ratio) / m


@jit
def _gas_volume(x: np.ndarray, layout: np.ndarray, held: np.ndarray, sa: float) -> float:
    """Gas volume, m^3: a state with compressible oil, else tied to the rod."""
    index = layout[L_GAS_VOLUME]
    if index >= 0:
        return x[index]
    return held[H_OIL_CONSTANT] + sa * x[0]


@jit
def _line_drop(flow: float, parameters: np.ndarray) -> float:
    """``(R_l + R_t |q|) q``, Pa (see ``HydraulicLine.pressure_drop``)."""
    return (parameters[P_LAMINAR] + parameters[P_TURBULENT] * abs(flow)) * flow


@jit
def _line_flow(drop: float, parameters: np.ndarray) -> float:
    """The flow a pressure drop drives, m^3/s (see ``HydraulicLine.flow``)."""
    r_l, r_t = parameters[P_LAMINAR], parameters[P_TURBULENT]
    return 2.0 * drop / (r_l + math.sqrt(r_l * r_l + 4.0 * r_t * abs(drop)))


@jit
def _oil_side(x, vel, v_gas, p_g, parameters, layout, held):
    """Chamber pressure (Pa), line flow (m^3/s), line loss (W), oil and line energy (J).

    See :class:`~wire_fmu.core.units.hydraulics.oil_side.OilSide` for the four forms.
    """
    form, sa = layout[L_OIL_FORM], parameters[P_SA]
    if form == OIL_LOSSLESS_RIGID:
        return p_g, sa * vel, 0.0, 0.0
    if form == OIL_RIGID:
        flow = sa * vel
        drop = _line_drop(flow, parameters)
        return p_g - drop, flow, drop * flow, 0.0
    compliance = held[H_COMPLIANCE]
    if form == OIL_ONE_NODE:
        c_gas = v_gas / (parameters[P_EXPONENT] * p_g)
        flow = sa * vel * c_gas / (c_gas + compliance)
        return p_g, flow, 0.0, 0.5 * compliance * p_g * p_g
    p_c = x[layout[L_CHAMBER_PRESSURE]]
    stored = 0.5 * compliance * p_c * p_c
    if layout[L_FLOW] >= 0:
        flow = x[layout[L_FLOW]]
        stored += 0.5 * parameters[P_INERTANCE] * flow * flow
    else:
        flow = _line_flow(p_g - p_c, parameters)
    drop = _line_drop(flow, parameters)
    return p_c, flow, drop * flow, stored


@jit
def _stop_forces(pos: float, vel: float, parameters: np.ndarray, held: np.ndarray):
    """Force (N), pad depths (m), trial stop forces (N), loss (W), pad energy (J).

    See :meth:`EndStops.forces <wire_fmu.core.components.end_stops.EndStops.forces>`.
    """
    k, c = parameters[P_STOP_STIFFNESS], parameters[P_STOP_DAMPING]
    depth = (-pos, pos - parameters[P_STROKE])
    inward = (-vel, vel)  # rate of penetration at each end
    trial = (k * depth[0] + c * inward[0], k * depth[1] + c * inward[1])
    force = loss = energy = 0.0
    for end in (RETRACTED, EXTENDED):
        direction = 1.0 if end == RETRACTED else -1.0
        if held[H_CUSHION + end] != 0.0:
            speed = max(inward[end], 0.0)
            cushion = parameters[P_CUSHION_COEFFICIENT] * speed * speed
            force += direction * cushion
            loss += cushion * speed
        if held[H_CONTACT + end] != 0.0:  # smooth inside the mode, whatever the depth's sign
            energy += 0.5 * k * depth[end] ** 2
            force += direction * trial[end]
            loss += c * inward[end] ** 2
        elif depth[end] > 0.0:  # the unloaded pad relaxes behind a rod that leaves faster
            energy += 0.5 * k * depth[end] ** 2
            loss -= k * depth[end] * inward[end]
    return force, depth[0], depth[1], trial[0], trial[1], loss, energy


@jit
def evaluate(x: np.ndarray, data) -> Point:
    """Pressures, flow, forces and losses at state ``x`` (``HydraulicsModel.evaluate``).

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        See the module docstring.

    Returns
    -------
    Point
        The model at ``x``; ``stored`` holds only the oil and line energy (J).
    """
    parameters, layout, held = data
    pos, vel = x[0], x[1]
    sa = parameters[P_SA]
    v_gas = _gas_volume(x, layout, held, sa)
    p_g = _gas_pressure(max(v_gas, 0.5 * parameters[P_DEAD_VOLUME]), held, parameters)
    p_c, flow, loss, stored = _oil_side(x, vel, v_gas, p_g, parameters, layout, held)
    hydraulic = sa * (p_c - parameters[P_AMBIENT])
    stop_force, depth_r, depth_e, trial_r, trial_e, stop_loss = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if layout[L_STOPS]:
        stop_force, depth_r, depth_e, trial_r, trial_e, stop_loss, _ = _stop_forces(
            pos, vel, parameters, held
        )
    viscous = parameters[P_VISCOUS]
    force = held[H_FORCE] + hydraulic + parameters[P_WEIGHT] + stop_force - viscous * vel
    loss += stop_loss + viscous * vel * vel
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
    )


@jit
def _sliding_friction(vel: float, parameters: np.ndarray) -> float:
    """Sliding seal friction at ``vel``, N (see ``SealSpec.sliding``)."""
    coulomb, stribeck = parameters[P_SEAL_COULOMB], parameters[P_STRIBECK]
    if stribeck <= 0.0:
        return coulomb
    decay = math.exp(-((vel / stribeck) ** 2))
    return coulomb + (parameters[P_SEAL_STATIC] - coulomb) * decay


@jit
def accelerate(point: Point, data):
    """Acceleration (m/s^2), seal friction force on the rod (N) and its loss (W).

    A stuck seal holds the rod (no acceleration) with whatever force that needs; a sliding
    one opposes the motion with its sliding force (``RodSeal.accelerate``).

    Parameters
    ----------
    point : Point
        The model at a state (:func:`evaluate`).
    data : tuple
        See the module docstring.
    """
    parameters, layout, held = data
    mass = parameters[P_MASS]
    if not layout[L_SEAL]:
        return point.force / mass, 0.0, 0.0
    sliding = _sliding_friction(point.v, parameters)
    mode = held[H_SEAL_MODE]
    if mode == 0.0:
        return 0.0, 0.0 - point.force, 0.0
    link = -mode * sliding
    return (point.force + link) / mass, link, 0.0 - link * point.v


@jit
def _chamber_pressure(point: Point, acceleration: float, data) -> float:
    """Pressure at the cylinder port, Pa (``HydraulicsModel.chamber_pressure``)."""
    parameters, layout, _ = data
    if layout[L_COLUMN]:
        return point.chamber_pressure - parameters[P_INERTANCE] * parameters[P_SA] * acceleration
    return point.chamber_pressure


@jit
def _seal_stuck(data) -> bool:
    """Whether there is a seal and it holds the rod."""
    return data[1][L_SEAL] != 0 and data[2][H_SEAL_MODE] == 0.0


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
        See the module docstring.
    """
    parameters, layout, held = data
    point = evaluate(x, data)
    acc, _, friction_loss = accelerate(point, data)
    out = np.empty_like(x)
    stuck = _seal_stuck(data)
    out[0] = 0.0 if stuck else point.v
    out[1] = 0.0 if stuck else acc
    if layout[L_GAS_VOLUME] >= 0:
        out[layout[L_GAS_VOLUME]] = point.flow
    if layout[L_CHAMBER_PRESSURE] >= 0:
        rate = (point.flow - parameters[P_SA] * point.v) / held[H_COMPLIANCE]
        out[layout[L_CHAMBER_PRESSURE]] = rate
    if layout[L_FLOW] >= 0:
        drop = _line_drop(point.flow, parameters)
        pressure = point.gas_pressure - point.chamber_pressure - drop
        out[layout[L_FLOW]] = pressure / parameters[P_INERTANCE]
    out[layout[L_DISSIPATED]] = point.loss + friction_loss
    return out


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
def _stop_guards(out: np.ndarray, first: int, point: Point, parameters, layout, held) -> None:
    """Contact, pad and cushion guards of both ends into ``out`` from ``first`` on.

    See :meth:`EndStops.guard <wire_fmu.core.components.end_stops.EndStops.guard>`.
    """
    depths = (point.depth_retracted, point.depth_extended)
    trials = (point.trial_retracted, point.trial_extended)
    length, stroke = parameters[P_CUSHION_LENGTH], parameters[P_STROKE]
    i = first
    for end in (RETRACTED, EXTENDED):
        if held[H_CONTACT + end] != 0.0:
            out[i] = trials[end]
        else:
            out[i] = max(-parameters[P_STOP_STIFFNESS] * depths[end], -trials[end])
        out[i + 1] = -depths[end]
        i += 2
        if layout[L_CUSHIONS]:
            boundary = length if end == RETRACTED else stroke - length
            inside = point.x - boundary if end == EXTENDED else boundary - point.x
            out[i] = inside if held[H_CUSHION + end] != 0.0 else -inside
            i += 1


@jit
def _guard_values(point: Point, acc: float, link: float, data) -> np.ndarray:
    """The guards at ``point`` with the rod's acceleration (m/s^2) and seal force (N)."""
    parameters, layout, held = data
    out = np.empty(guard_count(layout))
    i = 0
    if layout[L_SEAL]:
        mode = held[H_SEAL_MODE]
        out[0] = parameters[P_SEAL_STATIC] - abs(link) if mode == 0.0 else mode * point.v
        i = 1
    out[i] = point.gas_volume - parameters[P_DEAD_VOLUME]
    out[i + 1] = parameters[P_FULL_VOLUME] - point.gas_volume
    out[i + 2] = _chamber_pressure(point, acc, data) - parameters[P_CAVITATION]
    if layout[L_STOPS]:
        _stop_guards(out, i + 3, point, parameters, layout, held)
    else:
        out[i + 3] = point.x
        out[i + 4] = parameters[P_STROKE] - point.x
    return out


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
        See the module docstring.

    Returns
    -------
    numpy.ndarray
        One value per guard, in the order of the module docstring.
    """
    point = evaluate(x, data)
    acc, link, _ = accelerate(point, data)
    return _guard_values(point, acc, link, data)


@jit
def limits_and_force(x: np.ndarray, data) -> tuple[int, float]:
    """The first limit guard already below zero at ``x`` (-1: none) and the force on the rod.

    The limits are the gas volume's two ends, cavitation and (without stops) the stroke; the
    force is every force on the rod but seal friction and the column's inertia, N.

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        See the module docstring.
    """
    layout = data[1]
    point = evaluate(x, data)
    acc, link, _ = accelerate(point, data)
    values = _guard_values(point, acc, link, data)
    first = layout[L_SEAL]
    last = first + (3 if layout[L_STOPS] else 5)
    for i in range(first, last):
        if values[i] < 0.0:
            return i, point.force
    return -1, point.force


@jit
def project(x: np.ndarray, data) -> np.ndarray:
    """Hold a stuck rod exactly where it stuck, at rest (``x`` changed in place).

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        See the module docstring.
    """
    if _seal_stuck(data):
        x[0] = data[2][H_HELD_POSITION]
        x[1] = 0.0
    return x


@jit
def _stored_energy(point: Point, data) -> float:
    """Stored energy at ``point``, J (see the package docstring, Energy)."""
    parameters, layout, held = data
    pos, vel = point.x, point.v
    pad_energy = 0.0
    if layout[L_STOPS]:
        pad_energy = _stop_forces(pos, vel, parameters, held)[6]
    weight = parameters[P_WEIGHT]
    gas_volume = max(point.gas_volume, 0.5 * parameters[P_DEAD_VOLUME])
    return point.stored + (
        0.5 * parameters[P_MASS] * vel * vel
        + _gas_energy(gas_volume, held, parameters)
        + pad_energy
        + parameters[P_SA] * parameters[P_AMBIENT] * pos
        - weight * pos
    )


@jit
def report(x: np.ndarray, data) -> np.ndarray:
    """The quantities of :data:`REPORT` at ``x``, in one array (one crossing back to Python).

    Parameters
    ----------
    x : numpy.ndarray
        State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
    data : tuple
        See the module docstring.

    Returns
    -------
    numpy.ndarray
        Position (m), velocity (m/s), acceleration (m/s^2), chamber pressure (Pa),
        hydraulic force (N), gas pressure (Pa) and volume (m^3), line flow (m^3/s),
        oil in the accumulator (m^3), stiffness (N/m), stop force (N), seal friction
        force (N), stored energy (J).
    """
    parameters, layout, held = data
    point = evaluate(x, data)
    acc, link, _ = accelerate(point, data)
    if _seal_stuck(data):
        acc = 0.0
    p_c = _chamber_pressure(point, acc, data)
    gas_compliance = point.gas_volume / (
        parameters[P_EXPONENT] * _gas_pressure(point.gas_volume, held, parameters)
    )
    if layout[L_GAS_VOLUME] >= 0:  # compressible oil
        gas_compliance += held[H_COMPLIANCE]
    area = parameters[P_AREA]
    out = np.empty(len(REPORT))
    out[0], out[1], out[2], out[3] = point.x, point.v, acc, p_c
    out[4] = parameters[P_SA] * (p_c - parameters[P_AMBIENT])
    out[5], out[6], out[7] = point.gas_pressure, point.gas_volume, point.flow
    out[8] = parameters[P_FULL_VOLUME] - point.gas_volume
    out[9] = area**2 / gas_compliance
    out[10] = point.stop_force
    out[11] = link - parameters[P_VISCOUS] * point.v
    out[12] = _stored_energy(point, data)
    return out


@jit
def _breaks_away(force: float, data) -> bool:
    """Whether a stuck seal lets go under ``force`` (N) (``RodSeal.settle``)."""
    return _seal_stuck(data) and abs(force) > data[0][P_SEAL_STATIC]


@jit
def quiet_step(method, t0, t1, n, x, directions, tol, data):
    """A communication step in which nothing happens, in one call.

    What ``RefinedStepping.advance`` does for such a step: check the limits, settle the
    seal (project), integrate over ``[t0, t1]`` as :class:`CompiledFixedStep
    <wire_fmu.core.framework.compiled_step.CompiledFixedStep>` would, report the end.

    Parameters
    ----------
    method : int
        A value of ``COMPILED_METHODS``.
    t0, t1 : float
        The communication step, s.
    n : int
        Number of equal internal steps over ``[t0, t1]``.
    x : numpy.ndarray
        State at ``t0`` (not changed).
    directions : numpy.ndarray
        Guard directions.
    tol : float
        Event time tolerance, s.
    data : tuple
        See the module docstring (the seal held where ``x`` is).

    Returns
    -------
    tuple
        ``(True, state at t1, report)`` (:func:`report`), or ``(False, x, empty)`` when a
        limit is reached, the seal lets go, a guard fires or a step is not finite.
    """
    nothing = np.empty(0)
    violated, force = limits_and_force(x, data)
    if violated >= 0 or _breaks_away(force, data):
        return False, x, nothing
    start = project(x.copy(), data)
    result = advance_to_event(
        rhs, guards, project, method, t0, t1, n, 0, t0, start, directions, tol, data
    )
    if result[0] != STATUS_DONE:
        return False, x, nothing
    end = result[1]
    return True, end, report(end, data)


@jit
def advance(method, t0, t1, n, k, t, x, directions, tol, data):
    """:func:`~wire_fmu.core.framework.compiled_step.advance_to_event` over this kernel.

    Parameters
    ----------
    method, t0, t1, n, k, t, x, directions, tol, data
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    """
    return advance_to_event(rhs, guards, project, method, t0, t1, n, k, t, x, directions, tol, data)
