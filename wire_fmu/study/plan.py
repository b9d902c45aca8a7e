"""The plan of a study: its settings from a scene's ``[study]`` table, and its grid.

:func:`study_settings` reads the plan (key outputs, stop time, macro
steps, output grid, the quick study's window) a scene asks for
(:mod:`~wire_fmu.study.study_table`, :mod:`~wire_fmu.study.window`),
:func:`build_grid` lists the
configurations of the accuracy study (:mod:`wire_fmu.study.accuracy`),
:func:`study_scene` and :func:`configured_scene` set a scene up for the
study and for one configuration; :class:`StudyOptions` are how a study
runs, whatever it varies (shared with :mod:`wire_fmu.study.effects`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, TextIO

from wire_fmu.core.errors import WireFmuError
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.run import find_scene, with_run_settings
from wire_fmu.master.scene import (
    ALGORITHMS,
    EXTRAPOLATIONS,
    Scene,
    VarRef,
    load_scene,
)
from wire_fmu.master.validate import Structure

from .solvers import DEFAULT_SOLVERS, SolverChoice, scene_solver
from .study_table import (
    STUDY_KEYS,
    read_key_outputs,
    read_output_interval,
    read_steps,
    read_study_table,
)
from .window import QUICK_WINDOW, quick_window

__all__ = [
    "StudyError",
    "STUDY_KEYS",
    "DEFAULT_STOP_TIME",
    "QUICK_STOP_TIME",
    "GRIDS",
    "COUPLINGS",
    "DEFAULT_COUPLINGS",
    "parse_couplings",
    "StudySettings",
    "study_settings",
    "with_stop_time",
    "Configuration",
    "family_label",
    "solver_choices",
    "build_grid",
    "study_scene",
    "configured_scene",
    "load_study_scene",
    "StudyOptions",
]

DEFAULT_STOP_TIME = 10.0
"""Study stop time, s, unless ``[study] stop_time`` says otherwise (capped by the scene's)."""

QUICK_STOP_TIME = 1.0
"""Stop time of the quick mode, s (capped by the study's), unless ``[study] quick_window``
names a window (:mod:`wire_fmu.study.window`)."""


class StudyError(WireFmuError):
    """A study cannot be made (no reference, no key outputs, ...)."""


def _coupling(interface: bool, ramped: bool, synchronised: bool) -> dict[str, bool]:
    return {
        "interface_models": interface,
        "ramped_flows": ramped,
        "synchronise_events": synchronised,
    }


COUPLINGS = {
    "held": _coupling(False, False, False),
    "interface": _coupling(True, False, False),
    "ramped": _coupling(False, True, False),
    "interface+ramped": _coupling(True, True, False),
    "synchronised": _coupling(False, False, True),
    "interface+synchronised": _coupling(True, False, True),
    "ramped+synchronised": _coupling(False, True, True),
    "interface+ramped+synchronised": _coupling(True, True, True),
}
"""How the units meet at a bond, by name, as the run settings that make it:

``held``
    every input held (or extrapolated) over the macro step, today's coupling;
``interface``
    the flow side of a bond that offers an interface model integrates its step against
    the effort's local model (``[run] interface_models``);
``ramped``
    the effort side of a bond that takes a flow ramp gets the flow at the step's start
    and its slope over the step instead of its average (``[run] ramped_flows``);
``synchronised``
    a mode change inside a step rolls every unit back to it (``[run] synchronise_events``);
and the combinations joined by ``+``.
"""
DEFAULT_COUPLINGS = (
    "held",
    "interface",
    "ramped",
    "interface+ramped",
    "synchronised",
    "interface+synchronised",
)
"""The couplings a study compares unless told otherwise (those of :data:`COUPLINGS` with
both ramps and synchronisation are left to an explicit choice)."""


def parse_couplings(text: str) -> tuple[str, ...]:
    """Couplings named on a command line: keys of :data:`COUPLINGS`, comma-separated, or ``all``.

    Parameters
    ----------
    text : str
        For example ``"held,ramped,interface+ramped"``.

    Returns
    -------
    tuple of str
        The keys, in the order given, each once.

    Raises
    ------
    ValueError
        Naming every unknown key at once, and the known ones.
    """
    if text.strip() == "all":
        return tuple(COUPLINGS)
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in COUPLINGS]
    if unknown or not names:
        said = f"unknown {', '.join(repr(n) for n in unknown)}" if unknown else "none given"
        raise ValueError(
            f"couplings: {said}; give keys of {', '.join(COUPLINGS)} joined by commas, or all"
        )
    return tuple(dict.fromkeys(names))


