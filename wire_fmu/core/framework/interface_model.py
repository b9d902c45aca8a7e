"""A flow-side port's local model of the effort it is given: held, or linearised.

Across a power bond the effort side (the block train computing a rope's tension)
offers, with the effort ``E0`` at the communication point ``t0``, its
linearisation there (:data:`~wire_fmu.core.framework.ports.INTERFACE_QUANTITIES`):
``K = -dE/dx``, ``D = -dE/dv``, ``R = dE/dt`` with the port held still, and the
position and velocity ``x_ref``, ``v_ref`` it was taken at. A flow side that accepts
them integrates its step against

``E(x, v, t) = E0 - K (x - x_ref) - D (v - v_ref) + R (t - t0)``

instead of ``E0`` held (issue 17, SPEC section 15b; reduced interface models after
Peiret, Kovecses et al., 2019), so the stiff mode across the bond is inside its own
solver. With ``K = D = R = 0`` the effort is ``E0``, bit for bit.

:class:`EffortModel` holds ``K, D, R, x_ref, v_ref`` and ``t0`` and evaluates the
effort (each term added only when its coefficient is nonzero, in the order above:
the compiled kernels do the same operations in the same order), the power of its
damper and rate terms and the exact work of its spring. The flow side's inputs are
``{port}.{quantity}`` (:func:`interface_inputs` declares them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES, INTERFACE_UNITS
from wire_fmu.core.framework.variables import Variable, input_

__all__ = ["EffortModel", "inputs_taken", "interface_input_names", "interface_inputs"]


def interface_input_names(port: str) -> tuple[str, ...]:
    """The flow side's inputs of ``port``'s interface model, in :class:`EffortModel`'s order.

    Parameters
    ----------
    port : str
        The port's name (``"rod"``, ``"rope"``).
    """
    return tuple(f"{port}.{quantity}" for quantity in INTERFACE_QUANTITIES)


@dataclass(frozen=True)
class EffortModel:
    """The effort side's local model of a port's effort about a communication point.

    Parameters
    ----------
    stiffness : float
        ``K = -dE/dx`` (N/m for a rope or a rod), >= 0.
    damping : float
        ``D = -dE/dv`` (N s/m), >= 0.
    effort_rate : float
        ``R = dE/dt`` with the port held still (N/s).
    reference_position : float
        The port's position ``x_ref`` the effort was linearised at, in the port's own
        position variable (m).
    reference_velocity : float
        The port's velocity ``v_ref`` there (m/s).
    start : float
        The communication point ``t0`` the model is about, s.
    """

    stiffness: float = 0.0
    damping: float = 0.0
    effort_rate: float = 0.0
    reference_position: float = 0.0
    reference_velocity: float = 0.0
    start: float = 0.0

    @property
    def active(self) -> bool:
        """Whether the effort varies over the step (any of ``K``, ``D``, ``R`` nonzero)."""
        return self.stiffness != 0.0 or self.damping != 0.0 or self.effort_rate != 0.0

    def effort(self, held: float, t: float, x: float, v: float, x_ref: float) -> float:
        """``E(x, v, t)``, the effort of the local model (N for a rope or a rod).

        Parameters
        ----------
        held : float
            ``E0``, the effort side's effort at the communication point.
        t : float
            Time, s.
        x : float
            The port's position, in the same frame as ``x_ref``, m.
        v : float
            The port's velocity, m/s.
        x_ref : float
            The reference position in that frame (``reference_position`` itself when
            ``x`` is the port's own position variable), m.
        """
        effort = held
        if self.stiffness != 0.0:
            effort = effort - self.stiffness * (x - x_ref)
        if self.damping != 0.0:
            effort = effort - self.damping * (v - self.reference_velocity)
        if self.effort_rate != 0.0:
            effort = effort + self.effort_rate * (t - self.start)
        return effort

    def power(self, t: float, v: float) -> float:
        """Power of the damper and rate terms into the port, ``(R (t - t0) - D (v - v_ref)) v``, W.

        Parameters
        ----------
        t : float
            Time, s.
        v : float
            The port's velocity, m/s.
        """
        return (
            self.effort_rate * (t - self.start) - self.damping * (v - self.reference_velocity)
        ) * v

    def elastic_work(self, x0: float, x1: float, x_ref: float) -> float:
        """Work of the spring term as the port moves from ``x0`` to ``x1`` (m), J.

        ``-K [(x1 - x_ref)^2 - (x0 - x_ref)^2] / 2``, written as a product so that a
        small move about a far reference loses no digits.

        Parameters
        ----------
        x0, x1 : float
            The port's position at the step's start and end, m.
        x_ref : float
            The reference position in the same frame, m.
        """
        return -0.5 * self.stiffness * (x1 - x0) * ((x1 - x_ref) + (x0 - x_ref))

    def problems(self, port: str) -> list[str]:
        """A spring or damper of the wrong sign, naming the input (NaN is checked apart).

        Parameters
        ----------
        port : str
            The port's name, for the inputs' names (``"rod"``, ``"rope"``).
        """
        out = []
        for quantity, value, unit in (
            ("stiffness", self.stiffness, "N/m"),
            ("damping", self.damping, "N.s/m"),
        ):
            if value < 0.0:
                out.append(
                    f"input '{port}.{quantity}' must be >= 0 {unit} (the effort side's spring "
                    f"and damper resist the {port}'s motion), got {value!r}"
                )
        return out


def interface_inputs(
    port: str, kind: str, effort: str, position: str, velocity: str
) -> tuple[Variable, ...]:
    """Declare a flow-side port's interface-model inputs (all 0: the effort is held).

    Parameters
    ----------
    port : str
        The port's name (``"rod"``).
    kind : str
        Its kind (a key of :data:`~wire_fmu.core.framework.ports.INTERFACE_UNITS`).
    effort, position, velocity : str
        The port's effort input and its position and velocity outputs (full names,
        ``"rod.force"``), for the descriptions.

    Returns
    -------
    tuple of Variable
        The inputs, named by :func:`interface_input_names`.
    """
    stiffness, damping, rate, position_unit, velocity_unit = INTERFACE_UNITS[kind]
    model = (
        f"the {effort} over the step is {effort} - K ({position} - reference_position) "
        f"- D ({velocity} - reference_velocity) + R (t - t0)"
    )
    described = (
        (stiffness, f"K = -d {effort} / d {position} of the effort side, >= 0; {model}"),
        (damping, f"D = -d {effort} / d {velocity} of the effort side, >= 0"),
        (
            rate,
            f"R = d {effort} / d t with the {port} held still (the effort side's other "
            "inputs), from the communication point t0",
        ),
        (
            position_unit,
            f"{position} at which the effort side took {effort} and its derivatives",
        ),
        (
            velocity_unit,
            f"{velocity} at which the effort side took {effort} and its derivatives",
        ),
    )
    return tuple(
        input_(name, 0.0, unit, f"Interface model: {text}")
        for name, (unit, text) in zip(interface_input_names(port), described, strict=True)
    )


def inputs_taken(values: Sequence[float], stiffness_at: int) -> bool:
    """Whether a flow side can step with its inputs' flat ``values``: all finite, and the
    interface model's spring and damper (``values[stiffness_at]`` and the next, as
    :class:`EffortModel` orders them) not negative, as :meth:`EffortModel.problems` asks.

    The quiet steps' check, without a word put together; the general way names what is
    wrong.

    Parameters
    ----------
    values : sequence of float
        The unit's flat inputs, the interface model's among them.
    stiffness_at : int
        Where the interface model's stiffness is in ``values``.
    """
    return (
        all(map(math.isfinite, values))
        and values[stiffness_at] >= 0.0
        and values[stiffness_at + 1] >= 0.0
    )
