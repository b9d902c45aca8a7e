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
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import logging
import os
import sys
import tempfile
import time
import zipfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import CancelledError
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import wire_fmu
from wire_fmu._fingerprint import fingerprint, package_dir
from wire_fmu.core.errors import WireFmuError
from wire_fmu.export.guard import BUILD_INFO_FILE
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.run import find_scene, run_scene
from wire_fmu.master.scene import Scene, load_scene
from wire_fmu.master.simulation import SimulationStoppedError
from wire_fmu.master.slave import StepRefusedError, UnitFailedError
from wire_fmu.master.validate import Structure, check_structure, resolve_units

from .cases import Case, apply_case, check_targets, expand, with_figures_recorded
from .results import DONE_STATUSES, CaseOutcome, ResultStore, plot_summary
from .spec import Figure, SweepError, SweepSpec, SweepSpecError, load_sweep_spec

__all__ = ["run_sweep", "SweepResult", "CaseTask", "execute_case", "scene_key"]

logger = logging.getLogger(__name__)

CASE_ERRORS = (WireFmuError, SimulationStoppedError, UnitFailedError, StepRefusedError)
"""Errors that belong to a case (its values, its scene): recorded, never retried."""
CaseCallback = Callable[[dict[str, Any]], None]


# -- what a worker runs ------------------------------------------------------------------------
@dataclass(frozen=True)
class CaseTask:
    """One case, ready to run anywhere.

    Attributes
    ----------
    case : Case
        Its id and values.
    scene : Scene
        The scene with the case applied; each unit's ``fmu`` is the path of
        the FMU file on the client.
    figures : tuple of Figure
        Key figures to compute from the recorded time series.
    """

    case: Case
    scene: Scene
    figures: tuple[Figure, ...]


def _describe(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {exc}"


def _folder_files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def _figures(figures: Sequence[Figure], csv_path: Path) -> dict[str, float | None]:
    from wire_fmu.master.plots import read_results

    if not csv_path.exists():
        return {f.name: None for f in figures}
    columns = read_results(csv_path)
    return {f.name: f.evaluate(columns) for f in figures}


def _on_local_fmus(scene: Scene, local: Mapping[str, Path]) -> Scene:
    units = {
        name: dataclasses.replace(u, fmu=str(local.get(u.fmu, u.fmu)))
        for name, u in scene.units.items()
    }
    return dataclasses.replace(scene, units=units)


def execute_case(
    task: CaseTask, local_fmus: Mapping[str, Path] | None = None, worker: str = "local"
) -> CaseOutcome:
    """Run one case in a temporary folder; its outcome with the folder's files.

    Parameters
    ----------
    task : CaseTask
        The case.
    local_fmus : mapping, optional
        Client FMU path -> the same FMU's path here (when they differ).
    worker : str
        Who runs it, for the record.

    Returns
    -------
    CaseOutcome
        ``finished``, ``stopped`` (a unit stopped the run) or ``failed``
        (one of :data:`CASE_ERRORS`); other exceptions propagate.
    """
    scene = _on_local_fmus(task.scene, local_fmus or {})
    cid = task.case.case_id
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix=f"wire_fmu_case_{cid}_") as tmp:
        folder = Path(tmp)
        try:
            outcome = run_scene(scene, folder, plots=False)
        except CASE_ERRORS as exc:
            logger.info("case %s failed: %s", cid, exc)
            return CaseOutcome(
                cid,
                "failed",
                _describe(exc),
                time.perf_counter() - start,
                files=_folder_files(folder),
                worker=worker,
            )
        result = outcome.result
        if result.status == "interrupted":  # Ctrl-C ends the sweep, the case is not done
            raise KeyboardInterrupt
        status = result.status if result.status in ("finished", "stopped") else "failed"
        return CaseOutcome(
            cid,
            status,
            result.message or None if status != "finished" else None,
            time.perf_counter() - start,
            result.end_time,
            _figures(task.figures, outcome.csv_path),
            _folder_files(folder),
            worker,
        )


def _execute_here(task: CaseTask) -> CaseOutcome:
    """Run a case in this process; an unexpected exception is recorded, not raised."""
    start = time.perf_counter()
    try:
        return execute_case(task)
    except Exception as exc:  # noqa: BLE001 - recorded with its message, the sweep goes on
        logger.exception("case %s raised", task.case.case_id)
        return CaseOutcome(
            task.case.case_id, "failed", _describe(exc), time.perf_counter() - start, worker="local"
        )


