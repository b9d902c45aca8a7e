"""How a recorded signal is best drawn: a discrete state, a line, or an envelope.

* A **discrete state** (a brake's 0 released / 1 slipping / 2 holding, a count
  of slack spans) is a pure number that takes a few whole values; it gets an
  axis of its own with its levels named (:func:`is_discrete`,
  :func:`state_levels`).
* A signal that turns back and forth faster than the plot can show (stick-slip
  at 5 to 15 Hz over a 40 s run) would be drawn as a solid band. It is drawn as
  its envelope, the least and greatest value in each short window, with the
  window's mean, and a detail of the raw samples where it moves most
  (:func:`envelope`, :func:`busiest_window`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

__all__ = [
    "MAX_LEVELS",
    "BINS",
    "Envelope",
    "is_discrete",
    "state_levels",
    "envelope",
    "busiest_window",
    "finite_range",
]

MAX_LEVELS = 12
"""Most distinct whole values a pure-number column may take to be drawn as a discrete state."""

BINS = 300
"""Windows across a plot's width (about two pixels each) for :func:`envelope`."""

_DENSE_SHARE = 0.05
"""Share of windows with two or more reversals above which a signal is drawn as an envelope."""

_LEVEL = re.compile(r"(?:^|[:,;]\s*)(\d+)\s*(?:=\s*)?([A-Za-z][^,;]*?)\s*(?=[,;]|$)")


def is_discrete(values: np.ndarray, unit: str) -> bool:
    """Whether a column is a discrete state: a pure number taking a few whole values.

    Parameters
    ----------
    values : ndarray, shape (rows,)
        The recorded values (NaN cells ignored).
    unit : str
        The column's unit (``"1"`` for a pure number).

    Returns
    -------
    bool
        True when the unit is ``"1"``, every finite value is a whole number
        and there are at most :data:`MAX_LEVELS` of them.
    """
    if unit != "1":
        return False
    finite = values[np.isfinite(values)]
    if finite.size == 0 or not np.all(finite == np.round(finite)):
        return False
    return np.unique(finite).size <= MAX_LEVELS


def state_levels(description: str) -> dict[int, str]:
    """The named levels of a state from its description (``"Brake: 0 released, 1 slipping"``).

    Parameters
    ----------
    description : str
        The variable's description, levels listed as ``<n> <name>`` (or
        ``<n> = <name>``) separated by commas or semicolons, after a colon.

    Returns
    -------
    dict of int to str
        Name of each level; empty unless at least two are listed.
    """
    text = description.split(":", 1)[1] if ":" in description else description
    levels = {int(n): name.strip() for n, name in _LEVEL.findall(text.strip())}
    return levels if len(levels) >= 2 else {}


@dataclass(frozen=True)
class Envelope:
    """A signal summarised per window.

    Attributes
    ----------
    time : ndarray
        Middle of each window, s.
    low, high, mean : ndarray
        Least, greatest and mean value in each window (the signal's unit).
    window : float
        Length of a window, s.
    """

    time: np.ndarray
    low: np.ndarray
    high: np.ndarray
    mean: np.ndarray
    window: float


def _reversals(values: np.ndarray, bins: int) -> np.ndarray | None:
    """Turns of direction in each of ``bins`` windows of equal sample count (None: too few)."""
    n = values.size
    if n < 4 * bins or not np.all(np.isfinite(values)):
        return None
    span = float(np.ptp(values))
    if span == 0.0:
        return np.zeros(bins, dtype=int)
    step = np.diff(values)
    sign = np.where(np.abs(step) > 1e-3 * span, np.sign(step), 0.0)
    # carry the last significant direction over insignificant steps
    index = np.where(sign != 0.0, np.arange(sign.size), 0)
    np.maximum.accumulate(index, out=index)
    held = sign[index]
    turns = np.zeros(sign.size, dtype=int)
    turns[1:] = (held[1:] * held[:-1] < 0.0).astype(int)
    edges = np.linspace(0, sign.size, bins + 1).astype(int)
    return np.add.reduceat(turns, edges[:-1])


def envelope(time: np.ndarray, values: np.ndarray, bins: int = BINS) -> Envelope | None:
    """The signal's envelope when it turns faster than ``bins`` windows can show; else None.

    Parameters
    ----------
    time : ndarray, shape (rows,)
        Recorded times, s, increasing.
    values : ndarray, shape (rows,)
        The signal.
    bins : int
        Windows across the plot.

    Returns
    -------
    Envelope or None
        The least, greatest and mean value per window when more than 5 % of
        the windows hold two or more turns of direction (each by more than
        0.1 % of the signal's range); None for a signal a line shows.
    """
    turns = _reversals(values, bins)
    if turns is None or np.mean(turns >= 2) <= _DENSE_SHARE:
        return None
    edges = np.linspace(0, values.size, bins + 1).astype(int)
    parts = [slice(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]
    return Envelope(
        time=np.array([0.5 * (time[p.start] + time[p.stop - 1]) for p in parts]),
        low=np.array([values[p].min() for p in parts]),
        high=np.array([values[p].max() for p in parts]),
        mean=np.array([values[p].mean() for p in parts]),
        window=float(time[-1] - time[0]) / len(parts),
    )


def busiest_window(values: np.ndarray, samples: int) -> slice:
    """The ``samples`` consecutive samples where the signal turns most often.

    Parameters
    ----------
    values : ndarray, shape (rows,)
        The signal.
    samples : int
        Length of the window, samples.

    Returns
    -------
    slice
        The window (the whole signal if it is shorter).
    """
    n = values.size
    if n <= samples:
        return slice(0, n)
    step = np.diff(values)
    turns = np.zeros(n)
    turns[1:-1] = (step[1:] * step[:-1] < 0.0).astype(float)
    counts = np.convolve(turns, np.ones(samples), mode="valid")
    start = int(np.argmax(counts))
    return slice(start, start + samples)


def finite_range(*arrays: np.ndarray) -> tuple[float, float]:
    """Least and greatest finite value over ``arrays`` ((nan, nan) if none).

    Parameters
    ----------
    *arrays : ndarray
        Values.
    """
    parts = [a[np.isfinite(a)] for a in arrays if a.size]
    parts = [p for p in parts if p.size]
    if not parts:
        return math.nan, math.nan
    return float(min(p.min() for p in parts)), float(max(p.max() for p in parts))
