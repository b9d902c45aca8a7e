"""What a sweep's worker runs: one case, in a temporary folder, anywhere.

:func:`execute_case` runs a :class:`CaseTask` with the master and returns
its outcome with the folder's files; a Dask worker first writes the FMU
files the client scattered into its own folder (see
:mod:`wire_fmu.sweep.runner`).
"""

from __future__ import annotations

import dataclasses
import logging
import os
import tempfile
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import wire_fmu
from wire_fmu._fingerprint import fingerprint, package_dir
from wire_fmu.core.errors import WireFmuError
from wire_fmu.master.run import run_scene
from wire_fmu.master.run_result import SimulationStoppedError
from wire_fmu.master.scene import Scene
from wire_fmu.master.slave import StepRefusedError, UnitFailedError

from .cases import Case
from .figures import Figure
from .results import CaseOutcome

__all__ = ["CASE_ERRORS", "CaseTask", "execute_case"]

logger = logging.getLogger(__name__)

CASE_ERRORS = (WireFmuError, SimulationStoppedError, UnitFailedError, StepRefusedError)
"""Errors that belong to a case (its values, its scene): recorded, never retried."""


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
