"""Shared machinery of the hard-case tests (SPEC section 17, issue 7).

Our FMUs are built once per test module into a temporary folder and scenes
refer to them by path, so a change another engineer makes to ``wire_fmu``
while the tests run cannot trigger a rebuild half-way. A scene is written
as a plain dict naming our units (``"fmu": "BlockTrain"``), as a TOML file
would; :func:`run_case` swaps in the built FMUs, validates, runs it in our
master with a :class:`~wire_fmu.master.observers.CsvRecorder` and reads the
results back; :func:`reference` solves the same dict as one monolithic ODE.

The global criteria of SPEC section 17 are checked on a results table by
:func:`check_global_criteria`; :func:`assert_converges` is the step-refinement
criterion.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wire_fmu.export.builder import build_fmu
from wire_fmu.master.catalog import OUR_FMUS, ROOT
from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.plots import read_results
from wire_fmu.master.run_result import RunResult
from wire_fmu.master.scene import Scene, parse_scene
from wire_fmu.master.simulation import Simulation
from wire_fmu.master.validate import validate_scene
from wire_fmu.study.monolithic import MonolithicResult, run_monolithic

__all__ = [
    "HOISTING_UNITS",
    "CaseRun",
    "build_our_fmus",
    "master_scene",
    "run_case",
    "reference",
    "error_against",
    "check_global_criteria",
    "assert_converges",
    "rigid_drum",
    "units_with_ledgers",
]

HOISTING_UNITS = ("BlockTrain", "Winch", "Hydraulics")
"""The units of the hoisting gear that the hard cases exercise."""

LEDGER_FLOOR = 1e-9
"""J: ledger residuals below this are round-off, whatever the throughput."""


def build_our_fmus(directory: Path) -> dict[str, Path]:
    """Build the hoisting units' FMUs from ``models/`` into ``directory``; paths by name."""
    return {name: build_fmu(ROOT / "models" / OUR_FMUS[name], directory) for name in HOISTING_UNITS}


def rigid_drum(inertia: float) -> str:
    """A winch drive train of one mass (the drum, no damping) as the JSON parameter."""
    return json.dumps(
        {
            "masses": [{"name": "drum", "inertia": inertia, "damping": 0.0, "ratio": 1.0}],
            "shafts": [],
        }
    )


@dataclass
class CaseRun:
    """One run of a scene in our master.

    Attributes
    ----------
    columns : dict of str to ndarray
        The recorded table (``timeseries.csv``), by column.
    result : RunResult
        Status, message, step counts, bond residuals.
    directory : Path
        Where ``timeseries.csv`` and ``metadata.json`` were written.
    scene : Scene
        The scene as run (FMU paths substituted).
    """

    columns: dict[str, np.ndarray]
    result: RunResult
    directory: Path
    scene: Scene

    @property
    def time(self) -> np.ndarray:
        """Recorded times, s."""
        return self.columns["time"]

    def __getitem__(self, column: str) -> np.ndarray:
        return self.columns[column]

    @property
    def metadata(self) -> dict[str, Any]:
        """``metadata.json`` of the run (settings, columns, final summary)."""
        return json.loads((self.directory / "metadata.json").read_text())


def master_scene(
    data: Mapping[str, Any], fmus: Mapping[str, Path], base_dir: Path, **run_settings: Any
) -> Scene:
    """Parse ``data`` with our units replaced by the built FMUs and run settings overridden."""
    data = copy.deepcopy(dict(data))
    data["run"] = {**data.get("run", {}), **run_settings}
    for unit in data["units"].values():
        if unit["fmu"] in fmus:
            unit["fmu"] = str(fmus[unit["fmu"]])
    return parse_scene(data, base_dir=base_dir)


