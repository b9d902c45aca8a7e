"""What accuracy costs in time: work-precision study of a scene (SPEC section 16).

``wire-fmu study accuracy SCENE`` runs the scene with the master over a grid
of configurations,

    coupling algorithm (jacobi, gauss_seidel)
    x extrapolation (constant, linear, quadratic)
    x macro step (a geometric series H_max / 2^k)
    x internal solver of the units (its method, tolerance or internal step),

compares each run's key outputs with the monolithic reference (the same core
units as one ODE, Radau at rtol 1e-10, :mod:`wire_fmu.study.monolithic`),
and writes

``accuracy.csv``
    one row per run: error, wall time per simulated second, FMU calls and
    the share of the wall time spent in the physics (inside the core units'
    ``advance``), in the FMI layers around it, and in the master itself;
``accuracy.md``
    the observed convergence order of every family next to the theory, the
    equal-error comparison and the table;
``accuracy.json``
    the same figures for programs;
``work_precision.png``
    error against wall time per simulated second, log-log, one curve per
    family along its macro-step series, the monolithic solver's own curve
    and the reference's cost as a horizontal line (the speed floor);
``convergence.png``
    error against macro step with slope-1 and slope-2 guides.

Error metric
------------
Outputs are compared on a common grid of spacing ``output_interval`` (a
multiple of every macro step, so each recorded row is a step end). For each
key output ``k``::

    e_k = max_t |y_k(t) - y_ref_k(t)| / range_k,
    range_k = max(max_t y_ref_k - min_t y_ref_k, 1e-6 max_t |y_ref_k|, 1e-300)

and the run's error is ``max_k e_k`` (the key output that sets it is
recorded). A run that stops early (a refused step, a unit failure, a
blow-up to non-finite numbers) has no error: it is recorded with its
status and message and left out of the fits and plots.

Families, orders, equal error
-----------------------------
A *family* is one (algorithm, extrapolation, solver); its runs differ only
in the macro step. The observed order is the least-squares slope of
``log e`` against ``log H`` over the family's runs in which coupling error
dominates: error at most :data:`ASYMPTOTIC_LIMIT` (beyond it the run is not
in the asymptotic range) and at least :data:`DOMINANCE` times the solver's
floor (the smallest error any run with that solver reached, an upper bound
of its own integration error). Theory (SPEC section 15): a held effort or
signal converges at order 1 held constant and at order 2 held at the
midpoint of a linear (or the step average of a quadratic) extrapolant; a
flow that a unit integrates into a position handed over exactly at each
step start (a bond's ``position`` link) is second order even held
constant. Configurations are compared at equal achieved error, never at
equal tolerance: for each target error the cost of every family is
interpolated (log-log, between the two runs that bracket the target) and
the cheapest configuration named.

Timing
------
Wall time is measured from the end of initialisation to the end of the
run. Physics time is the time spent inside the core units' ``advance``
(our FMUs run the ``wire_fmu`` imported by this process, so wrapping the
class method sees it); FMI time is the time the master spends in FMI calls
(:attr:`Slave.seconds`); FMI overhead is FMI time minus physics; the master
is the rest. The machine is shared: repeat a study before trusting a 20 %
difference in cost.
"""

from __future__ import annotations

import copy
import csv
import importlib
import json
import logging
import math
import shutil
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from wire_fmu.core.errors import ModelError, WireFmuError
from wire_fmu.core.framework.hybrid import SOLVERS as HYBRID_SOLVERS
from wire_fmu.core.framework.hybrid import IntegrationError
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.plots import read_results
from wire_fmu.master.run import find_scene, with_run_settings
from wire_fmu.master.scene import (
    ALGORITHMS,
    EXTRAPOLATIONS,
    Scene,
    SceneError,
    VarRef,
    load_scene,
)
from wire_fmu.master.simulation import Simulation
from wire_fmu.master.validate import Structure, validate_scene

from .monolithic import CORE_UNITS, MonolithicResult, run_monolithic

__all__ = [
    "SolverChoice",
    "StudySettings",
    "Configuration",
    "Timing",
    "RunRow",
    "OrderRow",
    "EqualErrorRow",
    "AccuracyStudy",
    "StudyError",
    "DEFAULT_SOLVERS",
    "GRIDS",
    "scene_solver",
    "solver_choices",
    "THEORY",
    "study_settings",
    "with_stop_time",
    "load_study_scene",
    "study_scene",
    "build_grid",
    "output_error",
    "theoretical_order",
    "observed_orders",
    "equal_error",
    "reference_run",
    "run_accuracy_study",
    "TimedRun",
    "timed_run",
    "fastest_run",
    "pinned",
    "StudyProgress",
]

logger = logging.getLogger(__name__)

THEORY = {"constant": 1, "linear": 2, "quadratic": 2}
"""Order of a held effort or signal per extrapolation (SPEC section 15)."""

ASYMPTOTIC_LIMIT = 0.3
"""Runs with a larger error (a fraction of the output's range) are not asymptotic."""

DOMINANCE = 4.0
"""A run counts for the order only if its error is this many times the solver's floor."""

STUDY_KEYS = ("key_outputs", "stop_time", "steps", "output_interval")
"""Keys of a scene's optional ``[study]`` table."""

DEFAULT_STOP_TIME = 10.0
"""Study stop time, s, unless ``[study] stop_time`` says otherwise (capped by the scene's)."""

QUICK_STOP_TIME = 1.0
"""Stop time of the quick mode, s (capped by the study's)."""

REFERENCE_MARGIN = 100.0
"""Errors below this many times the reference's tolerance are the reference's own."""

MONOLITHIC_RADAU = "monolithic / radau"
"""Family of the monolithic model at looser Radau tolerances."""

_RANGE_FLOOR = 1e-6
_DIVERGED = 1.0  # an error above the output's whole range: the run blew up


class StudyError(WireFmuError):
    """A study cannot be made (no reference, no key outputs, ...)."""


# ----------------------------------------------------------------------- settings
UNIT_SOLVER_DEFAULTS = {
    "solver": "ros2",
    "solver_max_step": 1e-3,
    "solver_rtol": 1e-6,
    "solver_atol": 1e-9,
}
"""Solver parameters of a unit of ours that declares none (the winch's default is rk4)."""


@dataclass(frozen=True)
class SolverChoice:
    """Internal-solver parameters applied to the units of a configuration.

    Parameters
    ----------
    label : str
        Short name used in tables and legends, e.g. ``"ros2 h=1e-3"``.
    parameters : mapping
        Unit parameters (``solver``, ``solver_max_step``, ``solver_rtol``,
        ``solver_atol``) given to every unit of ours that has them.
    only : str, optional
        Model name (``"Winch"``): the choice applies only to units of this
        model, the others keep ``parameters_others``; a scene without such a
        unit skips the choice.
    parameters_others : mapping
        What the other units get when ``only`` is set.
    settings : mapping, optional
        The complete solver settings the choice amounts to (defaults filled
        in), when ``parameters`` leaves some to the units; used to compare
        choices and to solve the monolithic model the same way.
    """

    label: str
    parameters: Mapping[str, Any]
    only: str | None = None
    parameters_others: Mapping[str, Any] = field(default_factory=dict)
    settings: Mapping[str, Any] | None = None

    def applies_to(self, scene: Scene) -> bool:
        """Whether the scene has the units this choice is about."""
        return self.only is None or any(u.fmu == self.only for u in scene.units.values())

    @property
    def complete(self) -> dict[str, Any]:
        """Solver settings with the units' defaults filled in."""
        return {**UNIT_SOLVER_DEFAULTS, **(self.settings or self.parameters)}

    def for_model(self, fmu: str) -> Mapping[str, Any]:
        """Parameters for a unit of model ``fmu``."""
        if self.only is None or fmu == self.only:
            return self.parameters
        return self.parameters_others


