"""What a parsed scene holds: variable references, units, connections, bonds, drivers,
events, plots and run settings (see :mod:`wire_fmu.master.scene` for the file format)."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from wire_fmu.core.errors import ConfigurationError

from ..energy_guard import DEFAULT_SHARE

__all__ = [
    "VarRef",
    "UnitSpec",
    "Connection",
    "Bond",
    "DriverSpec",
    "EventSpec",
    "RunSettings",
    "PlotSpec",
    "Scene",
    "SceneError",
    "ALGORITHMS",
    "EXTRAPOLATIONS",
    "BOND_KINDS",
]

ALGORITHMS = ("jacobi", "gauss_seidel")
EXTRAPOLATIONS = ("constant", "linear", "quadratic")
BOND_KINDS = {
    # kind: (effort unit, flow unit, position unit)
    "translational": ("N", "m/s", "m"),
    "rope": ("N", "m/s", "m"),
    "rotational": ("N.m", "rad/s", "rad"),
    "hydraulic": ("Pa", "m3/s", "m3"),
}


class SceneError(ConfigurationError):
    """A scene with problems; ``problems`` lists every one."""


@dataclass(frozen=True, order=True)
class VarRef:
    """``unit.variable``: the first dotted component names the unit."""

    unit: str
    variable: str

    def __str__(self) -> str:
        return f"{self.unit}.{self.variable}"

    @classmethod
    def parse(cls, text: Any) -> VarRef | None:
        """Parse ``"unit.variable.path"``; None if malformed.

        Parameters
        ----------
        text : object
            The reference; anything but such text gives None.
        """
        if not isinstance(text, str) or "." not in text.strip():
            return None
        unit, _, variable = text.strip().partition(".")
        if not unit or not variable:
            return None
        return cls(unit, variable)


@dataclass(frozen=True)
class UnitSpec:
    """One unit of the scene.

    Attributes
    ----------
    name : str
        Instance name used in connections.
    fmu : str
        Name of one of our FMUs (``"BlockTrain"``) or a path to an FMU.
    effects : tuple of str
        Effects to include (ours only); everything else is the simplest model.
    parameters : dict
        Parameter values; tables become JSON text for String parameters.
    """

    name: str
    fmu: str
    effects: tuple[str, ...] = ()
    parameters: dict[str, Any] = field(default_factory=dict)

    def parameter_values(self) -> dict[str, Any]:
        """Parameters as FMI values (tables and lists serialised to JSON)."""
        out = {}
        for key, value in self.parameters.items():
            out[key] = json.dumps(value) if isinstance(value, Mapping | list) else value
        return out


@dataclass(frozen=True)
class Connection:
    """An output feeding an input.

    ``role`` is ``"effort"``, ``"flow"`` or ``"position"`` inside a bond,
    ``"signal"`` otherwise.
    """

    source: VarRef
    target: VarRef
    role: str = "signal"
    bond: str | None = None
    extrapolation: str | None = None


@dataclass(frozen=True)
class Bond:
    """A power bond between two units (effort one way, flow back)."""

    name: str
    kind: str
    effort: Connection
    flow: Connection
    position: Connection | None = None

    @property
    def connections(self) -> tuple[Connection, ...]:
        """The bond's connections."""
        return tuple(c for c in (self.effort, self.flow, self.position) if c is not None)


@dataclass(frozen=True)
class DriverSpec:
    """A time signal on an input (and optionally its rate on another)."""

    target: VarRef
    spec: dict[str, Any]
    rate_target: VarRef | None = None
    label: str = ""


@dataclass(frozen=True)
class EventSpec:
    """Inputs set to new values at a scheduled time."""

    time: float
    values: dict[VarRef, Any]
    label: str = ""


@dataclass(frozen=True)
class PlotSpec:
    """One figure of the scene's key outputs."""

    title: str
    variables: tuple[VarRef, ...]
    ylabel: str = ""


@dataclass(frozen=True)
class RunSettings:
    """How to run the scene (see the module docstring for the keys)."""

    stop_time: float = 10.0
    step: float = 0.01
    algorithm: str = "gauss_seidel"
    extrapolation: str = "linear"
    output_interval: float | None = None
    iterations: int = 1
    iteration_tolerance: float = 1e-6
    adaptive: bool = False
    synchronise_events: bool = False
    energy_tolerance: float = 10.0
    energy_guard: float = DEFAULT_SHARE
    min_step: float = 1e-5
    max_step: float | None = None
    order: tuple[str, ...] = ()
    max_steps: int = 10_000_000


@dataclass(frozen=True)
class Scene:
    """A parsed scene."""

    name: str
    description: str
    units: dict[str, UnitSpec]
    bonds: tuple[Bond, ...]
    connections: tuple[Connection, ...]
    drivers: tuple[DriverSpec, ...]
    events: tuple[EventSpec, ...]
    outputs: tuple[VarRef, ...] | None
    plots: tuple[PlotSpec, ...]
    run: RunSettings
    base_dir: Path
    source: Path | None = None
    study: dict = field(default_factory=dict)

    @property
    def all_connections(self) -> tuple[Connection, ...]:
        """Signal connections and every bond's connections."""
        return self.connections + tuple(c for b in self.bonds for c in b.connections)
