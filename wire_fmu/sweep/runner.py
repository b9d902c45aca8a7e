"""Running a sweep: every case a co-simulation run, on dask.distributed or serially.

:func:`run_sweep` expands the spec into cases, builds our FMUs once (in
this, the client, process), reads what an earlier invocation left in the
output folder and runs only the cases missing there:

* ``workers=N`` (default 2): a :class:`distributed.LocalCluster` on this
  machine, N worker processes of one thread each, nothing to set up;
* ``scheduler="tcp://host:8786"``: an existing cluster (see docs/sweeps.md);
* ``workers=0``: one case after the other in this process, no Dask (the
  reference the parallel runs are compared with).

Each worker process loads its own FMUs: the client sends each FMU file's
bytes to the workers once (``scatter``, broadcast), a worker writes them
into its local folder under their SHA-256 and runs the case with
:func:`~wire_fmu.master.run.run_scene` in a temporary folder, then returns
the status, the key figures and the folder's files to the client, which
writes them (:class:`~wire_fmu.sweep.results.ResultStore`) as each case
finishes (``as_completed``). Workers need no shared file system.

Nothing is lost:

* a case whose run raises one of our errors (a unit refuses its
  parameters, a scene problem) is recorded as ``failed`` with the message;
  a run that a unit stopped is recorded as ``stopped`` with its message and
  the figures of what was recorded; the sweep goes on;
* an unexpected exception in a worker is retried by Dask (``retries``),
  then recorded as ``failed``;
* a case whose worker died is rescheduled by Dask itself (up to its
  ``allowed-failures``); if Dask gives up (``KilledWorker``) the client
  submits it again, up to ``max_attempts`` times, then records it as
  ``lost``; after the last case the client checks that every submitted
  case has a record and runs any that has not once more;
* an interrupted sweep keeps every finished case; the next invocation with
  the same output folder runs only the cases without a record (and the
  ``lost`` ones; with ``rerun_failed`` also ``failed`` and ``stopped``).

Modules: :mod:`~wire_fmu.sweep.worker` (what a worker runs),
:mod:`~wire_fmu.sweep.cluster` (Dask), this one (the sweep).
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import logging
import sys
import time
import zipfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import wire_fmu
from wire_fmu._fingerprint import fingerprint, package_dir
from wire_fmu.core.errors import WireFmuError
from wire_fmu.export.guard import BUILD_INFO_FILE
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.run import find_scene
from wire_fmu.master.scene import Scene, load_scene
from wire_fmu.master.validate import Structure, check_structure, resolve_units

from .cases import Case, apply_case, expand, target_problems, with_figures_recorded
from .cluster import _check_workers, _client, _run_on_dask, scheduler_problem
from .figures import Figure
from .results import DONE_STATUSES, CaseOutcome, ResultStore, plot_summary
from .spec import SweepError, SweepSpec, SweepSpecError, load_sweep_spec
from .units import case_metadata, sweep_units
from .worker import CaseTask, _describe, _execute_here

__all__ = ["run_sweep", "load_sweep", "SweepResult", "ProgressWriter", "scene_key"]

logger = logging.getLogger(__name__)

CaseCallback = Callable[[dict[str, Any]], None]


# -- progress ------------------------------------------------------------------------------
class ProgressWriter:
    """One line per finished case on a stream (stderr by default), with an estimate of the rest.

    Parameters
    ----------
    total : int
        Cases in the sweep.
    done : int
        Cases already on disk.
    stream : text stream, optional
        Where to write.
    """

    def __init__(self, total: int, done: int, stream: TextIO | None = None) -> None:
        self.total, self.done, self.initial = total, done, done
        self.stream = stream or sys.stderr
        self.start = time.perf_counter()
        self.width = len(str(total))

    def restart_clock(self) -> None:
        """Estimate the rest from now on (after the cluster started)."""
        self.start = time.perf_counter()

    def note(self, text: str) -> None:
        """A free line.

        Parameters
        ----------
        text : str
            The line (without its newline).
        """
        self.stream.write(text + "\n")
        self.stream.flush()

    def case(self, case: Case, row: Mapping[str, Any]) -> None:
        """The line of a finished case.

        Parameters
        ----------
        case : Case
            The case.
        row : mapping
            Its summary row (status, wall time in s, error).
        """
        self.done += 1
        ran = self.done - self.initial
        elapsed = time.perf_counter() - self.start
        left = (self.total - self.done) * elapsed / ran if ran else 0.0
        error = (row.get("error") or "").strip().splitlines()
        why = f"  ({error[0][:100]})" if error else ""
        self.note(
            f"[{self.done:>{self.width}}/{self.total}] {case.case_id} "
            f"{row['status']:<8} {row['wall_time'] or 0.0:6.2f} s  {case.label()}{why}"
            f"  ~{left:.0f} s left"
        )


# -- the sweep --------------------------------------------------------------------------------
@dataclass(frozen=True)
class SweepResult:
    """What :func:`run_sweep` did.

    Attributes
    ----------
    directory : Path
        The output folder.
    summary_path : Path
        ``summary.parquet``.
    rows : list of dict
        The summary rows, one per case, in case order.
    plots : list of Path
        PNG files of the key figures.
    executed : int
        Cases run by this invocation.
    reused : int
        Cases found on disk and not run again.
    wall_time : float
        Seconds for the whole invocation.
    startup_time : float
        Seconds to start (or reach) the cluster and check its workers.
    """

    directory: Path
    summary_path: Path
    rows: list[dict[str, Any]]
    plots: list[Path]
    executed: int
    reused: int
    wall_time: float
    startup_time: float = 0.0

    @property
    def counts(self) -> dict[str, int]:
        """Number of cases per status."""
        out: dict[str, int] = {}
        for row in self.rows:
            out[row["status"]] = out.get(row["status"], 0) + 1
        return out

    @property
    def complete(self) -> bool:
        """Whether every case finished."""
        return all(r["status"] == "finished" for r in self.rows)


def scene_key(scene: Scene) -> str:
    """Hash of what a scene asks for (not where its file is): results of one scene only.

    Parameters
    ----------
    scene : Scene
        The parsed scene.
    """
    normal = dataclasses.replace(scene, base_dir=Path("."), source=None)
    return hashlib.sha256(repr(normal).encode("utf-8")).hexdigest()[:16]


def _load(
    scene: str | Path | Scene, spec: str | Path | SweepSpec, fmu_dir: Path
) -> tuple[Scene, SweepSpec]:
    if not isinstance(scene, Scene):
        scene = load_scene(find_scene(scene))
    if not isinstance(spec, SweepSpec):
        spec = load_sweep(scene, Path(spec), fmu_dir)
    return scene, spec


def load_sweep(scene: Scene, path: Path, fmu_dir: Path = DEFAULT_FMU_DIR) -> SweepSpec:
    """Read the sweep spec at ``path``; if it has problems, say those of sweeping ``scene`` too.

    A spec with problems of its own (a bad value list, an unknown function) is
    also checked against the scene, as far as it can be: its well-formed targets
    and its key figures (:func:`~wire_fmu.sweep.cases.target_problems`), and the
    scene's units. Every problem is then said at once.

    Parameters
    ----------
    scene : Scene
        The scene to sweep.
    path : Path
        The spec file.
    fmu_dir : Path
        Where our FMUs are built and cached.

    Raises
    ------
    SweepSpecError
        Every problem of the spec and, if it has any, of sweeping ``scene`` with it.
    """
    try:
        return load_sweep_spec(path)
    except SweepSpecError as err:
        if not (err.targets or err.figures):  # unreadable, or nothing to check
            raise
        _, more = _scene_problems(scene, err.targets, err.figures, fmu_dir)
        if not more:
            raise
        raise SweepSpecError(
            f"{err.where} for scene {scene.name!r}", [*err.problems, *more]
        ) from None


def _scene_problems(
    scene: Scene, targets: Sequence[str], figures: Sequence[Figure], fmu_dir: Path
) -> tuple[Structure, list[str]]:
    """The scene's units built and checked, and the targets and figure columns it lacks."""
    structure, problems = resolve_units(scene, fmu_dir)
    if not problems:
        problems += check_structure(scene, structure) + _stale_fmus(structure)
    problems += target_problems(targets, figures, scene, structure if not problems else None)
    return structure, problems


