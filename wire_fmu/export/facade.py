"""The generic pythonfmu facade: one FMI variable per declared core variable.

A facade script only names the core unit::

    from wire_fmu.core.units.block_train.model import BlockTrainUnit
    from wire_fmu.export.facade import CoreFacade

    class BlockTrain(CoreFacade):
        unit_class = BlockTrainUnit

What the facade does at each FMI call
-------------------------------------
``fmi2Instantiate``
    Checks that the imported ``wire_fmu`` is the bundled one
    (:mod:`wire_fmu.export.guard`), creates the unit, registers its variables,
    and sets the start values of an FMU configured for one unit
    (:mod:`wire_fmu.export.start_values`).
``fmi2SetupExperiment``
    Remembers the start time.
``fmi2Get*``
    Of a calculated variable (an output), refused (status Error) before
    ``fmi2EnterInitializationMode``: it has no value yet (FMI 2.0 allows no get in the
    Instantiated state; the parameters' and inputs' start values stay readable). A
    value reference no variable has, or one of another type, fails the call naming each.
``fmi2EnterInitializationMode``
    ``unit.configure()``; a :class:`~wire_fmu.core.errors.ConfigurationError`
    is logged (status Error, every problem) and fails the call.
``fmi2ExitInitializationMode``
    Rebuilds the unit if a parameter was set in initialisation mode, then
    ``unit.initialize(start_time)``.
``fmi2DoStep``
    Refuses a step that is not finite and positive or does not start at the
    unit's time; then ``unit.timed_advance(t, h)`` (advance, timed). A step the unit refuses is
    logged (status Discard, with the unit's message) and returns ``False``
    (the binary answers ``fmi2Discard``; the state is that before the step).
``fmi2Get/SetFMUstate``
    The unit's full ``get_state()`` plus every variable value, as JSON data.

Errors
------
The FMU binary (``wire_fmu/export/native/fmi2_python.c``) answers any
exception with ``fmi2Error`` and keeps the instance alive, so a master can
restore a saved state or free it. Every entry point logs why first, once:
a deliberate :class:`~wire_fmu.core.errors.WireFmuError` with its message,
anything else as its type and message (the traceback goes to the Python
logger at debug level), both with status Error, then re-raises. Every
message is also sent to the Python logger ``wire_fmu.export.facade`` at
debug level (the master says the FMI message itself, once).

The logged entry points, the phases and :class:`FacadeError` are in
:mod:`~wire_fmu.export.facade_calls`; the FMU state in
:mod:`~wire_fmu.export.facade_state`.
"""

from __future__ import annotations

import functools
import logging
import math
import operator
from collections.abc import Callable, Iterable, Mapping
from typing import Any, ClassVar
from xml.etree.ElementTree import Element

from pythonfmu import Boolean, Fmi2Slave, Integer, Real, String
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability

import wire_fmu
from wire_fmu.core.errors import WireFmuError
from wire_fmu.core.framework.tuple_getter import tuple_getter
from wire_fmu.core.framework.unit import Causality, Unit, Variability, Variable
from wire_fmu.export.facade_calls import FacadeError, Phase, fmi_access, fmi_entry
from wire_fmu.export.facade_state import STATE_FORMAT, FacadeState
from wire_fmu.export.guard import check_core
from wire_fmu.export.start_values import (
    START_VALUES_FILE,
    StartValuesError,
    fits,
    read_start_values,
)

__all__ = ["CoreFacade", "FacadeError", "Phase", "STATE_FORMAT"]

logger = logging.getLogger(__name__)

STEP_TIME_TOLERANCE = 1e-9
"""Relative tolerance (of max(1 s, t)) between a step's start and the unit's time."""
PHYSICS_SECONDS = "physics_seconds"
"""Local variable of every unit: wall-clock time spent in its physics since instantiation, s."""

_SCALAR = {float: Real, int: Integer, bool: Boolean, str: String}
_CAUSALITY = {
    Causality.parameter: Fmi2Causality.parameter,
    Causality.input: Fmi2Causality.input,
    Causality.output: Fmi2Causality.output,
}
_VARIABILITY = {v: Fmi2Variability[v.value] for v in Variability}
_INITIAL = {
    Causality.parameter: Fmi2Initial.exact,
    Causality.input: None,  # FMI 2.0 forbids `initial` on inputs
    Causality.output: Fmi2Initial.calculated,
}

_SHOWN = 10
"""Most value references a message lists one by one."""


