"""The project's exception hierarchy.

Bad arguments raise one of these; numerical failure inside a step is a
:class:`~wire_fmu.core.framework.unit.StepResult` with a message instead.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

__all__ = [
    "WireFmuError",
    "ConfigurationError",
    "GeometryError",
    "ModelError",
    "check_positive",
]


class WireFmuError(Exception):
    """Base class of every error this project raises on purpose."""


class ConfigurationError(WireFmuError, ValueError):
    """A model description (parameters, reeving, effects) is invalid.

    Carries every problem found, so the user can fix them all at once.

    Parameters
    ----------
    where : str
        The unit or file the problems belong to.
    problems : iterable of str
        One human-readable sentence per problem, each naming the parameter,
        element or variable at fault and what was expected.
    """

    def __init__(self, where: str, problems: Iterable[str]) -> None:
        self.where = where
        self.problems = list(problems)
        lines = "\n".join(f"  - {p}" for p in self.problems)
        count = len(self.problems)
        noun = "problem" if count == 1 else "problems"
        super().__init__(f"{where}: {count} {noun}:\n{lines}")


class GeometryError(ConfigurationError):
    """Sheave geometry that admits no valid rope path (names the sheaves)."""


class ModelError(WireFmuError, RuntimeError):
    """The model reached a state it cannot continue from."""


def check_positive(
    name: str, value: float, out: list[str], unit: str, *, zero_ok: bool = False
) -> None:
    """Append a problem to ``out`` unless parameter ``name`` is finite and > 0 (>= 0).

    Parameters
    ----------
    name : str
        The parameter, as the user sets it.
    value : float
        Its value, in ``unit``.
    out : list of str
        Where the problem is appended.
    unit : str
        The parameter's unit, for the message.
    zero_ok : bool
        Whether 0 is allowed.
    """
    ok = value >= 0.0 if zero_ok else value > 0.0
    if not (ok and math.isfinite(value)):
        relation = ">= 0" if zero_ok else "> 0"
        out.append(f"parameter {name!r} must be {relation} {unit}, got {value}")