_ROS2 = {"solver": "ros2", "solver_max_step": 1e-3}
DEFAULT_SOLVERS = (
    SolverChoice("ros2 h=1e-3", _ROS2),
    SolverChoice("ros2 h=2.5e-4", {"solver": "ros2", "solver_max_step": 2.5e-4}),
    SolverChoice("rk4 h=1e-3", {"solver": "rk4", "solver_max_step": 1e-3}),
    SolverChoice(
        "radau rtol=1e-5",
        {"solver": "radau", "solver_rtol": 1e-5, "solver_atol": 1e-8, "solver_max_step": 1.0},
    ),
    SolverChoice(
        "radau rtol=1e-8",
        {"solver": "radau", "solver_rtol": 1e-8, "solver_atol": 1e-11, "solver_max_step": 1.0},
    ),
    SolverChoice(
        "bdf rtol=1e-6",
        {"solver": "bdf", "solver_rtol": 1e-6, "solver_atol": 1e-9, "solver_max_step": 1.0},
    ),
    SolverChoice("energy (winch)", {"solver": "energy"}, only="Winch"),
)
"""Internal solvers of the full grid (the winch's energy form only where there is a winch);
the scene's own solver settings are always studied as well."""

GRIDS = ("slices", "product")
"""``slices``: every coupling with the scene's own solvers, and every solver with the
scene's own coupling; ``product``: every coupling with every solver."""

SOLVER_KEYS = tuple(UNIT_SOLVER_DEFAULTS)


@dataclass(frozen=True)
class StudySettings:
    """Everything a study varies and keeps (a frozen plan, no behaviour).

    Attributes
    ----------
    key_outputs : tuple of VarRef
        Outputs the error is measured on.
    stop_time : float
        Simulated time of every run, s (a multiple of ``output_interval``).
    steps : tuple of float
        Macro steps, largest first; the largest is a multiple of every other.
    output_interval : float
        Spacing of the comparison grid, s (a multiple of every step).
    algorithms, extrapolations : tuple of str
        Coupling schemes of the grid.
    solvers : tuple of SolverChoice
        Internal solvers of the grid, besides the scene's own.
    grid : str
        One of :data:`GRIDS`: how couplings and solvers are combined.
    reference_rtol : float
        Tolerance of the monolithic reference (Radau), rtol = atol.
    monolithic_rtols : tuple of float
        Looser tolerances at which the monolithic model is run too, for its
        own work-precision curve (empty: none).
    run_budget : float
        Wall seconds one run may take: a family stops refining its macro
        step once the next run would likely take longer.
    solver_floors : bool
        Also solve the monolithic model with each unit solver choice: its
        error is that solver's own error on the scene with no coupling, the
        floor below which a family's order is not measured.
    repeats : int
        Runs per configuration; the fastest one's time counts.
    quick : bool
        Whether this is the reduced plan for CI.
    """

    key_outputs: tuple[VarRef, ...]
    stop_time: float
    steps: tuple[float, ...]
    output_interval: float
    algorithms: tuple[str, ...] = ALGORITHMS
    extrapolations: tuple[str, ...] = EXTRAPOLATIONS
    solvers: tuple[SolverChoice, ...] = DEFAULT_SOLVERS
    grid: str = "slices"
    reference_rtol: float = 1e-10
    monolithic_rtols: tuple[float, ...] = (1e-4, 1e-6, 1e-8)
    run_budget: float = 60.0
    solver_floors: bool = True
    repeats: int = 1
    quick: bool = False


def _multiple(big: float, small: float) -> bool:
    ratio = big / small
    return abs(ratio - round(ratio)) < 1e-6 * max(1.0, ratio) and round(ratio) >= 1


def _study_table(scene: Scene) -> Mapping[str, Any]:
    table = getattr(scene, "study", None) or {}
    unknown = sorted(set(table) - set(STUDY_KEYS))
    if unknown:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            [f"unknown keys {unknown}; known: {', '.join(STUDY_KEYS)}"],
        )
    return table


def _key_outputs(scene: Scene, table: Mapping[str, Any]) -> tuple[VarRef, ...]:
    raw = table.get("key_outputs")
    if raw is None:
        refs = [r for plot in scene.plots for r in plot.variables]
        refs = refs or list(scene.outputs or ())
        if not refs:
            raise SceneError(
                f"scene {scene.name!r}",
                [
                    'no key outputs: give [study] key_outputs = ["unit.variable", ...] or '
                    "[[plots]] variables"
                ],
            )
        return tuple(dict.fromkeys(refs))
    if not isinstance(raw, list) or not raw:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            ["key_outputs must be a non-empty list of 'unit.variable'"],
        )
    refs = [VarRef.parse(text) for text in raw]
    bad = [text for text, ref in zip(raw, refs, strict=True) if ref is None]
    if bad:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            [f"key_outputs: {text!r} is not 'unit.variable'" for text in bad],
        )
    return tuple(dict.fromkeys(refs))


def _steps(scene: Scene, table: Mapping[str, Any], quick: bool) -> tuple[float, ...]:
    raw = table.get("steps")
    if raw is None:
        exponents = (1, 0, -1) if quick else (2, 1, 0, -1, -2)
        return tuple(scene.run.step * 2.0**k for k in exponents)
    if (
        not isinstance(raw, list)
        or not raw
        or not all(isinstance(h, int | float) and not isinstance(h, bool) and h > 0 for h in raw)
    ):
        raise SceneError(
            f"scene {scene.name!r} [study]",
            ["steps must be a non-empty list of positive macro steps (s)"],
        )
    steps = tuple(sorted((float(h) for h in raw), reverse=True))
    if quick and len(steps) > 3:
        middle = len(steps) // 2
        steps = steps[middle - 1 : middle + 2]
    return steps


def _output_interval(scene: Scene, table: Mapping[str, Any], steps: Sequence[float]) -> float:
    interval = float(table.get("output_interval", steps[0]))
    problems = [
        f"output_interval {interval:g} s is not a multiple of the macro step {h:g} s"
        for h in steps
        if not _multiple(interval, h)
    ]
    if problems:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            problems
            + ["every run is compared on one grid of step ends: choose steps that divide it"],
        )
    return interval


def study_settings(scene: Scene, *, quick: bool = False) -> StudySettings:
    """The study plan for ``scene``: its ``[study]`` table, else defaults.

    Parameters
    ----------
    scene : Scene
        The scene; its optional ``[study]`` table may give ``key_outputs``,
        ``stop_time``, ``steps`` and ``output_interval``.
    quick : bool
        The reduced plan for CI: three macro steps, constant and linear
        extrapolation, the scene's own solvers only, at most
        :data:`QUICK_STOP_TIME` seconds, no monolithic curve.

    Raises
    ------
    SceneError
        Listing the problems of the ``[study]`` table.
    """
    table = _study_table(scene)
    keys = _key_outputs(scene, table)
    steps = _steps(scene, table, quick)
    interval = _output_interval(scene, table, steps)
    stop = float(table.get("stop_time", min(scene.run.stop_time, DEFAULT_STOP_TIME)))
    if quick:
        stop = min(stop, QUICK_STOP_TIME)
    stop = max(1, math.floor(stop / interval + 1e-9)) * interval
    settings = StudySettings(keys, stop, steps, interval)
    if quick:
        settings = replace(
            settings,
            extrapolations=("constant", "linear"),
            solvers=(),
            monolithic_rtols=(),
            run_budget=20.0,
            quick=True,
        )
    return settings


