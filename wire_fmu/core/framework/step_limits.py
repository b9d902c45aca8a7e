"""What one communication step may cost, and the error when a step cannot be integrated.

Every solver of :mod:`wire_fmu.core.framework.hybrid` keeps these limits, so
a unit refuses a step that would run for hours or loop on events, with a
message that says why (:class:`IntegrationError`).
"""

from __future__ import annotations

import math

__all__ = [
    "IntegrationError",
    "MAX_INTERNAL_STEPS",
    "MAX_EVENTS_PER_STEP",
    "internal_step_count",
    "internal_steps",
]


class IntegrationError(RuntimeError):
    """A step produced non-finite numbers or too many events."""


MAX_EVENTS_PER_STEP = 10_000
"""Most guard events one communication step may have."""
MAX_INTERNAL_STEPS = 100_000
"""Most internal steps one communication step may need; a longer one is refused
at once (its message says how long a step may be) rather than run for hours."""


def internal_steps(t0: float, t1: float, max_step: float) -> float:
    """How many steps of at most ``max_step`` (s) span ``[t0, t1]`` (s).

    Parameters
    ----------
    t0, t1 : float
        Start and end of the communication step, s.
    max_step : float
        Largest internal step, s.

    Raises
    ------
    IntegrationError
        When that is more than :data:`MAX_INTERNAL_STEPS`, naming the longest
        communication step the unit takes.
    """
    count = (t1 - t0) / max_step
    if not count <= MAX_INTERNAL_STEPS:
        raise IntegrationError(
            f"a step of {t1 - t0:.6g} s needs {count:.3g} internal steps of at most "
            f"{max_step:.3g} s, more than the {MAX_INTERNAL_STEPS} one step may take; "
            f"take communication steps of at most {MAX_INTERNAL_STEPS * max_step:.6g} s"
        )
    return count


def internal_step_count(t0: float, t1: float, max_step: float) -> int:
    """How many equal internal steps a fixed-step loop takes over ``[t0, t1]`` (s).

    :func:`internal_steps` rounded up to a whole number (a count a hair above one, by
    round-off, is that one), at least 1. Called every communication step: ``max()``
    is written out (the builtin parses keywords on every call).

    Raises
    ------
    IntegrationError
        As :func:`internal_steps`.
    """
    count = math.ceil(internal_steps(t0, t1, max_step) - 1e-9)
    return count if count > 1 else 1
