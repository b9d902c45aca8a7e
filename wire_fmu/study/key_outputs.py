"""Whether a study's key outputs can say anything: physical quantities that move.

Every error of a study is a deviation divided by a key output's swing
(:func:`~wire_fmu.study.measures.output_error`). Two kinds of key output
make that number meaningless, and a study checks for both before it
reports one:

* **Not a physical quantity.** A count (solver evaluations, internal steps,
  mode events), a flag or a state code says how a unit computed, not what
  it computed: a monolithic reference counts differently or not at all.
  :func:`physical_problem` reads the declaration: an Integer, Boolean,
  Enumeration or String variable; a dimensionless Real (unit ``"1"`` or
  none) whose name or description reads like a count or a state
  (:data:`COUNTER_WORDS`, :data:`STATE_CODES`);
  the FMU's own wall-clock timing (``physics_seconds``). A study refuses
  such a key output, naming it (:func:`check_physical`).
* **Not moving in the window.** An output whose swing in the reference (or,
  in the effects study, the run with every effect) is zero or within the
  reference's own noise — ``swing <= tolerance * max(|y|)`` or ``swing <=
  tolerance`` in its SI unit, with ``tolerance`` 100 times the reference's
  tolerance (:func:`still_tolerance`, 1e-8 for the default 1e-10) — gives
  an error scaled by nothing (a brake-held load in the first second). If
  every key output is still, the study refuses, naming the scene, the
  outputs and the window; if some move, it warns and measures only those
  (:func:`moving_key_outputs`): a key output quiet in one window does not
  make the others' errors meaningless, and the warning says which output
  the reported errors leave out.
"""

from __future__ import annotations

import logging
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from wire_fmu.master.scene import VarRef

from .plan import StudyError
from .timing import PHYSICS_SECONDS

__all__ = [
    "COUNTER_WORDS",
    "STATE_CODES",
    "physical_problem",
    "check_physical",
    "StillOutput",
    "still_tolerance",
    "still_outputs",
    "moving_key_outputs",
]

logger = logging.getLogger(__name__)

COUNTER_WORDS = re.compile(
    r"\b(number of|count|counts|counter|so far|evaluations|iterations|events?|"
    r"status|state|flag|index)\b",
    re.IGNORECASE,
)
"""Words of a dimensionless Real's name or description that make it a count or a state."""

STATE_CODES = re.compile(r"\b\d+\s*[=:]?\s*[a-z][\w ]*,\s*\d+\s*[=:]?\s*[a-z]", re.IGNORECASE)
"""A description listing coded states: ``"0 released, 1 slipping, 2 holding"``."""

_PYTHON_TYPES = {float: "Real", int: "Integer", bool: "Boolean", str: "String"}
_DIMENSIONLESS = ("", "1")
_ROUNDOFF = 1e-12  # relative: far above double round-off accumulated over a run


def _declared_type(var: Any) -> str:
    kind = getattr(var, "type", "Real")
    return _PYTHON_TYPES.get(kind, kind) if isinstance(kind, type) else str(kind)


def _declared_unit(var: Any) -> str:
    unit = getattr(var, "unit", None)
    if unit is None and getattr(var, "declaredType", None) is not None:
        unit = getattr(var.declaredType, "unit", None)
    return unit or ""


def physical_problem(var: Any) -> str | None:
    """Why a declared variable is not a physical quantity; None if it is one.

    Parameters
    ----------
    var : object
        A model variable as an FMU's model description declares it (fmpy's
        ``ScalarVariable``: ``name``, ``type`` ``"Real"``, ``"Integer"``,
        ...; ``unit`` or ``declaredType.unit``; ``description``) or as a core
        unit declares it (:class:`~wire_fmu.core.framework.variables.Variable`,
        ``type`` a Python type).
    """
    kind = _declared_type(var)
    if kind != "Real":
        return f"declared {kind}: a count, a flag or a state, not a physical quantity"
    if getattr(var, "name", "") == PHYSICS_SECONDS:
        return "the FMU's wall-clock time in its physics, not a quantity of the model"
    description = getattr(var, "description", None) or ""
    words = re.sub(r"[._]", " ", getattr(var, "name", "") or "") + " " + description
    if _declared_unit(var) in _DIMENSIONLESS and (
        COUNTER_WORDS.search(words) or STATE_CODES.search(description)
    ):
        return (
            f"a dimensionless Real described as {description!r}: a count or a state, "
            "not a physical quantity"
        )
    return None