def with_stop_time(settings: StudySettings, stop_time: float | None) -> StudySettings:
    """``settings`` with another stop time (a multiple of the output interval); None: as is."""
    if stop_time is None:
        return settings
    if not (math.isfinite(stop_time) and stop_time > 0):
        raise ValueError(f"stop_time must be a positive number of seconds, got {stop_time!r}")
    interval = settings.output_interval
    return replace(settings, stop_time=max(1, math.floor(stop_time / interval + 1e-9)) * interval)


# ----------------------------------------------------------------------- the grid
@dataclass(frozen=True)
class Configuration:
    """One run of the grid."""

    algorithm: str
    extrapolation: str
    step: float
    solver: SolverChoice

    @property
    def family(self) -> str:
        """The family label: everything but the macro step."""
        return family_label(self.algorithm, self.extrapolation, self.solver.label)


def family_label(algorithm: str, extrapolation: str, solver: str) -> str:
    """``"gauss_seidel / linear / ros2 h=1e-3"``."""
    return f"{algorithm} / {extrapolation} / {solver}"


def describe_solver(settings: Mapping[str, Any]) -> str:
    """``"ros2 h=1e-3"``, ``"radau rtol=1e-08"``: a solver by what sets its accuracy."""
    full = {**UNIT_SOLVER_DEFAULTS, **settings}
    method = str(full["solver"])
    if method in ("rk4", "ros2"):
        return f"{method} h={float(full['solver_max_step']):g}"
    if method in HYBRID_SOLVERS:
        return f"{method} rtol={float(full['solver_rtol']):g}"
    return method


def _unit_solver_defaults(fmu: str) -> dict[str, Any]:
    """Solver parameter defaults a core unit class declares (ours differ: the winch's is rk4)."""
    try:
        cls = _import(CORE_UNITS[fmu])
    except (ImportError, AttributeError):
        return dict(UNIT_SOLVER_DEFAULTS)
    declared = {v.name: v.start for v in cls.VARIABLES if v.name in SOLVER_KEYS}
    return {**UNIT_SOLVER_DEFAULTS, **declared}


def scene_solver(scene: Scene) -> SolverChoice:
    """The internal solvers as the scene sets them (nothing overridden)."""
    complete = [
        {
            **_unit_solver_defaults(spec.fmu),
            **{k: spec.parameters[k] for k in SOLVER_KEYS if k in spec.parameters},
        }
        for spec in scene.units.values()
        if spec.fmu in CORE_UNITS
    ]
    distinct = {json.dumps(c, sort_keys=True) for c in complete}
    if len(distinct) > 1:
        names = [n for n, spec in scene.units.items() if spec.fmu in CORE_UNITS]
        label = ", ".join(f"{n} {describe_solver(c)}" for n, c in zip(names, complete, strict=True))
        return SolverChoice(f"scene: {label}", {}, settings={"solver": "(mixed)"})
    settings = complete[0] if complete else dict(UNIT_SOLVER_DEFAULTS)
    return SolverChoice(f"{describe_solver(settings)} (scene)", {}, settings=settings)


def solver_choices(scene: Scene, settings: StudySettings) -> list[SolverChoice]:
    """The scene's own solvers, then every choice of the plan that differs and applies."""
    own = scene_solver(scene)
    out = [own]
    for choice in settings.solvers:
        if choice.applies_to(scene) and (
            choice.only is not None or choice.complete != own.complete
        ):
            out.append(choice)
    return out


def build_grid(scene: Scene, settings: StudySettings) -> list[Configuration]:
    """Every configuration, family by family, each from its largest step down.

    ``slices`` (the default): every algorithm and extrapolation with the
    scene's own solvers, then every other solver with the scene's own
    algorithm and extrapolation; ``product``: every combination.
    """
    solvers = solver_choices(scene, settings)
    couplings = [(a, e) for a in settings.algorithms for e in settings.extrapolations]
    if settings.grid == "product":
        return [
            Configuration(a, e, h, s) for s in solvers for a, e in couplings for h in settings.steps
        ]
    own = [Configuration(a, e, h, solvers[0]) for a, e in couplings for h in settings.steps]
    run = scene.run
    return own + [
        Configuration(run.algorithm, run.extrapolation, h, s)
        for s in solvers[1:]
        for h in settings.steps
    ]


def _solver_parameters(
    scene: Scene, structure: Structure | None, solver: SolverChoice
) -> dict[str, Any]:
    units = {}
    for name, spec in scene.units.items():
        params = copy.deepcopy(spec.parameters)
        chosen = solver.for_model(spec.fmu)
        if structure is None or structure.variable(VarRef(name, "solver")) is not None:
            params.update(chosen)
        units[name] = replace(spec, parameters=params)
    return units


def study_scene(scene: Scene, settings: StudySettings) -> Scene:
    """The scene as every run of the study sees it: stop time, grid, key outputs recorded."""
    scene = with_run_settings(
        scene,
        stop_time=settings.stop_time,
        output_interval=settings.output_interval,
        adaptive=False,
    )
    return replace(scene, outputs=settings.key_outputs)


def configured_scene(
    scene: Scene, config: Configuration, structure: Structure | None = None
) -> Scene:
    """A copy of a study scene set up for ``config`` (parameters deep-copied)."""
    scene = with_run_settings(
        scene, step=config.step, algorithm=config.algorithm, extrapolation=config.extrapolation
    )
    return replace(scene, units=_solver_parameters(scene, structure, config.solver))


# --------------------------------------------------------------------- timing
@dataclass
class Timing:
    """Where the wall time of one run went (seconds over the stepping phase)."""

    wall: float = 0.0
    simulated: float = 0.0
    physics: float = 0.0
    fmi: float = 0.0
    calls: int = 0
    do_steps: int = 0

    @property
    def per_simulated_second(self) -> float:
        """Wall seconds per simulated second."""
        return self.wall / self.simulated if self.simulated > 0 else math.nan

    def shares(self) -> tuple[float, float, float]:
        """Shares of the wall time: physics, FMI overhead (FMI minus physics), master."""
        if self.wall <= 0:
            return math.nan, math.nan, math.nan
        physics = min(self.physics, self.fmi)
        return (
            physics / self.wall,
            (self.fmi - physics) / self.wall,
            (self.wall - self.fmi) / self.wall,
        )


class PhysicsTimer:
    """Accumulates the time spent in ``advance`` of some core unit classes (wraps them).

    Parameters
    ----------
    classes : iterable of type
        Core unit classes whose ``advance`` is timed while the timer is entered.
    """

    def __init__(self, classes: Iterable[type]) -> None:
        self.classes = list(dict.fromkeys(classes))
        self.elapsed = 0.0
        self._originals: dict[type, Any] = {}

    def __enter__(self) -> PhysicsTimer:
        for cls in self.classes:
            self._originals[cls] = cls.__dict__.get("advance")
            cls.advance = self._timed(cls.advance)
        return self

    def __exit__(self, *exc) -> None:
        for cls, original in self._originals.items():
            if original is None:
                del cls.advance
            else:
                cls.advance = original
        self._originals.clear()

    def _timed(self, original):
        timer = self

        def advance(unit, time_, step):
            start = time.perf_counter()
            try:
                return original(unit, time_, step)
            finally:
                timer.elapsed += time.perf_counter() - start

        return advance


