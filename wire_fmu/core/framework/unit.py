"""How a core unit declares itself: variables, feedthrough, state and energy.

A *unit* is one piece of equipment (block train, winch, hydraulics) that
advances in time with its inputs held over a communication step. It knows
nothing of FMI: the export layer maps these declarations onto an FMU, and the
same unit can be stepped directly from Python.

Sign convention, stated once for every unit
-------------------------------------------
* A mechanical *port* is one end of a power bond: one unit outputs a flow
  (velocity or angular velocity, plus its integral, the position), the
  partner outputs the matching effort (force or torque). Each unit counts
  the power that flows *into it* through each port as positive; across a
  bond the two sides' port powers add to zero up to coupling error (the
  bond's energy residual).
* Each unit reports ``stored_energy`` (J) and ``dissipated_energy`` (J,
  integral of loss power, never decreasing) and ``external_work`` (J,
  integral of the power delivered into the unit through its ports). The
  ledger ``stored(t) - stored(0) + dissipated - external_work`` is zero up
  to integration error.
"""

from __future__ import annotations

import math
import time as clock
from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any, ClassVar

import numpy as np

from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.hybrid import IntegrationError
from wire_fmu.core.framework.ports import Port

__all__ = [
    "Causality",
    "Variability",
    "Variable",
    "StepResult",
    "Unit",
    "parameter",
    "input_",
    "output",
    "OdeView",
    "ModelOdeView",
    "STEP_ERRORS",
    "HeldInputsUnit",
]