def _worker_fmu(directory: Path, digest: str, name: str, blob: bytes) -> Path:
    """The FMU file in a worker's folder, written once (atomically) per content."""
    path = directory / digest / name
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{name}.{os.getpid()}.tmp")
        tmp.write_bytes(blob)
        os.replace(tmp, path)
    return path


def _dask_case(task: CaseTask, fmus: Mapping[str, tuple[str, bytes]]) -> CaseOutcome:
    """Task run by a Dask worker: materialise the FMUs, run the case."""
    from distributed import get_worker

    worker = get_worker()
    folder = Path(worker.local_directory) / "wire_fmu_fmus"
    local = {
        client_path: _worker_fmu(folder, digest, Path(client_path).name, blob)
        for client_path, (digest, blob) in fmus.items()
    }
    return execute_case(task, local, worker.address)


def _worker_core() -> tuple[str, str]:
    """Version and core fingerprint of the ``wire_fmu`` a worker imports."""
    return wire_fmu.__version__, fingerprint(package_dir())


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
        """A free line."""
        self.stream.write(text + "\n")
        self.stream.flush()

    def case(self, case: Case, row: Mapping[str, Any]) -> None:
        """The line of a finished case."""
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
    """Hash of what a scene asks for (not where its file is): results of one scene only."""
    normal = dataclasses.replace(scene, base_dir=Path("."), source=None)
    return hashlib.sha256(repr(normal).encode("utf-8")).hexdigest()[:16]


def _load(scene: str | Path | Scene, spec: str | Path | SweepSpec) -> tuple[Scene, SweepSpec]:
    if not isinstance(scene, Scene):
        scene = load_scene(find_scene(scene))
    if not isinstance(spec, SweepSpec):
        spec = load_sweep_spec(Path(spec))
    return scene, spec