def _import(target: str) -> Any:
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def core_classes(scene: Scene) -> list[type]:
    """Core unit classes of the scene's units of ours (those that cannot be imported skipped)."""
    out = []
    for fmu in sorted({u.fmu for u in scene.units.values() if u.fmu in CORE_UNITS}):
        try:
            out.append(_import(CORE_UNITS[fmu]))
        except (ImportError, AttributeError) as exc:
            logger.warning("cannot time the physics of %s: %s", fmu, exc)
    return out


class _TimingObserver:
    """Stamps the stepping phase: wall, physics and FMI time, call counts."""

    def __init__(self, timer: PhysicsTimer) -> None:
        self.timer = timer
        self.timing = Timing()
        self._start = (0.0, 0.0, 0.0, 0, 0)

    @staticmethod
    def _fmi(sim: Simulation) -> tuple[float, int, int]:
        seconds = sum(sum(s.seconds.values()) for s in sim.slaves.values())
        calls = sum(sum(s.calls.values()) for s in sim.slaves.values())
        steps = sum(s.calls.get("doStep", 0) for s in sim.slaves.values())
        return seconds, calls, steps

    def on_start(self, sim: Simulation) -> None:
        """Stamp the start of stepping."""
        self._start = (time.perf_counter(), self.timer.elapsed, *self._fmi(sim))

    def on_step(self, sim: Simulation) -> None:
        """Nothing per step."""

    def on_end(self, sim: Simulation, result) -> None:
        """Stamp the end."""
        wall0, physics0, fmi0, calls0, steps0 = self._start
        if wall0 == 0.0:
            return
        fmi, calls, steps = self._fmi(sim)
        self.timing = Timing(
            time.perf_counter() - wall0,
            sim.time,
            self.timer.elapsed - physics0,
            fmi - fmi0,
            calls - calls0,
            steps - steps0,
        )


@dataclass
class TimedRun:
    """One master run: its status, recorded columns and timing (zero if it could not start)."""

    status: str
    message: str
    columns: dict[str, np.ndarray]
    timing: Timing
    steps: int = 0
    rejected: int = 0


def timed_run(scene: Scene, structure: Structure, workdir: Path, timer: PhysicsTimer) -> TimedRun:
    """Run ``scene`` with the master, recording its outputs and timing the stepping.

    The scene was validated once (``structure``); each run builds a
    :class:`~wire_fmu.master.simulation.Simulation` as
    :func:`~wire_fmu.master.run.run_scene` does, without validating again
    (which would instantiate every unit once more, and rebuild FMUs if the
    core changed on disk during a study). A failure of any kind is a result.
    """
    timing = _TimingObserver(timer)
    recorder = CsvRecorder(workdir, scene.run.output_interval)
    try:
        sim = Simulation(scene, structure, [timing, recorder])
        result = sim.run()
        if result.status == "interrupted":  # Ctrl-C ends the study, not just this run
            raise KeyboardInterrupt
    except Exception as exc:  # noqa: BLE001 - one configuration failing must not end a study
        logger.debug("run failed: %s", exc, exc_info=True)
        return TimedRun("failed", f"{type(exc).__name__}: {exc}", {}, Timing())
    columns = read_results(recorder.csv_path) if recorder.csv_path.exists() else {}
    return TimedRun(
        result.status, result.message, columns, timing.timing, result.steps, result.rejected
    )


def fastest_run(
    scene: Scene, structure: Structure, workdir: Path, timer: PhysicsTimer, repeats: int = 1
) -> tuple[TimedRun, float]:
    """The fastest of ``repeats`` runs, and the spread of their costs (s per simulated s;
    NaN with fewer than two finished runs).

    A shared machine only ever slows a run down, so the minimum is the
    best estimate of its cost; outputs do not depend on the repeat.
    """
    runs = [timed_run(scene, structure, workdir, timer) for _ in range(max(1, repeats))]
    finished = [r for r in runs if r.status == "finished"]
    if not finished:
        return runs[-1], math.nan
    costs = [r.timing.per_simulated_second for r in finished]
    spread = max(costs) - min(costs) if len(costs) > 1 else math.nan
    return min(finished, key=lambda r: r.timing.per_simulated_second), spread


def pinned(structure: Structure, directory: Path) -> Structure:
    """The validated FMUs copied into ``directory``.

    A study keeps running the FMUs it validated, even if ours are rebuilt
    meanwhile because another process changed the core on disk (their
    guard would refuse an FMU whose core differs from the one imported here).
    """
    copies: dict[Path, Path] = {}
    for path in structure.paths.values():
        if path not in copies:
            copies[path] = directory / f"{len(copies)}_{path.name}"
            shutil.copy2(path, copies[path])
    return Structure({n: copies[p] for n, p in structure.paths.items()}, structure.descriptions)


# ---------------------------------------------------------------------- error
def _scale(reference: np.ndarray) -> float:
    span = float(np.ptp(reference)) if reference.size else 0.0
    return max(span, _RANGE_FLOOR * float(np.max(np.abs(reference), initial=0.0)), 1e-300)


def output_error(
    values: Mapping[str, np.ndarray],
    reference: Mapping[str, np.ndarray],
    keys: Sequence[VarRef | str],
) -> tuple[float, str]:
    """The study's error metric (module docstring) and the key output that sets it.

    Returns ``(nan, reason)`` if the run does not cover the reference grid.
    """
    worst, which = 0.0, ""
    for key in map(str, keys):
        ref = np.asarray(reference[key], dtype=float)
        got = np.asarray(values.get(key, ()), dtype=float)
        if got.shape != ref.shape:
            return math.nan, f"{key}: {got.size} samples, the reference has {ref.size}"
        error = float(np.max(np.abs(got - ref))) / _scale(ref)
        if not math.isfinite(error):
            return math.inf, key
        if error >= worst:
            worst, which = error, key
    return worst, which


# ---------------------------------------------------------------------- rows
@dataclass
class RunRow:
    """One row of ``accuracy.csv``."""

    family: str
    algorithm: str
    extrapolation: str
    solver: str
    step: float
    status: str
    error: float
    worst_output: str
    wall_time_s: float
    simulated_s: float
    wall_per_sim_s: float
    macro_steps: int
    rejected: int
    fmu_calls: int
    do_step_calls: int
    physics_share: float
    fmi_overhead_share: float
    master_share: float
    message: str = ""

    @property
    def usable(self) -> bool:
        """Finished with a finite error no larger than the outputs' range."""
        return self.status == "finished" and math.isfinite(self.error) and self.error <= _DIVERGED


def _row(config: Configuration, run: TimedRun, error: float, worst: str) -> RunRow:
    t = run.timing
    physics, overhead, master = t.shares()
    status = run.status
    if status == "finished" and not (math.isfinite(error) and error <= _DIVERGED):
        status = "diverged"
    return RunRow(
        config.family,
        config.algorithm,
        config.extrapolation,
        config.solver.label,
        config.step,
        status,
        error,
        worst,
        t.wall,
        t.simulated,
        t.per_simulated_second,
        run.steps,
        run.rejected,
        t.calls,
        t.do_steps,
        physics,
        overhead,
        master,
        one_line(run.message),
    )