def _prepare(scene: Scene, spec: SweepSpec, fmu_dir: Path) -> Scene:
    """Build our FMUs once, check the scene and the spec's targets; units given by file.

    Raises
    ------
    SweepSpecError
        Every problem of the scene's structure and of the spec's targets.
    """
    targets = [a.target for a in spec.axes]
    structure, problems = _scene_problems(scene, targets, spec.figures, fmu_dir)
    if problems:
        raise SweepSpecError(f"sweep {spec.name!r} of scene {scene.name!r}", problems)
    units = {
        name: dataclasses.replace(u, fmu=str(structure.paths[name].resolve()))
        for name, u in scene.units.items()
    }
    return with_figures_recorded(dataclasses.replace(scene, units=units), spec.figures)


def _built_core(path: Path) -> str | None:
    """Core fingerprint an FMU of ours records (None for FMUs not built by wire_fmu)."""
    try:
        with zipfile.ZipFile(path) as archive:
            names = [n for n in archive.namelist() if n.endswith(BUILD_INFO_FILE)]
            return json.loads(archive.read(names[0]))["fingerprint"] if names else None
    except (OSError, zipfile.BadZipFile, KeyError, ValueError):
        return None


def _stale_fmus(structure: Structure) -> list[str]:
    """FMUs built from another core than this one: every worker would refuse them."""
    current = fingerprint(package_dir())
    problems = []
    for unit, path in structure.paths.items():
        built = _built_core(path)
        if built is not None and built != current:
            problems.append(
                f"unit {unit!r}: {path} was built from another wire_fmu core "
                f"({built[:12]}, this one is {current[:12]}); rebuild it"
            )
    return problems


