"""How a unit declares its variables: parameters, inputs and outputs with units and ranges.

The export layer maps each :class:`Variable` onto an FMI scalar variable (its
causality, variability, start value, SI unit, range and the inputs an output
depends on directly); :func:`parameter`, :func:`input_` and :func:`output`
are the short ways to declare one.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from wire_fmu.core.framework.data_fields import acts_with_effects

__all__ = [
    "Causality",
    "Variability",
    "Variable",
    "Settings",
    "acts_with_settings",
    "input_",
    "output",
    "parameter",
]


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

Settings = tuple[tuple[str, tuple[Any, ...]], ...]
"""Parameter settings something needs to act: ``(parameter, values it acts with)`` pairs."""


def acts_with_settings(acts_when: Settings, parameters: Mapping[str, Any]) -> bool:
    """Whether something that needs the settings ``acts_when`` acts with ``parameters``.

    Parameters
    ----------
    acts_when : tuple of (str, tuple)
        Each parameter it needs and the values it acts with (one of them).
    parameters : mapping of str to object
        The unit's parameter values by name (a parameter not in it: no need checked).

    Returns
    -------
    bool
        True when every parameter named is set to one of its values.
    """
    return all(name not in parameters or parameters[name] in values for name, values in acts_when)


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
        Optional bounds (inclusive unless ``min_exclusive``) and scale, in ``unit``.
    min_exclusive : bool
        The value must be strictly greater than ``min`` (a length, a mass);
        the model description can only say ``min``, the unit refuses ``min`` itself.
    acts_with : tuple of str
        Effects of which at least one must be chosen for this variable to have
        any influence (``bearing_torque`` acts only with ``bearing_friction``);
        empty when it always acts.
    acts_without : tuple of str
        Effects none of which may be chosen for it to act (a speed command that
        only a drum without inertia follows); empty when none silences it.
    acts_when : tuple of (str, tuple)
        Parameter settings it needs to act, as ``(parameter, values)`` pairs: the
        parameter must be set to one of the values (``handle.torque_command`` acts
        only with ``handle_drive`` ``"torque"``); empty when no parameter silences it.
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
    min_exclusive: bool = False
    acts_with: tuple[str, ...] = ()
    acts_without: tuple[str, ...] = ()
    acts_when: Settings = ()

    def __post_init__(self) -> None:
        if self.type not in _TYPES:
            raise TypeError(f"variable {self.name!r}: type must be one of {_TYPES}")
        if not self.description:
            raise ValueError(f"variable {self.name!r}: a description is required")
        if self.type is float and not self.unit:
            raise ValueError(f"variable {self.name!r}: a Real needs a unit ('1' if none)")
        both = set(self.acts_with) & set(self.acts_without)
        if both:
            raise ValueError(
                f"variable {self.name!r}: effects {sorted(both)} in both acts_with and acts_without"
            )
        if self.min_exclusive and self.min is None:
            raise ValueError(f"variable {self.name!r}: min_exclusive needs a min")
        if not all(isinstance(p, str) and isinstance(v, tuple) for p, v in self.acts_when):
            raise ValueError(f"variable {self.name!r}: acts_when takes (parameter, values) pairs")

    def acts(self, effects: Iterable[str]) -> bool:
        """Whether the variable has any influence with the effects chosen.

        Parameters
        ----------
        effects : iterable of str
            The effects chosen for the unit.
        """
        return acts_with_effects(self.acts_with, self.acts_without, effects)


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
    min_exclusive: bool = False,
    acts_with: tuple[str, ...] = (),
    acts_without: tuple[str, ...] = (),
    acts_when: Settings = (),
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
        Bounds of a Real or an Integer, in ``unit``; None for none.
    min_exclusive : bool
        The value must be strictly greater than ``min``.
    acts_with, acts_without : tuple of str
        The effects without which (with which) it has no influence; see :class:`Variable`.
    acts_when : tuple of (str, tuple)
        The parameter settings it needs to act; see :class:`Variable`.

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
        min_exclusive=min_exclusive,
        acts_with=tuple(acts_with),
        acts_without=tuple(acts_without),
        acts_when=tuple(acts_when),
    )


def input_(
    name: str,
    start: Any,
    unit: str,
    description: str,
    *,
    type: type = float,  # noqa: A002
    acts_with: tuple[str, ...] = (),
    acts_without: tuple[str, ...] = (),
    acts_when: Settings = (),
) -> Variable:
    """Declare an input: continuous for a Real, discrete otherwise.

    Parameters
    ----------
    name, start, unit, description, type, acts_with, acts_without, acts_when
        As for :func:`parameter`.

    Returns
    -------
    Variable
        The declaration.
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
        acts_with=tuple(acts_with),
        acts_without=tuple(acts_without),
        acts_when=tuple(acts_when),
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
