"""A unit's parameter reference, read from its own declarations.

Everything here comes from what the units declare: their variables
(:mod:`wire_fmu.core.framework.variables`: unit, start, bounds, description,
the effects a variable needs), their ports, the fields of their structured
parameters (:mod:`wire_fmu.core.framework.data_fields`) and their effect
catalogues, all found through :mod:`wire_fmu.registry`. Nothing is restated.
"""

from __future__ import annotations

import difflib
import json
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.data_fields import DataField, acts_with_effects
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.ports import PORT_KINDS, Port, PortSide
from wire_fmu.core.framework.variables import Causality, Settings, Variable, acts_with_settings
from wire_fmu.registry import BY_NAME, UNIT_TYPES

__all__ = [
    "Entry",
    "UnitReference",
    "unit_reference",
    "unit_names",
    "chosen_effects",
    "format_value",
    "format_range",
    "condition_text",
    "settings_text",
    "port_quantities",
]

_TYPE_NAMES = {float: "Real", int: "Integer", bool: "Boolean", str: "String"}
_LONG_TEXT = 48
"""Longer default texts (JSON tables) are shown by their size, not in full."""


def format_value(value: Any) -> str:
    """A default as the reference shows it.

    Parameters
    ----------
    value : Any
        The value: a number, a vector, a text or None.

    Returns
    -------
    str
        ``repr`` of a float (round-trips), ``true``/``false``, a text in quotes
        (a long one by its size), a vector in brackets; empty for None.
    """
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "inf" if math.isinf(value) else repr(value)
    if isinstance(value, tuple | list):
        return "[" + ", ".join(format_value(float(v)) for v in value) + "]"
    if isinstance(value, str):
        if len(value) > _LONG_TEXT:
            return f"(JSON, {len(value)} characters)" if value[:1] in "{[" else "(long text)"
        return json.dumps(value)
    return str(value)


def format_range(
    low: float | None, high: float | None, low_open: bool = False, high_open: bool = False
) -> str:
    """A valid range as the reference shows it: ``> 0``, ``[1, 2]``, ``(0, 1]``, ``>= 1``.

    Parameters
    ----------
    low, high : float or None
        The bounds (None: unbounded on that side).
    low_open, high_open : bool
        The bound itself is not allowed.

    Returns
    -------
    str
        The range; empty when unbounded.
    """
    if low is None and high is None:
        return ""
    if high is None:
        return f"{'>' if low_open else '>='} {_bound(low)}"
    if low is None:
        return f"{'<' if high_open else '<='} {_bound(high)}"
    left, right = "(" if low_open else "[", ")" if high_open else "]"
    return f"{left}{_bound(low)}, {_bound(high)}{right}"


def _bound(value: float) -> str:
    return f"{value:g}"


