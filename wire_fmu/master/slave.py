"""One co-simulation unit as the master sees it: an FMI 2.0 CS FMU behind fmpy.

The master reaches units only through this class, so it runs any FMI 2.0
co-simulation FMU, not only ours. It adds name-based access with cached
value references, typed setters, FMU state save/restore, per-call counts
and time, and routes the FMU's log messages into Python logging (and keeps
the ones of status Warning or worse so a refused step can be explained).
Setting and reading by name, with every value checked against its type, is
in :mod:`~wire_fmu.master.named_values`; the exceptions a unit's answer
raises are in :mod:`~wire_fmu.master.unit_errors`.

fmpy keeps the logger callback it is handed in one global of a native
library for the whole process, so the callback objects are kept alive in
:data:`_KEEP_ALIVE` for as long as the process lives, and so are the FMU
binaries once loaded (see :meth:`Slave.terminate`); and because fmpy sends
every FMU's messages through the callback registered last, messages are
routed to their instance by name through :data:`_ROUTES`. These two are the
only module-level state of the master.
"""

from __future__ import annotations

import ctypes
import logging
import os
import time
from array import array
from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from operator import itemgetter
from pathlib import Path
from typing import Any

from fmpy import calloc, free, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2Integer,
    fmi2Real,
    fmi2ValueReference,
)
from fmpy.logging import addLoggerProxy

from .archive import ArchiveLimits, extract_temporary, remove_extracted
from .named_values import NamedValues, value_problem
from .unit_errors import StepRefusedError, UnitFailedError

__all__ = ["Slave", "StepRefusedError", "UnitFailedError", "FMI_STATUS", "value_problem"]

logger = logging.getLogger(__name__)

FMI_STATUS = {0: "OK", 1: "Warning", 2: "Discard", 3: "Error", 4: "Fatal", 5: "Pending"}
_C_TYPES = {"Real": fmi2Real, "Integer": fmi2Integer}
"""FMI types read every step into C arrays made once per list of value references."""
_COPY_LIST = itemgetter(slice(None))
"""A C array's values as a new list, made in C (``list()`` would iterate in Python)."""
_clock = time.perf_counter

_HOT_FUNCTIONS = ("fmi2SetReal", "fmi2GetReal", "fmi2GetInteger", "fmi2DoStep")
"""The C functions every macro step calls, taken from fmpy's library once per instantiation."""
_TRUE = ctypes.c_int(1)
"""``fmi2True``, as an ``fmi2Boolean`` argument of an untyped call."""
_KEEP_ALIVE: list[object] = []
_ROUTES: dict[str, _Messages] = {}


def _packed(values: Sequence[float]) -> bytes:
    """Floats as native doubles, as a C double array holds them."""
    return array("d", values).tobytes()


@dataclass
class _Messages:
    """Log messages of one FMU instance (Warning or worse are kept).

    fmpy sends every FMU's messages through the callback registered last, so
    each message is routed by the instance name it carries.
    """

    name: str
    kept: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        _ROUTES[self.name] = self

    def __call__(self, env, instance, status, category, message) -> None:
        text = message.decode("utf-8", "replace") if message else ""
        name = instance.decode("utf-8", "replace") if instance else self.name
        # Discard, Error and Fatal are kept and said once, by the exception the call raises
        level = logging.WARNING if status == 1 else logging.DEBUG
        logger.log(level, "%s [%s]: %s", name, FMI_STATUS.get(status, status), text)
        if status >= 1:
            _ROUTES.get(name, self).kept.append(text)


def _callbacks(messages: _Messages) -> fmi2CallbackFunctions:
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(messages)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    addLoggerProxy(ctypes.byref(callbacks))
    _KEEP_ALIVE.append(callbacks)
    return callbacks


