"""Checks of scene values: names, unit references, times, scalars and run settings, and
the warnings about bonds that cannot give the interface model the scene asks for and about
events after the stop time."""

from __future__ import annotations

import math
import re
from typing import Any

from .data import ALGORITHMS, EXTRAPOLATIONS, RunSettings, Scene, VarRef

__all__ = [
    "is_plain_name",
    "unknown_unit_problems",
    "valid_time",
    "is_scalar",
    "interface_warnings",
    "late_event_warnings",
]

MIN_TIME, MAX_TIME = 1e-9, 1e12
"""Shortest step and latest time a run can count (whole nanoseconds in 64 bits), s."""
MAX_ITERATIONS = 1000
"""Most sweeps of one macro step ``run.iterations`` may ask for."""
_SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,127}")


def is_plain_name(name: str) -> bool:
    """Whether ``name`` can name a folder inside another: letters, digits, ``_-.``, no ``..``.

    Parameters
    ----------
    name : str
        The name (of a scene, a sweep, a case).
    """
    return bool(_SAFE_NAME.fullmatch(name)) and ".." not in name


def unknown_unit_problems(scene: Scene) -> list[str]:
    """Every reference to a unit the scene does not have, naming where it is.

    Parameters
    ----------
    scene : Scene
        The scene (its bonds, connections, drivers, events, outputs, plots).

    Returns
    -------
    list of str
        One problem per reference to a unit that is not in ``scene.units``.
    """
    units = set(scene.units)
    known = ", ".join(sorted(units)) or "none"
    refs: list[tuple[str, VarRef]] = []
    for bond in scene.bonds:
        links = bond.connections + (() if bond.wired else bond.interface)  # wired or not
        refs += [(f"bond {bond.name!r} {c.role}", r) for c in links for r in (c.source, c.target)]
    for i, c in enumerate(scene.connections):
        refs += [(f"connection {i}", c.source), (f"connection {i}", c.target)]
    for i, d in enumerate(scene.drivers):
        refs += [(f"driver {i}", r) for r in (d.target, d.rate_target) if r is not None]
    for e in scene.events:
        refs += [(f"event {e.label!r}", r) for r in e.values]
    refs += [("outputs", r) for r in scene.outputs or ()]
    refs += [(f"plot {p.title!r}", r) for p in scene.plots for r in p.variables]
    return [
        f"{where}: {ref} names no unit {ref.unit!r}; the scene's units: {known}"
        for where, ref in refs
        if ref.unit not in units
    ]


def interface_warnings(scene: Scene) -> list[str]:
    """Each bond asked for its interface model by ``run.interface_models`` that has none,
    and each bond asked for a ramped flow by ``run.ramped_flows`` that cannot take one.

    Such a bond keeps its effort, flow and position links (a bond that asks by its own
    ``interface_model = true`` and cannot have it is a problem instead, found where the
    scene is read), and holds its flow over the step.

    Parameters
    ----------
    scene : Scene
        The scene.

    Returns
    -------
    list of str
        One warning per such bond, naming it and the port (and side) without the model,
        or saying that it is written link by link without interface links.
    """
    warnings = []
    for bond in scene.bonds:
        if bond.wired or bond.interface_model is not None or not scene.run.interface_models:
            continue
        if bond.interface_lacking:
            why = f"{' and '.join(bond.interface_lacking)} declares no interface model"
        else:
            why = "it is written link by link without 'interface' links"
        warnings.append(
            f"bond {bond.name!r}: run.interface_models asks for interface models, but {why}; "
            "the bond keeps its effort, flow and position links"
        )
    if scene.run.ramped_flows is True:
        warnings += [
            f"bond {bond.name!r}: run.ramped_flows asks for ramped flows, but no flow ramp "
            f"goes with its flow input {bond.flow.target} (the effort side's port declares "
            "none, or the bond is written link by link); its flow is held over the step"
            for bond in scene.bonds
            if not bond.ramped
        ]
    return warnings


def late_event_warnings(scene: Scene) -> list[str]:
    """Each event after the run's stop time: it will not happen.

    A warning, not a problem: a run shortened on purpose (``--stop-time``) ends before
    its later events.

    Parameters
    ----------
    scene : Scene
        The scene (its events and ``run.stop_time``, s).

    Returns
    -------
    list of str
        One warning per such event, naming it, its time and the stop time.
    """
    stop = scene.run.stop_time
    if not _finite(stop):
        return []  # a stop time that is no number is a problem, said where it is read
    return [
        f"event {e.label!r} at {e.time:g} s is after the run's stop time, {stop:g} s; "
        "it will not happen"
        for e in scene.events
        if e.time > stop
    ]


