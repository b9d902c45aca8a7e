"""Observers: they read the simulation and never change it.

:class:`CsvRecorder`
    streams the recorded variables to ``timeseries.csv`` as the run goes
    (one row per output interval, flushed every row, so a crash or Ctrl-C
    keeps everything up to that point), with energy channels: each bond's
    accumulated energy residual (energy its coupling created), the energy it
    carried, its power, and the sum of the units' ledger residuals.
    pandas reads it with ``pandas.read_csv``, fmpy with ``fmpy.util.read_csv``.
    ``metadata.json`` beside it gives units, descriptions, settings and, at
    the end, the summary (status, per-unit call counts and time).
:class:`Progress`
    a one-line progress bar on stderr.
"""

from __future__ import annotations

import csv
import json
import logging
import math
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

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
]

logger = logging.getLogger(__name__)

BOND_CHANNELS = ("energy_residual", "energy_carried", "power")
"""Per bond ``bond.<name>.<channel>``: energy its coupling created (J), energy it carried (J),
power it transmitted (W)."""

LEDGER_CHANNEL = "energy.units_balance"
"""Sum of the units' ``energy_balance`` outputs, J (each unit's own ledger)."""


class Observer(Protocol):
    """Reads the simulation; never changes it."""

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
    """

    def __init__(self, directory: Path, interval: float | None = None) -> None:
        self.directory = Path(directory)
        self.interval = interval
        self.csv_path = self.directory / "timeseries.csv"
        self.meta_path = self.directory / "metadata.json"
        self._file = None
        self._writer = None
        self._next = 0.0
        self.columns: list[str] = []

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
        self._file = self.csv_path.open("w", newline="")
        self._writer = csv.writer(self._file)
        self._writer.writerow(self.columns)
        self._write_metadata(sim, None)
        self._row(sim)

    def on_step(self, sim: Simulation) -> None:
        """Record when the next output time is reached.

        Parameters as in :meth:`Observer.on_step`.
        """
        if self.interval is None or sim.time >= self._next - 1e-9 * max(1.0, self._next):
            self._row(sim)

    def on_end(self, sim: Simulation, result: RunResult) -> None:
        """Close the file and write the summary into the metadata (also after a failure).

        Parameters as in :meth:`Observer.on_end`.
        """
        if self._file is not None:
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
        for name, slave in sim.slaves.items():
            if "energy_balance" in slave.variables and "energy_balance" not in plan[name]:
                plan[name].append("energy_balance")
        return plan

    def _row(self, sim: Simulation) -> None:
        values: list[Any] = [sim.time]
        ledger = 0.0
        for unit, names in self._plan.items():
            got = sim.slaves[unit].get(names) if names else {}
            values += [got[n] for n in names]
            if unit in self._ledger_units:
                ledger += float(got["energy_balance"])
        bonds = sim.energy.bonds
        values += [bond.created for bond in bonds.values()]
        values += [bond.carried for bond in bonds.values()]
        values += [sim.bond_power[b] for b in bonds]
        if self._ledger_units:
            values.append(ledger)
        self._writer.writerow([_cell(v) for v in values])
        self._file.flush()
        if self.interval is not None:
            # the first multiple of the interval after now (in one step, however small the
            # interval: a loop adding it could run for ever once it is below the round-off)
            reached = math.floor((sim.time + 1e-9 * max(1.0, sim.time)) / self.interval)
            self._next = max(self._next, (reached + 1) * self.interval)

    def _write_metadata(self, sim: Simulation, result: RunResult | None) -> None:
        variables = {}
        for unit, slave in sim.slaves.items():
            for v in slave.model_description.modelVariables:
                variables[f"{unit}.{v.name}"] = {
                    "unit": v.unit or "",
                    "description": v.description or "",
                    "causality": v.causality,
                }
        meta = {
            "scene": sim.scene.name,
            "description": sim.scene.description,
            "run": {k: getattr(sim.run_settings, k) for k in sim.run_settings.__dataclass_fields__},
            "order": sim.algorithm.order,
            "columns": self.columns,
            "variables": variables,
        }
        if result is not None:
            meta["result"] = {
                "status": result.status,
                "message": result.message,
                "end_time": result.end_time,
                "wall_time": result.wall_time,
                "real_time_factor": result.end_time / result.wall_time
                if result.wall_time
                else None,
                "steps": result.steps,
                "rejected_steps": result.rejected,
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
    """A one-line progress bar on a stream (stderr by default)."""

    def __init__(self, stream=None, width: int = 30, every: float = 0.2) -> None:
        self.stream = stream or sys.stderr
        self.width = width
        self.every = every
        self._last = 0.0
        self._start = 0.0

    def on_start(self, sim: Simulation) -> None:
        """Start the clock.

        Parameters as in :meth:`Observer.on_start`.
        """
        self._start = time.perf_counter()

    def on_step(self, sim: Simulation) -> None:
        """Redraw at most every ``every`` seconds.

        Parameters as in :meth:`Observer.on_step`.
        """
        now = time.perf_counter()
        if now - self._last >= self.every:
            self._last = now
            self._draw(sim, now)

    def on_end(self, sim: Simulation, result: RunResult) -> None:
        """Final state of the bar.

        Parameters as in :meth:`Observer.on_end`.
        """
        self._draw(sim, time.perf_counter())
        self.stream.write("\n")
        self.stream.flush()

    def _draw(self, sim: Simulation, now: float) -> None:
        stop = sim.run_settings.stop_time
        done = min(1.0, sim.time / stop) if stop else 1.0
        bar = "#" * int(done * self.width)
        elapsed = now - self._start
        rtf = sim.time / elapsed if elapsed > 0 else 0.0
        self.stream.write(
            f"\r{sim.scene.name}: [{bar:<{self.width}}] {100 * done:5.1f} % "
            f"t = {sim.time:8.3f} s  {rtf:6.2f}x real time"
        )
        self.stream.flush()


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
