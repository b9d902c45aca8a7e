"""Running an exported SSP package in FMPy's own SSP runner, ``fmpy.ssp.simulate_ssp``.

FMPy's runner (``fmpy/ssp/simulation.py``, FMPy 0.3) is a short Jacobi loop
with inputs held over each step, as libcosim's fixed-step algorithm and our
master with ``algorithm = "jacobi"``, ``extrapolation = "constant"``. It
differs from both in what it does before and around the loop; what follows
is read from its source:

* **No parameter bindings.** It applies none of the package's
  ``ssd:ParameterBinding`` elements; the only values it sets before
  initialisation are those of its ``parameter_set`` argument, named
  ``<component>.<variable>``. Our packages need none: each unit's FMU starts
  with the unit's values (:mod:`wire_fmu.export.start_values`).
  :func:`fmpy_parameter_set` makes that set from the package's own bindings,
  for a package whose bindings were edited after export.
* **No String values.** Its ``set_value`` raises ``Exception("Unsupported
  type: String")`` for a String variable. In our packages a String parameter
  (a unit's ``effects``, a block train's ``reeving``) reaches the unit as its
  FMU's start value; :func:`fmpy_parameter_set` leaves out a String equal to
  the FMU's start value and refuses any other, naming each.
* **Booleans from text.** It sets a Boolean to ``value != 0.0``, which is
  true for the SSV text ``"false"``; the set made here gives 0.0 or 1.0.
* **Inputs start at zero.** Every connector starts at 0.0 and the loop steps
  first and reads outputs after: during the first step every connected input
  is 0.0, whatever its partner's initial output (our master and libcosim hand
  the initial outputs over before the first step). Results agree with ours
  only for a system whose connected inputs start at zero.
* **Time.** It counts time by adding the step (``time += step_size``) and
  records at each time ``t`` the values after the step from ``t`` to ``t + h``.

``tests/test_interop_fmpy.py`` runs an exported package in it and compares
with our master step for step.
"""

from __future__ import annotations

import io
import logging
from pathlib import Path
from typing import Any

from wire_fmu.core.errors import ConfigurationError

__all__ = ["FmpyRunnerError", "fmpy_parameter_set"]

logger = logging.getLogger(__name__)


class FmpyRunnerError(ConfigurationError):
    """A package holds values FMPy's SSP runner cannot set; ``problems`` names each."""


def fmpy_parameter_set(package: str | Path) -> Any:
    """The package's bound parameter values as the ``parameter_set`` FMPy's runner takes.

    Parameters
    ----------
    package : str or Path
        An SSP package (``.ssp``), as :func:`~wire_fmu.interop.export_ssp` writes it.

    Returns
    -------
    fmpy.ssp.ssd.ParameterSet
        One parameter per bound value, named ``<component>.<variable>``: Reals
        and Integers as numbers in the variable's unit, Booleans as 0.0 or 1.0.
        Pass it as ``simulate_ssp(package, ..., parameter_set=...)``.

    Raises
    ------
    FmpyRunnerError
        When a bound value is a String other than the FMU's own start value
        (FMPy's runner raises on any String it sets), naming every one, or of
        a type it does not set.
    """
    from fmpy.ssp.ssd import Parameter, ParameterSet, read_ssd

    ssd = read_ssd(str(package))
    result = ParameterSet(name=f"{ssd.name or 'system'} parameters")
    problems: list[str] = []
    for component in ssd.system.elements:
        defaults = _start_values(package, component.source)
        for binding in getattr(component, "parameterBindings", []):
            for values in binding.parameterValues:
                for p in values.parameters:
                    name = f"{component.name}.{p.name}"
                    value = _number(p.type, p.value)
                    if value is None and p.type == "String" and defaults.get(p.name) == p.value:
                        continue  # the FMU's own start value: nothing to set
                    if value is None:
                        problems.append(
                            f"{name} is a {p.type} ({_shown(p.value)}); FMPy's simulate_ssp "
                            "sets Real, Integer and Boolean variables only"
                        )
                        continue
                    result.parameters.append(Parameter(name=name, type=p.type, value=value))
    if problems:
        raise FmpyRunnerError(f"SSP package {Path(package).name}", problems)
    logger.debug("%d parameters for FMPy's SSP runner", len(result.parameters))
    return result


def _start_values(package: str | Path, source: str | None) -> dict[str, str]:
    """Start values (as text) the FMU ``source`` of the package declares, by variable name."""
    if not source:
        return {}
    import zipfile

    from fmpy import read_model_description

    with zipfile.ZipFile(package) as archive:
        try:
            data = archive.read(source.removeprefix("file:"))
        except KeyError:
            return {}
    model = read_model_description(io.BytesIO(data), validate=False)
    return {v.name: v.start for v in model.modelVariables if v.start is not None}


def _number(kind: str | None, text: str | None) -> float | int | None:
    """An SSV value as the number FMPy's ``set_value`` sets correctly; None if it cannot."""
    if text is None:
        return None
    if kind == "Real":
        return float(text)
    if kind in ("Integer", "Enumeration"):
        return int(text)
    if kind == "Boolean":
        return 1.0 if text.strip().lower() in ("true", "1") else 0.0
    return None


def _shown(text: str | None, limit: int = 40) -> str:
    value = repr(text)
    return value if len(value) <= limit else value[: limit - 4] + "...'"
