"""How a unit declares the fields inside a structured parameter (a reeving given as JSON).

Some parameters are tables rather than numbers: the block train's ``reeving``
holds the rope, the bodies, every sheave and the rope's path. Each key of such
a table is declared once as a :class:`DataField` with its unit, default, valid
range, description and the effects it needs to act, exactly as an FMI
variable is (:mod:`~wire_fmu.core.framework.variables`). The parser of the
table reads defaults and bounds from these declarations, and the parameter
reference and the scene checks read the same ones.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

__all__ = ["DataField", "acts_with_effects"]

_KINDS = ("number", "vector", "text", "table", "list")


def acts_with_effects(
    acts_with: Iterable[str], acts_without: Iterable[str], effects: Iterable[str]
) -> bool:
    """Whether something that needs ``acts_with`` and is silenced by ``acts_without`` acts.

    Parameters
    ----------
    acts_with : iterable of str
        Effects of which one must be chosen (none: no such need).
    acts_without : iterable of str
        Effects none of which may be chosen.
    effects : iterable of str
        The effects chosen.

    Returns
    -------
    bool
        True when it has an influence with ``effects``.
    """
    chosen = set(effects)
    needed = set(acts_with)
    if needed and not needed & chosen:
        return False
    return not set(acts_without) & chosen


@dataclass(frozen=True)
class DataField:
    """One key of a table inside a structured parameter.

    Parameters
    ----------
    path : str
        Where the key is, dotted from the parameter's top; ``<name>`` stands for
        any entry of a named table (``"sheaves.<name>.efficiency"``) and ``[i]``
        for any node of a list (``"path[i].wrap"``).
    kind : str
        ``number``, ``vector`` (three numbers), ``text``, ``table`` or ``list``.
    unit : str
        Unit of a number or vector (``"N"``, ``"m"``, ``"1"``); empty otherwise.
    description : str
        One sentence, for humans.
    default : Any
        Value when the key is absent; None when it is required (or has no default).
    required : bool
        The key must be given.
    min, max : float or None
        Bounds of a number, in ``unit`` (inclusive unless ``min_exclusive``).
    min_exclusive : bool
        The value must be strictly greater than ``min``.
    acts_with, acts_without : tuple of str
        Effects of which one must (none may) be chosen for the key to have any
        influence, as for :class:`~wire_fmu.core.framework.variables.Variable`.
    """

    path: str
    kind: str
    unit: str
    description: str
    default: Any = None
    required: bool = False
    min: float | None = None
    max: float | None = None
    min_exclusive: bool = False
    acts_with: tuple[str, ...] = ()
    acts_without: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in _KINDS:
            raise ValueError(f"field {self.path!r}: kind must be one of {_KINDS}")
        if not self.description:
            raise ValueError(f"field {self.path!r}: a description is required")
        if self.kind in ("number", "vector") and not self.unit:
            raise ValueError(f"field {self.path!r}: a number needs a unit ('1' if none)")
        if self.min_exclusive and self.min is None:
            raise ValueError(f"field {self.path!r}: min_exclusive needs a min")

    @property
    def key(self) -> str:
        """The key itself, the last part of :attr:`path`."""
        return self.path.rsplit(".", 1)[-1].split("[", 1)[0]

    def acts(self, effects: Iterable[str]) -> bool:
        """Whether the field has any influence with the effects chosen.

        Parameters
        ----------
        effects : iterable of str
            The effects chosen for the unit.
        """
        return acts_with_effects(self.acts_with, self.acts_without, effects)
