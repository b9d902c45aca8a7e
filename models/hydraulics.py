"""FMI facade of the hydraulic cylinder with gas accumulator (riser tensioner spring).

The effects are a string parameter, so one FMU serves every effect set; see
:mod:`wire_fmu.core.units.hydraulics.unit` for the port and parameters. The rod port's
interface-model inputs (``rod.stiffness``, ``rod.damping``, ``rod.effort_rate``,
``rod.reference_position``, ``rod.reference_velocity``) are the unit's declared
variables like every other: the facade maps them and does nothing more.
"""

from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit
from wire_fmu.export.facade import CoreFacade


class Hydraulics(CoreFacade):
    """Hydraulics FMU (pythonfmu facade over :class:`HydraulicsUnit`)."""

    unit_class = HydraulicsUnit
