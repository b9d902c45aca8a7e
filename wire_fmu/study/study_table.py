"""A scene's ``[study]`` table read and checked: key outputs, macro steps, output grid.

:func:`~wire_fmu.study.plan.study_settings` makes the plan from these; the
quick window is read by :mod:`wire_fmu.study.window`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from wire_fmu.master.scene import Scene, SceneError, VarRef

from .window import QUICK_WINDOW

__all__ = [
    "STUDY_KEYS",
    "read_study_table",
    "read_key_outputs",
    "read_steps",
    "read_output_interval",
]

STUDY_KEYS = ("key_outputs", "stop_time", "steps", "output_interval", QUICK_WINDOW)
"""Keys of a scene's optional ``[study]`` table."""


def _multiple(big: float, small: float) -> bool:
    ratio = big / small
    return abs(ratio - round(ratio)) < 1e-6 * max(1.0, ratio) and round(ratio) >= 1


def read_study_table(scene: Scene) -> Mapping[str, Any]:
    """The scene's ``[study]`` table (empty if it has none), its keys checked.

    Parameters
    ----------
    scene : Scene
        The scene.

    Raises
    ------
    SceneError
        Naming the unknown keys.
    """
    table = getattr(scene, "study", None) or {}
    unknown = sorted(set(table) - set(STUDY_KEYS))
    if unknown:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            [f"unknown keys {unknown}; known: {', '.join(STUDY_KEYS)}"],
        )
    return table


def read_key_outputs(scene: Scene, table: Mapping[str, Any]) -> tuple[VarRef, ...]:
    """The key outputs: ``[study] key_outputs``, else the plots' variables, else the outputs.

    Parameters
    ----------
    scene : Scene
        The scene.
    table : mapping
        Its ``[study]`` table.

    Raises
    ------
    SceneError
        If there are none, or one is not ``unit.variable``.
    """
    raw = table.get("key_outputs")
    if raw is None:
        refs = [r for plot in scene.plots for r in plot.variables]
        refs = refs or list(scene.outputs or ())
        if not refs:
            raise SceneError(
                f"scene {scene.name!r}",
                [
                    'no key outputs: give [study] key_outputs = ["unit.variable", ...] or '
                    "[[plots]] variables"
                ],
            )
        return tuple(dict.fromkeys(refs))
    if not isinstance(raw, list) or not raw:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            ["key_outputs must be a non-empty list of 'unit.variable'"],
        )
    refs = [VarRef.parse(text) for text in raw]
    bad = [text for text, ref in zip(raw, refs, strict=True) if ref is None]
    if bad:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            [f"key_outputs: {text!r} is not 'unit.variable'" for text in bad],
        )
    return tuple(dict.fromkeys(refs))


def read_steps(scene: Scene, table: Mapping[str, Any], quick: bool) -> tuple[float, ...]:
    """The macro steps, s, largest first: ``[study] steps``, else the scene's step times 2^k.

    Parameters
    ----------
    scene : Scene
        The scene (its macro step, s).
    table : mapping
        Its ``[study]`` table.
    quick : bool
        Three steps only (the middle three of the table's).

    Raises
    ------
    SceneError
        If the steps are not a list of positive numbers.
    """
    raw = table.get("steps")
    if raw is None:
        exponents = (1, 0, -1) if quick else (2, 1, 0, -1, -2)
        return tuple(scene.run.step * 2.0**k for k in exponents)
    if (
        not isinstance(raw, list)
        or not raw
        or not all(isinstance(h, int | float) and not isinstance(h, bool) and h > 0 for h in raw)
    ):
        raise SceneError(
            f"scene {scene.name!r} [study]",
            ["steps must be a non-empty list of positive macro steps (s)"],
        )
    steps = tuple(sorted((float(h) for h in raw), reverse=True))
    if quick and len(steps) > 3:
        middle = len(steps) // 2
        steps = steps[middle - 1 : middle + 2]
    return steps


def read_output_interval(scene: Scene, table: Mapping[str, Any], steps: Sequence[float]) -> float:
    """The comparison grid's spacing, s: ``[study] output_interval``, else the largest step.

    Parameters
    ----------
    scene : Scene
        The scene.
    table : mapping
        Its ``[study]`` table.
    steps : sequence of float
        The macro steps, s; the interval must be a multiple of each.

    Raises
    ------
    SceneError
        Naming each step the interval is not a multiple of.
    """
    interval = float(table.get("output_interval", steps[0]))
    problems = [
        f"output_interval {interval:g} s is not a multiple of the macro step {h:g} s"
        for h in steps
        if not _multiple(interval, h)
    ]
    if problems:
        raise SceneError(
            f"scene {scene.name!r} [study]",
            problems
            + ["every run is compared on one grid of step ends: choose steps that divide it"],
        )
    return interval