GRIDS = ("slices", "product")
"""``slices``: every coupling with the scene's own solvers, and every solver with the
scene's own coupling; ``product``: every coupling with every solver."""


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
    couplings : tuple of str
        Keys of :data:`COUPLINGS` besides the scene's own; ``interface`` ones only where a
        bond offers an interface model.
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
    window_start : float
        Start of the compared window, s: every run starts at 0 s and stops at
        ``stop_time``; samples before ``window_start`` are not compared
        (:mod:`wire_fmu.study.window`).
    """

    key_outputs: tuple[VarRef, ...]
    stop_time: float
    steps: tuple[float, ...]
    output_interval: float
    algorithms: tuple[str, ...] = ALGORITHMS
    extrapolations: tuple[str, ...] = EXTRAPOLATIONS
    couplings: tuple[str, ...] = DEFAULT_COUPLINGS
    solvers: tuple[SolverChoice, ...] = DEFAULT_SOLVERS
    grid: str = "slices"
    reference_rtol: float = 1e-10
    monolithic_rtols: tuple[float, ...] = (1e-4, 1e-6, 1e-8)
    run_budget: float = 60.0
    solver_floors: bool = True
    repeats: int = 1
    quick: bool = False
    window_start: float = 0.0

    @property
    def window(self) -> tuple[float, float]:
        """The compared window, ``(window_start, stop_time)`` in s."""
        return self.window_start, self.stop_time


def _on_grid(stop: float, interval: float) -> float:
    """``stop`` rounded down to a multiple of ``interval`` (at least one interval), s."""
    return max(1, math.floor(stop / interval + 1e-9)) * interval


def study_settings(scene: Scene, *, quick: bool = False) -> StudySettings:
    """The study plan for ``scene``: its ``[study]`` table, else defaults.

    Parameters
    ----------
    scene : Scene
        The scene; its optional ``[study]`` table may give ``key_outputs``,
        ``stop_time``, ``steps``, ``output_interval`` and ``quick_window``.
    quick : bool
        The reduced plan for CI: three macro steps, constant and linear
        extrapolation, the scene's own solvers only, no monolithic curve,
        over the scene's ``quick_window`` (runs from 0 s to its end, samples
        compared within it), else the first :data:`QUICK_STOP_TIME` seconds.

    Raises
    ------
    SceneError
        Listing the problems of the ``[study]`` table.
    """
    table = read_study_table(scene)
    keys = read_key_outputs(scene, table)
    steps = read_steps(scene, table, quick)
    interval = read_output_interval(scene, table, steps)
    window = quick_window(scene, table, interval)
    stop = float(table.get("stop_time", min(scene.run.stop_time, DEFAULT_STOP_TIME)))
    start = 0.0
    if quick:
        start, stop = window if window is not None else (0.0, min(stop, QUICK_STOP_TIME))
    settings = StudySettings(keys, _on_grid(stop, interval), steps, interval, window_start=start)
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
    """``settings`` with another stop time (a multiple of the output interval); None: as is.

    The window keeps its start: a quick study of a window ``[a, b]`` given
    ``stop_time`` compares ``[a, stop_time]``.

    Parameters
    ----------
    settings : StudySettings
        The plan.
    stop_time : float or None
        Simulated time per run, s, rounded down to a multiple of the output
        interval (at least one interval).

    Raises
    ------
    ValueError
        If ``stop_time`` is not a positive finite number.
    StudyError
        If it leaves fewer than two samples after the window's start.
    """
    if stop_time is None:
        return settings
    if not (math.isfinite(stop_time) and stop_time > 0):
        raise ValueError(f"stop_time must be a positive number of seconds, got {stop_time!r}")
    stop = _on_grid(stop_time, settings.output_interval)
    if stop < settings.window_start + settings.output_interval * (1.0 - 1e-9):
        raise StudyError(
            f"a stop time of {stop_time:g} s leaves no window to compare: the study's window "
            f"starts at {settings.window_start:g} s ([study] {QUICK_WINDOW}); give a stop "
            f"time of at least {settings.window_start + settings.output_interval:g} s, or none"
        )
    return replace(settings, stop_time=stop)


# ----------------------------------------------------------------------- the grid
@dataclass(frozen=True)
class Configuration:
    """One run of the grid."""

    algorithm: str
    extrapolation: str
    step: float
    solver: SolverChoice
    coupling: str = "held"

    @property
    def family(self) -> str:
        """The family label: everything but the macro step."""
        return family_label(self.algorithm, self.extrapolation, self.solver.label, self.coupling)


def family_label(algorithm: str, extrapolation: str, solver: str, coupling: str = "held") -> str:
    """``"gauss_seidel / linear / ros2 h=1e-3"``, with `` / interface`` (etc.) appended.

    Parameters
    ----------
    algorithm, extrapolation : str
        The coupling scheme.
    solver : str
        The solver choice's label.
    coupling : str
        A key of :data:`COUPLINGS`; ``held`` is not written.
    """
    label = f"{algorithm} / {extrapolation} / {solver}"
    return label if coupling == "held" else f"{label} / {coupling}"


def scene_coupling(scene: Scene) -> str:
    """The key of :data:`COUPLINGS` the scene's own run settings make.

    Parameters
    ----------
    scene : Scene
        The scene.
    """
    run = scene.run
    own = _coupling(run.interface_models, run.ramped_flows, run.synchronise_events)
    return next(k for k, settings in COUPLINGS.items() if settings == own)


def coupling_choices(scene: Scene, settings: StudySettings) -> list[str]:
    """The scene's own coupling, then every other of the plan that would change a run.

    ``interface`` couplings need a bond whose two ports offer an interface model,
    ``ramped`` ones a bond whose effort side takes a flow ramp.

    Parameters
    ----------
    scene : Scene
        The study scene.
    settings : StudySettings
        The plan, with its couplings.
    """
    own = scene_coupling(scene)
    offered = {
        "interface_models": any(b.interface for b in scene.bonds),
        "ramped_flows": any(b.ramp is not None for b in scene.bonds),
        "synchronise_events": True,
    }
    out = [own]
    for name in settings.couplings:
        wanted = [key for key, on in COUPLINGS[name].items() if on]
        if name not in out and all(offered[key] for key in wanted):
            out.append(name)
    return out


def solver_choices(scene: Scene, settings: StudySettings) -> list[SolverChoice]:
    """The scene's own solvers, then every choice of the plan that differs and applies.

    Parameters
    ----------
    scene : Scene
        The study scene.
    settings : StudySettings
        The plan, with its solver choices.
    """
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
    scene's own solvers and coupling (:data:`COUPLINGS`), then every other
    coupling with every algorithm and the scene's own extrapolation and solvers,
    then every other solver with the scene's own algorithm, extrapolation and
    coupling; ``product``: every combination.

    Parameters
    ----------
    scene : Scene
        The study scene (its own coupling and solvers).
    settings : StudySettings
        The plan: algorithms, extrapolations, couplings, macro steps, solvers, grid.
    """
    solvers = solver_choices(scene, settings)
    couplings = [(a, e) for a in settings.algorithms for e in settings.extrapolations]
    if settings.grid == "product":
        return [
            Configuration(a, e, h, s, c)
            for c in coupling_choices(scene, settings)
            for s in solvers
            for a, e in couplings
            for h in settings.steps
        ]
    mine, *others = coupling_choices(scene, settings)
    own = [Configuration(a, e, h, solvers[0], mine) for a, e in couplings for h in settings.steps]
    run = scene.run
    return (
        own
        + [
            Configuration(a, run.extrapolation, h, solvers[0], c)
            for c in others
            for a in settings.algorithms
            for h in settings.steps
        ]
        + [
            Configuration(run.algorithm, run.extrapolation, h, s, mine)
            for s in solvers[1:]
            for h in settings.steps
        ]
    )


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
    """The scene as every run of the study sees it: stop time, grid, key outputs recorded.

    Parameters
    ----------
    scene : Scene
        The scene as given.
    settings : StudySettings
        Stop time (s), output interval (s) and key outputs of the study.
    """
    scene = with_run_settings(
        scene,
        stop_time=settings.stop_time,
        output_interval=settings.output_interval,
        adaptive=False,
    )
    return replace(scene, outputs=settings.key_outputs)


