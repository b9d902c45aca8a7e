"""Our unit types in one place: each FMU's model name, facade script and core unit class.

Everything that lists our units reads this table: the master's catalogue
(a scene's ``fmu = "BlockTrain"``), the monolithic reference of the studies,
``build_fmus.py``, ``wire-fmu build``, the benchmarks and the tests (which
prove that every entry builds, validates, round-trips its state and can be
solved monolithically). Adding a unit type is its core module, a facade
script in ``models/`` and one line here.

Standard library only, and nothing here is mutable: the master reads it
without importing the physics core, and every FMU in a process shares it.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

__all__ = ["UnitType", "UNIT_TYPES", "BY_NAME", "MODELS_DIR", "unit_type"]

MODELS_DIR = Path(__file__).resolve().parents[1] / "models"
"""The facade scripts (one FMU each), beside the package in the source tree."""


@dataclass(frozen=True)
class UnitType:
    """One of our unit types.

    Attributes
    ----------
    name : str
        The FMU's model name, as a scene names it.
    facade : str
        Its facade script in :data:`MODELS_DIR`.
    core : str
        Its core unit class, ``"module:Class"``.
    """

    name: str
    facade: str
    core: str

    @property
    def facade_path(self) -> Path:
        """The facade script."""
        return MODELS_DIR / self.facade

    def core_class(self) -> type:
        """The core unit class (imports the physics core)."""
        module, _, cls = self.core.partition(":")
        return getattr(importlib.import_module(module), cls)


UNIT_TYPES = (
    UnitType("BlockTrain", "block_train.py", "wire_fmu.core.block_train_unit:BlockTrainUnit"),
    UnitType("Winch", "winch.py", "wire_fmu.core.winch_unit:WinchUnit"),
    UnitType("Hydraulics", "hydraulics.py", "wire_fmu.core.hydraulics_unit:HydraulicsUnit"),
    UnitType("ScissorJack", "scissor_jack.py", "wire_fmu.core.scissor_jack_unit:ScissorJackUnit"),
    UnitType("MultiMassDrive", "drive.py", "wire_fmu.core.drive_unit:DriveUnit"),
    UnitType("MachineUnit", "machine_unit.py", "wire_fmu.core.machine_drive_unit:MachineDriveUnit"),
)
"""Every unit type we ship, in the order they are built and listed."""

BY_NAME = MappingProxyType({u.name: u for u in UNIT_TYPES})
"""The unit types by model name."""


def unit_type(name: str) -> UnitType:
    """The unit type a scene names ``name``.

    Raises
    ------
    KeyError
        Naming the known unit types.
    """
    try:
        return BY_NAME[name]
    except KeyError:
        raise KeyError(f"{name!r} is not one of our unit types ({', '.join(BY_NAME)})") from None
