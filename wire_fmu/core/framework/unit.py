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
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.data_fields import DataField
from wire_fmu.core.framework.hybrid import IntegrationError
from wire_fmu.core.framework.ode_view import ModelOdeView, OdeView
from wire_fmu.core.framework.ports import Port
from wire_fmu.core.framework.variables import (
    Causality,
    Variability,
    Variable,
    input_,
    output,
    parameter,
)

__all__ = [
    "Causality",
    "Variability",
    "Variable",
    "StepResult",
    "STEP_TAKEN",
    "Unit",
    "parameter",
    "input_",
    "output",
    "OdeView",
    "ModelOdeView",
    "STEP_ERRORS",
    "HeldInputsUnit",
    "MODE_CHANGE_TIME",
    "MODE_CHANGES",
    "mode_change_time_output",
]

MODE_CHANGE_TIME = "mode_change_time"
"""The output that tells when a unit's mode first changed inside its last step."""

MODE_CHANGES = "mode_changes"
"""The Integer output that counts a unit's mode changes (stick/slip, slack, a break)."""


def mode_change_time_output(what: str) -> Variable:
    """Declare :data:`MODE_CHANGE_TIME`, for a unit whose model notes ``first_event_time``.

    Parameters
    ----------
    what : str
        The unit's mode changes, for the description (``"stick/slip, slack, break"``).

    Returns
    -------
    Variable
        An output in s: the time of the first mode change inside the latest step
        that had one (:data:`MODE_CHANGES` moved), where the model located it,
        else that step's end; a step without one leaves it as it was. It
        therefore changes exactly at the steps where :data:`MODE_CHANGES` does,
        so a master can watch it in its batched read of Reals instead of reading
        the Integer counter too; one that sees it move to an instant inside the
        step can step every unit to that instant.
    """
    return output(
        MODE_CHANGE_TIME,
        "s",
        f"Time of the first mode change ({what}) inside the latest step that had one "
        "(that step's end where not located)",
    )


STEP_ERRORS: tuple[type[Exception], ...] = (
    IntegrationError,
    ModelError,
    ArithmeticError,
    ValueError,
)
"""What a model raises when the physics or the numerics cannot take a step (a refusal, not a
bug): the integrators' errors, a model's own, overflow, division by zero, non-finite values."""


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


