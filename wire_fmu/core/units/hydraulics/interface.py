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
evaluates ``F`` (:meth:`RodInterface.effort` in the readable reference and, the
same operations in the same order, in its compiled kernel) and books the work the
force does on the rod: ``E0 (x1 - x0)`` and the spring's
``-K [(x1 - x_ref)^2 - (x0 - x_ref)^2] / 2`` exactly
(:meth:`RodInterface.elastic_work`), the damper's and the rate's
``integral of (-D (v - v_ref) + R (t - t0)) v dt`` (:meth:`RodInterface.power`)
as a state integrated by the step's own solver.
"""

from __future__ import annotations

from dataclasses import dataclass

from wire_fmu.core.framework.interface_model import EffortModel, interface_input_names

__all__ = ["INTERFACE_INPUTS", "NO_INTERFACE", "RodInterface"]

INTERFACE_INPUTS = interface_input_names("rod")
"""The unit's inputs of the interface model, in the order of :class:`RodInterface`'s fields."""


@dataclass(frozen=True)
class RodInterface(EffortModel):
    """The effort side's local model of the rod force about a communication point.

    The fields and their units are :class:`~wire_fmu.core.framework.interface_model.EffortModel`'s
    (``reference_position`` in ``rod.displacement``'s convention: extension since
    the start); the rod's position in the cylinder's equations is its extension from
    fully retracted (:meth:`reference_extension`).
    """

    def reference_extension(self, initial_position: float) -> float:
        """``x_ref``: the rod's extension (from fully retracted) at ``d_ref``, m.

        Parameters
        ----------
        initial_position : float
            The rod's extension at the start, where its displacement is 0, m.
        """
        return initial_position + self.reference_position


NO_INTERFACE = RodInterface()
"""The held force: no interface model."""