STEP_ERRORS: tuple[type[Exception], ...] = (
    IntegrationError,
    ModelError,
    ArithmeticError,
    ValueError,
)
"""What a model raises when the physics or the numerics cannot take a step (a refusal, not a
bug): the integrators' errors, a model's own, overflow, division by zero, non-finite values."""


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
    """Declare an input.

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
        ``float`` (continuous), or ``int``, ``bool``, ``str`` (discrete).

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


@dataclass(frozen=True)
class StepResult:
    """Outcome of :meth:`Unit.advance`.

    A refused step (``success`` False) is a physical or numerical stop the
    unit could not step through; ``message`` says why, naming the unit and
    the quantity. The unit's state is then that at the start of the step.
    """

    success: bool
    message: str = ""
    events: tuple[str, ...] = field(default=())


class Unit(ABC):
    """Base class of every core unit.

    Subclasses declare ``VARIABLES`` (a tuple of :class:`Variable`) and
    implement :meth:`configure`, :meth:`initialize`, :meth:`advance`,
    :meth:`get_state` and :meth:`set_state`. Values of all declared
    variables live in :attr:`values`, a plain dict keyed by name, which the
    FMI facade reads and writes.

    Call order: construct -> set parameters and inputs in ``values`` ->
    :meth:`configure` -> :meth:`initialize` -> (set inputs, :meth:`advance`,
    read outputs) ...
    """

    NAME: ClassVar[str] = "Unit"
    DESCRIPTION: ClassVar[str] = ""
    VARIABLES: ClassVar[tuple[Variable, ...]] = ()
    PORTS: ClassVar[tuple[Port, ...]] = ()
    """The unit's power ports (:mod:`~wire_fmu.core.framework.ports`), over its variables."""

    def __init__(self, instance_name: str = "unit") -> None:
        self.instance_name = instance_name
        self.values: dict[str, Any] = {v.name: v.start for v in self.VARIABLES}
        self.physics_seconds = 0.0
        """Wall-clock time spent in :meth:`advance` since construction, s (the timing hook)."""

    # -- declarations -------------------------------------------------------
    @classmethod
    def variables(cls) -> tuple[Variable, ...]:
        """All declared variables, in declaration order."""
        return cls.VARIABLES

    @classmethod
    def variable(cls, name: str) -> Variable:
        """The declared variable called ``name``.

        Parameters
        ----------
        name : str
            Variable name.

        Raises
        ------
        KeyError
            If the unit declares no such variable; the message lists the known ones.
        """
        for var in cls.VARIABLES:
            if var.name == name:
                return var
        known = ", ".join(v.name for v in cls.VARIABLES)
        raise KeyError(f"{cls.NAME} has no variable {name!r}; known: {known}")

    @classmethod
    def check_declarations(cls) -> list[str]:
        """Problems with the declarations themselves (empty when sound)."""
        problems: list[str] = []
        names = [v.name for v in cls.VARIABLES]
        inputs = {v.name for v in cls.VARIABLES if v.causality is Causality.input}
        for name in sorted({n for n in names if names.count(n) > 1}):
            problems.append(f"{cls.NAME}: variable {name!r} declared twice")
        for var in cls.VARIABLES:
            unknown = [d for d in var.depends_on if d not in inputs]
            if unknown:
                problems.append(
                    f"{cls.NAME}.{var.name}: depends_on names {unknown}, which are not inputs"
                )
        causality = {v.name: v.causality.value for v in cls.VARIABLES}
        units = {v.name: v.unit for v in cls.VARIABLES if v.type is float}
        ports = [p.name for p in cls.PORTS]
        for name in sorted({n for n in ports if ports.count(n) > 1}):
            problems.append(f"{cls.NAME}: port {name!r} declared twice")
        for port in cls.PORTS:
            problems += [f"{cls.NAME}: {p}" for p in port.problems(causality, units)]
        return problems

    # -- life cycle ---------------------------------------------------------
    @abstractmethod
    def configure(self) -> None:
        """Build the model from the parameters in :attr:`values`.

        Raises
        ------
        wire_fmu.core.errors.ConfigurationError
            Listing every problem found in the parameters.
        """

    @abstractmethod
    def initialize(self, start_time: float) -> None:
        """Set the initial state from parameters and inputs; fill outputs.

        Parameters
        ----------
        start_time : float
            Start time, s.
        """

    def advance(self, time: float, step: float) -> StepResult:
        """Advance from ``time`` by ``step`` (s) with the inputs held: the life cycle all share.

        Refuses the step when :meth:`input_problems` finds inputs the unit cannot take; else
        saves the state, lets :meth:`_advance` integrate the model and, when it raises one of
        :data:`STEP_ERRORS` (the physics or the numerics cannot go on), restores the state
        and refuses the step with the reason. A step taken moves :attr:`time` and the
        outputs. Every refusal names the unit, the time and the reason.

        Parameters
        ----------
        time : float
            Start of the step, s.
        step : float
            Its length, s.
        """
        who = f"{self.who} at t = {time:.6g} s"
        bad = self.input_problems()
        if bad:
            return StepResult(False, f"{who}: step refused: " + "; ".join(bad))
        saved = self.get_state()
        try:
            events = self._advance(time, step)
            self.time = time + step
            self._update_outputs()
        except STEP_ERRORS as err:
            self.set_state(saved)
            return StepResult(False, f"{who}: step of {step:.3g} s refused: {err}")
        return StepResult(True, events=tuple(events))

    def timed_advance(self, time: float, step: float) -> StepResult:
        """:meth:`advance`, its wall-clock time added to :attr:`physics_seconds` (timing hook).

        Parameters
        ----------
        time : float
            Start of the step, s.
        step : float
            Its length, s.
        """
        started = clock.perf_counter()
        try:
            return self.advance(time, step)
        finally:
            self.physics_seconds += clock.perf_counter() - started

    def _advance(self, time: float, step: float) -> Sequence[str]:
        """Integrate the model from ``time`` by ``step`` (s); return its events, as text."""
        raise NotImplementedError(f"{type(self).__name__} implements neither advance nor _advance")

    def input_problems(self) -> list[str]:
        """Inputs now in :attr:`values` that the unit cannot step with (none by default)."""
        return []

    def _update_outputs(self) -> None:
        """Fill the outputs in :attr:`values` from the model's state (after a step)."""
        raise NotImplementedError(f"{type(self).__name__} fills no outputs")

    def non_finite_inputs(self, names: Sequence[str]) -> list[str]:
        """A problem naming the inputs among ``names`` that are not finite (or none).

        Parameters
        ----------
        names : sequence of str
            Names of the inputs to check (their values in :attr:`values`).
        """
        bad = [n for n in names if not math.isfinite(float(self.values[n]))]
        return [f"inputs {bad} are not finite"] if bad else []

    @property
    def who(self) -> str:
        """``"<NAME> '<instance>'"``, the prefix of the unit's messages."""
        return f"{self.NAME} {self.instance_name!r}"

    def _require_model(self) -> Any:
        """The model :meth:`configure` built (raises before it)."""
        model = getattr(self, "model", None)
        if model is None:
            raise RuntimeError(f"{self.who}: configure() first")
        return model

    @abstractmethod
    def get_state(self) -> dict[str, Any]:
        """Complete internal state as JSON-compatible data (a deep copy)."""

    @abstractmethod
    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state returned by :meth:`get_state`.

        Parameters
        ----------
        state : mapping
            A state returned by :meth:`get_state` of this unit.
        """

    def evaluate_outputs(self) -> None:
        """Recompute direct-feedthrough outputs for the inputs now in :attr:`values`.

        Called when a master reads such an output after setting inputs and
        before stepping. Must not change the unit's state. The default keeps
        the outputs of the last step, right for units without feedthrough.
        """
        return None

    # -- the unit as one piece of a monolithic ODE --------------------------------
    # A unit that implements these can be assembled with others into one
    # hybrid ODE (wire_fmu.study.monolithic), the reference co-simulation is
    # measured against. Inputs are then read from :attr:`values` as
    # instantaneous values (a position input at time t, its rate input as
    # its derivative), not held over a step.
    def ode(self) -> OdeView:
        """The unit's continuous dynamics (raises if the unit has none to offer)."""
        raise NotImplementedError(f"{self.NAME} cannot be part of a monolithic model")

    # -- helpers --------------------------------------------------------------
    def parameters(self) -> dict[str, Any]:
        """Current parameter values by name."""
        return {
            v.name: self.values[v.name]
            for v in self.VARIABLES
            if v.causality is Causality.parameter
        }

    def outputs(self) -> dict[str, Any]:
        """Current output values by name."""
        return {
            v.name: self.values[v.name] for v in self.VARIABLES if v.causality is Causality.output
        }