def coupled_scene(scene: Scene, coupling: str) -> Scene:
    """A copy of ``scene`` with the run settings of ``coupling`` (its bonds wired by them).

    Parameters
    ----------
    scene : Scene
        The scene.
    coupling : str
        A key of :data:`COUPLINGS`.
    """
    return with_run_settings(scene, **COUPLINGS[coupling])


def configured_scene(
    scene: Scene, config: Configuration, structure: Structure | None = None
) -> Scene:
    """A copy of a study scene set up for ``config`` (parameters deep-copied).

    Parameters
    ----------
    scene : Scene
        A study scene (see :func:`study_scene`).
    config : Configuration
        Coupling, macro step and solver of the run.
    structure : Structure, optional
        The validated scene: the solver parameters go only to units that
        have a ``solver`` variable (without it, to every unit).
    """
    scene = with_run_settings(
        scene,
        step=config.step,
        algorithm=config.algorithm,
        extrapolation=config.extrapolation,
        **COUPLINGS[config.coupling],
    )
    return replace(scene, units=_solver_parameters(scene, structure, config.solver))


def load_study_scene(scene: Scene | str | Path) -> Scene:
    """A parsed scene from a scene, a shipped name or a file.

    Parameters
    ----------
    scene : Scene, str or Path
        A parsed scene (returned as is), a shipped scene's name or a scene file.
    """
    return scene if isinstance(scene, Scene) else load_scene(find_scene(scene))


