"""Facade script of the test coupled-mass FMU."""

from wire_fmu_master_units import CoupledMassUnit

from wire_fmu.export.facade import CoreFacade


class CoupledMass(CoreFacade):
    """FMU facade of :class:`CoupledMassUnit`."""

    unit_class = CoupledMassUnit
