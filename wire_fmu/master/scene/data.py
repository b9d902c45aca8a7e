"""What a parsed scene holds: variable references, units, connections, bonds, drivers,
events, plots and run settings (see :mod:`wire_fmu.master.scene` for the file format).

A bond's interface model is wired by the :class:`Scene` itself, from the run's
``interface_models`` and the bond's own ``interface_model``: a bond whose ports
offer the model then carries its five links among its connections
(:attr:`Bond.connections`, role ``"interface"``), its effort and those links are
held at the effort side's values at the step's start (``constant``), and the
effort unit's switch parameter is set true in its parameters (recorded in
:attr:`UnitSpec.switched_on`). Since a :class:`Scene` is wired whenever it is made,
a copy with other run settings (``dataclasses.replace``, a sweep, a command-line
override) is wired by its own settings.
"""

from __future__ import annotations

import json
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field, replace
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
    "HELD",
    "INTERFACE_ROLE",
    "RAMP_ROLE",
]

ALGORITHMS = ("jacobi", "gauss_seidel")
EXTRAPOLATIONS = ("constant", "linear", "quadratic")
INTERFACE_ROLE = "interface"
"""The role of an interface model's links (effort side to flow side) in a bond."""
RAMP_ROLE = "ramp"
"""The role of a ramped flow's slope link (flow side's flow to the effort side's
``flow_ramp`` input) in a bond; wired by ``run.ramped_flows``."""
HELD = "constant"
"""The extrapolation of a wired interface model's links and of its bond's effort: the
effort side's values at the step's start, about which the model is taken (the flow side
steps first, so it has no newer ones; in an iterated step, or with ``run.order`` putting
the effort side first, a constant hold takes the newest values: the model about the
step's end)."""
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
    switched_on : tuple of str
        Boolean parameters among ``parameters`` that the scene did not write and that are
        true because a bond wires this unit's interface model (its ``interface_switch``).
    """

    name: str
    fmu: str
    effects: tuple[str, ...] = ()
    parameters: dict[str, Any] = field(default_factory=dict)
    switched_on: tuple[str, ...] = ()

    def own_parameters(self) -> dict[str, Any]:
        """The parameters the scene wrote (without those an interface model switched on)."""
        return {
            k: v for k, v in self.parameters.items() if not (k in self.switched_on and v is True)
        }

    def switched(self, switches: tuple[str, ...]) -> UnitSpec:
        """The unit with ``switches`` true where the scene does not set them itself.

        Parameters
        ----------
        switches : tuple of str
            Boolean parameters that wired interface models need on.

        Returns
        -------
        UnitSpec
            ``self`` when nothing changes, else a copy with the switches set.
        """
        own = self.own_parameters()
        added = tuple(sorted(name for name in set(switches) if name not in own))
        if added == self.switched_on and len(own) + len(added) == len(self.parameters):
            return self
        return replace(self, parameters={**own, **dict.fromkeys(added, True)}, switched_on=added)

    def parameter_values(self, leave_out: Collection[str] = ()) -> dict[str, Any]:
        """Parameters as FMI values (tables and lists serialised to JSON).

        Parameters
        ----------
        leave_out : collection of str
            Parameters not to give (those the unit cannot take, a table holding a date
            among them: JSON has none).
        """
        out = {}
        for key, value in self.parameters.items():
            if key not in leave_out:
                out[key] = json.dumps(value) if isinstance(value, Mapping | list) else value
        return out


@dataclass(frozen=True)
class Connection:
    """An output feeding an input.

    ``role`` is ``"effort"``, ``"flow"``, ``"position"``, ``"interface"`` (one of an
    interface model's links) or ``"ramp"`` (the flow's slope) inside a bond, ``"signal"``
    otherwise.
    """

    source: VarRef
    target: VarRef
    role: str = "signal"
    bond: str | None = None
    extrapolation: str | None = None


@dataclass(frozen=True)
class Bond:
    """A power bond between two units (effort one way, flow back).

    Attributes
    ----------
    name, kind : str
        The bond's name and kind (one of :data:`BOND_KINDS`).
    effort, flow : Connection
        The effort link (effort side to flow side) and the flow link (back).
    position : Connection or None
        The position link (back), if any.
    interface : tuple of Connection
        The interface model's links the bond offers (role ``"interface"``, effort side
        to flow side, held over the step); empty when either port lacks the model.
    interface_switch : VarRef or None
        The effort unit's Boolean parameter that turns its interface model on.
    interface_model : bool or None
        The bond's own choice of coupling (its ``interface_model`` key); None follows
        ``run.interface_models``.
    interface_lacking : tuple of str
        The ports that declare no interface model (``"unit.port (flow side)"``).
    extrapolation : str or None
        The bond's own extrapolation (its ``extrapolation`` key).
    wired : bool
        Whether the interface links are among the connections (set by the :class:`Scene`).
    ramp : Connection or None
        The flow's slope link (role ``"ramp"``) when the effort side takes one.
    ramped : bool
        Whether the ramp link is among the connections (``run.ramped_flows``; set by the
        :class:`Scene`): the flow input is then the flow at the step's start, ramping
        with the slope the master sets on the ramp link.
    """

    name: str
    kind: str
    effort: Connection
    flow: Connection
    position: Connection | None = None
    interface: tuple[Connection, ...] = ()
    interface_switch: VarRef | None = None
    interface_model: bool | None = None
    interface_lacking: tuple[str, ...] = ()
    extrapolation: str | None = None
    wired: bool = False
    ramp: Connection | None = None
    ramped: bool = False

    @property
    def connections(self) -> tuple[Connection, ...]:
        """The bond's connections: effort, flow, position, the interface links if wired and
        the ramp link if ramped."""
        links = tuple(c for c in (self.effort, self.flow, self.position) if c is not None)
        links += self.interface if self.wired else ()
        return links + ((self.ramp,) if self.ramped and self.ramp is not None else ())

    def asks_interface(self, run: RunSettings) -> bool:
        """Whether the scene asks this bond for its interface model.

        Parameters
        ----------
        run : RunSettings
            The scene's run settings (``interface_models``).
        """
        choice = run.interface_models if self.interface_model is None else self.interface_model
        return choice is True

    def wire(self, on: bool, ramp: bool = False) -> Bond:
        """The bond with its interface links wired (``on``, when it has them) or not, and
        its flow ramped (``ramp``, when the effort side takes a ramp) or not.

        Wired, the effort is held like the links (:data:`HELD`): the flow side takes
        the effort and its model about the same instant.

        Parameters
        ----------
        on : bool
            Whether the scene asks for the interface model.
        ramp : bool
            Whether the scene asks for ramped flows (``run.ramped_flows``).
        """
        wired = bool(on and self.interface)
        ramped = bool(ramp and self.ramp is not None)
        scheme = HELD if wired else self.extrapolation
        if wired == self.wired and ramped == self.ramped and self.effort.extrapolation == scheme:
            return self
        effort = replace(self.effort, extrapolation=scheme)
        return replace(self, effort=effort, wired=wired, ramped=ramped)


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
    interface_models: bool = False
    ramped_flows: bool = False
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

    def __post_init__(self) -> None:
        """Wire each bond's interface model as the run and the bond ask (module docstring)."""
        ramp = self.run.ramped_flows is True
        bonds = tuple(b.wire(b.asks_interface(self.run), ramp) for b in self.bonds)
        switches: dict[str, list[str]] = {}
        for bond in bonds:
            if bond.wired and bond.interface_switch is not None:
                switch = bond.interface_switch
                switches.setdefault(switch.unit, []).append(switch.variable)
        units = {
            name: spec.switched(tuple(switches.get(name, ()))) for name, spec in self.units.items()
        }
        if any(units[n] is not s for n, s in self.units.items()):
            object.__setattr__(self, "units", units)
        object.__setattr__(self, "bonds", bonds)

    @property
    def interface_bonds(self) -> tuple[Bond, ...]:
        """The bonds whose interface model is wired."""
        return tuple(b for b in self.bonds if b.wired)

    @property
    def all_connections(self) -> tuple[Connection, ...]:
        """Signal connections and every bond's connections."""
        return self.connections + tuple(c for b in self.bonds for c in b.connections)