@dataclass(frozen=True)
class Entry:
    """One row of the reference: a variable or a field of a structured parameter.

    Attributes
    ----------
    name : str
        Variable name, or a field's path inside its parameter.
    kind : str
        ``parameter``, ``input``, ``output`` or ``field``.
    type : str
        ``Real``, ``Integer``, ``Boolean``, ``String``; for a field its kind
        (``number``, ``vector``, ``text``, ``list``).
    unit : str
        Unit symbol (FMI form), empty when none.
    default : str
        Start value or default, formatted; empty when there is none (an output,
        a required field).
    range : str
        Valid range, formatted (``> 0``, ``[0, 1]``); empty when unbounded.
    description : str
        The declaration's description.
    acts_with, acts_without : tuple of str
        The effects it needs (one of), and those that silence it.
    acts_when : tuple of (str, tuple)
        The parameter settings it needs: ``(parameter, values it acts with)`` pairs.
    required : bool
        A field that must be given.
    tunable : bool
        A parameter that may change during a run.
    value : Any
        The default itself (None when there is none).
    """

    name: str
    kind: str
    type: str
    unit: str
    default: str
    range: str
    description: str
    acts_with: tuple[str, ...] = ()
    acts_without: tuple[str, ...] = ()
    required: bool = False
    tunable: bool = False
    value: Any = None
    acts_when: Settings = ()

    def is_default(self, value: Any) -> bool:
        """Whether ``value`` is the default (numbers compared as numbers).

        Parameters
        ----------
        value : Any
            A value a scene sets.
        """
        if self.value is None or isinstance(value, bool) != isinstance(self.value, bool):
            return False
        if isinstance(value, int | float) and isinstance(self.value, int | float):
            return float(value) == float(self.value)
        return value == self.value

    def acts(self, effects: Iterable[str]) -> bool:
        """Whether this has any influence with the effects chosen.

        Parameters
        ----------
        effects : iterable of str
            The effects chosen for the unit.
        """
        return acts_with_effects(self.acts_with, self.acts_without, effects)

    def acts_with_parameters(self, parameters: Mapping[str, Any]) -> bool:
        """Whether this has any influence with the unit's parameters set so.

        Parameters
        ----------
        parameters : mapping of str to object
            The unit's parameter values by name (its defaults where the scene sets none).
        """
        return acts_with_settings(self.acts_when, parameters)

    @classmethod
    def of_variable(cls, var: Variable) -> Entry:
        """The row of a declared variable.

        Parameters
        ----------
        var : Variable
            The declaration.
        """
        output = var.causality is Causality.output
        return cls(
            var.name,
            var.causality.value,
            _TYPE_NAMES[var.type],
            var.unit,
            "" if output else format_value(var.start),
            format_range(var.min, var.max, var.min_exclusive),
            var.description,
            var.acts_with,
            var.acts_without,
            tunable=var.variability.value == "tunable",
            value=None if output else var.start,
            acts_when=var.acts_when,
        )

    @classmethod
    def of_field(cls, field: DataField) -> Entry:
        """The row of a declared field of a structured parameter.

        Parameters
        ----------
        field : DataField
            The declaration.
        """
        return cls(
            field.path,
            "field",
            field.kind,
            field.unit,
            "" if field.required else format_value(field.default),
            format_range(field.min, field.max, field.min_exclusive),
            field.description,
            field.acts_with,
            field.acts_without,
            required=field.required,
            value=None if field.required else field.default,
        )


@dataclass(frozen=True)
class UnitReference:
    """Everything a scene can set or read on one unit type, from its declarations.

    Attributes
    ----------
    name : str
        Model name, as a scene's ``fmu`` names it.
    description : str
        The unit's one-line description.
    effects : tuple of Effect
        Its optional effects (empty when it has none).
    parameters, inputs, outputs : tuple of Entry
        Its variables by causality, in declaration order.
    ports : tuple of Port
        Its power ports.
    fields : dict of str to tuple of Entry
        The fields of each structured parameter, by parameter name.
    """

    name: str
    description: str
    effects: tuple[Effect, ...]
    parameters: tuple[Entry, ...]
    inputs: tuple[Entry, ...]
    outputs: tuple[Entry, ...]
    ports: tuple[Port, ...]
    fields: dict[str, tuple[Entry, ...]]

    @property
    def effect_names(self) -> tuple[str, ...]:
        """The effects' names, in declaration order."""
        return tuple(e.name for e in self.effects)

    def entry(self, name: str) -> Entry | None:
        """The parameter or input called ``name``, or None.

        Parameters
        ----------
        name : str
            Variable name.
        """
        for item in self.parameters + self.inputs:
            if item.name == name:
                return item
        return None


def unit_names() -> tuple[str, ...]:
    """Our unit types' model names, in the registry's order."""
    return tuple(u.name for u in UNIT_TYPES)