def run_case(
    data: Mapping[str, Any], fmus: Mapping[str, Path], directory: Path, **run_settings: Any
) -> CaseRun:
    """Validate (through FMI too) and run ``data`` in our master; read back its results.

    Parameters
    ----------
    data : mapping
        The scene as plain data, naming our units.
    fmus : mapping
        Built FMUs by unit name (:func:`build_our_fmus`).
    directory : Path
        Results folder (created).
    **run_settings
        Replace entries of the scene's ``[run]`` table.
    """
    scene = master_scene(data, fmus, directory, **run_settings)
    structure = validate_scene(scene)
    recorder = CsvRecorder(directory, scene.run.output_interval)
    result = Simulation(scene, structure, [recorder]).run()
    return CaseRun(read_results(recorder.csv_path), result, directory, scene)


def reference(data: Mapping[str, Any], *, rtol: float = 1e-8, **kwargs: Any) -> MonolithicResult:
    """The monolithic reference of ``data`` (SciPy's Radau over the joint hybrid ODE)."""
    scene = parse_scene(copy.deepcopy(dict(data)), base_dir=Path("."))
    return run_monolithic(scene, rtol=rtol, atol=rtol, **kwargs)


def error_against(run: CaseRun, ref: MonolithicResult, column: str) -> float:
    """Largest deviation of a recorded column from the reference, at the recorded times."""
    expected = np.interp(run.time, ref.time, ref.values[column])
    return float(np.max(np.abs(run[column] - expected)))


# --------------------------------------------------------------- global criteria
def units_with_ledgers(columns: Mapping[str, np.ndarray]) -> list[str]:
    """Units whose ``energy_balance`` was recorded."""
    return [
        name[: -len(".energy_balance")]
        for name in columns
        if name.endswith(".energy_balance") and name.count(".") == 1
    ]


def _throughput(columns: Mapping[str, np.ndarray], unit: str) -> float:
    """Energy that went through ``unit``: |external work| + dissipated + stored swing, J."""
    total = 0.0
    for name, reduce in (
        ("external_work", lambda v: np.max(np.abs(v))),
        ("dissipated_energy", lambda v: np.max(np.abs(v))),
        ("stored_energy", np.ptp),
    ):
        key = f"{unit}.{name}"
        if key in columns and columns[key].size:
            total += float(reduce(columns[key]))
    return total


def _assert_finite(columns: Mapping[str, np.ndarray]) -> None:
    bad = [name for name, values in columns.items() if not np.all(np.isfinite(values))]
    assert not bad, f"NaN or Inf in {bad}"


def _allowances(columns, tolerance: float, energy_scale: float | None) -> dict[str, float]:
    """Numerical error each unit may show: ``tolerance`` x its energy scale (+ round-off), J."""
    return {
        unit: tolerance * (energy_scale if energy_scale is not None else _throughput(columns, unit))
        + LEDGER_FLOOR
        for unit in units_with_ledgers(columns)
    }


def _assert_ledgers(columns, allowances: Mapping[str, float]) -> None:
    for unit, allowed in allowances.items():
        residual = float(np.max(np.abs(columns[f"{unit}.energy_balance"])))
        assert residual <= allowed, (
            f"{unit}: energy ledger residual {residual:.4g} J exceeds {allowed:.4g} J"
        )


def _assert_invariants(
    columns, dead_volumes: Mapping[str, float], allowances: Mapping[str, float]
) -> None:
    for name, values in columns.items():
        unit, _, variable = name.partition(".")
        if variable.endswith("tension") or variable == "tension_max":
            assert np.min(values) >= 0.0, f"{name} < 0: a rope pushed ({np.min(values):.6g} N)"
        elif variable == "dissipated_energy":
            # Summed decreases, against the ledger's allowance: a linearly implicit
            # solver (ros2) integrates the accumulator through (I - g h J)^-1 and may
            # take it down by round-off-to-integration-error amounts in a step.
            steps = np.diff(values)
            decrease = -float(np.sum(steps[steps < 0.0]))
            allowed = allowances.get(unit, LEDGER_FLOOR)
            assert decrease <= allowed, (
                f"{name} decreased by {decrease:.4g} J in all (allowed {allowed:.4g} J): "
                "friction or damping injected energy"
            )
        elif variable.endswith("pressure"):
            assert np.min(values) > 0.0, f"{name} <= 0 ({np.min(values):.6g} Pa)"
        elif variable == "gas.volume" and unit in dead_volumes:
            assert np.min(values) > dead_volumes[unit], (
                f"{name} reached its dead volume {dead_volumes[unit]} m3"
            )
        elif variable == "end_stop.force" and f"{unit}.stroke_used" in columns:
            # a stop pushes away from its end: down at extension, up at retraction
            away = np.where(columns[f"{unit}.stroke_used"] > 0.5, -1.0, 1.0)
            assert np.min(away * values) >= 0.0, f"{name}: an end stop pulled the rod"
        elif variable == "brake.torque" and f"{unit}.drum.speed" in columns:
            power = values * columns[f"{unit}.drum.speed"]
            assert np.max(power) <= 1e-9 * max(1.0, float(np.max(np.abs(values)))), (
                f"{name}: the brake drove the drum (friction injected power)"
            )


