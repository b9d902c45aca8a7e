"""The window of a study: the span of simulated time whose samples are compared.

A full study compares every sample from 0 s to its stop time. A quick study
(``--quick``) compares the window a scene's ``[study]`` table names where the
scene's action happens::

    [study]
    quick_window = [3.8, 4.8]   # s: the emergency stop, not the brake-held start

else the first :data:`~wire_fmu.study.plan.QUICK_STOP_TIME` seconds.

No unit can start mid-scene: the state at the window's start is the scene's
history up to it (a brake applied, a heave faded in, a load lowered). Every
run of the study, and the monolithic reference, therefore starts at 0 s and
stops at the window's end; only the window's samples are compared. The
lead-in costs simulated time but no extra run: the reference is solved once,
and each configuration runs once, from 0 s to the window's end (a
configuration's error in the window includes what it accumulated before
it, as in any run of the scene).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from wire_fmu.master.scene import Scene, SceneError

__all__ = ["QUICK_WINDOW", "quick_window", "window_problems", "first_sample"]

QUICK_WINDOW = "quick_window"
"""Key of a scene's ``[study]`` table: ``[start, stop]`` in s, the quick study's window."""

_SLACK = 1e-9  # relative slack of time comparisons on a grid of multiples of an interval


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def window_problems(window: Any, scene_stop: float, interval: float | None = None) -> list[str]:
    """What is wrong with ``window`` as a quick window (empty if nothing).

    Parameters
    ----------
    window : object
        The ``quick_window`` value as read: should be ``[start, stop]`` in s.
    scene_stop : float
        The scene's stop time, s: the window must end at or before it.
    interval : float, optional
        Spacing of the study's output grid, s: the window must hold at least
        two of its samples.
    """
    if (
        not isinstance(window, list | tuple)
        or len(window) != 2
        or not all(_is_number(v) for v in window)
    ):
        return [f"{QUICK_WINDOW} must be [start, stop], two numbers of seconds; got {window!r}"]
    start, stop = (float(v) for v in window)
    problems = []
    if start < 0.0:
        problems.append(f"{QUICK_WINDOW} starts at {start:g} s, before the scene starts (0 s)")
    if stop <= start:
        problems.append(f"{QUICK_WINDOW} [{start:g}, {stop:g}] s ends before it starts")
    if stop > scene_stop * (1.0 + _SLACK):
        problems.append(
            f"{QUICK_WINDOW} [{start:g}, {stop:g}] s ends after the scene's stop time "
            f"({scene_stop:g} s)"
        )
    if not problems and interval is not None and _samples(start, stop, interval) < 2:
        problems.append(
            f"{QUICK_WINDOW} [{start:g}, {stop:g}] s holds fewer than two samples of the "
            f"study's output grid ({interval:g} s): widen it"
        )
    return problems


def _samples(start: float, stop: float, interval: float) -> int:
    """Samples of a grid of ``interval`` from ``start`` to ``stop`` rounded down to the grid."""
    first = math.ceil(start / interval - _SLACK)
    last = math.floor(stop / interval + _SLACK)
    return max(0, last - first + 1)


def quick_window(
    scene: Scene, table: Mapping[str, Any], interval: float
) -> tuple[float, float] | None:
    """The quick window a scene's ``[study]`` table names, checked; None if it names none.

    Parameters
    ----------
    scene : Scene
        The scene (its name and stop time, s).
    table : mapping
        Its ``[study]`` table.
    interval : float
        Spacing of the study's output grid, s.

    Raises
    ------
    SceneError
        Naming the scene, ``quick_window`` and what is wrong with it.
    """
    raw = table.get(QUICK_WINDOW)
    if raw is None:
        return None
    problems = window_problems(raw, scene.run.stop_time, interval)
    if problems:
        raise SceneError(f"scene {scene.name!r} [study]", problems)
    return float(raw[0]), float(raw[1])


def first_sample(times: np.ndarray, start: float) -> int:
    """Index of the first sample at or after ``start`` (``len(times)`` if there is none).

    Parameters
    ----------
    times : ndarray
        Increasing sample times, s.
    start : float
        Start of the window, s (a grid time matches despite round-off).
    """
    return int(np.searchsorted(np.asarray(times, dtype=float), start - _SLACK * max(1.0, start)))
