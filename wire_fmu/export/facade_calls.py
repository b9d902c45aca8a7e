"""How the FMU binary's calls reach a facade: its phases, its error, the logged entry points.

:func:`fmi_entry` wraps every method of :class:`~wire_fmu.export.facade.CoreFacade`
the FMU binary calls, so that a failure is logged once (status Error, through the
facade's FMI logger) before it is re-raised; :func:`fmi_access` makes pythonfmu's
variable access such a method. A traceback goes to the facade's Python logger
``wire_fmu.export.facade`` at debug level, as :mod:`wire_fmu.export.facade` says.
"""

from __future__ import annotations

import functools
import logging
import traceback
from collections.abc import Callable
from enum import StrEnum
from typing import TYPE_CHECKING, Any, TypeVar

from pythonfmu.enums import Fmi2Status

from wire_fmu.core.errors import ConfigurationError, WireFmuError

if TYPE_CHECKING:
    from wire_fmu.export.facade import CoreFacade

__all__ = ["FacadeError", "Phase", "fmi_access", "fmi_entry"]

logger = logging.getLogger("wire_fmu.export.facade")
"""The facade's Python logger, by the name its documentation gives."""

_F = TypeVar("_F", bound=Callable[..., Any])


def fmi_access(fmi_name: str, access: Callable[..., Any], kind: type) -> Callable[..., Any]:
    """Make pythonfmu's variable access ``access`` a facade method whose failures are logged.

    A get of a calculated variable (an output, a calculated local) is refused before
    ``fmi2EnterInitializationMode``: it has no value before the unit is initialised (FMI
    2.0 allows no get in the Instantiated state at all; parameters and inputs, whose start
    values are set then, stay readable, as hosts that read back what they set rely on).
    While the facade writes its model description (its ``_describing``), pythonfmu reads
    the start values so. When ``access`` fails on value
    references, the failure names every reference no variable has and every one of
    another type than ``kind`` (the facade's ``_reference_problems``); the references are
    looked at only then, not on each call.

    Parameters
    ----------
    fmi_name : str
        The FMI function (``"fmi2GetReal"``), for messages.
    access : callable
        The :class:`pythonfmu.Fmi2Slave` method: ``(self, vrs)`` for a get, ``(self, vrs,
        values)`` for a set (value references and values in the variables' declared units).
    kind : type
        The pythonfmu variable class ``access`` reads or writes (``pythonfmu.Real`` ...).
    """
    reads = fmi_name.startswith("fmi2Get")

    def method(self: CoreFacade, vrs: list[int], *values: Any) -> Any:
        if reads and self._phase is Phase.instantiated and not self._describing:
            calculated = self._calculated_among(vrs)
            if calculated:
                raise FacadeError(
                    f"{fmi_name} of {', '.join(map(repr, calculated))} called in phase "
                    f"{Phase.instantiated.value!r}: calculated variables have values from "
                    "fmi2EnterInitializationMode on (parameters and inputs may be read before)"
                )
        try:
            return access(self, vrs, *values)
        except (KeyError, TypeError):
            problems = self._reference_problems(vrs, kind)
            if not problems:
                raise
            raise FacadeError("; ".join(problems)) from None

    method.__name__ = access.__name__
    method.__doc__ = (
        f"{fmi_name}, as :meth:`pythonfmu.Fmi2Slave.{access.__name__}` (failures logged)."
    )
    return fmi_entry(fmi_name)(method)


class FacadeError(WireFmuError, RuntimeError):
    """An FMI call the facade cannot honour (wrong phase, bad state, ...)."""


class Phase(StrEnum):
    """Life-cycle phase of a facade (FMI 2.0 co-simulation states)."""

    instantiated = "instantiated"
    initialization = "initialization"
    step = "step"
    terminated = "terminated"


def fmi_entry(fmi_name: str) -> Callable[[_F], _F]:
    """Decorate a method the FMU binary calls: log why it fails, then re-raise.

    Parameters
    ----------
    fmi_name : str
        The FMI function, for the message (e.g. ``"fmi2DoStep"``).
    """

    def decorate(method: _F) -> _F:
        """``method`` wrapped so that a failure is logged, then re-raised.

        Parameters
        ----------
        method : callable
            A facade method the FMU binary calls.
        """

        @functools.wraps(method)
        def guarded(self: CoreFacade, *args: Any, **kwargs: Any) -> Any:
            """Call the method; on failure report it through the facade and re-raise.

            Parameters
            ----------
            *args, **kwargs : Any
                Arguments of the method.
            """
            try:
                return method(self, *args, **kwargs)
            except ConfigurationError as exc:  # its problems, without the "where" we say already
                self._report(f"{fmi_name} failed: {'; '.join(exc.problems)}", Fmi2Status.error)
                raise
            except WireFmuError as exc:
                self._report(f"{fmi_name} failed: {exc}", Fmi2Status.error)
                raise
            except Exception as exc:
                logger.debug("%s: %s", fmi_name, traceback.format_exc())
                self._report(
                    f"{fmi_name} failed unexpectedly: {type(exc).__name__}: {exc}", Fmi2Status.error
                )
                raise

        return guarded  # type: ignore[return-value]

    return decorate
