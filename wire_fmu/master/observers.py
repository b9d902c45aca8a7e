"""Observers: they read the simulation and never change it.

:class:`CsvRecorder`
    streams the recorded variables to ``timeseries.csv`` as the run goes
    (one row per output interval, written out at least every
    :data:`FLUSH_EVERY` seconds of wall-clock time and at the end, also after
    a failure or Ctrl-C, so a crash of the process keeps all but the last
    fraction of a second), with energy channels: each bond's
    accumulated energy residual (energy its coupling created), the energy it
    carried, its power, and the sum of the units' ledger residuals.
    :func:`~wire_fmu.master.results_frame.read_results_frame` reads it as a
    pandas DataFrame with units, fmpy with ``fmpy.util.read_csv``.
    ``metadata.json`` beside it gives the unit of every column
    (``column_units``, see :mod:`~wire_fmu.master.column_units`), the units'
    variables with their units and descriptions, the settings, the scene's
    units with their parameter values, events, drivers and plots
    (:mod:`~wire_fmu.master.run_record`) and, at the end, the summary
    (status, per-unit call counts and time).
:class:`Progress`
    a progress bar on stderr with the time left: one line redrawn in place on a
    terminal, plain lines (a tenth of the run each) when redirected.
"""

from __future__ import annotations

import csv
import json
import logging
import math
import sys
import time
from operator import attrgetter
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from .column_units import (
    BOND_CHANNEL_UNITS,
    LEDGER_UNIT,
    TIME_UNIT,
    ledger_unit_problems,
    variable_unit,
)
from .results_text import number_lines
from .run_record import scene_record

if TYPE_CHECKING:
    from .run_result import RunResult
    from .simulation import Simulation

__all__ = [
    "Observer",
    "CsvRecorder",
    "Progress",
    "summary_rows",
    "BOND_CHANNELS",
    "LEDGER_CHANNEL",
    "LEDGER_TERMS",
]

logger = logging.getLogger(__name__)

BOND_CHANNELS = ("energy_residual", "energy_carried", "power")
"""Per bond ``bond.<name>.<channel>``: energy its coupling created (J), energy it carried (J),
power it transmitted (W)."""

LEDGER_TERMS = ("stored_energy", "dissipated_energy", "external_work", "energy_balance")
"""A unit's energy ledger, its outputs in J: recorded for every unit that keeps one
(``energy_balance`` = change of ``stored_energy`` + ``dissipated_energy`` −
``external_work``)."""

LEDGER_CHANNEL = "energy.units_balance"
"""Sum of the units' ``energy_balance`` outputs, J (each unit's own ledger)."""

_WHOLE_NUMBERS = ("Integer", "Enumeration")
"""FMI types whose values the file writes as their digits."""
_CREATED, _CARRIED = attrgetter("created"), attrgetter("carried")
"""A bond's energy created and carried so far (:class:`~.energy_guard.BondEnergy`)."""
_clock = time.perf_counter

FLUSH_EVERY = 0.1
"""Longest wall-clock time recorded rows wait before they are written to the file, s.

Rows are formatted and written in batches: a row's formatting and its write to
the file cost more than a macro step of the master when done one at a time."""


class Observer(Protocol):
    """Reads the simulation; never changes it.

    An observer that reads unit variables after steps asks, in ``on_start``, for
    them to be read with the units' own end-of-step reads
    (:meth:`~wire_fmu.master.simulation.Simulation.watch`): no FMI call of its own.
    """

    def on_start(self, sim: Simulation) -> None:
        """Called after initialisation, at the start time.

        Parameters
        ----------
        sim : Simulation
            The simulation, initialised; read it, never change it.
        """

    def on_step(self, sim: Simulation) -> None:
        """Called after every accepted macro step.

        Parameters
        ----------
        sim : Simulation
            The simulation at the end of the step (``sim.time``, s).
        """

    def on_end(self, sim: Simulation, result: RunResult) -> None:
        """Called once at the end, also after a failure or an interruption.

        Parameters
        ----------
        sim : Simulation
            The simulation where it ended.
        result : RunResult
            How it ended.
        """


