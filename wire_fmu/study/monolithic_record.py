"""What a monolithic run records, and how: a normal run's columns that one ODE can give honestly.

A co-simulated run records the scene's outputs (every unit's outputs when it
names none), its plotted variables, each unit's energy ledger (``energy_balance``
and its terms), three channels per bond and the sum of the units' ledgers
(:class:`~wire_fmu.master.observers.CsvRecorder`). A monolithic run records
the same columns, under the same names and in the same units (read from the
units' model descriptions), except those that have no counterpart in one ODE;
these are left out and named, with the reason, in ``metadata.json``
(``omitted_columns``):

``bond.<name>.energy_residual``
    Energy the co-simulation's held values created or destroyed. One ODE
    couples the units exactly at every evaluation: there is no such energy.
``bond.<name>.energy_carried``
    The integral of ``|power|`` over the macro steps. The monolithic run sees
    the power only at its output times, and a sum over those would be another
    quantity under the same name.
:data:`PER_STEP_OUTPUTS`
    Unit outputs that count or summarise the unit's own communication steps
    and solver (the machine unit's cycle statistics and solver counters): one
    ODE has neither.

``bond.<name>.power`` is recorded: the effort times the flow at the output
instant (W), the limit of the co-simulation's held effort times mean flow.

:class:`Recorder` streams the rows to ``timeseries.csv`` in batches (at least
every :data:`~wire_fmu.master.observers.FLUSH_EVERY` seconds of wall-clock
time, and at the end whatever happened) and writes ``metadata.json`` at the
start and, with the result, at the end.
"""

from __future__ import annotations

import csv
import json
import logging
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import IO, Any

import numpy as np

from wire_fmu.master.column_units import (
    BOND_CHANNEL_UNITS,
    LEDGER_UNIT,
    TIME_UNIT,
    ledger_unit_problems,
    variable_unit,
)
from wire_fmu.master.observers import BOND_CHANNELS, FLUSH_EVERY, LEDGER_CHANNEL, LEDGER_TERMS
from wire_fmu.master.results_text import number_lines
from wire_fmu.master.run_record import scene_record
from wire_fmu.master.run_result import RunResult
from wire_fmu.master.scene import Scene, VarRef
from wire_fmu.master.validate import Structure

from .monolithic import MonolithicModel

__all__ = [
    "PER_STEP_OUTPUTS",
    "ColumnPlan",
    "Recorder",
    "plan_columns",
    "record_interval",
    "run_metadata",
]

logger = logging.getLogger(__name__)

LEDGER = "energy_balance"
"""The unit output every unit's ledger residual is in (J)."""

_NO_STEPS = "counts the unit's own communication steps or solver, which one ODE does not have"
PER_STEP_OUTPUTS: Mapping[str, Mapping[str, str]] = MappingProxyType(
    {
        "MachineUnit": MappingProxyType(
            {
                **{
                    f"cycle.{name}": "a per-revolution statistic over the unit's communication "
                    "points, which one ODE does not have (the unit would leave it at 0)"
                    for name in ("count", "period", "omega_mean", "omega_max", "omega_min", "delta")
                },
                "solver.evaluations": _NO_STEPS,
                "solver.steps": _NO_STEPS,
            }
        ),
    }
)
"""Outputs a monolithic run cannot give, by FMU model name and output, with the reason."""

_RESIDUAL = (
    "the units are coupled exactly at every evaluation of one ODE: no coupling creates or "
    "destroys energy, so the co-simulation's residual has no counterpart"
)
_CARRIED = (
    "the integral of |power| over macro steps; the monolithic run sees the power only at its "
    "output times (recorded as bond.{name}.power), so it is left out rather than estimated"
)
_BOND_OMITTED = MappingProxyType({"energy_residual": _RESIDUAL, "energy_carried": _CARRIED})
"""Why each bond channel but the power is left out, by channel (``{name}``: the bond)."""


