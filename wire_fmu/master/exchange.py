"""What the master hands to its units and reads from them, unit by unit, each macro step.

:class:`UnitExchange` is the part of
:class:`~wire_fmu.master.simulation.Simulation` that builds the connections
(the links into each unit and their extrapolation histories), plans each unit's
one batched set of Real inputs and its end-of-step reads
(:mod:`~wire_fmu.master.unit_io`), and makes the calls the coupling algorithms
make: set a unit's inputs, step it, read its sources. The observers' watched
variables are read with the end-of-step reads (:meth:`UnitExchange.watch`).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence

from .extrapolation import History, held_value, push_all, ramp
from .scene.data import RAMP_ROLE
from .unit_io import EndValues, InputPlan, Link, Watch, input_order, read_plan

__all__ = ["MODE_OUTPUT", "UnitExchange"]

MODE_OUTPUT = "mode_changes"
"""The output whose change marks a unit's mode event (a rope break, a stick/slip switch)."""
_FLOAT = frozenset((float,))
"""The type of driven values sent as they are (``{float} >= set(map(type, values))``)."""


class UnitExchange:
    """The units' inputs and outputs across the FMI boundary (a mixin of the simulation).

    The simulation provides ``scene``, ``run_settings``, ``slaves``, ``drivers``,
    ``events``, ``held``, ``mode_markers``, ``_watches``, ``_watching``, ``_inputs``,
    ``_reads`` and ``_ends``.
    """

    # -- structure -------------------------------------------------------------
    def _build_links(self) -> None:
        self.links_into: dict[str, list[Link]] = defaultdict(list)
        self.source_keys: dict[str, list[str]] = defaultdict(list)
        self.latest: dict[str, float] = {}
        """The newest value of every source output (updated in place, never replaced:
        input plans keep it)."""
        self.histories: dict[str, History] = {}
        """The past values of the source outputs some link extrapolates from."""
        ramped = {b.name for b in self.scene.bonds if b.ramped}
        for c in self.scene.all_connections:
            slave = self.slaves[c.target.unit]
            scheme = c.extrapolation or self.run_settings.extrapolation
            key = str(c.source)
            ramp = "slope" if c.role == RAMP_ROLE else ""
            if c.role == "flow" and c.bond in ramped:
                ramp = "start"
            link = Link(c, key, slave.vr(c.target.variable), scheme, ramp=ramp)
            if link.extrapolated:
                link.history = self.histories.setdefault(key, History())
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
            links = input_order(self.links_into.get(name, ()))
            driven = tuple(self.drivers.targets(name))
            variables = [slave.variables.get(n) for n in driven]
            reals = all(v is not None and v.type == "Real" for v in variables)
            refs = [link.target_vr for link in links]
            if reals:
                refs += [v.valueReference for v in variables]
            evented = name in self.events.units
            self._inputs[name] = InputPlan(
                links, driven, refs, reals, evented, slave.writer(refs), self.latest
            )
            keys, refs = self.source_keys.get(name, []), self.source_vrs.get(name, [])
            mode = self.mode_markers.get(name)
            self._reads[name] = (
                read_plan(name, slave, keys, refs, mode),
                read_plan(name, slave, keys, refs, mode, self._watches),
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

    def watched_snapshots(self, watch: Watch, units: Sequence[str]) -> list[EndValues | list]:
        """:meth:`watched_values` of each of ``units``, kept for later.

        Parameters
        ----------
        watch : Watch
            From :meth:`watch`.
        units : sequence of str
            Instance names of units in the scene.

        Returns
        -------
        list of EndValues or list
            For each unit, in order, its end-of-step read when that holds the
            watched values, else the values read now; :meth:`Watch.unpack
            <.unit_io.Watch.unpack>` gives the values.
        """
        take, slaves, ends = watch.take, self.slaves, self._ends
        return [take(unit, slaves[unit], ends.get(unit)) for unit in units]

    def _set_connected_from_latest(self, unit: str) -> None:
        self._ends.pop(unit, None)
        refs, values = [], []
        for link in self.links_into.get(unit, ()):
            if link.key in self.latest:
                refs.append(link.target_vr)
                values.append(self.latest[link.key])
        self.slaves[unit].set_reals(refs, values)

    def _push(self, unit: str, t: float) -> None:
        self._keep_sources(self.read_sources(unit), t)

    def _keep_sources(self, values: dict[str, float], t: float) -> None:
        """Make ``values`` (source outputs by ``"unit.variable"``) the newest, at ``t`` (s)."""
        self.latest.update(values)
        push_all(self.histories, values, t)

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
        sources: dict[str, float] = {}
        self.add_sources(unit, sources)
        return sources

    def add_sources(self, unit: str, into: dict[str, float]) -> None:
        """Put :meth:`read_sources` of ``unit`` into ``into`` (one update, no new dict).

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        into : dict of str to float
            Source outputs by ``"unit.variable"`` name, updated in place.
        """
        end = self._ends.get(unit)
        if end is not None:  # read once, just after the unit's step
            end.add_sources(into)
            return
        keys = self.source_keys.get(unit, [])
        got = self.slaves[unit].get_reals(self.source_vrs.get(unit, []))
        into.update(zip(keys, got, strict=True))

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
        if plan.constant_keys:  # most links
            values = plan.constant_values(fresh)
            # as many values as targets by construction; strict= costs a keyword parse
            held.update(zip(plan.constant_targets, values))  # noqa: B905
        # each loop only where it has something to go over (an iterator is an object made)
        if plan.positions:  # the unit advances them with the held velocity
            latest = self.latest
            for key, target in plan.positions:
                value = latest[key]
                values.append(value)
                held[target] = value
        if plan.ramps:  # every history holds its latest value from initialisation on
            for source in plan.ramps:
                fresh_value = None if fresh is None else fresh.get(source.key)
                start, slope = ramp(source.history, t, h, source.scheme, fresh_value)
                average = start + 0.5 * slope * h  # what a start input holds over the step
                pair = source.pair
                if pair is not None:  # a bond's flow and its ramp: one of each
                    values.append(start)
                    values.append(slope)
                    held[pair[0]] = average
                    held[pair[1]] = slope
                    continue
                for target in source.starts:
                    values.append(start)
                    held[target] = average
                for target in source.slopes:
                    values.append(slope)
                    held[target] = slope
        if plan.extrapolated:
            for link in plan.extrapolated:
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
            elif _FLOAT.issuperset(map(type, driven)):  # every value a float, no subclass
                values += driven
            else:  # checked as a set by name would, then sent as floats
                slave.typed_values(dict(zip(plan.driven, driven, strict=True)))
                values += [float(v) for v in driven]
        others = None
        if by_name is None and plan.evented:  # the Reals the events set join the batch
            refs, event_values, others = plan.event_inputs(slave, self.events)
            slave.set_reals(refs, values + event_values)
        else:
            plan.write(values)
            if by_name is not None:  # as the events' values override the drivers'
                by_name.update(self.events.values(unit))
        if by_name:
            slave.set_many(by_name)
        if others:
            slave.set_typed(others)

    def step_unit(self, unit: str, t: float, h: float, sources: dict | None = None) -> None:
        """Step one unit (errors propagate as StepRefusedError / UnitFailedError).

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        t, h : float
            Start and length of the macro step, s.
        sources : dict of str to float, optional
            Where to put the unit's source outputs at the step's end, by
            ``"unit.variable"`` (what :meth:`add_sources` puts there, read once).
        """
        self._ends.pop(unit, None)
        slave = self.slaves[unit]
        slave.do_step(t, h)
        plain, watched = self._reads[unit]
        end = self._ends[unit] = (watched if self._watching else plain).read()
        if sources is not None:
            end.add_sources(sources)

    def _mode_mark(self, unit: str) -> float | int:
        """The unit's mode marker now (see ``mode_markers``; from its end-of-step read if valid)."""
        end = self._ends.get(unit)
        if end is not None and end.mode is not None:
            return end.mode
        marker = self.mode_markers[unit]
        return self.slaves[unit].get([marker])[marker]