def one_line(message: str, limit: int = 300) -> str:
    """A message on one line (a unit's list of problems joined), at most ``limit`` characters."""
    text = " ".join(message.split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _skipped(config: Configuration, reason: str) -> RunRow:
    return RunRow(
        config.family,
        config.algorithm,
        config.extrapolation,
        config.solver.label,
        config.step,
        "skipped",
        math.nan,
        "",
        math.nan,
        0.0,
        math.nan,
        0,
        0,
        0,
        0,
        math.nan,
        math.nan,
        math.nan,
        reason,
    )


def _monolithic_row(
    family: str, label: str, result: MonolithicResult, error: float, worst: str, stop: float
) -> RunRow:
    status = "finished" if math.isfinite(error) and error <= _DIVERGED else "diverged"
    return RunRow(
        family,
        "monolithic",
        "-",
        label,
        math.nan,
        status,
        error,
        worst,
        result.wall_time,
        stop,
        result.wall_time / stop,
        result.steps,
        0,
        0,
        0,
        1.0,
        0.0,
        0.0,
        f"{result.rhs_calls} right-hand side calls",
    )


# --------------------------------------------------------------------- orders
@dataclass
class OrderRow:
    """Observed convergence order of one family."""

    family: str
    algorithm: str
    extrapolation: str
    solver: str
    theory: int | None
    observed: float
    points: int
    steps_used: tuple[float, ...] = ()
    note: str = ""


def theoretical_order(scene: Scene, extrapolation: str) -> int | None:
    """Order the coupling of ``scene`` should show with ``extrapolation`` (SPEC section 15).

    Position links of a bond are exact at every step start; the flow of such
    a bond is integrated into that position, so its hold costs one order
    less than an effort's: second order even held constant. Every other
    held input (efforts, plain signals) has :data:`THEORY`'s order. None
    when nothing is held (no connections).
    """
    with_position = {b.name for b in scene.bonds if b.position is not None}
    orders = []
    for c in scene.all_connections:
        if c.role == "position":
            continue
        scheme = c.extrapolation or extrapolation
        if c.role == "flow" and c.bond in with_position:
            orders.append(2)
        else:
            orders.append(THEORY[scheme])
    return min(orders) if orders else None


def _slope(steps: Sequence[float], errors: Sequence[float]) -> float:
    x, y = np.log(np.asarray(steps)), np.log(np.asarray(errors))
    return float(np.polyfit(x, y, 1)[0])


def observed_orders(rows: Sequence[RunRow], scene: Scene, min_error: float = 0.0) -> list[OrderRow]:
    """The order of every family over its runs where coupling error dominates.

    ``min_error``: errors at or below it are the reference's own (the
    study passes 100 times the reference's tolerance).
    """
    floors = {
        r.solver: r.error for r in rows if r.family == f"monolithic / {r.solver}" and r.usable
    }
    out = []
    for family, runs in _families(rows).items():
        first = runs[0]
        if first.algorithm == "monolithic":
            continue
        floor = max(DOMINANCE * floors.get(first.solver, 0.0), min_error)
        kept = [r for r in runs if r.usable and floor < r.error <= ASYMPTOTIC_LIMIT]
        theory = theoretical_order(scene, first.extrapolation)
        if len(kept) < 2:
            note = (
                f"{len(kept)} run(s) with an error between {DOMINANCE:g} x the solver's own "
                f"error and {ASYMPTOTIC_LIMIT:g}: not measurable"
            )
            out.append(
                OrderRow(
                    family,
                    first.algorithm,
                    first.extrapolation,
                    first.solver,
                    theory,
                    math.nan,
                    len(kept),
                    note=note,
                )
            )
            continue
        observed = _slope([r.step for r in kept], [r.error for r in kept])
        out.append(
            OrderRow(
                family,
                first.algorithm,
                first.extrapolation,
                first.solver,
                theory,
                observed,
                len(kept),
                tuple(r.step for r in kept),
            )
        )
    return out


def _families(rows: Sequence[RunRow]) -> dict[str, list[RunRow]]:
    out: dict[str, list[RunRow]] = defaultdict(list)
    for r in rows:
        out[r.family].append(r)
    for runs in out.values():
        runs.sort(
            key=lambda r: (
                -r.step if math.isfinite(r.step) else 0.0,
                -r.error if math.isfinite(r.error) else 0.0,
            )
        )
    return dict(out)


# ---------------------------------------------------------------- equal error
@dataclass
class EqualErrorRow:
    """Cost of each family at one target error, and the cheapest."""

    target: float
    costs: dict[str, float]
    cheapest: str
    cheapest_cost: float

    def reached(self) -> int:
        """How many families reach the target."""
        return sum(1 for c in self.costs.values() if math.isfinite(c))


def _cost_at(runs: Sequence[RunRow], target: float) -> float:
    """Wall per simulated second at ``target`` error, interpolated log-log along the family."""
    points = [(r.error, r.wall_per_sim_s) for r in runs if r.usable and r.wall_per_sim_s > 0]
    points.sort(key=lambda p: -p[0])  # from large error (cheap) to small
    previous = None
    for error, cost in points:
        if error <= target:
            if previous is None or previous[0] <= error:
                return cost
            e0, c0 = previous
            w = (math.log(target) - math.log(e0)) / (math.log(error) - math.log(e0))
            return math.exp(math.log(c0) + w * (math.log(cost) - math.log(c0)))
        previous = (error, cost)
    return math.inf


def default_targets(rows: Sequence[RunRow], count: int = 4) -> list[float]:
    """Decades between the largest and the smallest achieved error (at most ``count``)."""
    errors = [r.error for r in rows if r.usable and r.error > 0]
    if not errors:
        return []
    top = math.floor(math.log10(max(errors)))
    bottom = math.log10(min(errors))
    return [10.0**k for k in range(top, top - count, -1) if k >= bottom]


def equal_error(rows: Sequence[RunRow], targets: Sequence[float]) -> list[EqualErrorRow]:
    """For each target error: every family's interpolated cost and the cheapest family."""
    families = _families(rows)
    out = []
    for target in targets:
        costs = {name: _cost_at(runs, target) for name, runs in families.items()}
        finite = {k: v for k, v in costs.items() if math.isfinite(v)}
        cheapest = min(finite, key=finite.get) if finite else ""
        out.append(EqualErrorRow(target, costs, cheapest, finite.get(cheapest, math.inf)))
    return out


# ------------------------------------------------------------------ reference
def reference_run(
    scene: Scene, settings: StudySettings, rtol: float | None = None
) -> MonolithicResult:
    """The monolithic model of a study scene on the study's output grid.

    Raises
    ------
    StudyError
        If the scene cannot be assembled into one ODE (a foreign FMU, a unit
        without an ODE view), saying which, or if its integration fails.
    """
    tol = settings.reference_rtol if rtol is None else rtol
    try:
        return run_monolithic(scene, rtol=tol, atol=tol, output_interval=settings.output_interval)
    except NotImplementedError as exc:
        raise StudyError(
            f"scene {scene.name!r}: no monolithic reference: {exc} (its core "
            "unit offers no ode() view yet)"
        ) from None
    except SceneError as exc:
        raise StudyError(f"scene {scene.name!r}: no monolithic reference: {exc}") from None
    except (IntegrationError, ModelError, FloatingPointError, ValueError) as exc:
        raise StudyError(
            f"scene {scene.name!r}: the monolithic reference (Radau, rtol "
            f"{tol:g}) failed: {type(exc).__name__}: {exc}"
        ) from None


# ------------------------------------------------------------------- progress
class StudyProgress:
    """One line per run on a stream (stderr by default), with elapsed time and an estimate.

    Parameters
    ----------
    total : int
        Runs planned.
    stream : text stream, optional
        Where to write (default ``sys.stderr``); None with ``enabled=False``.
    enabled : bool
        Write nothing when False.
    """

    def __init__(self, total: int, stream: TextIO | None = None, enabled: bool = True) -> None:
        self.total = total
        self.done = 0
        self.stream = stream
        self.enabled = enabled
        self._start = time.perf_counter()

    def note(self, text: str) -> None:
        """A line that is not a run."""
        if self.enabled:
            (self.stream or sys.stderr).write(text + "\n")
            (self.stream or sys.stderr).flush()

    def advance(self, text: str) -> None:
        """One run done."""
        self.done += 1
        elapsed = time.perf_counter() - self._start
        left = elapsed / self.done * (self.total - self.done)
        width = 20
        filled = int(width * self.done / max(self.total, 1))
        bar = "#" * filled + "." * (width - filled)
        self.note(
            f"[{bar}] {self.done:>3}/{self.total} {elapsed:6.0f} s (~{left:.0f} s left) {text}"
        )


# ------------------------------------------------------------------ the study
@dataclass
class AccuracyStudy:
    """Everything a study produced."""

    scene: str
    settings: StudySettings
    reference_wall_per_sim_s: float
    rows: list[RunRow]
    orders: list[OrderRow]
    comparison: list[EqualErrorRow]
    files: dict[str, Path] = field(default_factory=dict)
    elapsed: float = 0.0


def _describe(row: RunRow) -> str:
    where = f"{row.family} H={row.step:g}" if math.isfinite(row.step) else row.family
    if row.status == "finished":
        return f"{where}: error {row.error:.2e}, {row.wall_per_sim_s:.3g} s/s"
    return f"{where}: {row.status} {row.message[:80]}"


def _run_grid(
    scene: Scene,
    structure: Structure,
    grid: Sequence[Configuration],
    reference: MonolithicResult,
    settings: StudySettings,
    workdir: Path,
    progress: StudyProgress,
) -> list[RunRow]:
    rows: list[RunRow] = []
    over_budget: dict[str, float] = {}
    with PhysicsTimer(core_classes(scene)) as timer:
        for config in grid:
            if config.family in over_budget:
                row = _skipped(
                    config,
                    f"skipped: the run at a larger step took "
                    f"{over_budget[config.family]:.1f} s (budget "
                    f"{settings.run_budget:g} s)",
                )
            else:
                run, _ = fastest_run(
                    configured_scene(scene, config, structure),
                    structure,
                    workdir,
                    timer,
                    settings.repeats,
                )
                error, worst = (
                    output_error(run.columns, reference.values, settings.key_outputs)
                    if run.status == "finished"
                    else (math.nan, "")
                )
                row = _row(config, run, error, worst)
                if 2.0 * row.wall_time_s > settings.run_budget:
                    over_budget[config.family] = row.wall_time_s
            rows.append(row)
            progress.advance(_describe(row))
    return rows


def _monolithic_attempt(
    scene: Scene,
    settings: StudySettings,
    reference: MonolithicResult,
    family: str,
    label: str,
    **solver,
) -> RunRow:
    try:
        result = run_monolithic(scene, output_interval=settings.output_interval, **solver)
    except Exception as exc:  # noqa: BLE001 - a loose tolerance may fail; record it
        return RunRow(
            family,
            "monolithic",
            "-",
            label,
            math.nan,
            "failed",
            math.nan,
            "",
            math.nan,
            0.0,
            math.nan,
            0,
            0,
            0,
            0,
            math.nan,
            math.nan,
            math.nan,
            one_line(f"{type(exc).__name__}: {exc}"),
        )
    error, worst = output_error(result.values, reference.values, settings.key_outputs)
    return _monolithic_row(family, label, result, error, worst, settings.stop_time)


def _monolithic_solver(choice: SolverChoice) -> dict[str, Any] | None:
    """The monolithic solver arguments matching a unit solver choice (None if there is none)."""
    params = choice.complete
    if choice.only is not None or params["solver"] not in HYBRID_SOLVERS:
        return None
    return {
        "method": params["solver"],
        "rtol": float(params["solver_rtol"]),
        "atol": float(params["solver_atol"]),
        "max_step": float(params["solver_max_step"]),
    }


def _monolithic_rows(
    scene: Scene, settings: StudySettings, reference: MonolithicResult, progress: StudyProgress
) -> list[RunRow]:
    """The monolithic model at looser Radau tolerances, and with each unit solver."""
    rows = []
    for rtol in settings.monolithic_rtols:
        rows.append(
            _monolithic_attempt(
                scene,
                settings,
                reference,
                MONOLITHIC_RADAU,
                f"radau rtol={rtol:g}",
                method="radau",
                rtol=rtol,
                atol=rtol,
            )
        )
        progress.advance(_describe(rows[-1]))
    for choice in solver_choices(scene, settings) if settings.solver_floors else ():
        solver = _monolithic_solver(choice)
        if solver is not None:
            rows.append(
                _monolithic_attempt(
                    scene,
                    settings,
                    reference,
                    f"monolithic / {choice.label}",
                    choice.label,
                    **solver,
                )
            )
            progress.advance(_describe(rows[-1]))
    return rows


def _monolithic_runs(scene: Scene, settings: StudySettings) -> int:
    floors = (
        sum(1 for c in solver_choices(scene, settings) if _monolithic_solver(c) is not None)
        if settings.solver_floors
        else 0
    )
    return len(settings.monolithic_rtols) + floors


def run_accuracy_study(
    scene: Scene | str | Path,
    output_dir: Path,
    *,
    quick: bool = False,
    settings: StudySettings | None = None,
    repeats: int | None = None,
    grid: str | None = None,
    stop_time: float | None = None,
    fmu_dir: Path = DEFAULT_FMU_DIR,
    progress: bool = True,
    stream: TextIO | None = None,
) -> AccuracyStudy:
    """Run the accuracy study of ``scene`` and write its files into ``output_dir``.

    Parameters
    ----------
    scene : Scene, str or Path
        A parsed scene, a shipped scene's name or a scene file.
    output_dir : Path
        Folder for ``accuracy.csv``, ``accuracy.md``, ``accuracy.json``,
        ``work_precision.png`` and ``convergence.png`` (created).
    quick : bool
        The reduced plan (see :func:`study_settings`).
    settings : StudySettings, optional
        A plan of one's own instead of :func:`study_settings`'s.
    repeats : int, optional
        Runs per configuration (the fastest counts), instead of the plan's.
    grid : str, optional
        ``"slices"`` or ``"product"`` (see :func:`build_grid`), instead of the plan's.
    stop_time : float, optional
        Simulated seconds per run instead of the plan's (rounded down to a
        multiple of the output interval).
    fmu_dir : Path
        Where our FMUs are built and cached.
    progress : bool
        A line per run on ``stream`` (stderr).

    Raises
    ------
    SceneError
        The scene or its ``[study]`` table has problems.
    StudyError
        No monolithic reference can be built for the scene.
    """
    started = time.perf_counter()
    scene = load_study_scene(scene)
    settings = settings or study_settings(scene, quick=quick)
    settings = with_stop_time(settings, stop_time)
    settings = replace(settings, repeats=repeats or settings.repeats, grid=grid or settings.grid)
    if settings.grid not in GRIDS:
        raise ValueError(f"grid must be one of {GRIDS}, got {settings.grid!r}")
    base = study_scene(scene, settings)
    with tempfile.TemporaryDirectory(prefix="wire_fmu_study_") as tmp:
        structure = pinned(validate_scene(base, fmu_dir), Path(tmp))
        study = _study(scene.name, base, structure, settings, Path(tmp) / "run", progress, stream)
    study.elapsed = time.perf_counter() - started
    study.files = write_accuracy_files(study, Path(output_dir))
    return study


def _study(
    name: str,
    base: Scene,
    structure: Structure,
    settings: StudySettings,
    workdir: Path,
    progress: bool,
    stream: TextIO | None,
) -> AccuracyStudy:
    grid = build_grid(base, settings)
    report = StudyProgress(len(grid) + _monolithic_runs(base, settings), stream, progress)
    report.note(
        f"study of {name!r}: {len(grid)} runs of {settings.stop_time:g} s, "
        f"reference: monolithic Radau rtol {settings.reference_rtol:g}"
    )
    reference = reference_run(base, settings)
    report.note(
        f"reference: {reference.wall_time:.2f} s wall, {reference.rhs_calls} "
        f"right-hand side calls, {reference.events} events"
    )
    rows = _run_grid(base, structure, grid, reference, settings, workdir, report)
    rows += _monolithic_rows(base, settings, reference, report)
    orders = observed_orders(rows, base, REFERENCE_MARGIN * settings.reference_rtol)
    comparison = equal_error(rows, default_targets(rows))
    return AccuracyStudy(
        name, settings, reference.wall_time / settings.stop_time, rows, orders, comparison
    )


def load_study_scene(scene: Scene | str | Path) -> Scene:
    """A parsed scene from a scene, a shipped name or a file."""
    return scene if isinstance(scene, Scene) else load_scene(find_scene(scene))


def write_csv(rows: Sequence[Any], path: Path) -> Path:
    """Write dataclass rows to ``path`` (header from the fields)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        if not rows:
            return path
        writer = csv.writer(f)
        names = [fl.name for fl in fields(rows[0])]
        writer.writerow(names)
        for r in rows:
            writer.writerow([_cell(getattr(r, n)) for n in names])
    return path


def _cell(value: Any) -> Any:
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    if isinstance(value, tuple | list):
        return " ".join(map(str, value))
    return value


def to_json(value: Any) -> Any:
    """Plain JSON data (NaN and infinity as None)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, tuple | list):
        return [to_json(v) for v in value]
    if isinstance(value, VarRef | Path):
        return str(value)
    if hasattr(value, "__dataclass_fields__"):
        return to_json(asdict(value))
    return value