class CsvRecorder:
    """Write recorded variables and energy channels to ``directory``.

    Parameters
    ----------
    directory : Path
        Results folder (created).
    interval : float or None
        Record every ``interval`` seconds (at the first step at or after
        each multiple); None records every accepted step.
    flush_every : float
        Longest wall-clock time a recorded row waits before it is written to
        the file, s (0: every row at once).
    """

    def __init__(
        self, directory: Path, interval: float | None = None, flush_every: float = FLUSH_EVERY
    ) -> None:
        self.directory = Path(directory)
        self.interval = interval
        self.flush_every = flush_every
        self.csv_path = self.directory / "timeseries.csv"
        self.meta_path = self.directory / "metadata.json"
        self._file = None
        self._writer = None
        self._next = 0.0  # the next output time, s
        self._due_from = -math.inf  # a step ending at or after this time is recorded, s
        self._rows: list[tuple] = []  # recorded, not yet written (see _row)
        self._written = -math.inf  # wall-clock time of the last write, s
        self.columns: list[str] = []
        self.units: dict[str, str] = {}
        """Unit of each column, by column (see :mod:`~wire_fmu.master.column_units`)."""
        self.stepping_seconds = 0.0
        """Wall-clock time spent recording rows (and writing them) between steps, s."""

    # -- observer protocol -----------------------------------------------------
    def on_start(self, sim: Simulation) -> None:
        """Open the file, write the header and the initial row.

        Parameters as in :meth:`Observer.on_start`.
        """
        self.directory.mkdir(parents=True, exist_ok=True)
        self._plan = self._recorded(sim)
        self.columns = ["time"] + [f"{u}.{n}" for u, names in self._plan.items() for n in names]
        self.columns += [
            f"bond.{b}.{channel}" for channel in BOND_CHANNELS for b in sim.energy.bonds
        ]
        self._ledger_units = [u for u, s in sim.slaves.items() if "energy_balance" in s.variables]
        if self._ledger_units:
            self.columns.append(LEDGER_CHANNEL)
        self._ledger_at = {u: self._plan[u].index("energy_balance") for u in self._ledger_units}
        self._read_units = [u for u, names in self._plan.items() if names]
        self._ledger_of = [self._ledger_at.get(u) for u in self._read_units]
        kinds = [sim.slaves[u].variables[n].type for u, names in self._plan.items() for n in names]
        self._converted = [i + 1 for i, kind in enumerate(kinds) if kind in ("String", "Boolean")]
        self._integers = [i + 1 for i, kind in enumerate(kinds) if kind in _WHOLE_NUMBERS]
        self.units = self._column_units(sim)
        self._watch = sim.watch(self._plan, self._due)
        self._bond_names = list(sim.energy.bonds)
        self._bonds = list(sim.energy.bonds.values())
        self._file = self.csv_path.open("w", newline="")
        self._writer = csv.writer(self._file)
        self._writer.writerow(self.columns)
        self._write_metadata(sim, None)
        self._row(sim)

    def on_step(self, sim: Simulation) -> None:
        """Record when the next output time is reached.

        Parameters as in :meth:`Observer.on_step`.
        """
        if sim.time >= self._due_from:  # self._due(sim.time), after every step
            started = _clock()
            self._row(sim)
            self.stepping_seconds += _clock() - started

    def _due(self, t: float) -> bool:
        """Whether a row is recorded after a step ending at ``t`` (s)."""
        return t >= self._due_from

    def on_end(self, sim: Simulation, result: RunResult) -> None:
        """Close the file and write the summary into the metadata (also after a failure).

        Parameters as in :meth:`Observer.on_end`.
        """
        if self._file is not None:
            try:
                self._write_rows()
            finally:
                self._file.close()
                self._file = None
        self.directory.mkdir(parents=True, exist_ok=True)
        self._write_metadata(sim, result)

    # -- internals ---------------------------------------------------------------
    @staticmethod
    def _recorded(sim: Simulation) -> dict[str, list[str]]:
        plan: dict[str, list[str]] = {name: [] for name in sim.slaves}
        wanted = sim.scene.outputs
        if wanted is None:
            for name, slave in sim.slaves.items():
                plan[name] = [
                    v.name
                    for v in slave.model_description.modelVariables
                    if v.causality == "output"
                ]
        else:
            for ref in wanted:
                plan[ref.unit].append(ref.variable)
        for plot in sim.scene.plots:
            for ref in plot.variables:
                if ref.variable not in plan[ref.unit]:
                    plan[ref.unit].append(ref.variable)
        for name, slave in sim.slaves.items():  # every unit's whole energy ledger, if it keeps one
            if "energy_balance" in slave.variables:
                for term in LEDGER_TERMS:
                    if term in slave.variables and term not in plan[name]:
                        plan[name].append(term)
        return plan

    def _column_units(self, sim: Simulation) -> dict[str, str]:
        """Unit of each column: the unit variables' as their FMUs declare them, the master's own."""
        units = {"time": TIME_UNIT}
        for unit, names in self._plan.items():
            variables = sim.slaves[unit].variables
            units.update({f"{unit}.{n}": variable_unit(variables[n]) for n in names})
        for channel in BOND_CHANNELS:
            units.update(
                {f"bond.{b}.{channel}": BOND_CHANNEL_UNITS[channel] for b in sim.energy.bonds}
            )
        if self._ledger_units:
            units[LEDGER_CHANNEL] = LEDGER_UNIT
            ledgers = {u: sim.slaves[u].variables["energy_balance"] for u in self._ledger_units}
            for problem in ledger_unit_problems(ledgers):
                logger.warning(problem)
        return units

    def _row(self, sim: Simulation) -> None:
        """Record a row; it is put together and written with the next batch (:meth:`_write_rows`).

        What a row needs is kept as it is now: the units' end-of-step reads (never
        changed once made) and the bonds' energies (which change with every step).
        """
        taken = sim.watched_snapshots(self._watch, self._read_units)
        bonds = self._bonds
        cells = [  # the bonds' channels, in BOND_CHANNELS order
            *map(_CREATED, bonds),
            *map(_CARRIED, bonds),
            *map(sim.bond_power.__getitem__, self._bond_names),
        ]
        self._rows.append((sim.time, taken, cells))
        if _clock() - self._written >= self.flush_every:
            self._write_rows()
        if self.interval is not None:
            # the first multiple of the interval after now (in one step, however small the
            # interval: a loop adding it could run for ever once it is below the round-off)
            # (max() written out: the builtin parses keywords, a cost every row)
            now = sim.time
            reached = math.floor((now + 1e-9 * (now if now > 1.0 else 1.0)) / self.interval)
            following = (reached + 1) * self.interval
            if following > self._next:
                self._next = following
            self._due_from = self._next - 1e-9 * (self._next if self._next > 1.0 else 1.0)

    def _values(self, row: tuple) -> list[Any]:
        """The cells of a recorded row: time, recorded variables, bond channels, ledger."""
        t, taken, bond_cells = row
        values: list[Any] = [t]
        ledger = 0.0
        unpack = self._watch.unpack
        for unit, at, kept in zip(self._read_units, self._ledger_of, taken, strict=True):
            got = unpack(unit, kept)
            values += got
            if at is not None:
                ledger += float(got[at])
        values += bond_cells
        if self._ledger_units:
            values.append(ledger)
        for i in self._converted:  # text and booleans as the file shows them
            values[i] = _cell(values[i])
        return values

    def _block(self, rows: list[tuple]) -> np.ndarray:
        """The cells of recorded rows as one float array, a row each (no text or booleans).

        Column by column, as :meth:`_values` gives them row by row: the same
        numbers (an Integer's as a float), the units' ledgers summed in the same order.
        """
        unpack_rows = self._watch.unpack_rows
        columns = [np.array([row[0] for row in rows])[:, None]]
        ledger = np.zeros(len(rows))
        for i, (unit, at) in enumerate(zip(self._read_units, self._ledger_of, strict=True)):
            values = unpack_rows(unit, [row[1][i] for row in rows])
            columns.append(values)
            if at is not None:
                ledger += values[:, at]
        columns.append(np.array([row[2] for row in rows], dtype=float).reshape(len(rows), -1))
        if self._ledger_units:
            columns.append(ledger[:, None])
        return np.hstack(columns)

    def _number_cells(self, rows: list[tuple]) -> np.ndarray | list[list[float | int]]:
        """The cells of rows of numbers: an array, or lists when an Integer is written as one."""
        block = self._block(rows)
        if not self._integers:
            return block
        cells = block.tolist()
        for i in self._integers:
            for row in cells:
                row[i] = int(row[i])
        return cells

    def _write_rows(self) -> None:
        """Write the rows recorded since the last write and flush the file.

        Rows of numbers only (no cell of theirs needs quoting) are written by
        :func:`number_lines`, put together as one array; rows with text or booleans
        go through the csv module.
        """
        rows, self._rows = self._rows, []
        if rows and self._converted:
            self._writer.writerows([self._values(row) for row in rows])
        elif rows:
            self._file.write(number_lines(self._number_cells(rows)))
        self._file.flush()
        self._written = time.perf_counter()

    def _write_metadata(self, sim: Simulation, result: RunResult | None) -> None:
        variables = {}
        for unit, slave in sim.slaves.items():
            for v in slave.model_description.modelVariables:
                variables[f"{unit}.{v.name}"] = {
                    "unit": variable_unit(v),
                    "description": v.description or "",
                    "causality": v.causality,
                }
        descriptions = {unit: slave.model_description for unit, slave in sim.slaves.items()}
        meta = {
            "scene": sim.scene.name,
            "description": sim.scene.description,
            "run": {k: getattr(sim.run_settings, k) for k in sim.run_settings.__dataclass_fields__},
            "order": sim.algorithm.order,
            "columns": self.columns,
            "column_units": self.units,
            "variables": variables,
            **scene_record(sim.scene, descriptions),
        }
        if result is not None:
            meta["result"] = {
                **result.summary(),
                "rejected_steps": result.rejected,
                "synchronised_steps": result.synchronised,
                "sweeps": result.iterations,
                "bond_energy_residual": result.bond_residual,
                "bond_energy_carried": result.bond_carried,
                "bond_energy_error": result.bond_error,
                "units": {
                    u: {"calls": dict(s.calls), "seconds": dict(s.seconds)}
                    for u, s in sim.slaves.items()
                },
            }
        meta["run"]["order"] = list(meta["run"]["order"])
        self.meta_path.write_text(json.dumps(meta, indent=2, default=str) + "\n")


