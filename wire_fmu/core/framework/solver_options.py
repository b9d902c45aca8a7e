"""The four solver parameters every unit declares, and reading them back.

Each unit lets a scene choose its internal solver (:mod:`wire_fmu.core.framework.hybrid`)
through the same parameters ``solver``, ``solver_max_step``, ``solver_rtol``
and ``solver_atol``; only the defaults differ. Declaring and checking them
lives here, once.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

from wire_fmu.core.framework.hybrid import SOLVERS, SolverSettings
from wire_fmu.core.framework.unit import Variable, parameter

__all__ = ["solver_parameters", "solver_settings"]


def solver_parameters(
    method: str,
    max_step: float,
    *,
    rtol: float = 1e-6,
    atol: float = 1e-9,
    also: Collection[str] = (),
    note: str = "",
    acts_with: tuple[str, ...] = (),
) -> tuple[Variable, ...]:
    """Declarations of the solver parameters with a unit's defaults.

    Parameters
    ----------
    method : str
        Default solver.
    max_step : float
        Default largest internal step, s.
    rtol, atol : float
        Default tolerances of the adaptive solvers.
    also : collection of str
        Solvers the unit offers beyond :data:`~wire_fmu.core.framework.hybrid.SOLVERS`.
    note : str
        Appended to the description of ``solver``.
    acts_with : tuple of str
        Effects without which the unit integrates nothing (the solver then has no
        influence); empty when it always integrates.
    """
    names = ", ".join(sorted(set(SOLVERS) | set(also)))
    text = f"Internal solver: {names}" + (f" ({note})" if note else "")
    positive = {"min": 0.0, "min_exclusive": True, "acts_with": acts_with}
    return (
        parameter("solver", method, "", text, type=str, acts_with=acts_with),
        parameter("solver_max_step", max_step, "s", "Largest internal step", **positive),
        parameter(
            "solver_rtol", rtol, "1", "Relative tolerance of adaptive solvers", max=1.0, **positive
        ),
        parameter("solver_atol", atol, "1", "Absolute tolerance of adaptive solvers", **positive),
    )


def solver_settings(
    values: Mapping[str, Any], also: Collection[str] = ()
) -> tuple[SolverSettings, list[str]]:
    """The settings the solver parameters in ``values`` ask for, and their problems.

    Parameters
    ----------
    values : mapping
        The unit's variable values, with ``solver``, ``solver_max_step``,
        ``solver_rtol`` and ``solver_atol``.
    also : collection of str, optional
        Solvers the unit offers beyond :data:`~wire_fmu.core.framework.hybrid.SOLVERS`.
    """
    settings = SolverSettings(
        str(values["solver"]),
        float(values["solver_max_step"]),
        float(values["solver_rtol"]),
        float(values["solver_atol"]),
    )
    problems = [
        f"parameter {p}" if p.startswith("solver_") else f"parameter 'solver': {p}"
        for p in settings.problems(also)
    ]
    return settings, problems