def dumps(value: Any) -> str:
    """JSON text of study data."""
    return json.dumps(to_json(value), indent=2)


# -------------------------------------------------------------------- reports
def _fmt(value: float, spec: str = ".3g") -> str:
    return "—" if not math.isfinite(value) else format(value, spec)


def _pct(value: float) -> str:
    return "—" if not math.isfinite(value) else f"{100 * value:.0f} %"


def _plan_lines(study: AccuracyStudy) -> list[str]:
    s = study.settings
    steps = ", ".join(f"{h:g}" for h in s.steps)
    return [
        f"# Accuracy study: {study.scene}" + (" (quick)" if s.quick else ""),
        "",
        f"{sum(r.algorithm != 'monolithic' for r in study.rows)} co-simulation runs of "
        f"{s.stop_time:g} s simulated; macro steps {steps} s; errors on a grid of "
        f"{s.output_interval:g} s; key outputs {', '.join(map(str, s.key_outputs))}.",
        f"Reference: the monolithic model, Radau at rtol = atol = {s.reference_rtol:g}: "
        f"**{study.reference_wall_per_sim_s:.3g} s per simulated second** (the dash-dotted "
        "line in the diagram; the monolithic model at looser tolerances is the real floor). "
        "The study took "
        f"{study.elapsed:.0f} s.",
        "",
        "Error: for each key output, the largest deviation from the reference over the run "
        "divided by that output's range in the reference; the run's error is the largest "
        "of these. Cost: wall seconds per simulated second of the stepping phase.",
        "",
    ]