def _cell(value: Any) -> Any:
    if isinstance(value, bytes):  # fmpy reads a String variable as bytes
        return value.decode("utf-8", "replace")
    if isinstance(value, bool):
        return int(value)
    if isinstance(value, float):
        return repr(value)
    return value


class Progress:
    """A progress bar on a stream (stderr by default): done, simulated time, speed, time left.

    On a terminal the bar is one line redrawn in place (carriage return) at most
    every ``every`` seconds. On anything else (a file, a pipe, a CI log) it
    writes plain lines, one as each tenth of the run is done and one at the end,
    so that a redirected log holds readable lines and no carriage returns.

    Parameters
    ----------
    stream : text stream, optional
        Where to write (default ``sys.stderr``).
    width : int
        Characters of the bar.
    every : float
        Shortest wall-clock time between redraws on a terminal, s.
    """

    def __init__(self, stream=None, width: int = 30, every: float = 0.2) -> None:
        self.stream = stream or sys.stderr
        self.width = width
        self.every = every
        self._last = 0.0
        self._start = 0.0
        self._tenths = 0  # tenths of the run written as plain lines so far
        self._terminal = _is_terminal(self.stream)

    def on_start(self, sim: Simulation) -> None:
        """Start the clock.

        Parameters as in :meth:`Observer.on_start`.
        """
        self._start = time.perf_counter()
        self._last = 0.0
        self._tenths = 0

    def on_step(self, sim: Simulation) -> None:
        """Redraw (terminal) at most every ``every`` seconds, or write a line per tenth done.

        Parameters as in :meth:`Observer.on_step`.
        """
        now = time.perf_counter()
        if self._terminal:
            if now - self._last >= self.every:
                self._last = now
                self._write("\r" + self._text(sim, now))
            return
        tenths = int(10 * _done(sim) + 1e-9)
        if tenths > self._tenths and tenths < 10:  # the end is written by on_end
            self._tenths = tenths
            self._write(self._text(sim, now) + "\n")

    def on_end(self, sim: Simulation, result: RunResult) -> None:
        """Final state of the bar, ended by a new line.

        Parameters as in :meth:`Observer.on_end`.
        """
        text = self._text(sim, time.perf_counter())
        self._write(("\r" if self._terminal else "") + text + "\n")

    def _write(self, text: str) -> None:
        self.stream.write(text)
        self.stream.flush()

    def _text(self, sim: Simulation, now: float) -> str:
        """The bar: scene, bar, per cent, simulated time, real-time factor, time left."""
        done = _done(sim)
        bar = "#" * int(done * self.width)
        elapsed = now - self._start
        rtf = sim.time / elapsed if elapsed > 0 else 0.0
        return (
            f"{sim.scene.name}: [{bar:<{self.width}}] {100 * done:5.1f} % "
            f"t = {sim.time:8.3f} s  {rtf:6.2f}x real time  {_time_left(done, elapsed)}"
        )


