"""FMI facade of paper 002's multi-mass elastic drive (chain or two-motor tree).

See :mod:`wire_fmu.core.units.multimass_drive.unit` for ports and parameters; the drive is a
JSON parameter, so one FMU serves every drive, full or reduced.
"""

from wire_fmu.core.units.multimass_drive.unit import DriveUnit
from wire_fmu.export.facade import CoreFacade


class MultiMassDrive(CoreFacade):
    """Multi-mass drive FMU (pythonfmu facade over :class:`DriveUnit`)."""

    unit_class = DriveUnit
