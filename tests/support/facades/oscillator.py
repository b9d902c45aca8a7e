"""Facade script of the test oscillator FMU."""

from wire_fmu_test_units import OscillatorUnit

from wire_fmu.export.facade import CoreFacade


class Oscillator(CoreFacade):
    """FMU facade of :class:`OscillatorUnit`."""

    unit_class = OscillatorUnit
