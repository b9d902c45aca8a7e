"""Shared by the export tests: the test units of ``tests/support`` and facades over them.

Importing this module puts ``tests/support`` on ``sys.path``, so that the test
units (``wire_fmu_test_units``) import as a built FMU's facade script imports them.
"""

from __future__ import annotations

import sys
from pathlib import Path

from wire_fmu.export.facade import CoreFacade

__all__ = [
    "SUPPORT",
    "Oscillator",
    "OscillatorUnit",
    "SpringDamper",
    "SpringDamperUnit",
    "oscillator_position",
]

SUPPORT = Path(__file__).resolve().parent / "support"
"""The test units and facade scripts."""
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from wire_fmu_test_units import OscillatorUnit, SpringDamperUnit, oscillator_position  # noqa: E402


class Oscillator(CoreFacade):
    unit_class = OscillatorUnit


class SpringDamper(CoreFacade):
    unit_class = SpringDamperUnit
