"""The units' internal solvers as a study varies them: choices, defaults, labels.

A :class:`SolverChoice` is the solver parameters given to the units of one
configuration of the accuracy study (:mod:`wire_fmu.study.accuracy`);
:func:`scene_solver` is the choice a scene makes itself (the units'
declared defaults filled in) and :func:`describe_solver` names a setting by
what sets its accuracy.
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from wire_fmu.core.framework.hybrid import SOLVERS as HYBRID_SOLVERS
from wire_fmu.master.scene import Scene

from .monolithic import CORE_UNITS

__all__ = [
    "UNIT_SOLVER_DEFAULTS",
    "SolverChoice",
    "DEFAULT_SOLVERS",
    "SOLVER_KEYS",
    "describe_solver",
    "scene_solver",
]

UNIT_SOLVER_DEFAULTS = {
    "solver": "ros2",
    "solver_max_step": 1e-3,
    "solver_rtol": 1e-6,
    "solver_atol": 1e-9,
}
"""Solver parameters of a unit of ours that declares none (the winch's default is rk4)."""


@dataclass(frozen=True)
class SolverChoice:
    """Internal-solver parameters applied to the units of a configuration.

    Parameters
    ----------
    label : str
        Short name used in tables and legends, e.g. ``"ros2 h=1e-3"``.
    parameters : mapping
        Unit parameters (``solver``, ``solver_max_step``, ``solver_rtol``,
        ``solver_atol``) given to every unit of ours that has them.
    only : str, optional
        Model name (``"Winch"``): the choice applies only to units of this
        model, the others keep ``parameters_others``; a scene without such a
        unit skips the choice.
    parameters_others : mapping
        What the other units get when ``only`` is set.
    settings : mapping, optional
        The complete solver settings the choice amounts to (defaults filled
        in), when ``parameters`` leaves some to the units; used to compare
        choices and to solve the monolithic model the same way.
    """

    label: str
    parameters: Mapping[str, Any]
    only: str | None = None
    parameters_others: Mapping[str, Any] = field(default_factory=dict)
    settings: Mapping[str, Any] | None = None

    def applies_to(self, scene: Scene) -> bool:
        """Whether the scene has the units this choice is about.

        Parameters
        ----------
        scene : Scene
            The study scene.
        """
        return self.only is None or any(u.fmu == self.only for u in scene.units.values())

    @property
    def complete(self) -> dict[str, Any]:
        """Solver settings with the units' defaults filled in."""
        return {**UNIT_SOLVER_DEFAULTS, **(self.settings or self.parameters)}

    def for_model(self, fmu: str) -> Mapping[str, Any]:
        """Parameters for a unit of model ``fmu``.

        Parameters
        ----------
        fmu : str
            The unit's model name, e.g. ``"Winch"``.
        """
        if self.only is None or fmu == self.only:
            return self.parameters
        return self.parameters_others


_ROS2 = {"solver": "ros2", "solver_max_step": 1e-3}
DEFAULT_SOLVERS = (
    SolverChoice("ros2 h=1e-3", _ROS2),
    SolverChoice("ros2 h=2.5e-4", {"solver": "ros2", "solver_max_step": 2.5e-4}),
    SolverChoice("rk4 h=1e-3", {"solver": "rk4", "solver_max_step": 1e-3}),
    SolverChoice(
        "radau rtol=1e-5",
        {"solver": "radau", "solver_rtol": 1e-5, "solver_atol": 1e-8, "solver_max_step": 1.0},
    ),
    SolverChoice(
        "radau rtol=1e-8",
        {"solver": "radau", "solver_rtol": 1e-8, "solver_atol": 1e-11, "solver_max_step": 1.0},
    ),
    SolverChoice(
        "bdf rtol=1e-6",
        {"solver": "bdf", "solver_rtol": 1e-6, "solver_atol": 1e-9, "solver_max_step": 1.0},
    ),
    SolverChoice("energy (winch)", {"solver": "energy"}, only="Winch"),
)
"""Internal solvers of the full grid (the winch's energy form only where there is a winch);
the scene's own solver settings are always studied as well."""

SOLVER_KEYS = tuple(UNIT_SOLVER_DEFAULTS)


def describe_solver(settings: Mapping[str, Any]) -> str:
    """``"ros2 h=1e-3"``, ``"radau rtol=1e-08"``: a solver by what sets its accuracy.

    Parameters
    ----------
    settings : mapping
        Solver parameters (``solver``, ``solver_max_step`` in s,
        ``solver_rtol``, ...); missing ones take :data:`UNIT_SOLVER_DEFAULTS`.
    """
    full = {**UNIT_SOLVER_DEFAULTS, **settings}
    method = str(full["solver"])
    if method in ("rk4", "ros2"):
        return f"{method} h={float(full['solver_max_step']):g}"
    if method in HYBRID_SOLVERS:
        return f"{method} rtol={float(full['solver_rtol']):g}"
    return method


def _unit_solver_defaults(fmu: str) -> dict[str, Any]:
    """Solver parameter defaults a core unit class declares (ours differ: the winch's is rk4)."""
    try:
        cls = _import(CORE_UNITS[fmu])
    except (ImportError, AttributeError):
        return dict(UNIT_SOLVER_DEFAULTS)
    declared = {v.name: v.start for v in cls.VARIABLES if v.name in SOLVER_KEYS}
    return {**UNIT_SOLVER_DEFAULTS, **declared}


def _import(target: str) -> Any:
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def scene_solver(scene: Scene) -> SolverChoice:
    """The internal solvers as the scene sets them (nothing overridden).

    Parameters
    ----------
    scene : Scene
        The study scene; units that set different solvers make one
        ``(mixed)`` choice.
    """
    complete = [
        {
            **_unit_solver_defaults(spec.fmu),
            **{k: spec.parameters[k] for k in SOLVER_KEYS if k in spec.parameters},
        }
        for spec in scene.units.values()
        if spec.fmu in CORE_UNITS
    ]
    distinct = {json.dumps(c, sort_keys=True) for c in complete}
    if len(distinct) > 1:
        names = [n for n, spec in scene.units.items() if spec.fmu in CORE_UNITS]
        label = ", ".join(f"{n} {describe_solver(c)}" for n, c in zip(names, complete, strict=True))
        return SolverChoice(f"scene: {label}", {}, settings={"solver": "(mixed)"})
    settings = complete[0] if complete else dict(UNIT_SOLVER_DEFAULTS)
    return SolverChoice(f"{describe_solver(settings)} (scene)", {}, settings=settings)
