"""Running a scene: units, connections, drivers, events, stepping, rollback.

:class:`Simulation` owns the units (:class:`~wire_fmu.master.slave.Slave`,
FMI only), the connections with their extrapolation histories, the
manipulators (drivers and scheduled events, which set inputs) and the
observers (which read: recorder, progress, energy monitor). One macro step:

1. manipulators set driven inputs for ``[t, t + h]`` (a driven position
   gets its value at ``t`` and its rate input the step's mean rate, so the
   unit reaches the driver's value at ``t + h`` exactly);
2. the coupling algorithm sets connected inputs and steps every unit;
3. with ``iterations > 1`` the step is repeated from saved FMU states with
   the sources' new values until the inputs stop changing;
4. with ``adaptive`` the bonds' energy residual decides whether to accept
   the step; a rejected (or refused) step is rolled back and retried shorter;
5. accepted: histories advance (a unit whose ``mode_changes`` output moved
   has its outgoing histories reset, so nothing extrapolates across a rope
   break or a stick/slip switch), observers are told;
6. the energy guard (:mod:`~wire_fmu.master.energy_guard`) stops the run,
   with a message, once the energy a bond's coupling created and destroyed
   passes a share of what the bond carried: with any settings, a macro step
   too large for the dynamics across a bond is never a silent blow-up.

A bond whose interface model is wired (:mod:`~wire_fmu.master.scene.data`)
hands its flow side the effort side's stiffness, damping, effort rate and
reference motion with the effort, all held over the step at their values at
its start; those links count as the effort's in the step order, so the flow
side still steps first and takes the model about the step's start.

Across the FMI boundary each unit gets, per macro step, one batched set of
its Real inputs (connected, driven, set by events) and, after its step, one
batched read per FMI type of what the master needs: the outputs that feed
connections, the unit's mode marker (``mode_change_time``, a Real, on our units:
one read in all; the ``mode_changes`` counter on a unit without it) and, at the
steps an observer records, the variables it watches (:meth:`Simulation.watch`).
The value references are resolved once (:mod:`~wire_fmu.master.unit_io`).

The exchange with the units (the links, the batched sets and reads, the
calls the coupling algorithms make) is in :mod:`~wire_fmu.master.exchange`;
taking, judging and rolling back one macro step in
:mod:`~wire_fmu.master.macro_step`. The energy residual of a bond over a step
is computed in :mod:`~wire_fmu.master.bond_energy`; macro step sizes
(nanosecond times, the step after a rejection, the adaptive controller) in
:mod:`~wire_fmu.master.step_size`.
"""

from __future__ import annotations

import logging
import time
from collections import defaultdict

from .algorithms import make_algorithm, step_order
from .bond_energy import BondKeys
from .energy_guard import EnergyGuard, _remedies
from .exchange import MODE_OUTPUT, UnitExchange
from .interrupts import InterruptRequestedError, Interrupts
from .macro_step import MODE_CHANGE_TIME, MacroStep
from .manipulators import DriverSet, ScheduledEvents
from .run_result import RunResult, SimulationStoppedError
from .scene import INTERFACE_ROLE, Scene, interface_warnings
from .slave import Slave, StepRefusedError, UnitFailedError
from .step_size import _ns
from .unit_io import EndValues, InputPlan, ReadPlan, Watch
from .validate import Structure, unit_start_values

__all__ = ["Simulation"]

logger = logging.getLogger(__name__)