class HeldInputsUnit(Unit):
    """A unit whose model takes its inputs as one object held over the step.

    The subclass's ``_inputs()`` builds that object from :attr:`values` (with a
    ``problems()`` method naming inputs it cannot take); its model offers
    ``initialize(t, inputs)``, ``advance(t, h, inputs)``, ``stored_energy()``
    and ``last_events`` (``(time, text)`` pairs of the last step).
    """

    def initialize(self, start_time: float) -> None:
        """Initial state for the parameters and inputs set; outputs filled.

        Implements :meth:`Unit.initialize`.

        Parameters
        ----------
        start_time : float
            Start time, s.
        """
        model = self._require_model()
        model.initialize(start_time, self._inputs())
        self.time = start_time
        self.initial_energy = model.stored_energy()
        self._update_outputs()

    def input_problems(self) -> list[str]:
        """Inputs the model cannot step with, as its inputs object names them."""
        return self._inputs().problems()

    def _advance(self, time: float, step: float) -> list[str]:
        """Integrate the model with the inputs held; its events as text."""
        model = self._require_model()
        model.advance(time, step, self._inputs())
        return [f"t = {t:.9g} s: {text}" for t, text in model.last_events]

    @abstractmethod
    def _inputs(self) -> Any:
        """The model's inputs object, from :attr:`values`."""