def _prepare(scene: Scene, spec: SweepSpec, fmu_dir: Path) -> Scene:
    """Build our FMUs once, check the scene and the spec's targets; units given by file.

    Raises
    ------
    SweepSpecError
        Every problem of the scene's structure and of the spec's targets.
    """
    structure, problems = resolve_units(scene, fmu_dir)
    if not problems:
        problems += check_structure(scene, structure) + _stale_fmus(structure)
    problems += check_targets(spec, scene, structure if not problems else None)
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
        The output folder holds another scene's sweep; workers that cannot
        run this version of wire_fmu.
    """
    wall = time.perf_counter()
    scene, spec = _load(scene, spec)
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
    drawn = plot_summary(rows, spec, store.plots_dir) if plots and finished else []
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


# -- Dask ----------------------------------------------------------------------------------------
@contextmanager
def _client(workers: int, scheduler: str | None) -> Iterator[Any]:
    """A Dask client: to ``scheduler``, or to a new local cluster of ``workers`` processes."""
    from distributed import Client, LocalCluster

    if scheduler:
        with Client(scheduler) as client:
            yield client
        return
    if workers < 1:
        raise ValueError(f"workers must be >= 1 for a local cluster (0: serial), got {workers}")
    with (
        LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client


def _check_workers(client: Any) -> None:
    """Refuse workers whose wire_fmu differs from this one (the FMUs would refuse them).

    Raises
    ------
    SweepError
        Naming the workers and what they have.
    """
    if not client.scheduler_info().get("workers"):
        logger.warning("the scheduler has no worker yet; waiting for one to join")
        client.wait_for_workers(1)
    expected = _worker_core()
    try:
        found = client.run(_worker_core)
    except Exception as exc:  # noqa: BLE001 - any failure here means the workers cannot run us
        raise SweepError(
            f"the Dask workers cannot run wire_fmu ({_describe(exc)}); install "
            f"wire_fmu {expected[0]} on every worker"
        ) from exc
    wrong = {addr: core for addr, core in found.items() if tuple(core) != expected}
    if wrong:
        lines = ", ".join(f"{a}: {v} core {f[:12]}" for a, (v, f) in wrong.items())
        raise SweepError(
            f"workers with another wire_fmu than this client ({expected[0]} core "
            f"{expected[1][:12]}): {lines}; install the same version on every "
            "worker (the FMUs are built from this one)"
        )


class _Shipment:
    """The FMU files of a sweep, scattered to every worker; scattered again if lost."""

    def __init__(self, client: Any, paths: Sequence[str]) -> None:
        self.client = client
        self.blobs = {p: Path(p).read_bytes() for p in sorted(set(paths))}
        self.digests = {p: hashlib.sha256(b).hexdigest()[:16] for p, b in self.blobs.items()}
        self.futures: dict[str, Any] = {}
        self.refresh()

    def refresh(self) -> None:
        """Scatter every file not (or no longer) held by the cluster."""
        for path, blob in self.blobs.items():
            if path not in self.futures or self.futures[path].status != "finished":
                self.futures[path] = self.client.scatter(blob, broadcast=True, hash=False)

    def argument(self) -> dict[str, tuple[str, Any]]:
        """What a task gets: client path -> (digest, bytes future)."""
        return {p: (self.digests[p], self.futures[p]) for p in self.blobs}


def _lost(task: CaseTask, attempt: int, exc: BaseException) -> CaseOutcome:
    return CaseOutcome(
        task.case.case_id,
        "lost",
        f"worker lost {attempt} times; last: {_describe(exc)}",
        worker="",
        attempts=attempt,
    )


class _DaskRun:
    """Cases submitted to a Dask cluster, each outcome handed on as it completes."""

    def __init__(
        self, client: Any, tasks: Sequence[CaseTask], *, retries: int, max_attempts: int
    ) -> None:
        self.client = client
        self.retries = retries
        self.max_attempts = max_attempts
        self.shipment = _Shipment(client, [u.fmu for t in tasks for u in t.scene.units.values()])
        self.pending: dict[str, tuple[CaseTask, int]] = {}
        self.submitted = 0

    def submit(self, task: CaseTask, attempt: int) -> Any:
        """Submit one case (``attempt`` counts from 1)."""
        self.submitted += 1
        future = self.client.submit(
            _dask_case,
            task,
            self.shipment.argument(),
            retries=self.retries,
            pure=False,
            key=f"wire-fmu-case-{task.case.case_id}-{attempt}-{self.submitted}",
        )
        self.pending[future.key] = (task, attempt)
        return future

    def run(self, tasks: Sequence[CaseTask], sink: Callable[[CaseOutcome], None]) -> None:
        """Submit ``tasks``; outcomes go to ``sink`` in the order they complete."""
        from distributed import as_completed

        queue = as_completed([self.submit(t, 1) for t in tasks])
        for future in queue:
            task, attempt = self.pending.pop(future.key)
            outcome = self.collect(future, task, attempt)
            if outcome is None:
                queue.add(self.submit(task, attempt + 1))
                continue
            future.release()
            sink(outcome)

    def collect(self, future: Any, task: CaseTask, attempt: int) -> CaseOutcome | None:
        """The outcome of a completed future; None when the case was lost and goes again."""
        from distributed.scheduler import KilledWorker

        try:
            outcome = future.result()
        except (KilledWorker, CancelledError) as exc:
            if attempt < self.max_attempts:
                logger.warning(
                    "case %s: worker lost (%s); submitting it again",
                    task.case.case_id,
                    _describe(exc),
                )
                self.shipment.refresh()
                return None
            return _lost(task, attempt, exc)
        except Exception as exc:  # noqa: BLE001 - the task's own error, after Dask's retries
            return CaseOutcome(task.case.case_id, "failed", _describe(exc), attempts=attempt)
        outcome.attempts = attempt
        return outcome


def _run_on_dask(
    client: Any,
    tasks: Sequence[CaseTask],
    sink: Callable[[CaseOutcome], None],
    written: set[str],
    *,
    retries: int,
    max_attempts: int,
) -> None:
    """Run ``tasks`` on the cluster; then once more any that left no record (never expected)."""
    run = _DaskRun(client, tasks, retries=retries, max_attempts=max_attempts)
    run.run(tasks, sink)
    missing = [t for t in tasks if t.case.case_id not in written]
    if missing:
        logger.warning("%d cases left no record; running them again", len(missing))
        run.run(missing, sink)
