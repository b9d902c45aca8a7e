"""Helpers of the quiet-step tests: a unit made to step the general way, and a record of
which steps a unit took the quiet way."""

from __future__ import annotations

from wire_fmu.core.framework.unit import Unit


def general_way(unit: Unit) -> Unit:
    """``unit`` made to take every step the general way."""
    unit._take_quiet_step = lambda time, step: False
    return unit


def counted(unit: Unit) -> list[bool]:
    """Whether each step of ``unit`` from now on was taken the quiet way."""
    taken: list[bool] = []
    quiet = unit._take_quiet_step

    def counting(time, step):
        taken.append(quiet(time, step))
        return taken[-1]

    unit._take_quiet_step = counting
    return taken
