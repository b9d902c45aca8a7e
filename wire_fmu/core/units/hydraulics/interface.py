"""The rod force over one step: held, or the effort side's interface model of it.

The unit on the other side of the rod's bond (the block train whose rope the rod
pulls) computes the force; the cylinder integrates its rod against it. Held over a
communication step from ``t0`` the force is ``E0`` (``rod.force``); with the effort
side's *interface model* (issue 17, SPEC section 15b) it is the local model

``F(x, v, t) = E0 - K (d - d_ref) - D (v - v_ref) + R (t - t0)``

with ``d = x - x_start`` the rod's displacement (``rod.displacement``, the port's
position variable, which the master connects to the effort side's position input),
``v`` its velocity, ``K`` (``rod.stiffness``, N/m) and ``D`` (``rod.damping``,
N s/m) the effort's sensitivity to the rod's motion, ``R`` (``rod.effort_rate``,
N/s) its rate with the rod held still, and ``d_ref``, ``v_ref``
(``rod.reference_position``, ``rod.reference_velocity``) the displacement and
velocity the effort side took ``E0`` and its derivatives at. With ``K = D = R = 0``
the force is ``E0``, bit for bit.

:class:`RodInterface` holds ``K, D, R, d_ref, v_ref`` and ``t0``; the model
evaluates ``F`` (in the readable reference and, the same operations in the same
order, in its compiled kernel) and books the work the force does on the rod:
``E0 (x1 - x0)`` and the spring's ``-K [(x1 - x_ref)^2 - (x0 - x_ref)^2] / 2``
exactly (:meth:`RodInterface.elastic_work`), the damper's and the rate's
``integral of (-D (v - v_ref) + R (t - t0)) v dt`` (:meth:`RodInterface.power`) as
a state integrated by the step's own solver.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["INTERFACE_INPUTS", "NO_INTERFACE", "RodInterface"]

INTERFACE_INPUTS = (
    "rod.stiffness",
    "rod.damping",
    "rod.effort_rate",
    "rod.reference_position",
    "rod.reference_velocity",
)
"""The unit's inputs of the interface model, in the order of :class:`RodInterface`'s fields."""


@dataclass(frozen=True)
class RodInterface:
    """The effort side's local model of the rod force about a communication point.

    Parameters
    ----------
    stiffness : float
        ``K = -dF/dx``, N/m (>= 0).
    damping : float
        ``D = -dF/dv``, N s/m (>= 0).
    effort_rate : float
        ``R = dF/dt`` with the rod held still, N/s.
    reference_position : float
        Rod displacement ``d_ref`` the force was linearised at (``rod.displacement``'s
        convention: extension since the start), m.
    reference_velocity : float
        Rod velocity ``v_ref`` it was linearised at, m/s.
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
        """Whether the force varies over the step (any of ``K``, ``D``, ``R`` nonzero)."""
        return self.stiffness != 0.0 or self.damping != 0.0 or self.effort_rate != 0.0

    def reference_extension(self, initial_position: float) -> float:
        """``x_ref``: the rod's extension (from fully retracted) at ``d_ref``, m.

        Parameters
        ----------
        initial_position : float
            The rod's extension at the start, where its displacement is 0, m.
        """
        return initial_position + self.reference_position

    def force(self, held: float, t: float, x: float, v: float, x_ref: float) -> float:
        """``F(x, v, t)``: the rod force of the local model, N.

        Each term is added only when its coefficient is nonzero, so that without the
        model the force is ``held`` exactly (the compiled kernel does the same).

        Parameters
        ----------
        held : float
            ``E0``, the effort side's force at the communication point, N.
        t : float
            Time, s.
        x : float
            Rod extension, m.
        v : float
            Rod velocity, m/s.
        x_ref : float
            :meth:`reference_extension`, m.
        """
        force = held
        if self.stiffness != 0.0:
            force = force - self.stiffness * (x - x_ref)
        if self.damping != 0.0:
            force = force - self.damping * (v - self.reference_velocity)
        if self.effort_rate != 0.0:
            force = force + self.effort_rate * (t - self.start)
        return force

    def power(self, t: float, v: float) -> float:
        """Power of the damper and rate terms into the rod, ``(R (t - t0) - D (v - v_ref)) v``, W.

        Parameters
        ----------
        t : float
            Time, s.
        v : float
            Rod velocity, m/s.
        """
        return (
            self.effort_rate * (t - self.start) - self.damping * (v - self.reference_velocity)
        ) * v

    def elastic_work(self, x0: float, x1: float, x_ref: float) -> float:
        """Work of the spring term as the rod moves from ``x0`` to ``x1`` (m), J.

        ``-K [(x1 - x_ref)^2 - (x0 - x_ref)^2] / 2``, written as a product so that a
        small move about a far reference loses no digits.

        Parameters
        ----------
        x0, x1 : float
            Rod extension at the step's start and end, m.
        x_ref : float
            :meth:`reference_extension`, m.
        """
        return -0.5 * self.stiffness * (x1 - x0) * ((x1 - x_ref) + (x0 - x_ref))

    def problems(self) -> list[str]:
        """A spring or damper of the wrong sign, naming the input (NaN is checked apart)."""
        out = []
        for name, value, unit in (
            ("rod.stiffness", self.stiffness, "N/m"),
            ("rod.damping", self.damping, "N.s/m"),
        ):
            if value < 0.0:
                out.append(
                    f"input {name!r} must be >= 0 {unit} (the effort side's spring and damper "
                    f"resist the rod's motion), got {value!r}"
                )
        return out


NO_INTERFACE = RodInterface()
"""The held force: no interface model."""
