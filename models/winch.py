"""FMI facade of the winch (drawworks): drum, band brake, motor, drive train.

The effects and the drive train (JSON text) are string parameters, so one
FMU serves every configuration; see :mod:`wire_fmu.core.units.winch.unit` for ports.
"""

from wire_fmu.core.units.winch.unit import WinchUnit
from wire_fmu.export.facade import CoreFacade


class Winch(CoreFacade):
    """Winch FMU (pythonfmu facade over :class:`WinchUnit`)."""

    unit_class = WinchUnit