def valid_time(value: Any) -> bool:
    """A time a run can count: a number of seconds from 0 to :data:`MAX_TIME`, not a boolean.

    Parameters
    ----------
    value : object
        The time, s.
    """
    return _finite(value) and 0 <= value <= MAX_TIME


def is_scalar(value: Any) -> bool:
    """A finite number, a boolean or text: what one FMI variable can hold.

    Parameters
    ----------
    value : object
        The value.
    """
    return isinstance(value, bool | str) or _finite(value)


def _finite(value: Any) -> bool:
    """A finite number (not a boolean); an integer too large for a float is not."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _positive(value: Any) -> bool:
    return _finite(value) and value > 0


def _check_run(s: RunSettings, problems: list[str]) -> None:
    for key in ("stop_time", "step", "iteration_tolerance", "energy_tolerance", "min_step"):
        if not _positive(getattr(s, key)):
            problems.append(f"run.{key} must be a positive number, got {getattr(s, key)!r}")
    if not (_positive(s.energy_guard) or s.energy_guard == math.inf):
        problems.append(
            f"run.energy_guard must be a positive number (inf turns the guard "
            f"off), got {s.energy_guard!r}"
        )
    for key in ("output_interval", "max_step"):
        value = getattr(s, key)
        if value is not None and not _positive(value):
            problems.append(f"run.{key} must be a positive number, got {value!r}")
    if s.algorithm not in ALGORITHMS:
        problems.append(f"run.algorithm must be one of {ALGORITHMS}, got {s.algorithm!r}")
    if s.extrapolation not in EXTRAPOLATIONS:
        problems.append(
            f"run.extrapolation must be one of {EXTRAPOLATIONS}, got {s.extrapolation!r}"
        )
    if not isinstance(s.iterations, int) or isinstance(s.iterations, bool) or s.iterations < 1:
        problems.append(f"run.iterations must be an integer >= 1, got {s.iterations!r}")
    elif s.iterations > MAX_ITERATIONS:
        problems.append(
            f"run.iterations = {s.iterations}: at most {MAX_ITERATIONS} sweeps of "
            "one step (a coupling that needs more does not converge)"
        )
    for key in ("adaptive", "synchronise_events", "interface_models", "ramped_flows"):
        if not isinstance(getattr(s, key), bool):
            problems.append(f"run.{key} must be true or false, got {getattr(s, key)!r}")
    if not isinstance(s.order, tuple) or not all(isinstance(u, str) for u in s.order):
        problems.append(f"run.order must be a list of unit names, got {s.order!r}")
    elif len(set(s.order)) != len(s.order):
        problems.append(f"run.order names a unit more than once: {list(s.order)}")
    for key in ("stop_time", "step", "min_step", "max_step", "output_interval"):
        value = getattr(s, key)
        if _positive(value) and not MIN_TIME <= value <= MAX_TIME:
            problems.append(
                f"run.{key} = {value!r} s: times are counted in whole nanoseconds, from "
                f"{MIN_TIME:g} to {MAX_TIME:g} s"
            )
    if not isinstance(s.max_steps, int) or isinstance(s.max_steps, bool) or s.max_steps < 1:
        problems.append(f"run.max_steps must be an integer >= 1, got {s.max_steps!r}")
    elif _positive(s.stop_time) and _positive(s.step):
        _check_step_count(s, problems)
    if _positive(s.min_step) and s.max_step is not None and _positive(s.max_step):
        if s.min_step > s.max_step:
            problems.append(
                f"run.min_step {s.min_step!r} s is larger than run.max_step {s.max_step!r} s"
            )


def _check_step_count(s: RunSettings, problems: list[str]) -> None:
    """Refuse a run whose number of macro steps is absurd, saying how to allow it."""
    smallest = s.min_step if s.adaptive and _positive(s.min_step) else s.step
    count = s.stop_time / smallest
    if count > s.max_steps:
        what = "run.stop_time / run.min_step" if s.adaptive else "run.stop_time / run.step"
        problems.append(
            f"{what} = {s.stop_time:g} s / {smallest:g} s is up to {count:.3g} macro steps, more "
            f"than run.max_steps = {s.max_steps}; raise max_steps to allow it, or take a "
            "larger step"
        )
