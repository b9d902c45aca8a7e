"""The monolithic reference: a scene's core units as one hybrid ODE, no FMI between.

Every unit of the scene must be one of ours; its core class is configured
with the scene's parameters and effects, initialised in the same order as
the master would, and then seen through :meth:`Unit.ode`. Connections become
algebraic: at every evaluation of the right-hand side the outputs of each
unit are computed from its state and handed to the inputs they feed —
flow-side units first (their outputs depend on no input), then the units
whose outputs feed through — exactly the structure the master's scene
validation proves loop-free. Drivers give their value and rate at the
evaluation time; scheduled events are integration boundaries.

Solved with SciPy's Radau (or any method of :mod:`wire_fmu.core.framework.hybrid`)
at tight tolerance with event location, it is both the accuracy reference
for the co-simulation and the speed floor it is compared with.
"""

from __future__ import annotations

import logging
import time
from collections import defaultdict
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np

from wire_fmu.core.framework.hybrid import SolverSettings, make_solver
from wire_fmu.core.framework.unit import Causality, OdeView, Unit
from wire_fmu.master.algorithms import step_order
from wire_fmu.master.manipulators import DriverSet, ScheduledEvents
from wire_fmu.master.scene import Scene, SceneError, VarRef
from wire_fmu.master.scene.data import INTERFACE_ROLE
from wire_fmu.registry import BY_NAME, UNIT_TYPES

__all__ = [
    "CORE_UNITS",
    "MonolithicModel",
    "MonolithicResult",
    "advance_to",
    "run_monolithic",
]

logger = logging.getLogger(__name__)

CORE_UNITS = MappingProxyType({u.name: u.core for u in UNIT_TYPES})
"""FMU model name -> core unit class (module:class), from :mod:`wire_fmu.registry`."""


def _core_class(name: str) -> type[Unit]:
    return BY_NAME[name].core_class()


@dataclass
class MonolithicResult:
    """Recorded outputs of a monolithic run."""

    time: np.ndarray
    values: dict[str, np.ndarray]
    wall_time: float
    rhs_calls: int
    steps: int
    events: int = 0
    columns: list[str] = field(default_factory=list)


class _Instant:
    """Drivers read at an instant: value and rate at ``t`` (no step averaging)."""

    def __init__(self, drivers: DriverSet) -> None:
        self.drivers = drivers

    def values(self, unit: str, t: float) -> dict[str, float]:
        """The drivers' values and rates for ``unit`` at ``t``.

        Parameters
        ----------
        unit : str
            Unit name.
        t : float
            Time, s.
        """
        return self.drivers.values(unit, t, None)