def _order_lines(study: AccuracyStudy) -> list[str]:
    lines = [
        "## Observed convergence orders",
        "",
        f"Slope of log error against log macro step over the runs with an error below "
        f"{ASYMPTOTIC_LIMIT:g} and above {DOMINANCE:g} times the solver's smallest error "
        "(where coupling error dominates).",
        "",
        "| family | theory | observed | runs used | steps used (s) |",
        "|---|---:|---:|---:|---|",
    ]
    for o in study.orders:
        theory = "—" if o.theory is None else str(o.theory)
        used = ", ".join(f"{h:g}" for h in o.steps_used) or o.note
        lines.append(f"| {o.family} | {theory} | {_fmt(o.observed, '.2f')} | {o.points} | {used} |")
    return lines + [""]


def _comparison_lines(study: AccuracyStudy) -> list[str]:
    if not study.comparison:
        return ["## Equal-error comparison", "", "No run finished with a usable error.", ""]
    targets = [c.target for c in study.comparison]
    lines = [
        "## Equal-error comparison",
        "",
        "Wall seconds per simulated second each family needs to reach a target error "
        "(interpolated log-log between its runs; — : not reached on this grid).",
        "",
        "| family | " + " | ".join(f"error {t:.0e}" for t in targets) + " |",
        "|---|" + "---:|" * len(targets),
    ]
    for family in study.comparison[0].costs:
        cells = [_fmt(c.costs[family]) for c in study.comparison]
        lines.append(f"| {family} | " + " | ".join(cells) + " |")
    lines += [
        "| **cheapest** | "
        + " | ".join(
            f"{c.cheapest} ({_fmt(c.cheapest_cost)})" if c.cheapest else "—"
            for c in study.comparison
        )
        + " |",
        "",
    ]
    for c in study.comparison:
        if c.cheapest:
            ratio = c.cheapest_cost / study.reference_wall_per_sim_s
            lines.append(
                f"- error {c.target:.0e}: cheapest **{c.cheapest}**, "
                f"{c.cheapest_cost:.3g} s/s ({ratio:.2g} x the monolithic reference's "
                f"cost); {c.reached()} of {len(c.costs)} families reach it."
            )
    return lines + [""]


