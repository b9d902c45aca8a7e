"""A sweep on Dask: the client, its workers checked, the FMUs shipped, cases resubmitted.

See :mod:`wire_fmu.sweep.runner` for what happens when a worker dies.
"""

from __future__ import annotations

import hashlib
import logging
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import CancelledError
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from .results import CaseOutcome
from .spec import SweepError
from .worker import CaseTask, _dask_case, _describe, _worker_core

logger = logging.getLogger(__name__)

SCHEDULER_EXAMPLE = "tcp://10.0.0.5:8786"
"""A Dask scheduler address, as messages show one."""
_HOST_PORT_PROTOCOLS = frozenset({"tcp", "tls", "ws", "wss", "ucx"})


def scheduler_problem(address: str) -> str | None:
    """Why ``address`` is not the address of a Dask scheduler, or None if it is one.

    Only its form is checked (a known protocol, and a host and a port where the
    protocol needs them); whether a scheduler answers there is not.

    Parameters
    ----------
    address : str
        As given, e.g. ``"tcp://10.0.0.5:8786"`` (``tcp://`` may be left out).
    """
    from distributed.comm import registry
    from distributed.comm.addressing import parse_address, parse_host_port

    expected = f"expected PROTOCOL://HOST:PORT, e.g. {SCHEDULER_EXAMPLE}, got {address!r}"
    try:
        protocol, location = parse_address(address)
    except (TypeError, ValueError) as err:
        return f"{expected} ({err})"
    if protocol not in registry.backends:
        known = ", ".join(sorted(registry.backends))
        return f"{expected} (unknown protocol {protocol!r}; known: {known})"
    if protocol in _HOST_PORT_PROTOCOLS:
        try:
            parse_host_port(location)
        except ValueError as err:
            return f"{expected} ({err})"
    return None


@contextmanager
def _client(workers: int, scheduler: str | None) -> Iterator[Any]:
    """A Dask client: to ``scheduler``, or to a new local cluster of ``workers`` processes.

    Raises
    ------
    SweepError
        When no scheduler answers at ``scheduler``.
    """
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler)
        except OSError as err:
            raise SweepError(
                f"no Dask scheduler answers at {scheduler!r} ({err}); start one there "
                "(dask scheduler), or leave --scheduler out to run on a local cluster"
            ) from None
        with client:
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
        """Submit one case (``attempt`` counts from 1).

        Parameters
        ----------
        task : CaseTask
            The case.
        attempt : int
            How many times it has been submitted, this one included.
        """
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
        """Submit ``tasks``; outcomes go to ``sink`` in the order they complete.

        Parameters
        ----------
        tasks : sequence of CaseTask
            The cases.
        sink : callable
            Takes each :class:`~wire_fmu.sweep.results.CaseOutcome`.
        """
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
        """The outcome of a completed future; None when the case was lost and goes again.

        Parameters
        ----------
        future : distributed.Future
            The completed task.
        task : CaseTask
            Its case.
        attempt : int
            Its submission, from 1 (``lost`` after ``max_attempts``).
        """
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