def _joined(items: list[str], word: str) -> str:
    """``"a"``, ``"a or b"``, ``"a, b or c"`` (``word`` joins the last); past :data:`_SHOWN`
    items, ``"a, b, ... or N more"``."""
    if len(items) > _SHOWN:
        return f"{', '.join(items[:_SHOWN])} {word} {len(items) - _SHOWN} more"
    if len(items) == 1:
        return items[0]
    return f"{', '.join(items[:-1])} {word} {items[-1]}"


class CoreFacade(FacadeState, Fmi2Slave):
    """pythonfmu slave that exposes one core :class:`~wire_fmu.core.framework.unit.Unit`.

    Subclasses set :attr:`unit_class` and nothing else.

    Parameters
    ----------
    **kwargs
        As passed by the FMU binary: ``instance_name``, ``resources`` (the FMU's
        resources folder; ``None`` when the facade is used directly from
        Python, which skips the core-version guard), ``visible``, ``logger``.

    Attributes
    ----------
    unit : Unit
        The core unit; FMI variables read and write ``unit.values``.
    """

    unit_class: ClassVar[type[Unit] | None] = None

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        unit_class = self._unit_class()
        if self.resources is not None:
            self._guard_core(unit_class)
        self.modelName = unit_class.NAME
        self.description = unit_class.DESCRIPTION or None
        self.version = wire_fmu.__version__
        self.unit: Unit = unit_class(instance_name=self.instance_name)
        self._phase = Phase.instantiated
        self._describing = False  # to_xml reads start values through get_*, before any phase
        self._start_time = 0.0
        self._time = 0.0
        self._reconfigure = False
        self._inputs_changed = False
        self._initial_outputs_stale = True
        self._core_reals: dict[int, Variable] = {}  # value reference -> declared Real
        self._core_integers: dict[int, Variable] = {}  # value reference -> declared Integer
        self._read_plans: dict[tuple[int, ...], tuple[Callable, bool] | None] = {}
        self._integer_plans: dict[tuple[int, ...], tuple[Callable, bool] | None] = {}
        self._write_plans: dict[tuple[int, ...], tuple[str, ...] | None] = {}
        for var in unit_class.variables():
            self._register(var)
        self._register_timing()
        if self.resources is not None:
            self._apply_start_values(unit_class)

    # -- construction -----------------------------------------------------------
    @classmethod
    def _unit_class(cls) -> type[Unit]:
        unit_class = cls.unit_class
        if not (isinstance(unit_class, type) and issubclass(unit_class, Unit)):
            raise TypeError(
                f"{cls.__name__}.unit_class must be a wire_fmu.core.framework.unit.Unit subclass, "
                f"got {unit_class!r}"
            )
        return unit_class

    def _guard_core(self, unit_class: type[Unit]) -> None:
        try:
            check_core(self.resources, unit_class.NAME, self.instance_name)
        except WireFmuError as exc:
            # The instance does not exist yet, so its log queue never reaches
            # the master: the FMU binary logs the exception as fmi2Fatal, and
            # the Python logger reaches the master's process.
            logger.error("%s", exc)
            raise

    def _apply_start_values(self, unit_class: type[Unit]) -> None:
        """Set the values of the FMU's ``resources/start_values.json``, if it has one.

        An FMU configured by :func:`~wire_fmu.export.start_values.write_configured_fmu`
        carries a unit's parameter values as its start values; they are set here as a
        host would set them before initialisation (a host may still set others).
        """
        try:
            values = read_start_values(self.resources)
        except StartValuesError as exc:
            logger.error("%s %r: %s", unit_class.NAME, self.instance_name, exc)
            raise
        declared = {var.name: var for var in unit_class.variables()}
        problems = []
        for name, value in values.items():
            var = declared.get(name)
            if var is None or var.causality is Causality.output:
                problems.append(f"{name!r} is not a parameter or input of {unit_class.NAME}")
            elif not fits(var.type, value):
                problems.append(f"{name!r} = {value!r}: expected a {var.type.__name__}")
            else:
                try:  # as a host's set: the same checks
                    self._set_value(var, value)
                except FacadeError as exc:
                    problems.append(str(exc))
        if problems:
            exc = StartValuesError(
                f"{unit_class.NAME} {self.instance_name!r} {START_VALUES_FILE}", problems
            )
            logger.error("%s", exc)
            raise exc

    def _register(self, var: Variable) -> None:
        scalar = _SCALAR[var.type](
            var.name,
            causality=_CAUSALITY[var.causality],
            variability=_VARIABILITY[var.variability],
            initial=_INITIAL[var.causality],
            description=var.description,
            getter=functools.partial(self._get_value, var),
            setter=functools.partial(self._set_value, var),
        )
        # nested=False: dotted names are plain keys of unit.values.
        self.register_variable(scalar, nested=False)
        if var.type is float:
            self._core_reals[scalar.value_reference] = var
        elif var.type is int:
            self._core_integers[scalar.value_reference] = var

    def _register_timing(self) -> None:
        # the unit base's timing hook, readable by any master (studies time the physics)
        timing = Real(
            PHYSICS_SECONDS,
            causality=Fmi2Causality.local,
            variability=Fmi2Variability.continuous,
            initial=Fmi2Initial.calculated,
            description="wall-clock time spent in the unit's physics since instantiation, s",
            getter=lambda: self.unit.physics_seconds,
        )
        self.register_variable(timing, nested=False)

    def to_xml(self, model_options: dict[str, str] | None = None) -> Element:
        """The model description, as :meth:`pythonfmu.Fmi2Slave.to_xml` builds it.

        pythonfmu reads the start values through ``get_*``, which a host may not call
        before ``fmi2EnterInitializationMode``; here they are the unit's defaults.

        Parameters
        ----------
        model_options : dict of str to str, optional
            pythonfmu's model options.
        """
        self._describing = True
        try:
            return super().to_xml({} if model_options is None else model_options)
        finally:
            self._describing = False

    @property
    def phase(self) -> Phase:
        """Current life-cycle phase."""
        return self._phase

    @property
    def who(self) -> str:
        """``"<NAME> '<instance>'"``, the prefix of every message."""
        return f"{self.unit.NAME} {self.instance_name!r}"

    # -- messages -----------------------------------------------------------
    def _report(self, message: str, status: Fmi2Status) -> None:
        """Log to the FMI logger (the binary hands Warning and worse to every host) and
        mirror to the Python logger at debug level."""
        text = f"{self.who}: {message}"
        self.log(text, status)
        logger.debug("%s [%s]", text, status.name)

    def _require(self, fmi_name: str, *phases: Phase) -> None:
        if self._phase not in phases:
            allowed = " or ".join(p.value for p in phases)
            raise FacadeError(
                f"{fmi_name} called in phase {self._phase.value!r}; allowed in {allowed}"
            )

    # -- variable access --------------------------------------------------------
    def _get_value(self, var: Variable) -> Any:
        if var.causality is Causality.output:
            if self._phase is Phase.initialization and self._initial_outputs_stale:
                self._initialize_unit()  # masters (libcosim) read outputs before exiting
            elif var.depends_on and self._inputs_changed and self._phase is Phase.step:
                self._evaluate_outputs()
        return self.unit.values[var.name]

    def _initialize_unit(self) -> None:
        # the unit's initial state and outputs for the parameters and inputs set so far
        if self._reconfigure:
            self._rebuild_unit(self.unit.values)
            self._reconfigure = False
        self.unit.initialize(self._start_time)
        self._initial_outputs_stale = False

    def _evaluate_outputs(self) -> None:
        # recompute direct-feedthrough outputs from the new inputs, without stepping
        self.unit.evaluate_outputs()
        self._inputs_changed = False

    def _set_value(self, var: Variable, value: Any) -> None:
        if var.causality is Causality.output:
            raise FacadeError(f"output {var.name!r} cannot be set")
        settled = self._phase in (Phase.step, Phase.terminated)
        if settled and var.variability is Variability.fixed:
            raise FacadeError(
                f"fixed parameter {var.name!r} can only be set before fmi2ExitInitializationMode"
            )
        if var.type is float and (
            value != value or (var.causality is Causality.input and not math.isfinite(value))
        ):
            # a parameter may be infinite (no limit); NaN never, an input never infinite
            raise FacadeError(f"{var.causality.value} {var.name!r} = {value!r}: must be finite")
        self.unit.values[var.name] = var.type(value)
        self._initial_outputs_stale = True
        if var.causality is Causality.input:
            self._inputs_changed = True
        elif self._phase is Phase.initialization:
            self._reconfigure = True

    # The FMU binary's variable access, each failure logged (fmi2GetReal ... fmi2SetString).
    # Reals and Integers, read every step, take a plan worked out once per list of references
    # (and Reals, set every step, another).
    _get_reals = fmi_access("fmi2GetReal", Fmi2Slave.get_real, Real)
    _get_integers = fmi_access("fmi2GetInteger", Fmi2Slave.get_integer, Integer)
    get_boolean = fmi_access("fmi2GetBoolean", Fmi2Slave.get_boolean, Boolean)
    get_string = fmi_access("fmi2GetString", Fmi2Slave.get_string, String)
    _set_reals = fmi_access("fmi2SetReal", Fmi2Slave.set_real, Real)

    def get_real(self, vrs: list[int]) -> list[float]:
        """fmi2GetReal: the values of ``vrs``, in their declared units.

        While stepping, references read before are answered from a plan (their
        names, and whether any depends on inputs); everything else, and every
        failure, goes through :meth:`pythonfmu.Fmi2Slave.get_real` and the
        per-variable checks (failures logged).

        Parameters
        ----------
        vrs : list of int
            Value references.
        """
        values = self._planned_read(vrs, self._read_plans, self._core_reals, float)
        return self._get_reals(vrs) if values is None else values

    def get_integer(self, vrs: list[int]) -> list[int]:
        """fmi2GetInteger: the values of ``vrs``, planned as :meth:`get_real` plans its reads.

        Parameters
        ----------
        vrs : list of int
            Value references.
        """
        values = self._planned_read(vrs, self._integer_plans, self._core_integers, int)
        return self._get_integers(vrs) if values is None else values

    def _planned_read(
        self, vrs: list[int], plans: dict, declared: dict[int, Variable], kind: type
    ) -> list | None:
        """The values of ``vrs`` from their read plan while stepping; None where the
        generic, checked path must answer (another phase, or outputs to re-evaluate)."""
        key = tuple(vrs)
        plan = plans.get(key, False)
        if plan is False:
            plan = plans[key] = self._read_plan(key, declared)
        if plan is None or self._phase is not Phase.step:
            return None
        take, feedthrough = plan
        if feedthrough and self._inputs_changed:
            return None
        return list(map(kind, take(self.unit.values)))

    def _read_plan(
        self, vrs: tuple[int, ...], declared: dict[int, Variable]
    ) -> tuple[Callable[[Mapping[str, Any]], tuple], bool] | None:
        # None: not all declared variables of the unit, of one type (the generic path
        # answers, or refuses); else what takes their values out of the unit's, in order
        found = [declared.get(vr) for vr in vrs]
        if not all(found):
            return None
        feedthrough = any(v.causality is Causality.output and v.depends_on for v in found)
        return tuple_getter(operator.itemgetter, [v.name for v in found]), feedthrough

    def set_real(self, vrs: list[int], values: list[float]) -> None:
        """fmi2SetReal: set ``vrs`` to ``values``, in their declared units.

        While stepping, a list of finite values for inputs only, set before, is
        written at once; everything else goes through
        :meth:`pythonfmu.Fmi2Slave.set_real` and the per-variable checks
        (failures logged).

        Parameters
        ----------
        vrs : list of int
            Value references.
        values : list of float
            A value for each.
        """
        key = tuple(vrs)
        names = self._write_plans.get(key, False)
        if names is False:
            names = self._write_plans[key] = self._write_plan(key)
        if (
            names is not None
            and self._phase is Phase.step
            and len(values) == len(names)
            and all(map(math.isfinite, values))
        ):
            # as many values as names, checked above; strict= costs a keyword parse per call
            self.unit.values.update(zip(names, map(float, values)))  # noqa: B905
            self._initial_outputs_stale = True
            self._inputs_changed = True
            return
        self._set_reals(vrs, values)

    def _write_plan(self, vrs: tuple[int, ...]) -> tuple[str, ...] | None:
        # None: not all inputs of the unit (the generic path sets them, or refuses)
        found = [self._core_reals.get(vr) for vr in vrs]
        if not all(v is not None and v.causality is Causality.input for v in found):
            return None
        return tuple(v.name for v in found)

    set_integer = fmi_access("fmi2SetInteger", Fmi2Slave.set_integer, Integer)
    set_boolean = fmi_access("fmi2SetBoolean", Fmi2Slave.set_boolean, Boolean)
    set_string = fmi_access("fmi2SetString", Fmi2Slave.set_string, String)

    def _calculated_among(self, vrs: Iterable[int]) -> list[str]:
        """Names of the calculated variables (``initial="calculated"``: outputs, calculated
        locals) among the value references ``vrs``; those no variable has are left to the
        access, which names them.

        Parameters
        ----------
        vrs : iterable of int
            The value references of a get.
        """
        found = (self.vars.get(vr) for vr in vrs)
        return [v.name for v in found if v is not None and v.initial is Fmi2Initial.calculated]

    def _reference_problems(self, vrs: Iterable[int], kind: type) -> list[str]:
        """What is wrong with the value references of a get or set of ``kind`` variables.

        Called by :func:`~wire_fmu.export.facade_calls.fmi_access` only once pythonfmu's
        access failed, so a valid call never pays for it.

        Parameters
        ----------
        vrs : iterable of int
            The value references the host passed.
        kind : type
            The pythonfmu variable class of the call (``pythonfmu.Real`` ...).

        Returns
        -------
        list of str
            One sentence for the references no variable has, one for those to variables
            of another type (each names them all); empty if every reference is right.
        """
        wanted = list(dict.fromkeys(vrs))
        unknown = [str(vr) for vr in wanted if vr not in self.vars]
        others = [
            (vr, var)
            for vr in wanted
            if (var := self.vars.get(vr)) is not None and not isinstance(var, kind)
        ]
        problems = []
        if unknown:
            problems.append(
                f"no variable has value reference {_joined(unknown, 'or')}; the unit's value "
                f"references are 0 to {len(self.vars) - 1}"
            )
        article = "an" if kind.__name__[0] in "AEIOU" else "a"
        if len(others) == 1:
            vr, var = others[0]
            problems.append(
                f"value reference {vr} is the {type(var).__name__} variable {var.name!r}, "
                f"not {article} {kind.__name__}"
            )
        elif others:
            refs = _joined([str(vr) for vr, _ in others], "and")
            which = _joined([f"{v.name!r} ({type(v).__name__})" for _, v in others], "and")
            problems.append(f"value references {refs} are not {kind.__name__} variables: {which}")
        return problems

    # -- life cycle ---------------------------------------------------------------
    @fmi_entry("fmi2SetupExperiment")
    def setup_experiment(
        self, start_time: float, stop_time: float | None = None, tolerance: float | None = None
    ) -> None:
        """Remember the start time (before initialisation only; it must be finite).

        Parameters
        ----------
        start_time : float
            Start time, s.
        stop_time : float or None
            Stop time, s (not used).
        tolerance : float or None
            Relative tolerance, 1 (not used).
        """
        self._require("fmi2SetupExperiment", Phase.instantiated)
        if not math.isfinite(start_time):
            raise FacadeError(f"start time {start_time!r} s: must be finite")
        self._start_time = float(start_time)

    @fmi_entry("fmi2EnterInitializationMode")
    def enter_initialization_mode(self) -> None:
        """Configure the unit from its parameters."""
        self._require("fmi2EnterInitializationMode", Phase.instantiated)
        self.unit.configure()
        self._phase = Phase.initialization
        self._reconfigure = False
        self._initial_outputs_stale = True

    @fmi_entry("fmi2ExitInitializationMode")
    def exit_initialization_mode(self) -> None:
        """Initialise the unit at the start time."""
        self._require("fmi2ExitInitializationMode", Phase.initialization)
        self._initialize_unit()
        self._time = self._start_time
        self._phase = Phase.step
        self._inputs_changed = False

    @fmi_entry("fmi2DoStep")
    def do_step(self, current_time: float, step_size: float) -> bool:
        """Advance the unit; log and return ``False`` if it refuses the step.

        Parameters
        ----------
        current_time : float
            Communication point the step starts at, s.
        step_size : float
            Communication step, s.

        Returns
        -------
        bool
            True if the step was taken; False if refused (fmi2Discard).
        """
        self._require("fmi2DoStep", Phase.step)
        self._check_step(current_time, step_size)
        result = self.unit.timed_advance(current_time, step_size)
        for event in result.events:
            self._report(f"t = {current_time + step_size!r} s: {event}", Fmi2Status.ok)
        if not result.success:
            self._report(
                f"step from t = {current_time!r} s by {step_size!r} s refused: {result.message}",
                Fmi2Status.discard,
            )
            return False
        self._inputs_changed = False
        self._time = current_time + step_size
        return True

    def _check_step(self, current_time: float, step_size: float) -> None:
        if not (math.isfinite(step_size) and step_size > 0.0):
            raise FacadeError(f"communication step {step_size!r} s: must be finite and positive")
        scale = abs(self._time)  # max(1, |t|), written out: the builtin parses keywords
        if not math.isfinite(current_time) or abs(
            current_time - self._time
        ) > STEP_TIME_TOLERANCE * (scale if scale > 1.0 else 1.0):
            raise FacadeError(
                f"communication point {current_time!r} s: the unit is at t = {self._time!r} s "
                "(a step starts where the last one ended, or at a restored state's time)"
            )

    @fmi_entry("fmi2Terminate")
    def terminate(self) -> None:
        """Mark the instance terminated."""
        self._phase = Phase.terminated

    def _rebuild_unit(self, values: Mapping[str, Any]) -> None:
        """Fresh unit with ``values``, configured."""
        unit = self._unit_class()(instance_name=self.instance_name)
        unit.values.update(values)
        unit.configure()
        self.unit = unit