STEP_TAKEN = StepResult(True)
"""A step taken without events (a frozen result: one serves every such step)."""


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
    DATA_FIELDS: ClassVar[Mapping[str, tuple[DataField, ...]]] = MappingProxyType({})
    """The fields inside each structured (JSON text) parameter, by parameter name
    (:mod:`~wire_fmu.core.framework.data_fields`)."""

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
        parameters = {v.name for v in cls.VARIABLES if v.causality is Causality.parameter}
        for var in cls.VARIABLES:
            unknown = [d for d in var.depends_on if d not in inputs]
            if unknown:
                problems.append(
                    f"{cls.NAME}.{var.name}: depends_on names {unknown}, which are not inputs"
                )
            unknown = [p for p, _ in var.acts_when if p not in parameters]
            if unknown:
                problems.append(
                    f"{cls.NAME}.{var.name}: acts_when names {unknown}, which are not parameters"
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

        Takes a step in which nothing happens at once where the unit can
        (:meth:`_take_quiet_step`). Else refuses the step when :meth:`input_problems` finds
        inputs the unit cannot take; else saves the state, lets :meth:`_advance` integrate
        the model and, when it raises one of :data:`STEP_ERRORS` (the physics or the
        numerics cannot go on), restores the state and refuses the step with the reason. A
        step taken moves :attr:`time` and the outputs. Every refusal names the unit, the
        time and the reason.

        Parameters
        ----------
        time : float
            Start of the step, s.
        step : float
            Its length, s.
        """
        if self._take_quiet_step(time, step):
            return STEP_TAKEN
        return self._advance_checked(time, step)

    def _advance_checked(self, time: float, step: float) -> StepResult:
        """:meth:`advance` the general way: the inputs checked, the state saved to undo a
        refused step, the model integrated, the outputs filled.

        Parameters
        ----------
        time : float
            Start of the step, s.
        step : float
            Its length, s.
        """
        bad = self.input_problems()
        if bad:
            refused = f"{self.who} at t = {time:.6g} s: step refused: "
            return StepResult(False, refused + "; ".join(bad))
        saved = self._snapshot()
        changes = self.values.get(MODE_CHANGES)
        try:
            # numpy's floating-point warnings stay out of the host's terminal while the model
            # is integrated: a state that is not finite is refused, naming the unit and step
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                events = self._advance(time, step)
            self.time = time + step
            self._update_outputs()
            if MODE_CHANGE_TIME in self.values and self.values.get(MODE_CHANGES) != changes:
                self._note_mode_change_time(time, step)
        except STEP_ERRORS as err:
            self._restore_snapshot(saved)
            return StepResult(
                False, f"{self.who} at t = {time:.6g} s: step of {step:.3g} s refused: {err}"
            )
        return StepResult(True, events=tuple(events)) if events else STEP_TAKEN

    def _take_quiet_step(self, time: float, step: float) -> bool:
        """Take the step from ``time`` by ``step`` (s) at once if nothing happens in it.

        A unit whose compiled kernel can take a step in which no mode changes and no
        event falls, outputs included, in a few calls overrides this: it then takes the
        whole step (state, time, outputs) and answers True, or changes nothing and
        answers False, and :meth:`advance` takes the step the general way (checks, undo
        snapshot, events). By default: False.

        Parameters
        ----------
        time : float
            Start of the step, s.
        step : float
            Its length, s.
        """
        return False

    def _note_mode_change_time(self, time: float, step: float) -> None:
        """Write when the mode changed in the step just taken from ``time`` (s): the model's
        first located event inside ``(time, time + step)``, else the step's end, s."""
        first = getattr(self.model, "first_event_time", math.inf)
        self.values[MODE_CHANGE_TIME] = first if time < first < time + step else time + step

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
        values = self.values
        if all(map(math.isfinite, map(float, map(values.__getitem__, names)))):
            return []  # every step's case, without a Python loop
        bad = [n for n in names if not math.isfinite(float(values[n]))]
        return [f"inputs {bad} are not finite"]

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

    def _snapshot(self) -> Any:
        """What :meth:`advance` keeps to undo a refused step (default :meth:`get_state`).

        A unit may keep something cheaper than its full, serialisable state: this
        is taken every step and never leaves the process.
        """
        return self.get_state()

    def _restore_snapshot(self, saved: Any) -> None:
        """Undo a refused step from what :meth:`_snapshot` kept.

        Parameters
        ----------
        saved : object
            What :meth:`_snapshot` returned before the step.
        """
        self.set_state(saved)

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
        """
        model = self._require_model()
        model.initialize(start_time, self._inputs())
        self.time = start_time
        self.initial_energy = model.stored_energy()
        self._update_outputs()

    _step_inputs: Any = None
    """The inputs object of the step under way (see :meth:`_advance_checked`), else None."""

    def _advance_checked(self, time: float, step: float) -> StepResult:
        """:meth:`Unit._advance_checked`, the inputs object built once for the step: the
        check of the inputs and the integration take the same one (a quiet step, taken
        before, builds none).

        Parameters
        ----------
        time : float
            Start of the step, s.
        step : float
            Its length, s.
        """
        self._step_inputs = self._inputs()
        try:
            return super()._advance_checked(time, step)
        finally:
            self._step_inputs = None

    def step_inputs(self) -> Any:
        """The inputs object of the step under way, else one from :attr:`values` now."""
        inputs = self._step_inputs
        return self._inputs() if inputs is None else inputs

    def input_problems(self) -> list[str]:
        """Inputs the model cannot step with, as its inputs object names them."""
        return self.step_inputs().problems()

    def _advance(self, time: float, step: float) -> list[str]:
        """Integrate the model with the inputs held; its events as text."""
        model = self._require_model()
        model.advance(time, step, self.step_inputs())
        return [f"t = {t:.9g} s: {text}" for t, text in model.last_events]

    @abstractmethod
    def _inputs(self) -> Any:
        """The model's inputs object, from :attr:`values`."""