def _done(sim: Simulation) -> float:
    """Fraction of the run done, 0 to 1."""
    stop = sim.run_settings.stop_time
    return min(1.0, max(0.0, sim.time / stop)) if stop else 1.0


def _time_left(done: float, elapsed: float) -> str:
    """Wall-clock time left at the speed so far (``left 1 min 05 s``); unknown before 1 %."""
    if done >= 1.0:
        return f"took {_duration(elapsed)}"
    if done < 0.01 or elapsed <= 0.0:
        return "left --"
    return f"left {_duration(elapsed * (1.0 - done) / done)}"


def _duration(seconds: float) -> str:
    """A wall-clock duration for people: ``42 s``, ``3 min 05 s``, ``1 h 02 min``."""
    seconds = max(0.0, seconds)
    if seconds < 60.0:
        return f"{seconds:.0f} s" if seconds >= 9.5 else f"{seconds:.1f} s"
    minutes, secs = divmod(int(round(seconds)), 60)
    if minutes < 60:
        return f"{minutes} min {secs:02d} s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes:02d} min"


def _is_terminal(stream: Any) -> bool:
    """Whether ``stream`` is a terminal (a stream without ``isatty`` is taken as none)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def summary_rows(sim: Simulation, result: RunResult) -> list[tuple[str, str]]:
    """Key figures of a finished run, for a summary table.

    Parameters
    ----------
    sim : Simulation
        The simulation that ran.
    result : RunResult
        How it ended.

    Returns
    -------
    list of (str, str)
        Label and text of each figure: status, times, steps, each bond's energy
        residual, each unit's FMI calls.
    """
    rows = [
        ("status", result.status),
        ("simulated", f"{result.end_time:.6g} s"),
        ("wall time", f"{result.wall_time:.3g} s"),
        (
            "real-time factor",
            f"{result.end_time / result.wall_time:.3g}" if result.wall_time else "-",
        ),
        (
            "macro steps",
            f"{result.steps} accepted, {result.rejected} rejected, {result.iterations} sweeps",
        ),
    ]
    for name, value in result.bond_residual.items():
        error, carried = result.bond_error.get(name, 0.0), result.bond_carried.get(name, 0.0)
        rows.append(
            (
                f"bond {name} energy residual",
                f"{value:+.4g} J net, {error:.4g} J created or destroyed, "
                f"of {carried:.4g} J carried",
            )
        )
    for unit, slave in sim.slaves.items():
        steps = slave.calls.get("doStep", 0)
        secs = sum(slave.seconds.values())
        rows.append(
            (f"unit {unit}", f"{steps} doStep, {sum(slave.calls.values())} FMI calls, {secs:.3g} s")
        )
    return rows
