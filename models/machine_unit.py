"""FMI facade of paper 004's machine unit with variable reduced inertia.

See :mod:`wire_fmu.core.units.machine.unit` for ports and parameters; the
solver parameter chooses paper 004's energy-form integrator (``energy``,
``energy1``) or a reference integrator.
"""

from wire_fmu.core.units.machine.unit import MachineDriveUnit
from wire_fmu.export.facade import CoreFacade


class MachineUnit(CoreFacade):
    """Machine unit FMU (pythonfmu facade over :class:`MachineDriveUnit`)."""

    unit_class = MachineDriveUnit
