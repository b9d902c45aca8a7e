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
    effects : str or None
        Its effect catalogue, ``"module:NAME"``, if a scene can choose its effects.
    """

    name: str
    facade: str
    core: str
    effects: str | None = None

    @property
    def facade_path(self) -> Path:
        """The facade script."""
        return MODELS_DIR / self.facade

    def core_class(self) -> type:
        """The core unit class (imports the physics core)."""
        return _load(self.core)

    def effect_catalogue(self) -> object | None:
        """The effect catalogue (imports the physics core), or None."""
        return _load(self.effects) if self.effects else None


def _load(target: str) -> object:
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


_UNITS = "wire_fmu.core.units"
UNIT_TYPES = (
    UnitType(
        "BlockTrain",
        "block_train.py",
        f"{_UNITS}.block_train.unit:BlockTrainUnit",
        f"{_UNITS}.block_train.model:BLOCK_TRAIN_EFFECTS",
    ),
    UnitType(
        "Winch", "winch.py", f"{_UNITS}.winch.unit:WinchUnit", f"{_UNITS}.winch.model:WINCH_EFFECTS"
    ),
    UnitType(
        "Hydraulics",
        "hydraulics.py",
        f"{_UNITS}.hydraulics.unit:HydraulicsUnit",
        f"{_UNITS}.hydraulics.model:HYDRAULICS_EFFECTS",
    ),
    UnitType(
        "ScissorJack",
        "scissor_jack.py",
        f"{_UNITS}.scissor_jack.unit:ScissorJackUnit",
        f"{_UNITS}.scissor_jack.unit:JACK_EFFECTS",
    ),
    UnitType(
        "MultiMassDrive",
        "drive.py",
        f"{_UNITS}.multimass_drive.unit:DriveUnit",
        f"{_UNITS}.multimass_drive.unit:DRIVE_EFFECTS",
    ),
    UnitType("MachineUnit", "machine_unit.py", f"{_UNITS}.machine.unit:MachineDriveUnit"),
)
"""Every unit type we ship, in the order they are built and listed."""

BY_NAME = MappingProxyType({u.name: u for u in UNIT_TYPES})
"""The unit types by model name."""


def unit_type(name: str) -> UnitType:
    """The unit type a scene names ``name``.

    Parameters
    ----------
    name : str
        Model name of a unit type, e.g. ``"BlockTrain"``.

    Raises
    ------
    KeyError
        Naming the known unit types.
    """
    try:
        return BY_NAME[name]
    except KeyError:
        raise KeyError(f"{name!r} is not one of our unit types ({', '.join(BY_NAME)})") from None