class Simulation(UnitExchange, MacroStep):
    """A scene ready to run.

    Parameters
    ----------
    scene : Scene
        The parsed scene.
    structure : Structure
        Its units' FMU paths and model descriptions (from validation).
    observers : sequence of :class:`~wire_fmu.master.observers.Observer`
        Recorders, progress displays, monitors.
    """

    def __init__(self, scene: Scene, structure: Structure, observers=()) -> None:
        self.scene = scene
        self.run_settings = scene.run
        self.observers = list(observers)
        self.slaves = {name: Slave(name, structure.paths[name]) for name in scene.units}
        self.time = 0.0
        self.step_size = scene.run.step
        self._build_links()
        self.drivers = DriverSet(scene.drivers, scene.base_dir)
        self.events = ScheduledEvents(scene.events)
        self.algorithm = make_algorithm(scene.run.algorithm, self._order(structure))
        self.energy = EnergyGuard(
            (b.name for b in scene.bonds),
            scene.run.energy_guard,
            scene.run.energy_tolerance,
            _remedies(scene.run),
        )
        self.bond_power = {b.name: 0.0 for b in scene.bonds}
        self.held: dict[str, float] = {}
        self.mode_marks: dict[str, float | int] = {}  # see _watch_modes
        self.mode_markers: dict[str, str] = {}
        self.result = RunResult("not started")
        self._error_prev = 1.0
        self._interrupts = Interrupts()
        self._bond_keys = [BondKeys.of(b) for b in scene.bonds]
        self._watches: list[Watch] = []
        self._watching = False  # whether this step's end-of-step reads include the watches
        self._inputs: dict[str, InputPlan] = {}
        self._reads: dict[str, tuple[ReadPlan, ReadPlan]] = {}
        self._ends: dict[str, EndValues] = {}  # the units' end-of-step reads still valid

    @property
    def bond_residual(self) -> dict[str, float]:
        """Energy each bond's coupling has created since the start, J."""
        return {name: bond.created for name, bond in self.energy.bonds.items()}

    # -- structure -------------------------------------------------------------
    def _order(self, structure: Structure) -> list[str]:
        flows_to, feeds = defaultdict(set), defaultdict(set)
        for c in self.scene.all_connections:
            feeds[c.source.unit].add(c.target.unit)
            if c.role not in ("effort", INTERFACE_ROLE):  # these go with the effort
                flows_to[c.source.unit].add(c.target.unit)
        return step_order(list(self.scene.units), flows_to, feeds, self.run_settings.order)

    # -- initialisation ----------------------------------------------------------
    def initialize(self) -> None:
        """Instantiate, set parameters and start inputs, initialise in step order."""
        start = 0.0
        for name in self.algorithm.order:
            slave = self.slaves[name]
            slave.instantiate()
            values = unit_start_values(self.scene.units[name], slave)
            # the values the first step will hold, so nothing jumps at the first step
            values.update(self.drivers.values(name, start, self.run_settings.step))
            values.update(self.events.values(name))
            slave.initialize(start, values)
        # In initialisation mode, hand outputs to the inputs they feed, sources first,
        # twice over so that feedback (an effort returned to a flow side) settles.
        for _ in range(2):
            for name in self.algorithm.order:
                self._set_connected_from_latest(name)
                self._push(name, start)
        for name in self.algorithm.order:
            self._set_connected_from_latest(name)
            self.slaves[name].exit_initialization()
            self._push(name, start)
        self._watch_modes()
        self.time = start

    def _watch_modes(self) -> None:
        """Note each unit's mode marker: a mode event resets the unit's outgoing histories.

        Watched where the unit has outgoing connections and a ``mode_changes`` counter:
        through its Real ``mode_change_time`` where it declares one (it moves exactly
        when the counter does, and is read with the unit's other Reals), else
        through the Integer counter itself.
        """
        for name, slave in self.slaves.items():
            if MODE_OUTPUT not in slave.variables or not self.source_keys.get(name):
                continue
            told = slave.variables.get(MODE_CHANGE_TIME)
            marker = MODE_CHANGE_TIME if told is not None and told.type == "Real" else MODE_OUTPUT
            self.mode_markers[name] = marker
            self.mode_marks[name] = slave.get([marker])[marker]

    @property
    def event_time_units(self) -> set[str]:
        """Units whose mode the master watches through ``mode_change_time``: they tell when."""
        return {name for name, m in self.mode_markers.items() if m == MODE_CHANGE_TIME}

    def _fire_events(self, t: float) -> list[str]:
        fired = self.events.fire_due(t)
        if fired:  # inputs jump: nothing may be extrapolated across
            for history in self.histories.values():
                history.reset()
        return fired

    # -- the run --------------------------------------------------------------------------
    def run(self) -> RunResult:
        """Initialise and run to the stop time; observers see every accepted step.

        Never raises: the result's ``status`` (one of
        :data:`~wire_fmu.master.run_result.STATUSES`) and ``message`` say how
        the run ended, and every observer's ``on_end`` is called whatever
        happened. Ctrl-C (and SIGTERM) end the run after the
        macro step under way, with status ``interrupted``; a second Ctrl-C
        interrupts at once.
        """
        wall = time.perf_counter()
        result = RunResult("finished")
        with Interrupts() as interrupts:
            self._interrupts = interrupts
            try:
                for warning in interface_warnings(self.scene):
                    logger.warning("%s", warning)
                self.initialize()
                self._fire_events(self.time)
                for obs in self.observers:
                    obs.on_start(self)
                self._stepping(result)
            except (KeyboardInterrupt, InterruptRequestedError):
                result.status = "interrupted"
                result.message = f"interrupted at t = {self.time:.6g} s"
            except (SimulationStoppedError, StepRefusedError) as exc:
                result.status, result.message = "stopped", str(exc)
            except UnitFailedError as exc:
                result.status, result.message = "failed", str(exc)
            except Exception as exc:  # noqa: BLE001 - a run ends with a status, never a traceback
                logger.debug("unexpected failure at t = %g s", self.time, exc_info=True)
                result.status = "failed"
                result.message = (
                    f"t = {self.time:.6g} s: unexpected {type(exc).__name__}: "
                    f"{exc} (run with --verbose for the traceback)"
                )
            finally:
                self._finish(result, wall)
        return result

    def _finish(self, result: RunResult, wall: float) -> None:
        """Book the result, tell the observers, free the units (all of it, whatever fails)."""
        result.end_time, result.wall_time = self.time, time.perf_counter() - wall
        result.bond_residual = self.bond_residual
        result.bond_carried = {n: b.carried for n, b in self.energy.bonds.items()}
        result.bond_error = {n: b.error for n, b in self.energy.bonds.items()}
        self.result = result
        for obs in self.observers:
            try:
                obs.on_end(self, result)
            except Exception as exc:  # noqa: BLE001 - the other observers still get their end
                logger.warning("%s could not finish: %s", type(obs).__name__, exc)
                logger.debug("observer failure", exc_info=True)
        for slave in self.slaves.values():
            slave.terminate()

    def _watched_at(self, end: float) -> bool:
        """Whether some observer reads its watched variables after a step ending at ``end``."""
        for watch in self._watches:
            if watch.due(end):
                return True
        return False

    def _stepping(self, result: RunResult) -> None:
        """:meth:`_loop`, timed: the loop's wall time and the time in FMI calls within it."""
        fmi = self._fmi_seconds()
        start = time.perf_counter()
        try:
            self._loop(result)
        finally:
            result.stepping_wall_time = time.perf_counter() - start
            result.stepping_fmi_time = self._fmi_seconds() - fmi

    def _fmi_seconds(self) -> float:
        return sum(sum(slave.seconds.values()) for slave in self.slaves.values())

    def _loop(self, result: RunResult) -> None:
        # Time is counted in integer nanoseconds, as libcosim does: no drift over long
        # runs, event times hit exactly, and the same step sizes as libcosim's.
        stop_ns = _ns(self.run_settings.stop_time)
        now_ns = _ns(self.time)
        h = self.run_settings.step
        resume_h = None  # the step to go on with after one shortened to a mode change
        planned_ns = None  # where that shortened step was to end: the rest is stepped first
        while now_ns < stop_ns:
            # min(now + max(1, step), stop), written out: the builtins parse keywords
            step_ns = _ns(h)
            next_ns = now_ns + (step_ns if step_ns > 0 else 1)
            if next_ns > stop_ns:
                next_ns = stop_ns
            upcoming = self.events.next_time
            if upcoming is not None and now_ns < _ns(upcoming) < next_ns:
                next_ns = _ns(upcoming)
            t = now_ns / 1e9
            h = next_ns / 1e9 - t
            if self._interrupts.requested:
                raise InterruptRequestedError
            self._watching = self._watched_at(next_ns / 1e9)
            attempt = self._attempt(t, h)
            result.iterations += attempt.sweeps
            if attempt.event_end_ns is not None:  # step every unit to the mode change
                result.synchronised += 1
                resume_h = h if resume_h is None else resume_h
                planned_ns = next_ns if planned_ns is None else planned_ns
                h = (attempt.event_end_ns - now_ns) / 1e9
                continue
            if not attempt.accepted:
                result.rejected += 1
                if h <= self.run_settings.min_step * (1 + 1e-9):
                    raise SimulationStoppedError(
                        f"step refused at the minimum step "
                        f"{self.run_settings.min_step:g} s: "
                        f"{attempt.message}"
                    )
                h = max(self.run_settings.min_step, attempt.retry_step)
                logger.debug(
                    "t = %.6g s: step rejected (%s), retrying with %.3g s", t, attempt.message, h
                )
                continue
            self._accept(t, h, attempt.new, attempt.residuals)
            now_ns = next_ns
            self.time = now_ns / 1e9
            result.steps += 1
            self._fire_events(self.time)
            for obs in self.observers:
                obs.on_step(self)
            blow_up = self.energy.blow_up(self.time, h)
            if blow_up:
                raise SimulationStoppedError(blow_up)
            if planned_ns is not None and now_ns < planned_ns:  # the rest of a shortened step:
                h = (planned_ns - now_ns) / 1e9  # back on the grid (and the output times)
            elif resume_h is not None:  # then the step asked for
                h, resume_h, planned_ns = resume_h, None, None
            else:
                h = self._next_step(h, attempt.residuals)
