"""Facade script of the test spring-damper FMU."""

from wire_fmu_test_units import SpringDamperUnit

from wire_fmu.export.facade import CoreFacade


class SpringDamper(CoreFacade):
    """FMU facade of :class:`SpringDamperUnit`."""

    unit_class = SpringDamperUnit