def check_physical(
    scene: str, keys: Sequence[VarRef], variable: Callable[[VarRef], Any | None]
) -> None:
    """Refuse key outputs that are not physical quantities.

    Parameters
    ----------
    scene : str
        The scene's name, for the message.
    keys : sequence of VarRef
        The study's key outputs.
    variable : callable
        The declaration of a key output, or None if unknown (e.g.
        :meth:`~wire_fmu.master.validate.Structure.variable`); unknown ones
        pass (the scene's validation names them).

    Raises
    ------
    StudyError
        Naming the scene and each such key output, and why.
    """
    problems = []
    for key in keys:
        var = variable(key)
        why = None if var is None else physical_problem(var)
        if why:
            problems.append(f"key output {key} is {why}")
    if problems:
        raise StudyError(
            f"scene {scene!r}: "
            + "; ".join(problems)
            + ". Its error against the reference would mean nothing: name states or "
            "outputs with a physical unit in [study] key_outputs"
        )


@dataclass(frozen=True)
class StillOutput:
    """A key output that does not move in the window: its swing and magnitude there."""

    key: str
    swing: float
    magnitude: float

    def describe(self) -> str:
        """``"rope.line_a.tension (swing 0 of 1.18e+06)"``."""
        return f"{self.key} (swing {self.swing:.3g} of {self.magnitude:.3g})"


def still_tolerance(reference_rtol: float) -> float:
    """Swing (relative to magnitude, and absolute in SI units) below which an output is still.

    Parameters
    ----------
    reference_rtol : float
        Tolerance (rtol = atol) of the reference the swing is measured in.
    """
    return max(100.0 * reference_rtol, _ROUNDOFF)


def still_outputs(
    values: Mapping[str, np.ndarray], keys: Sequence[str], first: int, tolerance: float
) -> list[StillOutput]:
    """The key outputs whose swing from sample ``first`` on is zero or below ``tolerance``.

    An output is still when ``swing <= tolerance * max|y|`` or ``swing <=
    tolerance`` (or when its samples are not finite numbers).

    Parameters
    ----------
    values : mapping of str to ndarray
        The columns the swing is measured in (the reference), by name.
    keys : sequence of str
        The key outputs.
    first : int
        Index of the window's first sample.
    tolerance : float
        Relative (and absolute, SI) swing threshold, see :func:`still_tolerance`.
    """
    out = []
    for key in keys:
        y = np.asarray(values[key], dtype=float)[first:]
        swing = float(np.ptp(y)) if y.size else 0.0
        magnitude = float(np.max(np.abs(y))) if y.size else 0.0
        moves = (
            math.isfinite(swing)
            and swing > tolerance * magnitude
            and swing > tolerance
            and y.size > 1
        )
        if not moves:
            out.append(StillOutput(key, swing, magnitude))
    return out


def moving_key_outputs(
    scene: str,
    values: Mapping[str, np.ndarray],
    keys: Sequence[VarRef],
    window: tuple[float, float],
    first: int,
    tolerance: float,
    source: str = "reference",
) -> tuple[tuple[VarRef, ...], list[str]]:
    """The key outputs that move in the window, and a warning for each one left out.

    Parameters
    ----------
    scene : str
        The scene's name, for the messages.
    values : mapping of str to ndarray
        The columns of ``source``, by name.
    keys : sequence of VarRef
        The study's key outputs.
    window : tuple of float
        Start and end of the compared window, s.
    first : int
        Index of the window's first sample in ``values``.
    tolerance : float
        See :func:`still_outputs`.
    source : str
        What ``values`` are, for the messages (``"reference"``).

    Returns
    -------
    moving : tuple of VarRef
        The key outputs the errors are measured on.
    notes : list of str
        One warning per still key output (also logged).

    Raises
    ------
    StudyError
        If no key output moves: naming the scene, the outputs and the window.
    """
    still = {s.key: s for s in still_outputs(values, [str(k) for k in keys], first, tolerance)}
    span = f"[{window[0]:g}, {window[1]:g}] s"
    if len(still) == len(keys):
        listed = ", ".join(s.describe() for s in still.values())
        raise StudyError(
            f"scene {scene!r}: no key output moves in the studied window {span} of the "
            f"{source}: {listed}. An error scaled by a zero swing means nothing: study a "
            "window where the scene's action happens ([study] quick_window or --stop-time) "
            "or name key outputs that move"
        )
    notes = [
        f"key output {s.key} does not move in {span} of the {source} (swing {s.swing:.3g} "
        f"of {s.magnitude:.3g}): left out of the errors"
        for s in still.values()
    ]
    for note in notes:
        logger.warning("scene %r: %s", scene, note)
    return tuple(k for k in keys if str(k) not in still), notes