@dataclass(frozen=True)
class StudyOptions:
    """How a study runs, whatever it varies (the accuracy and the effects study).

    Parameters
    ----------
    quick : bool
        The reduced plan for CI (see :func:`study_settings`): short stop
        time, few configurations, one run per case.
    settings : StudySettings, optional
        A plan of one's own (key outputs, stop time, ...) instead of
        :func:`study_settings`'s.
    repeats : int, optional
        Runs per configuration or case, the fastest counts; None: the
        study's default.
    stop_time : float, optional
        Simulated time per run instead of the plan's, s (rounded down to a
        multiple of the output interval).
    fmu_dir : Path
        Where our FMUs are built and cached.
    progress : bool
        A line per run on ``stream``.
    stream : text stream, optional
        For the progress lines (stderr by default).
    """

    quick: bool = False
    settings: StudySettings | None = None
    repeats: int | None = None
    stop_time: float | None = None
    fmu_dir: Path = DEFAULT_FMU_DIR
    progress: bool = True
    stream: TextIO | None = None

    def prepare(self, scene: Scene | str | Path) -> tuple[Scene, StudySettings]:
        """The parsed scene and the study's plan for it (its own or this one's settings).

        Parameters
        ----------
        scene : Scene, str or Path
            A parsed scene, a shipped scene's name or a scene file.

        Raises
        ------
        SceneError
            The scene or its ``[study]`` table has problems.
        StudyError
            The plan's window holds fewer than two samples.
        """
        scene = load_study_scene(scene)
        settings = self.settings or study_settings(scene, quick=self.quick)
        try:
            settings = with_stop_time(settings, self.stop_time)
        except StudyError as exc:
            raise StudyError(f"scene {scene.name!r}: {exc}") from None
        start, stop = settings.window
        if not 0.0 <= start <= stop - settings.output_interval * (1.0 - 1e-9):
            raise StudyError(
                f"scene {scene.name!r}: the study's window [{start:g}, {stop:g}] s holds "
                f"fewer than two samples of its {settings.output_interval:g} s grid"
            )
        return scene, settings