class OdeView(ABC):
    """A configured, initialised unit seen as a hybrid ODE (see :mod:`~.framework.hybrid`).

    ``bind_inputs(t)`` reads the unit's inputs from its ``values`` as their
    instantaneous values at ``t``; ``rhs``, ``guards``, ``guard_directions``,
    ``handle_events`` and ``project`` are those of a
    :class:`~wire_fmu.core.framework.hybrid.HybridSystem`; ``publish(t, x)`` writes the
    outputs for state ``x`` into ``values``; ``state``/``set_state`` move the
    continuous state in and out of the unit.
    """

    @property
    @abstractmethod
    def state(self) -> Any:
        """Continuous state vector (a copy)."""

    @abstractmethod
    def set_state(self, x: Any, t: float) -> None:
        """Adopt ``x`` at time ``t`` (and refresh the outputs).

        Parameters
        ----------
        x : array_like
            Continuous state (see :attr:`state`).
        t : float
            Time, s.
        """

    @abstractmethod
    def bind_inputs(self, t: float) -> None:
        """Take the inputs now in ``values`` as their values at ``t``.

        Parameters
        ----------
        t : float
            Time the inputs hold at, s.
        """

    @abstractmethod
    def publish(self, t: float, x: Any) -> None:
        """Write the outputs of state ``x`` at ``t`` into ``values``.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).
        """

    @abstractmethod
    def rhs(self, t: float, x: Any) -> Any:
        """State derivative.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            ``dx/dt``, in the layout of ``x``.
        """

    @abstractmethod
    def guards(self, t: float, x: Any) -> Any:
        """Guard values.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            One value per guard; a guard fires when it crosses zero in its direction
            (:meth:`guard_directions`).
        """

    @abstractmethod
    def guard_directions(self) -> Any:
        """Guard directions."""

    @abstractmethod
    def handle_events(self, t: float, x: Any, fired: list[int]) -> Any:
        """Switch modes; return the projected state.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).
        fired : list of int
            Indices of the guards that fired at ``t``.

        Returns
        -------
        numpy.ndarray
            The state after the switches, projected.
        """

    @abstractmethod
    def project(self, x: Any) -> Any:
        """Enforce the mode's invariants.

        Parameters
        ----------
        x : array_like
            Continuous state (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            The state satisfying the invariants (it may be ``x``, changed in place).
        """

    def reconcile(self, t: float, x: Any) -> Any:
        """Inputs jumped at ``t`` (an event): settle modes, act on commands; return the state.

        The default changes nothing.

        Parameters
        ----------
        t : float
            Time of the input jump, s.
        x : array_like
            Continuous state at ``t`` (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            The state to continue from.
        """
        return x


class ModelOdeView(OdeView):
    """An :class:`OdeView` of a unit whose model is a hybrid system over the unit's state.

    The model keeps its continuous state in ``model.state``; the unit keeps
    its time in ``unit.time`` and fills its outputs with
    ``unit._update_outputs()``. The hybrid-system methods are the model's.
    Subclasses add ``bind_inputs`` (and ``reconcile`` where inputs can switch
    modes) and override what differs.
    """

    def __init__(self, unit: Any, model: Any) -> None:
        self.unit = unit
        self.model = model

    @property
    def state(self) -> Any:
        """Continuous state (a copy)."""
        return self.model.state.copy()

    def set_state(self, x: Any, t: float) -> None:
        """Adopt ``x`` at ``t`` and refresh the outputs.

        Implements :meth:`OdeView.set_state`.

        Parameters
        ----------
        x : array_like
            The model's state vector.
        t : float
            Time, s.
        """
        self.model.state = np.array(x, dtype=float)
        self.unit.time = t
        self.bind_inputs(t)
        self.unit._update_outputs()

    def publish(self, t: float, x: Any) -> None:
        """Outputs of ``x`` at ``t`` into ``values``; the state is left alone.

        Implements :meth:`OdeView.publish`.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            The model's state vector.
        """
        saved, self.model.state = self.model.state, np.asarray(x, dtype=float)
        saved_time, self.unit.time = self.unit.time, t
        try:
            self.unit._update_outputs()
        finally:
            self.model.state, self.unit.time = saved, saved_time

    def rhs(self, t: float, x: Any) -> Any:
        """The model's state derivative.

        Implements :meth:`OdeView.rhs`.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            The model's state vector.
        """
        return self.model.rhs(t, x)

    def guards(self, t: float, x: Any) -> Any:
        """The model's guards.

        Implements :meth:`OdeView.guards`.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            The model's state vector.
        """
        return self.model.guards(t, x)

    def guard_directions(self) -> Any:
        """The model's guard directions."""
        return self.model.guard_directions()

    def handle_events(self, t: float, x: Any, fired: list[int]) -> Any:
        """The model's mode switches.

        Implements :meth:`OdeView.handle_events`.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            The model's state vector.
        fired : list of int
            Indices of the guards that fired at ``t``.
        """
        return self.model.handle_events(t, x, fired)

    def project(self, x: Any) -> Any:
        """The model's invariants.

        Implements :meth:`OdeView.project`.

        Parameters
        ----------
        x : array_like
            The model's state vector.
        """
        return self.model.project(x)


def is_finite(value: float) -> bool:
    """True for a finite float (helper for output checks).

    Parameters
    ----------
    value : float
        The value to check.
    """
    return math.isfinite(value)