class Slave(NamedValues):
    """An instantiated FMU.

    Parameters
    ----------
    name : str
        Instance name (the scene's unit name).
    path : Path
        The ``.fmu`` file.
    """

    def __init__(self, name: str, path: Path) -> None:
        self.name = name
        self.path = Path(path)
        self.model_description = read_model_description(str(self.path))
        self.variables = {v.name: v for v in self.model_description.modelVariables}
        self.calls: dict[str, int] = defaultdict(int)
        self.seconds: dict[str, float] = defaultdict(float)
        self.messages = _Messages(name)
        self._fmu: FMU2Slave | None = None
        # the prepared gets and sets of get_typed and set_reals, by type and references
        self._prepared: dict[tuple[str, tuple[int, ...]], Callable[..., Any]] = {}
        self._hot: _HotCalls | None = None
        self._fatal = False
        self._unzipdir: str | None = None

    # -- description ---------------------------------------------------------
    @property
    def can_save_state(self) -> bool:
        """Whether the FMU can get and set its state (needed for rollback)."""
        cs = self.model_description.coSimulation
        return bool(cs and cs.canGetAndSetFMUstate)

    def output_dependencies(self) -> dict[str, list[str] | None]:
        """For each output, the inputs it depends on directly (None: all, per FMI)."""
        out = {}
        for unknown in self.model_description.outputs:
            deps = unknown.dependencies
            out[unknown.variable.name] = None if deps is None else [d.name for d in deps]
        return out

    def vr(self, name: str) -> int:
        """Value reference of ``name``.

        Parameters
        ----------
        name : str
            A variable of the FMU's model description.
        """
        return self.variables[name].valueReference

    # -- life cycle ------------------------------------------------------------
    def instantiate(
        self, unzipdir: str | None = None, *, limits: ArchiveLimits | None = None
    ) -> None:
        """Load the binary and instantiate (logging on, into Python logging).

        Parameters
        ----------
        unzipdir : str, optional
            A folder the FMU is already extracted to (left alone). Without it
            the FMU is extracted safely (:mod:`wire_fmu.master.archive`) into
            a private temporary folder, removed by :meth:`terminate`, or at
            once if instantiation fails.
        limits : ArchiveLimits, optional
            Bounds on the extracted size and member count (default 1 GiB,
            10,000 members).

        Raises
        ------
        ArchiveError
            If the FMU cannot be extracted safely (not a zip, too large, a
            member outside the folder); it names the FMU and the problem.
        """
        md = self.model_description
        if unzipdir is None:
            self._remove_unzipdir()  # left by an earlier instantiation that was not terminated
            self._unzipdir = str(
                extract_temporary(self.path, what="FMU", prefix="wire_fmu_fmu_", limits=limits)
            )
            unzipdir = self._unzipdir
        cwd = os.getcwd()
        try:
            self._hot = None
            self._fmu = FMU2Slave(
                guid=md.guid,
                unzipDirectory=unzipdir,
                modelIdentifier=md.coSimulation.modelIdentifier,
                instanceName=self.name,
            )
            self._call("instantiate", callbacks=_callbacks(self.messages), loggingOn=True)
            self._hot = _HotCalls.of(self._fmu)
        except BaseException:
            try:  # fmpy leaves the working directory in the binary's folder if loading fails
                os.chdir(cwd)
            except OSError as exc:
                logger.debug("%s: cannot return to %s: %s", self.name, cwd, exc)
            self._remove_unzipdir()
            raise

    def _remove_unzipdir(self) -> None:
        """Remove the folder this instance extracted its FMU to, if any."""
        if self._unzipdir:
            remove_extracted(self._unzipdir)
            self._unzipdir = None

    def initialize(self, start_time: float, values: dict[str, Any], inputs_first=None) -> None:
        """Set ``values`` (parameters, start inputs), then enter initialisation mode.

        Parameters
        ----------
        start_time : float
            Start of the experiment, s.
        values : dict of str to object
            Start values by variable name, each checked against its type.
        inputs_first : optional
            Unused (no caller passes it).
        """
        self._call("setupExperiment", startTime=start_time)
        self.set_many(values)
        self._call("enterInitializationMode")

    def exit_initialization(self) -> None:
        """Leave initialisation mode."""
        self._call("exitInitializationMode")

    def terminate(self) -> None:
        """Terminate and free the instance (errors ignored: we are cleaning up).

        The FMU's shared library stays loaded until the process ends: a Python
        FMU's code runs in the interpreter it shares with us, which may still
        hold objects whose code lives in it.
        """
        if self._fmu is None:
            self._remove_unzipdir()
            return
        fmu = self._fmu
        if self._fatal:  # FMI 2.0: after fmi2Fatal no further call is allowed
            _KEEP_ALIVE.append(fmu)
            self._fmu, self._hot = None, None
            self._remove_unzipdir()
            return
        for name, call in (
            ("terminate", fmu.terminate),
            ("freeInstance", lambda: fmu.fmi2FreeInstance(fmu.component)),
        ):
            try:
                call()
            except Exception as exc:  # noqa: BLE001 - cleaning up, report and go on
                logger.debug("%s: %s failed during cleanup: %s", self.name, name, exc)
        _KEEP_ALIVE.append(fmu)  # keep the library (and its handle) alive
        self._fmu, self._hot = None, None
        self._remove_unzipdir()  # the loaded library stays mapped; its files can go

    # -- values ------------------------------------------------------------------
    def reader(self, kind: str, refs: Sequence[int]) -> Callable[[], list[Any]]:
        """A get of ``refs`` made ready once, for a read the master makes every macro step.

        The value references and the answer's C array are made here; each call
        is then the FMU's C function, its status checked, counted and timed as
        ``get{kind}`` (see :meth:`get_typed`, which keeps one per list of references).

        Parameters
        ----------
        kind : str
            The variables' FMI type: ``"Real"``, ``"Integer"``, ``"Boolean"`` or
            ``"String"`` (the last two through fmpy's own getters).
        refs : sequence of int
            Value references (see :meth:`vr`).

        Returns
        -------
        callable
            ``read()``: a value for each reference, in the variable's unit (a String
            as bytes), as a new list.
        """
        refs = tuple(refs)
        if not refs:
            return list
        if kind not in _C_TYPES:
            return lambda: self._call(f"get{kind}", list(refs))
        return self._prepared_get(kind, refs, _COPY_LIST, list)

    def packed_reader(self, refs: Sequence[int]) -> Callable[[], bytes]:
        """A get of the Reals ``refs`` made ready once, answering the values packed.

        As :meth:`reader`, but the answer is the C array's bytes (``8 * len(refs)``,
        native doubles): one copy and no float objects, for reads that are mostly
        kept (the recorder turns many of them into one array without a loop).

        Parameters
        ----------
        refs : sequence of int
            Value references of Real variables (see :meth:`vr`).

        Returns
        -------
        callable
            ``read()``: the values, in the variables' units, as native doubles.
        """
        refs = tuple(refs)
        if not refs:
            return bytes
        return self._prepared_get("Real", refs, bytes, _packed)

    def _prepared_get(
        self, kind: str, refs: tuple[int, ...], answer: Callable, through_fmpy: Callable
    ) -> Callable[[], Any]:
        """A get of ``refs`` (Reals or Integers) into a C array made once.

        ``answer(array)`` makes the result from the C array; ``through_fmpy(values)``
        from the list fmpy's wrapper gives when the C function is not at hand.
        """
        fn, native, n = f"get{kind}", f"fmi2Get{kind}", len(refs)
        vrs, values = (fmi2ValueReference * n)(*refs), (_C_TYPES[kind] * n)()
        count = ctypes.c_size_t(n)
        seconds, calls = self.seconds, self.calls

        def read() -> Any:
            hot = self._hot
            if hot is None:  # not instantiated (raises), or an fmpy without C functions
                return through_fmpy(self._call(fn, list(refs)))
            start = _clock()
            status = hot.functions[native](hot.component, vrs, count, values)
            seconds[fn] += _clock() - start
            calls[fn] += 1
            if status > 1:  # worse than fmi2Warning
                raise self._failure(fn, status)
            return answer(values)

        return read

    def writer(self, refs: Sequence[int]) -> Callable[[Sequence[float]], None]:
        """A set of the Reals ``refs`` made ready once, for the master's set every macro step.

        Parameters
        ----------
        refs : sequence of int
            Value references of Real variables (see :meth:`vr`).

        Returns
        -------
        callable
            ``write(values)``: sets a value (in the variable's unit) for each
            reference; a list of another length raises ValueError. Counted and
            timed as ``setReal``.
        """
        refs = tuple(refs)
        n = len(refs)
        if not n:
            return lambda values: None
        vrs, array = (fmi2ValueReference * n)(*refs), (fmi2Real * n)()
        count = ctypes.c_size_t(n)
        seconds, calls = self.seconds, self.calls

        def write(values: Sequence[float]) -> None:
            hot = self._hot
            if hot is None:  # not instantiated (raises), or an fmpy without C functions
                self._call("setReal", list(refs), _listed(values))
                return
            array[:] = values  # the FMU copies them during the call
            start = _clock()
            status = hot.functions["fmi2SetReal"](hot.component, vrs, count, array)
            seconds["setReal"] += _clock() - start
            calls["setReal"] += 1
            if status > 1:
                raise self._failure("setReal", status)

        return write

    def get_typed(self, kind: str, refs: Sequence[int]) -> list[Any]:
        """Values of variables of one FMI type by value reference, in one call.

        Parameters
        ----------
        kind : str
            The variables' FMI type: ``"Real"``, ``"Integer"``, ``"Boolean"`` or
            ``"String"``.
        refs : sequence of int
            Value references (see :meth:`vr`).

        Returns
        -------
        list of object
            A value for each, in the variable's unit (a String as bytes).
        """
        key = (kind, refs if type(refs) is tuple else tuple(refs))
        read = self._prepared.get(key)
        if read is None:
            read = self._prepared[key] = self.reader(kind, key[1])
        return read()

    def set_reals(self, refs: Sequence[int], values: Sequence[float]) -> None:
        """Set Reals by value reference, in one call.

        Parameters
        ----------
        refs : sequence of int
            Value references (see :meth:`vr`).
        values : sequence of float
            A value for each, in the variable's unit.
        """
        key = ("setReal", refs if type(refs) is tuple else tuple(refs))
        write = self._prepared.get(key)
        if write is None:
            write = self._prepared[key] = self.writer(key[1])
        write(values)

    def get_reals(self, refs: Sequence[int]) -> list[float]:
        """Fast path: get Reals by value reference.

        Parameters
        ----------
        refs : sequence of int
            Value references (see :meth:`vr`).

        Returns
        -------
        list of float
            A value for each, in the variable's unit.
        """
        return self._call("getReal", _listed(refs)) if refs else []

    # -- stepping and state ---------------------------------------------------------
    def do_step(self, t: float, h: float) -> None:
        """One communication step.

        Parameters
        ----------
        t : float
            Current communication point, s.
        h : float
            Communication step size, s.

        Raises
        ------
        StepRefusedError
            On fmi2Discard, with the unit's last messages.
        UnitFailedError
            On fmi2Error or fmi2Fatal.
        """
        self.messages.kept.clear()
        hot = self._hot
        if hot is None:
            self._step_through_fmpy(t, h)
            return
        start = _clock()  # currentCommunicationPoint, communicationStepSize, noSetFMUState...
        hot.start.value, hot.size.value = t, h
        status = hot.functions["fmi2DoStep"](hot.component, hot.start, hot.size, _TRUE)
        self.seconds["doStep"] += _clock() - start
        self.calls["doStep"] += 1
        if status > 1:
            raise self._step_failure(t, h, status)

    def _step_through_fmpy(self, t: float, h: float) -> None:
        """:meth:`do_step` by fmpy's wrapper (not instantiated: raises; or no C functions)."""
        try:
            self._call("doStep", t, h, 1)
        except FMICallException as exc:
            raise self._step_failure(t, h, exc.status) from None

    def _step_failure(self, t: float, h: float, status: int) -> Exception:
        """What a step answered with ``status`` (Discard, Error, Fatal) raises."""
        self._fatal = self._fatal or status == 4
        said = "; ".join(self.messages.kept[-3:]) or "no message"
        if status == 2:
            return StepRefusedError(
                f"unit {self.name!r} refused the step at t = {t:.6g} s (h = {h:.3g} s): {said}",
                self.name,
            )
        return UnitFailedError(
            f"unit {self.name!r} failed at t = {t:.6g} s with "
            f"{FMI_STATUS.get(status, status)}: {said}",
            self.name,
        )

    def get_state(self) -> object:
        """Save the FMU state (for rollback)."""
        return self._call("getFMUstate")

    def set_state(self, state: object) -> None:
        """Restore a saved FMU state.

        Parameters
        ----------
        state : object
            A state from :meth:`get_state`, not yet freed.
        """
        self._call("setFMUstate", state)

    def free_state(self, state: object) -> None:
        """Free a saved FMU state.

        Parameters
        ----------
        state : object
            A state from :meth:`get_state`; not used again.
        """
        self._call("freeFMUstate", state)

    def _call(self, fn: str, *args, **kwargs):
        fmu = self._fmu
        if fmu is None:
            raise UnitFailedError(f"unit {self.name!r} is not instantiated", self.name)
        return self._invoke(fn, getattr(fmu, fn), *args, **kwargs)

    def _invoke(self, fn: str, method, *args, **kwargs):
        """``method(*args, **kwargs)``, an FMI call counted and timed as ``fn``."""
        start = _clock()
        try:
            return method(*args, **kwargs)
        except FMICallException as exc:
            if fn == "doStep":
                raise
            raise self._failure(fn, exc.status) from None
        finally:
            self.seconds[fn] += _clock() - start
            self.calls[fn] += 1

    def _failure(self, fn: str, status: int) -> UnitFailedError:
        """What an FMI call ``fn`` other than a step that answered ``status`` raises."""
        self._fatal = self._fatal or status == 4
        said = "; ".join(dict.fromkeys(self.messages.kept[-5:]))
        return UnitFailedError(  # the unit's own words name the call, else we do
            f"unit {self.name!r}: {said}"
            if said
            else f"unit {self.name!r}: {fn} failed with {FMI_STATUS.get(status, status)} "
            "and no message",
            self.name,
        )


