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

Across the FMI boundary each unit gets, per macro step, one batched set of
its Real inputs (connected, driven, set by events) and, after its step, one
batched read per FMI type of what the master needs: the outputs that feed
connections, the ``mode_changes`` counter and, at the steps an observer
records, the variables it watches (:meth:`Simulation.watch`). The value
references are resolved once (:mod:`~wire_fmu.master.unit_io`).

The energy residual of a bond over a step is computed in
:mod:`~wire_fmu.master.bond_energy`; macro step sizes (nanosecond times, the
step after a rejection, the adaptive controller) in
:mod:`~wire_fmu.master.step_size`.
"""

from __future__ import annotations

import logging
import math
import time
from collections import defaultdict
from dataclasses import dataclass, field

from .algorithms import make_algorithm, step_order
from .bond_energy import BondKeys, step_energy
from .energy_guard import EnergyGuard, _remedies
from .extrapolation import History, held_value
from .interrupts import _InterruptRequestedError, _Interrupts
from .manipulators import DriverSet, ScheduledEvents
from .run_result import RunResult, SimulationStoppedError
from .scene import Scene
from .slave import Slave, StepRefusedError, UnitFailedError
from .step_size import _PI, _ns, new_h
from .unit_io import EndValues, InputPlan, Link, ReadPlan, Watch, read_plan
from .validate import Structure, unit_start_values

__all__ = ["Simulation"]

logger = logging.getLogger(__name__)

MODE_OUTPUT = "mode_changes"


@dataclass
class _Attempt:
    """One try at a macro step."""

    accepted: bool
    residuals: dict[str, float]
    sweeps: int
    new: dict[str, float] = field(default_factory=dict)
    retry_step: float = 0.0
    message: str = ""


class Simulation:
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
        self.mode_counts: dict[str, int] = {}
        self.result = RunResult("not started")
        self._error_prev = 1.0
        self._interrupts = _Interrupts()
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
    def _build_links(self) -> None:
        self.links_into: dict[str, list[Link]] = defaultdict(list)
        self.source_keys: dict[str, list[str]] = defaultdict(list)
        self.histories: dict[str, History] = {}
        for c in self.scene.all_connections:
            slave = self.slaves[c.target.unit]
            scheme = c.extrapolation or self.run_settings.extrapolation
            key = str(c.source)
            history = self.histories.setdefault(key, History())
            link = Link(c, key, slave.vr(c.target.variable), scheme, history)
            self.links_into[c.target.unit].append(link)
            if key not in self.source_keys[c.source.unit]:
                self.source_keys[c.source.unit].append(key)
        self.source_vrs = {
            unit: [self.slaves[unit].vr(k.split(".", 1)[1]) for k in keys]
            for unit, keys in self.source_keys.items()
        }

    def _build_plans(self) -> None:
        """Each unit's batched set and end-of-step reads (after the observers' watches)."""
        for name, slave in self.slaves.items():
            links = tuple(self.links_into.get(name, ()))
            driven = tuple(self.drivers.targets(name))
            variables = [slave.variables.get(n) for n in driven]
            reals = all(v is not None and v.type == "Real" for v in variables)
            refs = [link.target_vr for link in links]
            if reals:
                refs += [v.valueReference for v in variables]
            evented = name in self.events.units
            self._inputs[name] = InputPlan(links, driven, refs, reals, evented)
            sources = self.source_vrs.get(name, [])
            mode = MODE_OUTPUT if name in self.mode_counts else None
            self._reads[name] = (
                read_plan(name, slave, sources, mode),
                read_plan(name, slave, sources, mode, self._watches),
            )

    def watch(self, names: dict[str, list[str]], due) -> Watch:
        """Read variables with the units' end-of-step reads at the steps ``due`` names.

        For observers: call it in ``on_start``; the values of a step are then
        read with what the master reads at the end of the step anyway.

        Parameters
        ----------
        names : dict of str to list of str
            Variable names by unit.
        due : callable
            ``due(t)``: whether the observer reads after the step that ends at
            ``t`` (s).

        Returns
        -------
        Watch
            Its :meth:`~wire_fmu.master.unit_io.Watch.values` gives a unit's
            variables now, from the end-of-step read when it has them.
        """
        watch = Watch(names, due)
        self._watches.append(watch)
        self._reads.clear()  # planned again before the next step
        return watch

    def watched_values(self, watch: Watch, unit: str) -> list:
        """The current values of the variables ``watch`` names at ``unit``.

        Parameters
        ----------
        watch : Watch
            From :meth:`watch`.
        unit : str
            Instance name of the unit in the scene.

        Returns
        -------
        list of object
            Each value, in its unit, in the order the watch names them.
        """
        return watch.values(unit, self.slaves[unit], self._ends.get(unit))

    def watched_snapshot(self, watch: Watch, unit: str) -> EndValues | list:
        """:meth:`watched_values`, kept for later (:meth:`Watch.unpack <.unit_io.Watch.unpack>`).

        Parameters
        ----------
        watch : Watch
            From :meth:`watch`.
        unit : str
            Instance name of the unit in the scene.

        Returns
        -------
        EndValues or list
            The unit's end-of-step read when it holds the watched values, else
            the values read now.
        """
        return watch.take(unit, self.slaves[unit], self._ends.get(unit))

    def _order(self, structure: Structure) -> list[str]:
        flows_to, feeds = defaultdict(set), defaultdict(set)
        for c in self.scene.all_connections:
            feeds[c.source.unit].add(c.target.unit)
            if c.role != "effort":
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
        for name, slave in self.slaves.items():
            # a mode event resets the unit's outgoing histories: watched where there are any
            if MODE_OUTPUT in slave.variables and self.source_keys.get(name):
                self.mode_counts[name] = int(slave.get([MODE_OUTPUT])[MODE_OUTPUT])
        self.time = start

    def _set_connected_from_latest(self, unit: str) -> None:
        self._ends.pop(unit, None)
        refs, values = [], []
        for link in self.links_into.get(unit, ()):
            if self.histories[link.key].points:
                refs.append(link.target_vr)
                values.append(self.histories[link.key].latest)
        self.slaves[unit].set_reals(refs, values)

    def _push(self, unit: str, t: float) -> None:
        for key, value in self.read_sources(unit).items():
            self.histories[key].push(t, value)

    # -- what algorithms call ------------------------------------------------------
    def read_sources(self, unit: str) -> dict[str, float]:
        """Current values of ``unit``'s outputs that feed connections.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.

        Returns
        -------
        dict of str to float
            Each output's value by its ``"unit.variable"`` name, in its unit.
        """
        end = self._ends.get(unit)
        if end is not None:  # read once, just after the unit's step
            return dict(end.sources)
        keys = self.source_keys.get(unit, [])
        return dict(
            zip(keys, self.slaves[unit].get_reals(self.source_vrs.get(unit, [])), strict=True)
        )

    def set_inputs(self, unit: str, t: float, h: float, fresh: dict | None) -> None:
        """Held values of every connected, driven or overridden input of ``unit``.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        t, h : float
            Start and length of the macro step, s.
        fresh : dict or None
            Source outputs (``"unit.variable"``) at ``t + h`` from the previous
            sweep of an iterated step; None extrapolates from the past.
        """
        self._ends.pop(unit, None)
        plan = self._inputs[unit]
        if plan.idle:
            return
        held, values = self.held, []
        for link in plan.links:
            if link.position:
                value = link.history.points[-1][1]  # the unit advances it with the held velocity
            else:
                value = held_value(
                    link.history, t, h, link.scheme, None if fresh is None else fresh.get(link.key)
                )
            values.append(value)
            held[link.target] = value
        slave = self.slaves[unit]
        by_name = None
        if plan.driven:
            driven = self.drivers.step_values(unit, t, h)
            if not plan.driven_reals:
                by_name = dict(zip(plan.driven, driven, strict=True))  # set by name, checked
            elif all(type(v) is float for v in driven):
                values += driven
            else:  # checked as a set by name would, then sent as floats
                slave.typed_values(dict(zip(plan.driven, driven, strict=True)))
                values += [float(v) for v in driven]
        refs, others = plan.refs, None
        if by_name is not None:  # as the events' values override the drivers'
            by_name.update(self.events.values(unit))
        elif plan.evented:
            refs, event_values, others = plan.event_inputs(slave, self.events)
            values += event_values
        slave.set_reals(refs, values)
        if by_name:
            slave.set_many(by_name)
        if others:
            slave.set_typed(others)

    def step_unit(self, unit: str, t: float, h: float) -> None:
        """Step one unit (errors propagate as StepRefusedError / UnitFailedError).

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        t, h : float
            Start and length of the macro step, s.
        """
        self._ends.pop(unit, None)
        slave = self.slaves[unit]
        slave.do_step(t, h)
        plain, watched = self._reads[unit]
        plan = watched if self._watching else plain
        self._ends[unit] = plan.read(slave, self.source_keys.get(unit, ()))

    def _fire_events(self, t: float) -> list[str]:
        fired = self.events.fire_due(t)
        if fired:  # inputs jump: nothing may be extrapolated across
            for history in self.histories.values():
                history.reset()
        return fired

    # -- one macro step -----------------------------------------------------------------
    def _save(self):
        return {name: s.get_state() for name, s in self.slaves.items()}

    def _restore(self, states) -> None:
        self._ends.clear()
        for name, state in states.items():
            self.slaves[name].set_state(state)

    def _free(self, states) -> None:
        for name, state in states.items():
            self.slaves[name].free_state(state)

    def _read_all(self) -> dict[str, float]:
        new = {}
        for unit in self.slaves:
            end = self._ends.get(unit)
            new.update(end.sources if end is not None else self.read_sources(unit))
        return new

    def _sweep_iterated(self, t: float, h: float, states) -> tuple[dict[str, float], int]:
        self.algorithm.sweep(self, t, h)
        new = self._read_all()
        sweeps, changes = 1, []
        for _ in range(self.run_settings.iterations - 1):
            if not all(map(math.isfinite, new.values())):
                return new, sweeps  # never handed on: the caller rejects the step
            before = dict(self.held)
            self._restore(states)
            self.algorithm.sweep(self, t, h, fresh=new)
            new = self._read_all()
            sweeps += 1
            changes.append(
                max(
                    (
                        abs(self.held[k] - before.get(k, 0.0)) / max(1.0, abs(self.held[k]))
                        for k in self.held
                    ),
                    default=0.0,
                )
            )
            if changes[-1] < self.run_settings.iteration_tolerance:
                return new, sweeps
        if len(changes) >= 3 and changes[-1] > changes[0]:  # the fixed point runs away
            raise SimulationStoppedError(
                f"t = {t:.6g} s: the iteration over the step of {h:.3g} s diverges (input "
                f"change {changes[0]:.3g} after the second sweep, {changes[-1]:.3g} after the "
                f"last of {sweeps}): the coupling cannot be resolved at this step; use a "
                "smaller step or adaptive steps"
            )
        return new, sweeps

    def bond_residuals(self, new: dict[str, float], h: float) -> dict[str, float]:
        """Energy each bond's coupling created over the step just taken, J.

        Parameters
        ----------
        new : dict of str to float
            Source outputs (``"unit.variable"``) at the end of the step.
        h : float
            The step just taken, s.

        Returns
        -------
        dict of str to float
            The energy residual by bond name, J (positive: created).
        """
        out = {}
        histories, held, power = self.histories, self.held, self.bond_power
        for keys in self._bond_keys:
            out[keys.name], power[keys.name] = step_energy(keys, histories, held, new, h)
        return out

    def _attempt(self, t: float, h: float) -> _Attempt:
        """Take one macro step, rolling back when it is refused or rejected."""
        if not self._reads:  # planned once, after the observers' watches
            self._build_plans()
        rollback = self.run_settings.iterations > 1 or self.run_settings.adaptive
        states = self._save() if rollback else None
        try:
            if states is not None:
                new, sweeps = self._sweep_iterated(t, h, states)
            else:
                self.algorithm.sweep(self, t, h)
                new, sweeps = self._read_all(), 1
        except StepRefusedError as exc:
            if states is None:
                raise SimulationStoppedError(str(exc)) from None
            self._restore(states)
            self._free(states)
            return _Attempt(False, {}, 0, retry_step=new_h(h, 4.0), message=str(exc))
        if not all(map(math.isfinite, new.values())):  # never accepted, never recorded
            bad = ", ".join(
                f"{key} = {value!r}" for key, value in new.items() if not math.isfinite(value)
            )
            message = f"t = {t:.6g} s: after the step of {h:.3g} s, {bad}"
            if states is None:
                raise SimulationStoppedError(
                    f"{message}: not finite; the run stops here, "
                    "everything before is kept; try a smaller step"
                )
            self._restore(states)
            self._free(states)
            return _Attempt(False, {}, sweeps, retry_step=new_h(h, 4.0), message=message)
        residuals = self.bond_residuals(new, h)
        if self.run_settings.adaptive:
            error = max((abs(r) for r in residuals.values()), default=0.0)
            error /= self.run_settings.energy_tolerance
            if error > 1.0 and h > self.run_settings.min_step * (1 + 1e-9):
                self._restore(states)
                self._free(states)
                return _Attempt(
                    False,
                    residuals,
                    sweeps,
                    retry_step=new_h(h, error),
                    message=f"bond energy residual {error:.3g} x tolerance",
                )
            if error > 1.0:
                self._free(states)
                raise SimulationStoppedError(
                    f"t = {t:.6g} s: the bonds' energy residual is {error:.3g} times "
                    f"energy_tolerance even at the minimum step {h:.3g} s: the coupling "
                    "cannot meet the tolerance; lower min_step or raise energy_tolerance"
                )
        if states is not None:
            self._free(states)
        return _Attempt(True, residuals, sweeps, new)

    def _accept(self, t: float, h: float, new: dict[str, float], residuals) -> None:
        histories, end = self.histories, t + h
        for key, value in new.items():
            histories[key].push(end, value)
        switched = set()
        for name, before in self.mode_counts.items():
            now = self._mode_count(name)
            if now != before:
                switched.add(name)
                self.mode_counts[name] = now
                for key in self.source_keys.get(name, ()):
                    histories[key].reset()
        across = (
            {
                b.name
                for b in self.scene.bonds
                if b.effort.source.unit in switched or b.flow.source.unit in switched
            }
            if switched
            else ()
        )
        self.energy.book(residuals, self.bond_power, h, across_events=across)
        self.time = t + h

    def _mode_count(self, unit: str) -> int:
        """The unit's ``mode_changes`` output now (from its end-of-step read if valid)."""
        end = self._ends.get(unit)
        if end is not None and end.mode is not None:
            return end.mode
        return int(self.slaves[unit].get([MODE_OUTPUT])[MODE_OUTPUT])

    def _next_step(self, h: float, residuals) -> float:
        s = self.run_settings
        if not s.adaptive:
            return s.step
        error = max((abs(r) for r in residuals.values()), default=0.0) / s.energy_tolerance
        error = max(error, 1e-10)
        factor = _PI["safety"] * error ** -_PI["k_i"] * (self._error_prev / error) ** _PI["k_p"]
        self._error_prev = error
        factor = min(_PI["grow"], max(_PI["shrink"], factor))
        return min(s.max_step or math.inf, max(s.min_step, h * factor))

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
        with _Interrupts() as interrupts:
            self._interrupts = interrupts
            try:
                self.initialize()
                self._fire_events(self.time)
                for obs in self.observers:
                    obs.on_start(self)
                self._stepping(result)
            except (KeyboardInterrupt, _InterruptRequestedError):
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
        while now_ns < stop_ns:
            next_ns = min(now_ns + max(1, _ns(h)), stop_ns)
            upcoming = self.events.next_time
            if upcoming is not None and now_ns < _ns(upcoming) < next_ns:
                next_ns = _ns(upcoming)
            t = now_ns / 1e9
            h = next_ns / 1e9 - t
            if self._interrupts.requested:
                raise _InterruptRequestedError
            self._watching = self._watched_at(next_ns / 1e9)
            attempt = self._attempt(t, h)
            result.iterations += attempt.sweeps
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
            h = self._next_step(h, attempt.residuals)