def unit_reference(name: str) -> UnitReference:
    """The reference of unit type ``name``.

    Parameters
    ----------
    name : str
        Model name (``"BlockTrain"``); case and underscores are not significant
        (``block_train`` finds it too).

    Returns
    -------
    UnitReference
        Its declarations.

    Raises
    ------
    ConfigurationError
        When no unit type has that name, listing those that do.
    """
    unit_type = BY_NAME.get(name) or _loose_match(name)
    if unit_type is None:
        close = difflib.get_close_matches(name, list(BY_NAME), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ConfigurationError(
            "wire-fmu info",
            [f"no unit type {name!r}{hint}; unit types: {', '.join(unit_names())}"],
        )
    cls = unit_type.core_class()
    catalogue: EffectCatalogue | None = unit_type.effect_catalogue()
    variables = cls.variables()

    def rows(causality: Causality) -> tuple[Entry, ...]:
        return tuple(Entry.of_variable(v) for v in variables if v.causality is causality)

    return UnitReference(
        unit_type.name,
        cls.DESCRIPTION.removesuffix(", wire_fmu"),
        catalogue.effects if catalogue else (),
        rows(Causality.parameter),
        rows(Causality.input),
        rows(Causality.output),
        tuple(cls.PORTS),
        {param: tuple(Entry.of_field(f) for f in fs) for param, fs in cls.DATA_FIELDS.items()},
    )


def _loose_match(name: str):
    """The unit type whose name matches ``name`` ignoring case and underscores."""
    key = name.replace("_", "").replace("-", "").lower()
    for unit_type in UNIT_TYPES:
        if unit_type.name.lower() == key:
            return unit_type
    return None


def chosen_effects(ref: UnitReference, effects: Iterable[str]) -> frozenset[str]:
    """The effects asked for, checked against the unit's catalogue.

    Parameters
    ----------
    ref : UnitReference
        The unit.
    effects : iterable of str
        Effect names.

    Returns
    -------
    frozenset of str
        The effects.

    Raises
    ------
    ConfigurationError
        Listing every unknown effect (with the unit's effects) and every
        effect whose required effects are missing.
    """
    names = [str(e) for e in effects]
    if not ref.effects:
        if names:
            raise ConfigurationError(
                f"unit type {ref.name!r}",
                [f"has no optional effects; got {', '.join(names)}"],
            )
        return frozenset()
    catalogue = EffectCatalogue(ref.name, ref.effects)
    chosen, problems = catalogue.parse(names)
    if problems:
        raise ConfigurationError(f"unit type {ref.name!r}", problems)
    return chosen


def condition_text(
    effects: tuple[Effect, ...],
    acts_with: tuple[str, ...],
    acts_without: tuple[str, ...],
    acts_when: Settings = (),
) -> str:
    """When something acts, in words: the effects it needs (and what those need), and the
    parameter settings.

    Parameters
    ----------
    effects : tuple of Effect
        The unit's effect catalogue (for what each needed effect requires).
    acts_with, acts_without : tuple of str
        The effects it needs (one of) and those that silence it.
    acts_when : tuple of (str, tuple)
        The parameter settings it needs (:func:`settings_text`).

    Returns
    -------
    str
        E.g. ``"acts only with effect 'bearing_friction' (which needs 'sheave_inertia')"``;
        empty when it always acts.
    """
    requires = {e.name: e.requires for e in effects}
    parts = []
    if acts_with:
        named = [
            f"{name!r}"
            + (f" (which needs {_quoted(requires[name])})" if requires.get(name) else "")
            for name in acts_with
        ]
        noun = "effect" if len(named) == 1 else "one of the effects"
        parts.append(f"acts only with {noun} {', '.join(named)}")
    if acts_without:
        noun = "effect" if len(acts_without) == 1 else "the effects"
        parts.append(f"acts only without {noun} {_quoted(acts_without)}")
    if acts_when:
        parts.append(f"acts only with {settings_text(acts_when)}")
    return "; ".join(parts)


def settings_text(settings: Settings) -> str:
    """Parameter settings in words, as a scene sets them.

    Parameters
    ----------
    settings : tuple of (str, tuple)
        ``(parameter, values)`` pairs.

    Returns
    -------
    str
        E.g. ``'handle_drive = "torque"'``; values joined by ``or``, pairs by ``and``.
    """
    return " and ".join(
        f"{name} = {' or '.join(format_value(v) for v in values)}" for name, values in settings
    )


def _quoted(names: Iterable[str]) -> str:
    return ", ".join(f"{n!r}" for n in names)


def port_quantities(port: Port) -> tuple[str, str]:
    """What a port's unit computes and what it takes, each variable with its unit.

    Parameters
    ----------
    port : Port
        The port.

    Returns
    -------
    gives, takes : str
        ``"rod.force [N]"`` and ``"rod.velocity [m/s], rod.displacement [m]"``: the
        outputs and the inputs of the bond at this port.
    """
    units = dict(zip(("effort", "flow", "position"), PORT_KINDS[port.kind], strict=True))
    names = {"effort": port.effort, "flow": port.flow, "position": port.position}
    motion = ("flow", "position")
    effort_side = port.side is PortSide.effort
    gives, takes = (("effort",), motion) if effort_side else (motion, ("effort",))
    return tuple(
        ", ".join(f"{names[q]} [{units[q]}]" for q in quantities if names[q])
        for quantities in (gives, takes)
    )
