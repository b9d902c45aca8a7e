"""How a unit declares its variables: parameters, inputs and outputs with units and ranges.

The export layer maps each :class:`Variable` onto an FMI scalar variable (its
causality, variability, start value, SI unit, range and the inputs an output
depends on directly); :func:`parameter`, :func:`input_` and :func:`output`
are the short ways to declare one.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any

__all__ = ["Causality", "Variability", "Variable", "input_", "output", "parameter"]


class Causality(StrEnum):
    """Role of a variable at the unit boundary (FMI 2.0 names)."""

    parameter = "parameter"
    input = "input"
    output = "output"


class Variability(StrEnum):
    """How a variable may change (FMI 2.0 names)."""

    fixed = "fixed"
    tunable = "tunable"
    discrete = "discrete"
    continuous = "continuous"


_TYPES = (float, int, bool, str)


@dataclass(frozen=True)
class Variable:
    """One declared variable of a unit.

    Parameters
    ----------
    name : str
        Dotted name, e.g. ``"line_a.tension"``; unique within the unit.
    causality : Causality
        Parameter, input or output.
    type : type
        ``float``, ``int``, ``bool`` or ``str``.
    start : Any
        Start value (parameters and inputs; outputs before initialisation).
    unit : str
        Unit symbol in FMI form (``"N"``, ``"m/s"``, ``"N.m"``, ``"1"``);
        empty for non-Real variables.
    description : str
        One sentence, for humans.
    variability : Variability
        ``fixed`` parameters may be set only before initialisation.
    depends_on : tuple of str
        For outputs: the inputs this output depends on *directly* within
        one step (direct feedthrough). An output of a state of an inertia
        depends on no input. Ignored for non-outputs.
    min, max, nominal : float or None
        Optional bounds and scale for Reals.
    """

    name: str
    causality: Causality
    type: type = float
    start: Any = 0.0
    unit: str = ""
    description: str = ""
    variability: Variability = Variability.continuous
    depends_on: tuple[str, ...] = ()
    min: float | None = None
    max: float | None = None
    nominal: float | None = None

    def __post_init__(self) -> None:
        if self.type not in _TYPES:
            raise TypeError(f"variable {self.name!r}: type must be one of {_TYPES}")
        if not self.description:
            raise ValueError(f"variable {self.name!r}: a description is required")
        if self.type is float and not self.unit:
            raise ValueError(f"variable {self.name!r}: a Real needs a unit ('1' if none)")


def parameter(
    name: str,
    start: Any,
    unit: str,
    description: str,
    *,
    type: type = float,  # noqa: A002 - mirrors the FMI attribute name
    fixed: bool = True,
    min: float | None = None,  # noqa: A002
    max: float | None = None,  # noqa: A002
) -> Variable:
    """Declare a parameter (``fixed`` unless ``fixed=False``).

    Parameters
    ----------
    name : str
        Variable name (``port.quantity`` for a port's variables).
    start : Any
        Start value, in ``unit`` for a Real.
    unit : str
        Unit symbol in FMI form (``"N"``, ``"m/s"``, ``"1"``); ignored for non-Reals.
    description : str
        One sentence, for humans.
    type : type
        ``float``, ``int``, ``bool`` or ``str``.
    fixed : bool
        True: settable only before initialisation; False: tunable.
    min, max : float or None
        Bounds of a Real, in ``unit``; None for none.

    Returns
    -------
    Variable
        The declaration.
    """
    return Variable(
        name,
        Causality.parameter,
        type=type,
        start=start,
        unit=unit if type is float else "",
        description=description,
        variability=Variability.fixed if fixed else Variability.tunable,
        min=min,
        max=max,
    )


def input_(
    name: str,
    start: Any,
    unit: str,
    description: str,
    *,
    type: type = float,  # noqa: A002
) -> Variable:
    """Declare an input: continuous for a Real, discrete otherwise.

    Parameters
    ----------
    name, start, unit, description, type
        As for :func:`parameter`.
    """
    variability = Variability.continuous if type is float else Variability.discrete
    return Variable(
        name,
        Causality.input,
        type=type,
        start=start,
        unit=unit if type is float else "",
        description=description,
        variability=variability,
    )


def output(
    name: str,
    unit: str,
    description: str,
    *,
    depends_on: tuple[str, ...] = (),
    type: type = float,  # noqa: A002
    start: Any = None,
) -> Variable:
    """Declare an output and the inputs it depends on directly.

    Parameters
    ----------
    name : str
        Variable name (``port.quantity`` for a port's variables).
    unit : str
        Unit symbol in FMI form (``"N"``, ``"m/s"``, ``"1"``); ignored for non-Reals.
    description : str
        One sentence, for humans.
    depends_on : tuple of str
        The inputs this output depends on directly within one step (direct feedthrough).
    type : type
        ``float`` (continuous), or ``int``, ``bool``, ``str`` (discrete).
    start : Any
        Start value; None for the type's zero value (``type()``).

    Returns
    -------
    Variable
        The declaration.
    """
    variability = Variability.continuous if type is float else Variability.discrete
    if start is None:
        start = type()
    return Variable(
        name,
        Causality.output,
        type=type,
        start=start,
        unit=unit if type is float else "",
        description=description,
        variability=variability,
        depends_on=tuple(depends_on),
    )