def _run_lines(study: AccuracyStudy) -> list[str]:
    lines = [
        "## Runs",
        "",
        "| family | H (s) | status | error | worst output | s/s | doStep | FMU calls | "
        "physics | FMI overhead | master |",
        "|---|---:|---|---:|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in study.rows:
        lines.append(
            f"| {r.family} | {_fmt(r.step, 'g')} | {r.status} | {_fmt(r.error, '.2e')} "
            f"| {r.worst_output} | {_fmt(r.wall_per_sim_s)} | {r.do_step_calls} | "
            f"{r.fmu_calls} | {_pct(r.physics_share)} | {_pct(r.fmi_overhead_share)} | "
            f"{_pct(r.master_share)} |"
        )
    failed = [r for r in study.rows if r.status not in ("finished", "skipped")]
    if failed:
        lines += ["", "### Runs that did not finish or blew up", ""]
        lines += [
            f"- {r.family}, H = {r.step:g} s: {r.status}: {r.message or '(no message)'}"
            for r in failed
        ]
    return lines + [""]


def accuracy_markdown(study: AccuracyStudy) -> str:
    """The summary ``accuracy.md``."""
    files = [
        "",
        "Files: `accuracy.csv` (the table), `accuracy.json`, `work_precision.png`, "
        "`convergence.png`.",
        "",
    ]
    return "\n".join(
        _plan_lines(study)
        + _order_lines(study)
        + _comparison_lines(study)
        + _run_lines(study)
        + files
    )


def _style(study_rows: Sequence[RunRow]):
    solvers = list(dict.fromkeys(r.solver for r in study_rows if r.algorithm != "monolithic"))
    colours = {s: f"C{i % 10}" for i, s in enumerate(solvers)}
    dashes = {"constant": ":", "linear": "-", "quadratic": "--"}
    markers = {"gauss_seidel": "o", "jacobi": "s"}
    return colours, dashes, markers


def _legend(ax, colours, dashes, markers, work_precision: bool) -> None:
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=c, lw=2, label=s) for s, c in colours.items()]
    handles += [Line2D([], [], color="0.3", ls=d, label=e) for e, d in dashes.items()]
    handles += [Line2D([], [], color="0.3", ls="", marker=m, label=a) for a, m in markers.items()]
    if work_precision:
        handles += [
            Line2D([], [], color="k", marker="D", ms=4, label="monolithic, Radau rtol"),
            Line2D(
                [],
                [],
                color="w",
                ls="",
                marker="*",
                ms=11,
                mec="k",
                label="monolithic, unit solver",
            ),
            Line2D([], [], color="k", ls="-.", lw=1, label="monolithic reference"),
        ]
    else:
        handles += [
            Line2D(
                [],
                [],
                color="0.3",
                ls=(0, (1, 3)),
                label="solver's own error\n(monolithic, same solver)",
            )
        ]
    ax.legend(
        handles=handles,
        loc="center left",
        bbox_to_anchor=(1.01, 0.5),
        fontsize="small",
        frameon=False,
    )


def _figure(title: str, xlabel: str, ylabel: str):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 6), dpi=110, layout="constrained")
    ax = fig.add_subplot()
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.25)
    return fig, ax


def _plot_families(ax, study: AccuracyStudy, x_of, y_of, work_precision: bool) -> None:
    colours, dashes, markers = _style(study.rows)
    labelled = False
    for runs in _families(study.rows).values():
        ok = [r for r in runs if r.usable]
        if not ok:
            continue
        first = ok[0]
        if first.family == MONOLITHIC_RADAU:
            ax.plot([x_of(r) for r in ok], [y_of(r) for r in ok], color="k", marker="D", ms=4)
            continue
        if first.algorithm == "monolithic":
            ax.plot(
                [x_of(first)],
                [y_of(first)],
                ls="",
                marker="*",
                ms=11,
                mec="k",
                color=colours.get(first.solver, "k"),
            )
            continue
        ax.plot(
            [x_of(r) for r in ok],
            [y_of(r) for r in ok],
            color=colours[first.solver],
            ls=dashes[first.extrapolation],
            marker=markers[first.algorithm],
            ms=4,
            lw=1.2,
        )
        if work_precision and not labelled:
            for r in ok:
                ax.annotate(
                    f"H={r.step:g}",
                    (x_of(r), y_of(r)),
                    fontsize="x-small",
                    textcoords="offset points",
                    xytext=(4, 4),
                )
            labelled = True
    _legend(ax, colours, dashes, markers, work_precision)


def plot_work_precision(study: AccuracyStudy, path: Path) -> Path:
    """The work-precision diagram: error (x) against wall s per simulated s (y), log-log."""
    fig, ax = _figure(
        f"{study.scene}: what accuracy costs",
        "error (max over key outputs of max |y - y_ref| / range of y_ref)",
        "wall time per simulated second (s/s)",
    )
    _plot_families(ax, study, lambda r: r.error, lambda r: r.wall_per_sim_s, work_precision=True)
    floor = study.reference_wall_per_sim_s
    ax.axhline(floor, color="k", ls="-.", lw=1)
    ax.annotate(
        f"monolithic reference, Radau rtol {study.settings.reference_rtol:g}: {floor:.3g} s/s",
        (0.01, floor),
        xycoords=("axes fraction", "data"),
        fontsize="small",
        textcoords="offset points",
        xytext=(0, 4),
    )
    fig.savefig(path)
    return path


def plot_convergence(study: AccuracyStudy, path: Path) -> Path:
    """Error against macro step for every family, with slope-1 and slope-2 guides."""
    fig, ax = _figure(f"{study.scene}: convergence in the macro step", "macro step H (s)", "error")
    rows = [r for r in study.rows if r.algorithm != "monolithic"]
    _plot_families(
        ax, replace(study, rows=rows), lambda r: r.step, lambda r: r.error, work_precision=False
    )
    colours = _style(study.rows)[0]
    for r in study.rows:
        if r.algorithm == "monolithic" and r.family != MONOLITHIC_RADAU and r.usable:
            ax.axhline(r.error, color=colours.get(r.solver, "k"), ls=(0, (1, 3)), lw=1)
    usable = [r for r in rows if r.usable]
    if usable:
        h = np.array(sorted({r.step for r in usable}))
        anchor = max(r.error for r in usable if r.step == h[-1])
        for order, ls in ((1, (0, (6, 3))), (2, (0, (2, 2)))):
            ax.plot(h, anchor * (h / h[-1]) ** order, color="0.5", ls=ls, lw=1)
            ax.annotate(
                f"order {order}",
                (h[0], anchor * (h[0] / h[-1]) ** order),
                fontsize="small",
                color="0.4",
            )
    fig.savefig(path)
    return path


def write_accuracy_files(study: AccuracyStudy, directory: Path) -> dict[str, Path]:
    """Write the table, the summary, the JSON and both diagrams; return their paths."""
    directory.mkdir(parents=True, exist_ok=True)
    files = {"csv": write_csv(study.rows, directory / "accuracy.csv")}
    files["md"] = directory / "accuracy.md"
    files["md"].write_text(accuracy_markdown(study))
    files["json"] = directory / "accuracy.json"
    files["json"].write_text(
        dumps(
            {
                "scene": study.scene,
                "settings": study.settings,
                "elapsed_s": study.elapsed,
                "reference_wall_per_sim_s": study.reference_wall_per_sim_s,
                "orders": study.orders,
                "equal_error": study.comparison,
                "runs": study.rows,
            }
        )
    )
    files["work_precision"] = plot_work_precision(study, directory / "work_precision.png")
    files["convergence"] = plot_convergence(study, directory / "convergence.png")
    return files


def summary_text(study: AccuracyStudy) -> str:
    """Orders and the equal-error comparison as plain text (for the command line)."""
    lines = [f"observed convergence orders ({study.scene}):"]
    width = max((len(o.family) for o in study.orders), default=10)
    for o in study.orders:
        theory = "-" if o.theory is None else str(o.theory)
        lines.append(
            f"  {o.family:<{width}}  theory {theory}  observed "
            f"{_fmt(o.observed, '.2f'):>5}  ({o.points} runs)"
        )
    lines.append(f"monolithic reference: {study.reference_wall_per_sim_s:.3g} s per simulated s")
    for c in study.comparison:
        if c.cheapest:
            lines.append(
                f"  at error {c.target:.0e}: cheapest {c.cheapest} "
                f"({c.cheapest_cost:.3g} s/s, {c.reached()}/{len(c.costs)} reach it)"
            )
    return "\n".join(lines)
