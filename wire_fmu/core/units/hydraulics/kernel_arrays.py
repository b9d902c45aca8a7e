"""The three arrays the cylinder's compiled kernel takes: their indices and how they are built.

Everything a kernel function needs is in one tuple ``data = (parameters, layout, held)``,
built by :func:`kernel_data` from the model:

==============  =====  ===============================================================
array           type   contents
==============  =====  ===============================================================
``parameters``  float  fixed when the model is built (``P_*`` indices): areas, masses,
                       line resistances and inertance, gas exponent and volume limits,
                       cavitation pressure, stroke, seal and stop parameters
``layout``      int    fixed when the model is built (``L_*`` indices): where the
                       optional states are (-1 when absent), the oil side's form and
                       which parts (seal, stops, cushions, oil column) there are; a
                       step with the rod's interface model takes a second layout,
                       with the interface's work as one more state
``held``        float  what changes between calls (``H_*`` indices): the rod force
                       over the step (held, or the interface model's), the seal's
                       mode and held position, the stops' contact and cushion modes,
                       the gas reference state, the oil compliance, the oil constant
                       and the time of the state the report and the limits are for
==============  =====  ===============================================================
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from wire_fmu.core.components.end_stops import EXTENDED, RETRACTED

if TYPE_CHECKING:
    from wire_fmu.core.units.hydraulics.model import HydraulicsModel, Layout

__all__ = ["QUIET_OUTPUTS", "REPORT", "kernel_data", "kernel_layout", "kernel_parameters"]

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
L_INTERFACE_WORK = 9  # index of the interface model's work state, or -1
N_LAYOUT = 10

# ------------------------------------------------------------ held (per call)
H_FORCE = 0  # external rod force at the step's start E0 (held without interface model), N
H_SEAL_MODE = 1  # 0 stuck, +1/-1 sliding direction
H_HELD_POSITION = 2  # where a stuck rod is held, m
H_CONTACT = 3  # on the retracted stop, on the extended stop (2 entries)
H_CUSHION = 5  # in the retracted cushion, in the extended cushion (2 entries)
H_GAS_PRESSURE = 7  # gas reference pressure p0, Pa
H_GAS_VOLUME = 8  # gas reference volume V0, m^3
H_COMPLIANCE = 9  # oil compliance C, m^3/Pa
H_OIL_CONSTANT = 10  # gas volume minus s A x (rigid oil), m^3
H_STIFFNESS = 11  # interface model: K = -dF/dx, N/m
H_DAMPING = 12  # interface model: D = -dF/dv, N s/m
H_EFFORT_RATE = 13  # interface model: R = dF/dt, N/s
H_REFERENCE_EXTENSION = 14  # interface model: rod extension x_ref it is taken at, m
H_REFERENCE_VELOCITY = 15  # interface model: rod velocity v_ref it is taken at, m/s
H_STEP_START = 16  # interface model: the communication point t0 it is about, s
H_TIME = 17  # time of the state the report and the limits are evaluated for, s
N_HELD = 18

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
"""What the kernel's ``report`` gives, in order (the keys of ``HydraulicsModel.report``)."""

QUIET_OUTPUTS = (
    *REPORT,
    "displacement",
    "stroke_used",
    "dissipated_energy",
    "external_work",
    "energy_balance",
)
"""What ``kernel_quiet_step.quiet_step_outputs`` gives, in order: the report, then the
rod's displacement since the start (m), the share of the stroke used (1), the energy
dissipated (J), the work done on the rod (J) and the ledger's balance (J)."""


def kernel_parameters(model: HydraulicsModel) -> np.ndarray:
    """The fixed parameters (``P_*``) of ``model``, built once.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder, with its seal and stops built.

    Returns
    -------
    numpy.ndarray
        ``N_PARAMETERS`` floats in SI units (see the ``P_*`` indices).
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


def kernel_layout(model: HydraulicsModel, lay: Layout) -> np.ndarray:
    """The fixed layout (``L_*``) of ``model`` with the state layout ``lay``, built once.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder, with its seal and stops built.
    lay : Layout
        Where the model's states are: its own, or with the interface's work.

    Returns
    -------
    numpy.ndarray
        ``N_LAYOUT`` integers (see the ``L_*`` indices).
    """
    out = np.zeros(N_LAYOUT, dtype=np.int64)
    out[L_GAS_VOLUME], out[L_CHAMBER_PRESSURE] = lay.gas_volume, lay.chamber_pressure
    out[L_FLOW], out[L_DISSIPATED] = lay.flow, lay.dissipated
    out[L_OIL_FORM] = model.oil_form()
    out[L_SEAL] = model.seal is not None
    out[L_STOPS] = model.stops is not None
    out[L_CUSHIONS] = model.stops is not None and model.stops.spec.cushion_length > 0.0
    out[L_COLUMN] = model.has_inertance and not model.compressible
    out[L_INTERFACE_WORK] = lay.interface_work
    return out


def kernel_data(
    model: HydraulicsModel, time: float | None = None, layout: np.ndarray | None = None
) -> tuple:
    """The tuple of arrays the kernel functions take, from ``model``'s present values.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder (see the module docstring).
    time : float or None
        Time the report and the limits are evaluated at, s; None: the model's ``time``.
    layout : numpy.ndarray or None
        The layout array (:func:`kernel_layout`) of the states given with the data; None:
        the model's present one.

    Returns
    -------
    tuple
        ``(parameters, layout, held)``; ``held`` is made afresh from the present modes,
        rod force (N) and its interface model, and gas and oil references.
    """
    seal, stops, gas, interface = model.seal, model.stops, model.gas, model.interface
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
        interface.stiffness,
        interface.damping,
        interface.effort_rate,
        interface.reference_extension(model.initial_position),
        interface.reference_velocity,
        interface.start,
        model.time if time is None else time,
    )
    layout = model.kernel_layout if layout is None else layout
    return model.kernel_parameters, layout, np.array(held, dtype=np.float64)


_NO_STOPS = ((False, False), (False, False))
"""Contact and cushion modes without the effect."""