def _manifest(scene: Scene, spec: SweepSpec, cases: Sequence[Case]) -> dict[str, Any]:
    return {
        "scene": scene.name,
        "scene_key": scene_key(scene),
        "scene_file": str(scene.source) if scene.source else None,
        "spec_name": spec.name,
        "spec_file": str(spec.source) if spec.source else None,
        "spec": copy.deepcopy(dict(spec.data)),
        "cases": len(cases),
        "wire_fmu": wire_fmu.__version__,
        "core": fingerprint(package_dir())[:16],
    }


def _to_run(cases: Sequence[Case], records: Mapping[str, dict], rerun_failed: bool) -> list[Case]:
    keep = {"finished"} if rerun_failed else DONE_STATUSES
    return [c for c in cases if records.get(c.case_id, {}).get("status") not in keep]


def _tasks(
    base: Scene, spec: SweepSpec, cases: Sequence[Case], sink: Callable[[CaseOutcome], None]
) -> list[CaseTask]:
    """Tasks of the cases; a case whose values cannot be applied is recorded as failed."""
    tasks = []
    for case in cases:
        try:
            tasks.append(CaseTask(case, apply_case(base, case.values), spec.figures))
        except WireFmuError as exc:
            sink(CaseOutcome(case.case_id, "failed", _describe(exc), worker="client"))
    return tasks


