"""A shipped scene run for a benchmark that counts (bytecodes, instructions) rather than
times: shortened, observed, and with the results' rows written after the last step."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from wire_fmu.master.run import Outcome, run_scene

__all__ = ["run_counted"]


def run_counted(name: str, results: Path, observer: Any, stop_time: float) -> Outcome:
    """Run the shipped scene ``name`` to ``stop_time`` with ``observer`` watching.

    The recorder writes its rows every 0.1 s of wall-clock time in a run at full speed,
    hundreds a batch, but every few steps in one slowed down by counting: here it writes
    them after the last step instead, so that what is counted does not depend on the
    clock (a batch's cost per row is numpy's and orjson's).

    Parameters
    ----------
    name : str
        A shipped scene's name.
    results : Path
        Folder the scene's results go into.
    observer : Observer
        Watches the run (see :class:`~wire_fmu.master.observers.Observer`).
    stop_time : float
        Simulated time of the run, s.

    Raises
    ------
    RuntimeError
        If the run did not finish, with its status and message.
    """
    outcome = run_scene(
        name,
        results,
        plots=False,
        observers=(observer,),
        flush_every=math.inf,
        stop_time=stop_time,
    )
    result = outcome.result
    if result.status != "finished":
        raise RuntimeError(f"{name}: {result.status}: {result.message}")
    return outcome