@dataclass(frozen=True)
class ColumnPlan:
    """The columns of a monolithic run and what each row reads.

    Attributes
    ----------
    columns : list of str
        The header: ``time``, the unit variables, the bonds' power, the ledger sum.
    units : dict of str to str
        Unit of each column (as a normal run's ``column_units``).
    recorded : list of VarRef
        The unit variables recorded, in column order.
    reads : list of VarRef
        Every unit variable a row reads: the recorded ones, then the bonds' efforts
        and flows not among them.
    kinds : list of type
        The core type of each of ``reads`` (float, int, bool or str).
    bonds : list of (str, VarRef, VarRef)
        Each bond's name, effort source and flow source.
    ledgers : list of VarRef
        The ``energy_balance`` outputs summed into :data:`LEDGER_CHANNEL`.
    omitted : dict of str to str
        Columns a normal run records that this one does not, with the reason.
    """

    columns: list[str]
    units: dict[str, str]
    recorded: list[VarRef]
    reads: list[VarRef]
    kinds: list[type]
    bonds: list[tuple[str, VarRef, VarRef]] = field(default_factory=list)
    ledgers: list[VarRef] = field(default_factory=list)
    omitted: dict[str, str] = field(default_factory=dict)

    @property
    def texts(self) -> bool:
        """Whether a recorded variable is text (its rows go through the csv module)."""
        return str in self.kinds

    def row(self, model: MonolithicModel, t: float, x: np.ndarray) -> list[Any]:
        """The cells of one row at state ``x``.

        Parameters
        ----------
        model : MonolithicModel
            The scene as one ODE.
        t : float
            Time, s.
        x : ndarray
            Joint state at ``t``.

        Returns
        -------
        list
            ``t`` (s), each recorded variable in its unit, each bond's power (W) and
            the ledger sum (J); whole numbers and flags as ints, text as str.
        """
        floats = [r for r, kind in zip(self.reads, self.kinds, strict=True) if kind is float]
        got = dict(zip(floats, model.outputs(t, x, floats), strict=True))  # sets every value
        for ref, kind in zip(self.reads, self.kinds, strict=True):
            if kind is not float:
                value = model.units[ref.unit].values[ref.variable]
                got[ref] = value if kind is str else int(value)
        cells: list[Any] = [float(t)] + [got[r] for r in self.recorded]
        cells += [got[effort] * got[flow] for _, effort, flow in self.bonds]
        if self.ledgers:
            cells.append(sum(got[r] for r in self.ledgers))
        return cells


def _planned(scene: Scene, structure: Structure) -> dict[str, list[str]]:
    """The variables a normal run records, by unit, in its order (as ``CsvRecorder``)."""
    plan: dict[str, list[str]] = {name: [] for name in scene.units}
    if scene.outputs is None:
        for name in scene.units:
            md = structure.descriptions[name]
            plan[name] = [v.name for v in md.modelVariables if v.causality == "output"]
    else:
        for ref in scene.outputs:
            plan[ref.unit].append(ref.variable)
    for plot in scene.plots:
        for ref in plot.variables:
            if ref.variable not in plan[ref.unit]:
                plan[ref.unit].append(ref.variable)
    for name in scene.units:  # every unit's whole energy ledger, if it keeps one
        if structure.variable(VarRef(name, LEDGER)) is None:
            continue
        for term in LEDGER_TERMS:
            if structure.variable(VarRef(name, term)) is not None and term not in plan[name]:
                plan[name].append(term)
    return plan


def _core_kind(model: MonolithicModel, ref: VarRef) -> type:
    """The declared type of a unit variable in its core class."""
    for variable in model.units[ref.unit].VARIABLES:
        if variable.name == ref.variable:
            return variable.type
    raise KeyError(f"unit {ref.unit!r} declares no variable {ref.variable!r}")


def plan_columns(scene: Scene, structure: Structure, model: MonolithicModel) -> ColumnPlan:
    """The columns of a monolithic run of ``scene``: a normal run's, less what one ODE lacks.

    Parameters
    ----------
    scene : Scene
        The scene, validated.
    structure : Structure
        Its units' model descriptions (the units of the columns).
    model : MonolithicModel
        The scene as one ODE (the types of the variables).

    Returns
    -------
    ColumnPlan
        Columns, their units, what each row reads, and the omitted columns with reasons.
    """
    omitted: dict[str, str] = {}
    recorded: list[VarRef] = []
    for unit, names in _planned(scene, structure).items():
        per_step = PER_STEP_OUTPUTS.get(scene.units[unit].fmu, {})
        for name in names:
            if name in per_step:
                omitted[f"{unit}.{name}"] = per_step[name]
            else:
                recorded.append(VarRef(unit, name))
    bonds = [(b.name, b.effort.source, b.flow.source) for b in scene.bonds]
    for channel in BOND_CHANNELS:
        if channel != "power":
            reason = _BOND_OMITTED.get(channel, "not computed by a monolithic run")
            omitted.update({f"bond.{n}.{channel}": reason.format(name=n) for n, _, _ in bonds})
    ledgers = [r for r in recorded if r.variable == LEDGER]
    reads = list(recorded)
    reads += [r for _, e, f in bonds for r in (e, f) if r not in reads]
    columns = ["time"] + [str(r) for r in recorded] + [f"bond.{b}.power" for b, _, _ in bonds]
    units = {"time": TIME_UNIT}
    units.update({str(r): variable_unit(structure.variable(r)) for r in recorded})
    units.update({f"bond.{b}.power": BOND_CHANNEL_UNITS["power"] for b, _, _ in bonds})
    if ledgers:
        columns.append(LEDGER_CHANNEL)
        units[LEDGER_CHANNEL] = LEDGER_UNIT
        for problem in ledger_unit_problems({r.unit: structure.variable(r) for r in ledgers}):
            logger.warning(problem)
    return ColumnPlan(
        columns,
        units,
        recorded,
        reads,
        [_core_kind(model, r) for r in reads],
        bonds,
        ledgers,
        omitted,
    )


