"""The project's exception hierarchy.

Bad arguments raise one of these; numerical failure inside a step is a
:class:`~wire_fmu.core.framework.unit.StepResult` with a message instead.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["WireFmuError", "ConfigurationError", "GeometryError", "ModelError"]


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
