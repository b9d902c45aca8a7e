"""Running a scene from Python in a few lines.

>>> from wire_fmu.master.run import run_scene          # doctest: +SKIP
>>> outcome = run_scene("riser_tensioner")             # doctest: +SKIP
>>> outcome.csv_path                                   # doctest: +SKIP
>>> frame = outcome.frame()                            # doctest: +SKIP
>>> frame.attrs["units"]["rope.path_end.tension"]      # doctest: +SKIP
'N'

A scene is named (one we ship, see :func:`shipped_scenes`) or given by path.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from .catalog import DEFAULT_FMU_DIR
from .observers import FLUSH_EVERY, CsvRecorder, Progress
from .results_frame import IncompleteResultsWarning, ResultsError, read_results_frame
from .run_result import RunResult
from .scene import Scene, SceneError, late_event_warnings, read_scene
from .simulation import Simulation
from .validate import validate_scene

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "SCENE_DIR",
    "shipped_scenes",
    "find_scene",
    "run_scene",
    "with_run_settings",
    "Outcome",
    "load_scene_file",
    "read_scene_file",
    "check_scene",
    "read_results_frame",
    "ResultsError",
    "IncompleteResultsWarning",
]

logger = logging.getLogger(__name__)

SCENE_DIR = Path(__file__).resolve().parents[1] / "scenes"


def shipped_scenes() -> dict[str, Path]:
    """Scenes we ship, by name."""
    return {p.stem: p for p in sorted(SCENE_DIR.glob("*.toml"))}


def find_scene(name_or_path: str | Path) -> Path:
    """The scene file for a shipped name or a path.

    Parameters
    ----------
    name_or_path : str or Path
        A shipped scene's name (see :func:`shipped_scenes`) or a scene file.

    Raises
    ------
    SceneError
        Naming the shipped scenes when neither matches.
    """
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists():
        if not path.exists():
            raise SceneError(str(path), ["no such scene file"])
        return path
    shipped = shipped_scenes()
    if str(name_or_path) in shipped:
        return shipped[str(name_or_path)]
    raise SceneError(
        str(name_or_path),
        [f"not a shipped scene nor a file; shipped scenes: {', '.join(shipped) or 'none'}"],
    )


def load_scene_file(path: Path) -> Scene:
    """A scene file (TOML) or an SSP package (``.ssp``, see :mod:`wire_fmu.interop.ssp_read`).

    Parameters
    ----------
    path : Path
        The file.

    Raises
    ------
    SceneError
        Listing every problem of the scene's data.
    """
    scene, problems = read_scene_file(path)
    if problems:
        raise SceneError(f"scene {scene.name!r}" if scene else str(path), problems)
    return scene


def read_scene_file(path: Path) -> tuple[Scene | None, list[str]]:
    """A scene file or an SSP package and its problems (see :func:`~.scene.read_scene`).

    Parameters
    ----------
    path : Path
        A scene file (TOML) or an SSP package (``.ssp``).

    Returns
    -------
    scene : Scene or None
        The scene (None if it cannot be read at all).
    problems : list of str
        Every problem of its data; empty if none.
    """
    if Path(path).suffix.lower() == ".ssp":
        from wire_fmu.interop.ssp_read import read_ssp

        try:
            return read_ssp(Path(path)), []
        except SceneError as err:
            return None, [f"{err.where}: {p}" for p in err.problems]
    return read_scene(path)


def check_scene(
    scene: str | Path | Scene, fmu_dir: Path = DEFAULT_FMU_DIR, *, dry_run: bool = True
) -> Scene:
    """Every problem a run would refuse, found before anything steps.

    The scene's data, its structure against the units' model descriptions,
    each unit's own check of its parameters and (``dry_run``) the
    initialisation of every unit as a run does it.

    Parameters
    ----------
    scene : str, Path or Scene
        A shipped scene's name, a scene file or SSP package, or a parsed scene.
    fmu_dir : Path
        Where our FMUs are built and cached.
    dry_run : bool
        Also instantiate and initialise every unit as a run does.

    Returns
    -------
    Scene
        The scene, checked.

    Raises
    ------
    SceneError
        Listing every problem, each once.
    """
    problems: list[str] = []
    if not isinstance(scene, Scene):
        path = find_scene(scene)
        scene, problems = read_scene_file(path)
        if scene is None:
            raise SceneError(str(path), problems)
    validate_scene(scene, fmu_dir, dry_run=dry_run, problems=problems)
    return scene


@dataclass
class Outcome:
    """What a run produced."""

    scene: Scene
    result: RunResult
    directory: Path
    csv_path: Path
    plots: list[Path] = field(default_factory=list)
    simulation: Simulation | None = None

    def frame(self) -> pd.DataFrame:
        """The run's results as a DataFrame indexed by time (s), with units.

        Returns
        -------
        pandas.DataFrame
            One column per recorded column, ``attrs["units"]`` the unit of each
            (see :func:`~wire_fmu.master.results_frame.read_results_frame`).

        Raises
        ------
        ResultsError
            When the run recorded nothing (it failed in its initialisation).

        Warns
        -----
        IncompleteResultsWarning
            When the run did not finish: the rows it recorded are read.
        """
        return read_results_frame(self.directory)


def with_run_settings(scene: Scene, **changes) -> Scene:
    """A copy of ``scene`` with some run settings replaced (checked like the file's).

    Parameters
    ----------
    scene : Scene
        The scene.
    **changes
        Run settings by name (see :class:`~.scene.RunSettings`), e.g.
        ``stop_time=5.0`` (s); a None value keeps the scene's setting.

    Raises
    ------
    SceneError
        Listing every problem of the new settings.
    """
    from .scene.checks import _check_run

    settings = replace(scene.run, **{k: v for k, v in changes.items() if v is not None})
    problems: list[str] = []
    _check_run(settings, problems)
    if problems:
        raise SceneError(f"scene {scene.name!r}", problems)
    return replace(scene, run=settings)


def run_scene(
    scene: str | Path | Scene,
    results: Path | None = None,
    *,
    progress: bool = False,
    plots: bool = True,
    fmu_dir: str | Path = DEFAULT_FMU_DIR,
    observers=(),
    flush_every: float = FLUSH_EVERY,
    **run_overrides,
) -> Outcome:
    """Validate and run a scene; write results (and plots) to ``results``.

    Parameters
    ----------
    scene : str, Path or Scene
        A shipped scene's name, a scene file, or a parsed scene.
    results : Path, optional
        Results folder (default ``results/<scene name>`` in the working folder).
    progress : bool
        Show a progress bar on stderr.
    plots : bool
        Draw the scene's plots as PNG files after the run.
    fmu_dir : str or Path
        Where our FMUs are built and cached.
    observers : sequence
        More observers (see :class:`~wire_fmu.master.observers.Observer`).
    flush_every : float
        Longest wall-clock time recorded rows wait before they are written, s
        (:class:`~wire_fmu.master.observers.CsvRecorder`; ``math.inf``: at the end).
    **run_overrides
        Replace run settings of the scene, e.g. ``stop_time=5.0`` for a quick run.

    Returns
    -------
    Outcome
        The scene run, its result, the results folder and files, the simulation.
    """
    problems: list[str] = []
    if not isinstance(scene, Scene):
        path = find_scene(scene)
        scene, problems = read_scene_file(path)
        if scene is None:
            raise SceneError(str(path), problems)
    if run_overrides:
        scene, problems = _with_overrides(scene, run_overrides, problems)
    if problems:  # with the problems the units find, before a results folder is made
        validate_scene(scene, Path(fmu_dir), problems=problems)  # raises: there are problems
    directory = Path(results) if results else Path("results") / scene.name
    make_results_folder(directory)
    with WarningLog() as said:
        structure = validate_scene(scene, Path(fmu_dir))
        for warning in late_event_warnings(scene):
            logger.warning("%s", warning)
        recorder = CsvRecorder(directory, scene.run.output_interval, flush_every)
        chain = [recorder, *observers] + ([Progress()] if progress else [])
        sim = Simulation(scene, structure, chain)
        result = sim.run()
        outcome = Outcome(scene, result, directory, recorder.csv_path, simulation=sim)
        if plots and scene.plots:
            outcome.plots = _plots(scene, recorder.csv_path, directory)
    note_warnings(recorder.meta_path, said.messages)
    return outcome


def _with_overrides(scene: Scene, overrides: dict, problems: list[str]) -> tuple[Scene, list[str]]:
    """:func:`with_run_settings`, its problems added to ``problems`` (the scene's own kept)."""
    try:
        return with_run_settings(scene, **overrides), problems
    except SceneError as err:
        return scene, problems + err.problems


class WarningLog(logging.Handler):
    """Collects what the package's loggers warn about while it is entered (``messages``).

    Attributes
    ----------
    messages : list of dict
        Each warning as ``{"level", "source", "message"}``, in order, once each.
    """

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[dict[str, str]] = []

    def emit(self, record: logging.LogRecord) -> None:
        """Keep the record's level, logger name and message (repeats kept once).

        Parameters
        ----------
        record : logging.LogRecord
            A warning or worse from a ``wire_fmu`` logger.
        """
        entry = {
            "level": record.levelname.lower(),
            "source": record.name,
            "message": record.getMessage(),
        }
        if entry not in self.messages:
            self.messages.append(entry)

    def __enter__(self) -> WarningLog:
        logging.getLogger("wire_fmu").addHandler(self)
        return self

    def __exit__(self, *exc: object) -> None:
        logging.getLogger("wire_fmu").removeHandler(self)


def note_warnings(meta_path: Path, messages: list[dict[str, str]]) -> None:
    """Add the run's warnings to its ``metadata.json`` (``"warnings"``), if it was written.

    Parameters
    ----------
    meta_path : Path
        The run's ``metadata.json``.
    messages : list of dict
        The warnings (:class:`WarningLog`).
    """
    try:
        meta = json.loads(Path(meta_path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return
    meta["warnings"] = messages
    Path(meta_path).write_text(json.dumps(meta, indent=2, default=str) + "\n")


def make_results_folder(directory: Path) -> Path:
    """Create ``directory`` (and its parents) for results, or say why it cannot be.

    Parameters
    ----------
    directory : Path
        The results folder.

    Returns
    -------
    Path
        ``directory``.

    Raises
    ------
    SceneError
        When it is a file, a device, or cannot be created.
    """
    try:
        Path(directory).mkdir(parents=True, exist_ok=True)
    except OSError as err:
        reason = err.strerror or type(err).__name__
        raise SceneError(str(directory), [f"cannot be the results folder: {reason}"]) from None
    return Path(directory)


def _plots(scene: Scene, csv_path: Path, directory: Path) -> list[Path]:
    """The scene's plots of what was recorded; none (with a warning) if nothing was."""
    if not csv_path.is_file():
        logger.info("no plots: nothing was recorded (the run ended before its first step)")
        return []
    from .plots import plot_scene

    try:
        return plot_scene(scene, csv_path, directory)
    except Exception as exc:  # noqa: BLE001 - the run's results stand without their plots
        logger.warning("the plots could not be drawn: %s", exc)
        logger.debug("plot failure", exc_info=True)
        return []