class Recorder:
    """``timeseries.csv`` streamed in batches, ``metadata.json`` at the start and the end."""

    def __init__(self, directory: Path, plan: ColumnPlan, meta: dict[str, Any]) -> None:
        self.csv_path = directory / "timeseries.csv"
        self.meta_path = directory / "metadata.json"
        self.plan = plan
        self.meta = meta
        self._file: IO[str] | None = None
        self._writer: Any = None
        self._rows: list[list[Any]] = []
        self._written = -math.inf

    def open(self) -> None:
        """Create the file and write the header."""
        self._file = self.csv_path.open("w", newline="")
        self._writer = csv.writer(self._file)
        self._writer.writerow(self.plan.columns)

    def add(self, cells: list[Any]) -> None:
        """Keep a row; write the kept rows once :data:`FLUSH_EVERY` seconds have passed.

        Parameters
        ----------
        cells : list
            A row (see :meth:`ColumnPlan.row`).
        """
        self._rows.append(cells)
        if time.perf_counter() - self._written >= FLUSH_EVERY:
            self._flush()

    def _flush(self) -> None:
        if self._file is not None:
            if self.plan.texts:
                self._writer.writerows(self._rows)
            elif self._rows:  # numbers only: as the co-simulation's recorder writes them
                self._file.write(number_lines(self._rows))
            self._file.flush()
        self._rows.clear()
        self._written = time.perf_counter()

    def close(self) -> None:
        """Write what is kept and close the file."""
        if self._file is not None:
            try:
                self._flush()
            finally:
                self._file.close()
                self._file = None

    def write_metadata(self, result: RunResult | None = None, **solver: int) -> None:
        """Write ``metadata.json``, with the result once there is one.

        Parameters
        ----------
        result : RunResult, optional
            How the run ended.
        **solver : int
            Solver counts for the result (``rhs_calls``, ``events``).
        """
        meta = dict(self.meta)
        if result is not None:
            meta["result"] = {**result.summary(), **solver}
        self.meta_path.write_text(json.dumps(meta, indent=2, default=str) + "\n")


def run_metadata(
    scene: Scene,
    structure: Structure,
    model: MonolithicModel,
    plan: ColumnPlan,
    solver: dict[str, Any],
) -> dict[str, Any]:
    """What ``metadata.json`` says of a monolithic run before it ends.

    Parameters
    ----------
    scene : Scene
        The scene, with its run settings.
    structure : Structure
        Its units' model descriptions (every variable's unit and description).
    model : MonolithicModel
        The scene as one ODE (the order it evaluates the units in).
    plan : ColumnPlan
        The columns, their units and those left out.
    solver : dict
        The solver and its settings (``method``, ``rtol``, ``atol``).

    Returns
    -------
    dict
        The scene, ``"mode": "monolithic"``, the run settings that apply, the
        solver, the order, the columns and their units, the columns left out
        and why, the variables, and the scene's units, events, drivers and
        plots (:func:`~wire_fmu.master.run_record.scene_record`).
    """
    variables = {
        f"{unit}.{v.name}": {
            "unit": variable_unit(v),
            "description": v.description or "",
            "causality": v.causality,
        }
        for unit, md in structure.descriptions.items()
        for v in md.modelVariables
    }
    return {
        "scene": scene.name,
        "description": scene.description,
        "mode": "monolithic",
        "run": {"stop_time": scene.run.stop_time, "output_interval": record_interval(scene)},
        "solver": solver,
        "order": list(model.order),
        "columns": plan.columns,
        "column_units": plan.units,
        "omitted_columns": plan.omitted,
        "variables": variables,
        **scene_record(scene, structure.descriptions),
    }


def record_interval(scene: Scene) -> float:
    """Record spacing of a monolithic run, s: the scene's output interval, else its step.

    Parameters
    ----------
    scene : Scene
        The scene.
    """
    return scene.run.output_interval or scene.run.step