class MonolithicModel:
    """A scene's core units as one :class:`~wire_fmu.core.framework.hybrid.HybridSystem`.

    Parameters
    ----------
    scene : Scene
        A scene whose units are all ours.
    """

    def __init__(self, scene: Scene) -> None:
        problems = [
            f"unit {n!r}: {u.fmu!r} is not one of ours ({', '.join(CORE_UNITS)})"
            for n, u in scene.units.items()
            if u.fmu not in CORE_UNITS
        ]
        if problems:
            raise SceneError(f"scene {scene.name!r} (monolithic)", problems)
        self.scene = scene
        self.units: dict[str, Unit] = {}
        for name, spec in scene.units.items():
            unit = _core_class(spec.fmu)(name)
            values = spec.parameter_values()
            for switch in spec.switched_on:  # one ODE needs no unit's interface model
                values[switch] = False
            if "effects" in unit.values:
                values["effects"] = ",".join(spec.effects)
            unit.values.update(values)
            unit.configure()
            self.units[name] = unit
        # an interface model's links stand in for the exact coupling the one ODE solves
        self.connections = tuple(c for c in scene.all_connections if c.role != INTERFACE_ROLE)
        self.into: dict[str, list] = defaultdict(list)
        for c in self.connections:
            self.into[c.target.unit].append(c)
        flows_to, feeds = defaultdict(set), defaultdict(set)
        for c in self.connections:
            feeds[c.source.unit].add(c.target.unit)
            if c.role != "effort":
                flows_to[c.source.unit].add(c.target.unit)
        self.order = step_order(list(scene.units), flows_to, feeds, scene.run.order)
        self.drivers = _Instant(DriverSet(scene.drivers, scene.base_dir))
        self.events = ScheduledEvents(scene.events)
        self.views: dict[str, OdeView] = {}
        self.slices: dict[str, slice] = {}
        self._dirs = np.zeros(0)
        self._guard_slices: dict[str, slice] = {}

    # -- set-up ------------------------------------------------------------------
    def initialize(self, t0: float = 0.0) -> np.ndarray:
        """Initialise the units in step order, as the master does; return the state.

        Parameters
        ----------
        t0 : float
            Start time, s.
        """
        self.events.fire_due(t0)
        ready: set[str] = set()
        for name in self.order:  # as the master: sources first, each from what is ready
            unit = self.units[name]
            unit.values.update(self.drivers.values(name, t0))
            unit.values.update(self.events.values(name))
            self._feed(name, ready)
            unit.initialize(t0)
            ready.add(name)
        for name in self.order:  # once more with every partner's initial outputs
            self._feed(name)
            self.units[name].initialize(t0)
        for name in self.order:
            self._feed(name)
        start, g_start, dirs = 0, 0, []
        for name in self.order:
            view = self.units[name].ode()
            n = len(view.state)
            self.views[name] = view
            self.slices[name] = slice(start, start + n)
            d = np.asarray(view.guard_directions(), dtype=float)
            self._guard_slices[name] = slice(g_start, g_start + d.size)
            dirs.append(d)
            start, g_start = start + n, g_start + d.size
        self._dirs = np.concatenate(dirs) if dirs else np.zeros(0)
        return self.state()

    def state(self) -> np.ndarray:
        """The joint state vector."""
        return np.concatenate([self.views[n].state for n in self.order])

    def _feed(self, name: str, only: set[str] | None = None) -> None:
        """Copy the current outputs of ``name``'s sources (those in ``only``) into its inputs."""
        unit = self.units[name]
        for c in self.into.get(name, ()):
            if only is None or c.source.unit in only:
                unit.values[c.target.variable] = self.units[c.source.unit].values[c.source.variable]

    def _propagate(self, t: float, x: np.ndarray) -> None:
        """Outputs from states, inputs from outputs, in step order."""
        for name in self.order:
            unit = self.units[name]
            unit.values.update(self.drivers.values(name, t))
            unit.values.update(self.events.values(name))
            self._feed(name)
            view = self.views[name]
            view.bind_inputs(t)
            view.publish(t, x[self.slices[name]])
        for name in self.order:  # inputs fed by units later in the order
            if any(
                self.order.index(c.source.unit) >= self.order.index(name)
                for c in self.into.get(name, ())
            ):
                self._feed(name)
                self.views[name].bind_inputs(t)

    # -- HybridSystem ----------------------------------------------------------------
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """Joint state derivative.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Joint state, the units' states in step order.
        """
        self._propagate(t, x)
        return np.concatenate([self.views[n].rhs(t, x[self.slices[n]]) for n in self.order])

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Every unit's guards, in step order.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Joint state.
        """
        self._propagate(t, x)
        return (
            np.concatenate(
                [np.asarray(self.views[n].guards(t, x[self.slices[n]])) for n in self.order]
            )
            if self.order
            else np.zeros(0)
        )

    def guard_directions(self) -> np.ndarray:
        """Every unit's guard directions."""
        return self._dirs

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Hand each fired guard to its unit.

        Parameters
        ----------
        t : float
            Event time, s.
        x : ndarray
            Joint state at the event.
        fired : list of int
            Indices of the fired guards in the joint guard vector.
        """
        x = np.array(x, dtype=float)
        self._propagate(t, x)
        for name in self.order:
            g = self._guard_slices[name]
            local = [i - g.start for i in fired if g.start <= i < g.stop]
            if local:
                x[self.slices[name]] = self.views[name].handle_events(
                    t, x[self.slices[name]], local
                )
        self._dirs = np.concatenate(
            [np.asarray(self.views[n].guard_directions(), dtype=float) for n in self.order]
        )
        return x

    def project(self, x: np.ndarray) -> np.ndarray:
        """Every unit's invariants.

        Parameters
        ----------
        x : ndarray
            Joint state, projected in place.
        """
        for name in self.order:
            x[self.slices[name]] = self.views[name].project(x[self.slices[name]])
        return x

    def reconcile(self, t: float, x: np.ndarray) -> np.ndarray:
        """After an event: every unit settles its modes for the new inputs.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Joint state.
        """
        x = np.array(x, dtype=float)
        self._propagate(t, x)
        for name in self.order:
            x[self.slices[name]] = self.views[name].reconcile(t, x[self.slices[name]])
        return x

    def outputs(self, t: float, x: np.ndarray, refs: list[VarRef]) -> list[float]:
        """Values of ``refs`` at state ``x``.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Joint state.
        refs : list of VarRef
            Unit variables to read.
        """
        self._propagate(t, x)
        return [float(self.units[r.unit].values[r.variable]) for r in refs]


def advance_to(
    model: MonolithicModel, solver: Any, t: float, x: np.ndarray, t_next: float
) -> tuple[np.ndarray, int]:
    """Solve ``model`` from ``t`` to ``t_next``, stopping at every scheduled event between.

    Parameters
    ----------
    model : MonolithicModel
        The scene's units as one ODE, initialised.
    solver : object
        A solver of :func:`~wire_fmu.core.framework.hybrid.make_solver`.
    t : float
        Time of ``x``, s.
    x : ndarray
        Joint state at ``t``.
    t_next : float
        Time to reach, s (> ``t``).

    Returns
    -------
    x : ndarray
        Joint state at ``t_next``.
    events : int
        Guard events the solver located on the way.
    """
    events = 0
    while t < t_next - 1e-12:
        upcoming = model.events.next_time
        target = min(t_next, upcoming) if upcoming is not None and upcoming > t else t_next
        x, n = solver.advance(model, t, x, target)
        events += n
        t = target
        if model.events.fire_due(t):
            x = model.reconcile(t, x)
    return x, events


def _recorded(model: MonolithicModel) -> list[VarRef]:
    scene = model.scene
    if scene.outputs is not None:
        refs = list(scene.outputs)
    else:
        refs = [
            VarRef(n, v.name)
            for n, u in model.units.items()
            for v in u.VARIABLES
            if v.causality is Causality.output and v.type is float
        ]
    for plot in scene.plots:
        refs += [r for r in plot.variables if r not in refs]
    return refs


def run_monolithic(
    scene: Scene,
    *,
    method: str = "radau",
    rtol: float = 1e-10,
    atol: float = 1e-10,
    output_interval: float | None = None,
    max_step: float = np.inf,
) -> MonolithicResult:
    """Solve ``scene`` as one ODE and record its outputs.

    Parameters
    ----------
    scene : Scene
        A scene of our units.
    method : str
        A solver of :mod:`wire_fmu.core.framework.hybrid` (default SciPy's Radau, stiff).
    rtol, atol : float
        Tolerances (the reference uses ``rtol <= 1e-10``).
    output_interval : float, optional
        Record spacing, s (default: the scene's, else its macro step).
    max_step : float
        Largest internal step, s.
    """
    model = MonolithicModel(scene)
    x = model.initialize(0.0)
    refs = _recorded(model)
    dt = output_interval or scene.run.output_interval or scene.run.step
    stop = scene.run.stop_time
    n_out = int(round(stop / dt))
    times = np.linspace(0.0, n_out * dt, n_out + 1)
    solver = make_solver(SolverSettings(method=method, max_step=max_step, rtol=rtol, atol=atol))
    rows = [model.outputs(0.0, x, refs)]
    start, events = time.perf_counter(), 0
    t = 0.0
    for t_next in times[1:]:
        x, n = advance_to(model, solver, t, x, t_next)
        events += n
        t = t_next
        rows.append(model.outputs(t, x, refs))
    wall = time.perf_counter() - start
    data = np.array(rows)
    return MonolithicResult(
        times,
        {str(r): data[:, i] for i, r in enumerate(refs)},
        wall,
        solver.rhs_calls,
        solver.steps,
        events,
        [str(r) for r in refs],
    )