@dataclass(frozen=True)
class _HotCalls:
    """An instance's component and the C functions every macro step calls, untyped.

    fmpy's wrapper around each call (a method, its ``_call`` and the optional call
    logger, which the master does not use) costs about as much as the call itself
    for the calls every macro step makes per unit: ``fmi2SetReal``, ``fmi2DoStep``
    and ``fmi2Get{Real,Integer}``. So these C functions are called directly, and
    without declared argument types: ctypes converts each argument of a function
    that declares them through the type's ``from_param``, an ``isinstance`` check
    through ``__instancecheck__`` and a conversion, which cost more than the rest of
    the crossing. Called untyped, a function takes C values as they are, so every
    argument is one: the component (:attr:`component`), the value references and
    values as C arrays and their count as a ``size_t``, each made once per prepared
    get or set, and a step's times as C doubles made once per instance
    (:attr:`start`, :attr:`size`), their values set before each step. The result is
    an ``int``, the ``fmi2Status``.

    The C signatures are FMI 2.0's (``fmi2Functions.h``): ``fmi2SetReal(c, vr[], nvr,
    value[])``, the gets alike, and ``fmi2DoStep(c, t, h, noSetFMUStatePriorToCurrentPoint)``.
    """

    component: ctypes.c_void_p
    functions: dict[str, Any]
    start: ctypes.c_double = field(default_factory=ctypes.c_double)
    """A step's ``currentCommunicationPoint``, s."""
    size: ctypes.c_double = field(default_factory=ctypes.c_double)
    """A step's ``communicationStepSize``, s."""

    @classmethod
    def of(cls, fmu: FMU2Slave) -> _HotCalls | None:
        """The hot calls of an instantiated ``fmu``; None if fmpy's loaded library or the
        instance is not at hand as this fmpy version keeps them."""
        library, component = getattr(fmu, "dll", None), getattr(fmu, "component", None)
        if not isinstance(library, ctypes.CDLL) or not isinstance(component, int):
            return None
        functions = {}
        for name in _HOT_FUNCTIONS:
            try:
                function = library[name]  # a function object of its own: no argument types
            except AttributeError:
                return None
            function.restype = ctypes.c_int  # fmi2Status
            functions[name] = function
        return cls(ctypes.c_void_p(component), functions)


def _listed(items: Sequence[Any]) -> list[Any]:
    """``items`` as a list (itself when it is one: fmpy copies it into a C array)."""
    return items if type(items) is list else list(items)
