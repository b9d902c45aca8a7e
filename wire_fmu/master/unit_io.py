"""What the master sets and reads at each unit per macro step, worked out once.

Per unit and macro step the master makes one batched set of its Real inputs
(connected, driven and set by events) before the step and one batched get per
FMI type after it: the outputs that feed connections, the unit's mode marker
(its Real ``mode_change_time`` where it has one, so that our units are read in
one get of Reals; else its Integer ``mode_changes`` counter) and, at the steps
an observer records, the variables it records. The
value references of all of these are resolved here, once, into plans:

:class:`ReadPlan`
    the value references a unit's end-of-step read asks for, by type, and
    where each output sits in the answer;
:class:`EndValues`
    what that read returned (valid until the unit is set, stepped or
    restored again);
:class:`Watch`
    variables an observer reads at the end of the steps it records: read with
    the unit's end-of-step read when due, else on their own.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from operator import itemgetter
from struct import Struct
from types import MappingProxyType
from typing import Any

import numpy as np

from .extrapolation import History
from .manipulators import ScheduledEvents
from .scene import Connection
from .slave import Slave

__all__ = [
    "EndValues",
    "InputPlan",
    "Link",
    "RampedSource",
    "ReadPlan",
    "Watch",
    "input_order",
    "read_plan",
]

_Place = tuple[str, int]  # (FMI type, position in that type's answer)


@dataclass(slots=True)
class Link:
    """A connection as the master holds it over a step.

    Parameters
    ----------
    connection : Connection
        The scene's connection.
    key : str
        Its source, ``"unit.variable"``.
    target_vr : int
        Value reference of the input it sets.
    scheme : str
        Its extrapolation (``"constant"``, ``"linear"``, ``"quadratic"``).
    history : History or None
        Its source's history (shared by every link from that source), for a link
        that extrapolates (:attr:`extrapolated`); the others take their source's
        newest value.
    ramp : str
        ``"start"`` for a ramped bond's flow link (set to the ramp's value at the step's
        start), ``"slope"`` for its ramp link (set to the slope), ``""`` otherwise
        (see :func:`~wire_fmu.master.extrapolation.ramp`).
    """

    connection: Connection
    key: str
    target_vr: int
    scheme: str
    history: History | None = None
    ramp: str = ""
    target: str = field(init=False)
    """The input it sets, ``"unit.variable"``."""
    position: bool = field(init=False)
    """Whether it is a bond's position link (held at the source's latest value)."""
    constant: bool = field(init=False)
    """Whether it is held ``constant`` (at its source's latest value, or its new one when
    the source has stepped), and is neither a position nor a ramped link."""
    extrapolated: bool = field(init=False)
    """Whether its held value is worked out from its source's past values: neither
    :attr:`constant` nor a position."""

    def __post_init__(self) -> None:
        self.target = str(self.connection.target)
        self.position = self.connection.role == "position"
        self.constant = self.scheme == "constant" and not (self.position or self.ramp)
        self.extrapolated = not (self.constant or self.position)


def _order_group(link: Link) -> int:
    """Where ``link`` goes in a unit's batched set: 0 held constant, 1 a position,
    2 ramped, 3 extrapolated."""
    if link.constant:
        return 0
    if link.position:
        return 1
    return 2 if link.ramp else 3


def input_order(links: Sequence[Link]) -> tuple[Link, ...]:
    """``links`` in the order a unit's batched set takes their values (:class:`InputPlan`).

    The links held constant first, then the positions, then the ramped links with each
    source's start links before its slope links, then the extrapolated ones; within each,
    in their order in ``links``.

    Parameters
    ----------
    links : sequence of Link
        The connections into one unit.

    Returns
    -------
    tuple of Link
    """
    sources: dict[str, int] = {}
    for link in links:
        if link.ramp:
            sources.setdefault(link.key, len(sources))

    def rank(item: tuple[int, Link]) -> tuple[int, int, int, int]:
        i, link = item
        group = _order_group(link)
        if group == 2:
            return group, sources[link.key], link.ramp != "start", i
        return group, 0, 0, i

    return tuple(link for _, link in sorted(enumerate(links), key=rank))


@dataclass(frozen=True)
class RampedSource:
    """The ramped links from one source output (see :func:`.extrapolation.ramp`).

    Parameters
    ----------
    key : str
        The source, ``"unit.variable"``.
    history : History
        Its past values.
    scheme : str
        Its extrapolation.
    starts : tuple of str
        The inputs set to the ramp's value at the step's start (``"unit.variable"``);
        the master holds the ramp's average over the step for them.
    slopes : tuple of str
        The inputs set to the ramp's slope.

    Attributes
    ----------
    pair : (str, str) or None
        The start and the slope input when there is one of each (a bond's flow and ramp
        links, the usual case: set without a loop), else None.
    """

    key: str
    history: History
    scheme: str
    starts: tuple[str, ...]
    slopes: tuple[str, ...]
    pair: tuple[str, str] | None = field(init=False)

    def __post_init__(self) -> None:
        one_each = len(self.starts) == 1 and len(self.slopes) == 1
        object.__setattr__(self, "pair", (self.starts[0], self.slopes[0]) if one_each else None)

    @classmethod
    def of(cls, links: Sequence[Link]) -> RampedSource:
        """The entry of ``links``, all from one source, the start links first."""
        first = links[0]
        if first.history is None:
            raise ValueError(f"ramped link {first.target} has no history")
        return cls(
            first.key,
            first.history,
            first.scheme,
            tuple(link.target for link in links if link.ramp == "start"),
            tuple(link.target for link in links if link.ramp == "slope"),
        )


@dataclass
class InputPlan:
    """What one unit's batched set holds before each step.

    Parameters
    ----------
    links : tuple of Link
        Connections into the unit, in :func:`input_order`.
    driven : tuple of str
        Inputs set by drivers, in the order of
        :meth:`~wire_fmu.master.manipulators.DriverSet.step_values`.
    refs : list of int
        Value references of the links' inputs, then of the driven inputs when
        they are all Reals (:attr:`driven_reals`).
    driven_reals : bool
        Whether every driven input is a Real (else they are set by name, checked).
    evented : bool
        Whether some scheduled event sets an input of the unit.
    write : callable
        The set of :attr:`refs` made ready (:meth:`Slave.writer
        <wire_fmu.master.slave.Slave.writer>`).
    latest : mapping of str to float
        The newest value of every source output by ``"unit.variable"``, kept up to
        date by the master (the same mapping for the whole run).

    Attributes
    ----------
    idle : bool
        Whether nothing sets an input of the unit during the run.
    constant_keys, constant_targets : tuple of str
        Source and target of each link held ``constant`` (:attr:`Link.constant`): set
        from their sources' values without a Python loop.
    positions : tuple of (str, str)
        Source and target of each bond's position link (:attr:`Link.position`): set to
        their sources' latest values.
    ramps : tuple of RampedSource
        The ramped links, one entry per source (its ramp is worked out once).
    extrapolated : tuple of Link
        The other links, each held at its own extrapolation.
    """

    links: tuple[Link, ...]
    driven: tuple[str, ...]
    refs: list[int]
    driven_reals: bool
    evented: bool
    write: Callable[[Sequence[float]], None]
    latest: Mapping[str, float]
    _fired: int = field(default=-1, repr=False)
    _event_refs: list[int] = field(default_factory=list, repr=False)
    _event_values: list[float] = field(default_factory=list, repr=False)
    _event_others: dict[str, tuple[list[int], list[Any]]] = field(default_factory=dict, repr=False)
    idle: bool = field(init=False)
    constant_keys: tuple[str, ...] = field(init=False)
    constant_targets: tuple[str, ...] = field(init=False)
    positions: tuple[tuple[str, str], ...] = field(init=False)
    ramps: tuple[RampedSource, ...] = field(init=False)
    extrapolated: tuple[Link, ...] = field(init=False)

    def __post_init__(self) -> None:
        if self.links != input_order(self.links):
            raise ValueError("an input plan takes its links in input_order()")
        self.idle = not (self.links or self.driven or self.evented)
        constant = [link for link in self.links if link.constant]
        self.constant_keys = tuple(link.key for link in constant)
        self.constant_targets = tuple(link.target for link in constant)
        self.positions = tuple((link.key, link.target) for link in self.links if link.position)
        ramped: dict[str, list[Link]] = {}
        for link in self.links:
            if link.ramp:
                ramped.setdefault(link.key, []).append(link)
        self.ramps = tuple(RampedSource.of(links) for links in ramped.values())
        self.extrapolated = tuple(link for link in self.links if _order_group(link) == 3)

    def constant_values(self, fresh: Mapping[str, float] | None) -> list[float]:
        """The values of the ``constant`` links: their sources' new values where ``fresh``
        has them (the source stepped first), else their latest.

        Parameters
        ----------
        fresh : mapping of str to float, or None
            Source outputs at the step's end by ``"unit.variable"``.
        """
        if fresh:
            values = list(map(fresh.get, self.constant_keys))
            if None not in values:
                return values
            latest = self._latest()  # some sources have not stepped yet
            return [y if v is None else v for v, y in zip(values, latest, strict=True)]
        return self._latest()

    def _latest(self) -> list[float]:
        return list(map(self.latest.__getitem__, self.constant_keys))

    def event_inputs(
        self, slave: Slave, events: ScheduledEvents
    ) -> tuple[list[int], list[float], dict[str, tuple[list[int], list[Any]]]]:
        """The inputs the events so far set, checked once after each event fires.

        Parameters
        ----------
        slave : Slave
            The unit.
        events : ScheduledEvents
            The scene's events.

        Returns
        -------
        refs : list of int
            :attr:`refs` followed by the Reals the events set.
        values : list of float
            The values of those Reals, in their units.
        others : dict of str to (list of int, list of object)
            Inputs of other FMI types the events set, by type.

        Raises
        ------
        UnitFailedError
            For an unknown variable or a value its type cannot take.
        """
        if self._fired != events.fired:
            typed = slave.typed_values(events.values(slave.name))
            event_refs, self._event_values = typed.pop("Real", ([], []))
            self._event_refs = self.refs + event_refs
            self._event_others = typed
            self._fired = events.fired
        return self._event_refs, self._event_values, self._event_others


@dataclass
class Watch:
    """Variables an observer reads after the steps it is due at.

    Parameters
    ----------
    names : mapping of str to sequence of str
        Variable names by unit, in the order :meth:`values` gives them.
    due : callable
        ``due(t)``: whether the observer reads at a step that ends at ``t`` (s).
    """

    names: Mapping[str, Sequence[str]]
    due: Callable[[float], bool]
    places: dict[str, list[_Place]] = field(default_factory=dict, repr=False)
    _pickers: dict[str, tuple[str, Callable | None, bool]] = field(default_factory=dict, repr=False)
    _columns: dict[str, dict[str, tuple[list[int], list[int]]]] = field(
        default_factory=dict, repr=False
    )  # by unit and FMI type: the watched variables' columns and their positions in the read

    def values(self, unit: str, slave: Slave, end: EndValues | None) -> list[Any]:
        """The watched variables of ``unit`` now, in the order of :attr:`names`.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        slave : Slave
            The unit, read directly when ``end`` does not hold the values.
        end : EndValues or None
            What the unit's last end-of-step read returned, if it is still valid.

        Returns
        -------
        list of object
            Each variable's value, in its unit (a String as bytes).
        """
        return self.unpack(unit, self.take(unit, slave, end))

    def take(self, unit: str, slave: Slave, end: EndValues | None) -> EndValues | list[Any]:
        """What :meth:`values` would give, kept as cheaply as possible for :meth:`unpack`.

        Parameters
        ----------
        unit, slave, end
            As for :meth:`values`.

        Returns
        -------
        EndValues or list
            The end-of-step read itself when it holds the watched variables (its
            lists are never changed), else their values read now.
        """
        if end is not None and end.watched and unit in self.places:
            return end
        names = self.names.get(unit, ())
        if not names:
            return []
        got = slave.get(names)
        return [got[n] for n in names]

    def unpack(self, unit: str, taken: EndValues | list[Any]) -> list[Any]:
        """The values of :meth:`values` from what :meth:`take` kept.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        taken : EndValues or list
            What :meth:`take` returned for ``unit``.

        Returns
        -------
        list of object
            Each variable's value, in its unit, in the order of :attr:`names`.
        """
        if type(taken) is list:  # read now, not from the end-of-step read
            return taken
        kind, pick, single = self._pickers[unit]
        if pick is None:  # of several FMI types, or none
            read = {kind: taken.of_kind(kind) for kind in self._columns[unit]}
            return [read[kind][position] for kind, position in self.places[unit]]
        got = pick(taken.of_kind(kind))
        return [got] if single else list(got)

    def unpack_rows(self, unit: str, taken: Sequence[EndValues | list[Any]]) -> np.ndarray:
        """:meth:`unpack` of each of ``taken``, as the rows of one float array.

        When every one is an end-of-step read of one plan, their packed Reals are
        joined and read as one array (no float object is made), their Integers
        stacked as one.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        taken : sequence of EndValues or list
            What :meth:`take` returned for ``unit`` at several steps; every watched
            variable a Real or an Integer.

        Returns
        -------
        numpy.ndarray
            Shape ``(len(taken), len(names[unit]))``: the same numbers as
            :meth:`unpack`, as floats.
        """
        columns = self._columns.get(unit, {})
        if taken and columns and all(type(t) is EndValues for t in taken):
            rows = np.empty((len(taken), len(self.places[unit])))
            for kind, (at, positions) in columns.items():
                read = _stacked(kind, taken)
                if read is None:  # reads of different plans
                    break
                rows[:, at] = read[:, positions]
            else:
                return rows
        return np.array([self.unpack(unit, t) for t in taken], dtype=float)

    def place(self, unit: str, places: list[_Place]) -> None:
        """Say where ``unit``'s watched variables sit in its end-of-step read.

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.
        places : list of (str, int)
            For each watched variable of the unit, in order, its FMI type and its
            position in that type's answer.
        """
        self.places[unit] = places
        kinds = {kind for kind, _ in places}
        positions = [position for _, position in places]
        self._columns[unit] = {
            kind: (
                [i for i, (k, _) in enumerate(places) if k == kind],
                [position for k, position in places if k == kind],
            )
            for kind in kinds
        }
        if len(kinds) == 1:  # all of one type (the usual case): one C call picks them
            self._pickers[unit] = (kinds.pop(), itemgetter(*positions), len(positions) == 1)
        else:
            self._pickers[unit] = ("", None, False)


_NO_OTHERS: Mapping[str, list[Any]] = MappingProxyType({})
"""The values of FMI types other than Real of a read that has only Reals (shared, read-only)."""
_DOUBLE = Struct("d")
"""One native double, as a C double array holds it."""


def _stacked(kind: str, taken: Sequence[EndValues]) -> np.ndarray | None:
    """The values of FMI type ``kind`` of several reads as the rows of one float array.

    None when the reads are not all of the same length (of different plans).
    """
    if kind == "Real":
        if len({len(t.reals) for t in taken}) != 1:
            return None
        joined = np.frombuffer(b"".join([t.reals for t in taken]), dtype=np.float64)
        return joined.reshape(len(taken), -1)
    lists = [t.others[kind] for t in taken]
    if len({len(values) for values in lists}) != 1:
        return None
    return np.array(lists, dtype=float)


@dataclass(frozen=True)
class ReadPlan:
    """What one unit's end-of-step read asks for.

    Parameters
    ----------
    groups : tuple of (str, list of int)
        For each FMI type with something to read, its value references, Real
        first; the Reals start with the unit's source outputs, in order.
    source_keys : tuple of str
        ``"unit.variable"`` names of the unit's source outputs, the first Reals.
    mode : (str, int) or None
        Type and position of the unit's mode marker (its ``mode_change_time``, else
        its ``mode_changes`` counter), if the master watches one.
    watched : bool
        Whether the read includes the watched variables.
    read_reals : callable
        The get of the Reals made ready, answering them packed
        (:meth:`Slave.packed_reader <wire_fmu.master.slave.Slave.packed_reader>`).
    other_readers : tuple of (str, callable)
        For each other FMI type read, the type and its get made ready
        (:meth:`Slave.reader <wire_fmu.master.slave.Slave.reader>`).
    """

    groups: tuple[tuple[str, list[int]], ...]
    source_keys: tuple[str, ...]
    mode: _Place | None
    watched: bool
    read_reals: Callable[[], bytes]
    other_readers: tuple[tuple[str, Callable[[], list[Any]]], ...]
    unpack_sources: Callable[[bytes], tuple[float, ...]] = field(init=False, repr=False)
    """The source outputs from the packed Reals."""

    def __post_init__(self) -> None:
        unpack = Struct(f"{len(self.source_keys)}d").unpack_from
        object.__setattr__(self, "unpack_sources", unpack)

    def read(self) -> EndValues:
        """Read the plan's values from the unit, just stepped: one call per FMI type.

        Returns
        -------
        EndValues
        """
        reals = self.read_reals()
        others = _NO_OTHERS
        if self.other_readers:
            others = {kind: read() for kind, read in self.other_readers}
        mode = None
        if self.mode is not None:
            kind, position = self.mode
            if kind == "Real":
                mode = _DOUBLE.unpack_from(reals, 8 * position)[0]
            else:
                mode = others[kind][position]
        return EndValues(self, reals, others, mode)


class EndValues:
    """What a unit's end-of-step read returned (made for every unit and step).

    Parameters
    ----------
    plan : ReadPlan
        The read's plan.
    reals : bytes
        The Reals, packed as native doubles in the order of the plan's value
        references: the source outputs first, the watched variables after.
    others : mapping of str to list
        The values of each other FMI type read, by type, in the plan's order.
    mode : float, int or None
        The unit's mode marker (``mode_change_time`` or ``mode_changes``), if read.

    Attributes
    ----------
    watched : bool
        Whether the watched variables were read too.
    """

    __slots__ = ("plan", "reals", "others", "mode", "watched")

    def __init__(
        self,
        plan: ReadPlan,
        reals: bytes,
        others: Mapping[str, list[Any]],
        mode: float | int | None,
    ) -> None:
        self.plan = plan
        self.reals = reals
        self.others = others
        self.mode = mode
        self.watched = plan.watched

    def of_kind(self, kind: str) -> Sequence[Any]:
        """The values read of FMI type ``kind``, in the plan's order (Reals as floats)."""
        return memoryview(self.reals).cast("d") if kind == "Real" else self.others[kind]

    def add_sources(self, into: dict[str, float]) -> None:
        """Put the source outputs into ``into``, by ``"unit.variable"`` name, in their units."""
        plan = self.plan
        if plan.source_keys:  # as many values as keys by construction; strict= costs a dict
            into.update(zip(plan.source_keys, plan.unpack_sources(self.reals)))  # noqa: B905


