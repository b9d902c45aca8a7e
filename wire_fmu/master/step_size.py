"""Macro step sizes: times in whole nanoseconds, the shorter step after a rejection,
and the constants of the adaptive (PI) step controller."""

from __future__ import annotations

__all__ = ["new_h"]

_PI = {"safety": 0.99, "k_p": 0.2, "k_i": 0.15, "shrink": 0.2, "grow": 1.5}


def _ns(seconds: float) -> int:
    """Seconds as integer nanoseconds."""
    return int(round(seconds * 1e9))


def new_h(h: float, error: float) -> float:
    """A shorter step after a rejection, from the error ratio (> 1).

    Parameters
    ----------
    h : float
        The rejected step, s.
    error : float
        Its error over the tolerance, 1 (> 1).

    Returns
    -------
    float
        The step to try instead, s: 0.2 to 0.9 times ``h``.
    """
    return h * max(_PI["shrink"], min(0.9, 0.9 * error**-0.5))