def _assert_passive(columns, allowances: Mapping[str, float]) -> None:
    """Stored energy minus the work of external forces never grows (beyond the allowance)."""
    total = np.zeros_like(columns["time"])
    for unit in allowances:
        total = total + columns[f"{unit}.stored_energy"]
        if f"{unit}.external_work" in columns:
            total = total - columns[f"{unit}.external_work"]
    allowed = sum(allowances.values())
    gain = float(np.max(total - total[0]))
    assert gain <= allowed, f"passive scene gained {gain:.4g} J of energy (allowed {allowed:.4g} J)"


def check_global_criteria(
    columns: Mapping[str, np.ndarray],
    *,
    ledger_tolerance: float,
    energy_scale: float | None = None,
    passive: bool = False,
    dead_volumes: Mapping[str, float] | None = None,
) -> None:
    """The global criteria of SPEC section 17 on a results table.

    * no NaN or Inf in any column;
    * every unit's ledger ``energy_balance`` (stored change + dissipated -
      external work) stays within ``ledger_tolerance`` times the energy
      throughput of that unit (max |external work| + max dissipated + swing
      of the stored energy), or times ``energy_scale`` when the case gives
      a physical scale (a conservative oscillation has no throughput);
    * invariants: rope tensions >= 0; dissipated energy never decreases
      (friction and dampers never inject power: its summed decreases stay
      within the ledger's allowance, the integration error of a linearly
      implicit solver's accumulator); pressures > 0; gas volume
      above its dead volume (``dead_volumes`` by unit); end-stop forces push
      the rod away from the stop, never pull; the brake torque never drives
      the drum (``torque * speed <= 0``);
    * with ``passive``: the total stored energy minus the work of external
      forces (a constant force's potential) never grows by more than the
      units' ledger allowances together.

    Parameters
    ----------
    columns : mapping
        A results table (:func:`wire_fmu.master.plots.read_results`).
    ledger_tolerance : float
        Relative tolerance of the ledgers (and of the passive bound), 1.
    energy_scale : float, optional
        Physical energy scale of the case, J.
    passive : bool
        Whether nothing but conservative external forces acts.
    dead_volumes : mapping, optional
        Gas dead volume of each hydraulic unit, m^3.
    """
    _assert_finite(columns)
    allowances = _allowances(columns, ledger_tolerance, energy_scale)
    _assert_ledgers(columns, allowances)
    _assert_invariants(columns, dead_volumes or {}, allowances)
    if passive:
        _assert_passive(columns, allowances)


def assert_converges(
    errors: Sequence[float], *, floor: float, ratio: float = 0.75, what: str = "error"
) -> None:
    """Step refinement converges: each finer run's error is at most ``ratio`` of the coarser.

    An error at or below ``floor`` (the case is exact to round-off, or at
    the accuracy of its reference) counts as converged.
    """
    assert all(math.isfinite(e) for e in errors), f"{what}: {errors}"
    for coarse, fine in zip(errors[:-1], errors[1:], strict=True):
        assert fine <= ratio * coarse or fine <= floor, (
            f"{what} does not shrink under step refinement: {errors}"
        )