def read_plan(
    unit: str,
    slave: Slave,
    source_keys: Sequence[str],
    source_refs: Sequence[int],
    mode_output: str | None,
    watches: Sequence[Watch] = (),
) -> ReadPlan:
    """The end-of-step read of one unit; the watches learn where their variables sit.

    Parameters
    ----------
    unit : str
        Instance name of the unit in the scene.
    slave : Slave
        The unit.
    source_keys : sequence of str
        ``"unit.variable"`` names of its outputs that feed connections, in order.
    source_refs : sequence of int
        Their value references (Reals), in the same order.
    mode_output : str or None
        Name of the unit's mode-change counter output, if it is read.
    watches : sequence of Watch
        Observers' variables to read too (empty: the plain plan).

    Returns
    -------
    ReadPlan
    """
    groups: dict[str, list[int]] = {"Real": list(source_refs)}
    index: dict[_Place, int] = {}
    for position, ref in enumerate(source_refs):
        index.setdefault(("Real", ref), position)

    def place(name: str) -> _Place:
        var = slave.variables[name]
        key = (var.type, var.valueReference)
        if key not in index:
            refs = groups.setdefault(var.type, [])
            index[key] = len(refs)
            refs.append(var.valueReference)
        return var.type, index[key]

    mode = None if mode_output is None else place(mode_output)
    for watch in watches:
        watch.place(unit, [place(name) for name in watch.names.get(unit, ())])
    kept = tuple((kind, refs) for kind, refs in groups.items() if refs)
    others = tuple((kind, slave.reader(kind, refs)) for kind, refs in kept if kind != "Real")
    read_reals = slave.packed_reader(groups["Real"])
    return ReadPlan(kept, tuple(source_keys), mode, bool(watches), read_reals, others)