def run_sweep(
    scene: str | Path | Scene,
    spec: str | Path | SweepSpec,
    out_dir: Path,
    workers: int = 2,
    scheduler: str | None = None,
    *,
    fmu_dir: Path = DEFAULT_FMU_DIR,
    progress: bool = True,
    rerun_failed: bool = False,
    retries: int = 1,
    max_attempts: int = 3,
    plots: bool = True,
    on_case: CaseCallback | None = None,
    stream: TextIO | None = None,
) -> SweepResult:
    """Run every case of a sweep that the output folder does not hold yet.

    Parameters
    ----------
    scene : str, Path or Scene
        A shipped scene's name, a scene file or a parsed scene.
    spec : str, Path or SweepSpec
        The sweep spec file or a parsed spec.
    out_dir : Path
        Output folder (see :mod:`wire_fmu.sweep.results`); an existing one of
        the same scene is resumed.
    workers : int
        Worker processes of the local cluster; 0 runs the cases in this
        process without Dask. Ignored with ``scheduler``.
    scheduler : str, optional
        Address of an existing Dask scheduler, e.g. ``"tcp://10.0.0.5:8786"``.
    fmu_dir : Path
        Where our FMUs are built and cached.
    progress : bool
        A line per finished case on ``stream``.
    rerun_failed : bool
        Also run again the cases recorded as ``failed`` or ``stopped``.
    retries : int
        Dask retries of a task that raised an unexpected exception.
    max_attempts : int
        Submissions of a case whose workers keep dying before it is ``lost``.
    plots : bool
        Draw each key figure against the swept parameters (PNG).
    on_case : callable, optional
        Called with each case's summary row right after it is written.
    stream : text stream, optional
        For the progress lines (stderr by default).

    Returns
    -------
    SweepResult

    Raises
    ------
    SweepSpecError
        The spec's targets or figures do not fit the scene (every problem).
    SweepError
        A count of workers below 0 or a scheduler address of the wrong form
        (said before anything runs); the output folder holds another scene's
        sweep; no scheduler answers; workers that cannot run this version of
        wire_fmu.
    """
    wall = time.perf_counter()
    _check_options(workers, scheduler)
    scene, spec = _load(scene, spec, fmu_dir)
    cases = expand(spec)
    base = _prepare(scene, spec, fmu_dir)
    store = ResultStore(out_dir, spec, cases)
    todo = _to_run(cases, store.open(_manifest(scene, spec, cases)), rerun_failed)
    reused = len(cases) - len(todo)
    logger.info(
        "sweep %r of scene %r: %d cases, %d on disk, %d to run",
        spec.name,
        scene.name,
        len(cases),
        reused,
        len(todo),
    )
    writer = ProgressWriter(len(cases), reused, stream) if progress else None
    if writer:
        writer.note(
            f"sweep {spec.name!r} of scene {scene.name!r}: {len(cases)} cases, "
            f"{reused} already in {out_dir}, {len(todo)} to run"
        )
    sink = _Sink(store, cases, writer, on_case)
    startup, finished = 0.0, False
    try:
        tasks = _tasks(base, spec, todo, sink)
        startup = _execute(
            tasks,
            sink,
            workers,
            scheduler,
            retries=retries,
            max_attempts=max_attempts,
            writer=writer,
        )
        finished = True
    finally:
        rows = store.consolidate()
    drawn = (
        plot_summary(rows, spec, store.plots_dir, _units(spec, store, rows))
        if plots and finished
        else []
    )
    result = SweepResult(
        store.directory,
        store.summary_path,
        rows,
        drawn,
        len(sink.written),
        reused,
        time.perf_counter() - wall,
        startup,
    )
    logger.info("sweep %r: %s in %.3g s", spec.name, result.counts, result.wall_time)
    return result


def _check_options(workers: Any, scheduler: str | None) -> None:
    """Refuse a count of workers or a scheduler address that cannot be, before any work.

    Raises
    ------
    SweepError
        Naming each option at fault and what it takes.
    """
    problems = []
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 0:
        problems.append(
            f"workers = {workers!r}: expected a whole number >= 1, or 0 to run the cases "
            "in this process"
        )
    if scheduler is not None and (problem := scheduler_problem(scheduler)):
        problems.append(f"scheduler: {problem}")
    if problems:
        raise SweepError("; ".join(problems))


def _units(spec: SweepSpec, store: ResultStore, rows: list[dict[str, Any]]) -> dict[str, str]:
    """Units of the axes and figure columns, read from a finished case's metadata."""
    finished = [store.case_dir(r["case_id"]) for r in rows if r.get("status") == "finished"]
    return sweep_units(
        [a.target for a in spec.axes], [f.column for f in spec.figures], case_metadata(finished)
    )


class _Sink:
    """Where each case's outcome goes: the store, the progress lines, the caller's callback."""

    def __init__(
        self,
        store: ResultStore,
        cases: Sequence[Case],
        writer: ProgressWriter | None,
        on_case: CaseCallback | None,
    ) -> None:
        self.store, self.writer, self.on_case = store, writer, on_case
        self.cases = {c.case_id: c for c in cases}
        self.written: set[str] = set()

    def __call__(self, outcome: CaseOutcome) -> None:
        """Write one case's outcome, show it, tell the caller."""
        case = self.cases[outcome.case_id]
        row = self.store.write(case, outcome)
        self.written.add(case.case_id)
        if self.writer:
            self.writer.case(case, row)
        if self.on_case:
            self.on_case(row)


def _execute(
    tasks: Sequence[CaseTask],
    sink: _Sink,
    workers: int,
    scheduler: str | None,
    *,
    retries: int,
    max_attempts: int,
    writer: ProgressWriter | None,
) -> float:
    """Run the tasks here (``workers=0``) or on Dask; seconds it took to reach the cluster."""
    if not tasks:
        return 0.0
    if scheduler is None and workers == 0:
        for task in tasks:
            sink(_execute_here(task))
        return 0.0
    started = time.perf_counter()
    with _client(workers, scheduler) as client:
        _check_workers(client)
        startup = time.perf_counter() - started
        if writer:
            writer.restart_clock()
        _run_on_dask(client, tasks, sink, sink.written, retries=retries, max_attempts=max_attempts)
    return startup
