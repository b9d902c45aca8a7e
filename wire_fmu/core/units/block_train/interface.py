"""The block train's interface model: each port's effort linearised about the present state.

A unit on the flow side of a bond (the cylinder whose rod carries the moving
sheaves, the winch paying out the fast line) that integrates its step against the
rope's *local model* of the effort, instead of a value held over the step, carries
the stiff rope mode across the bond inside its own implicit solver (issue 17;
reduced interface models after Peiret, Kovecses et al., 2019). The block train
offers, per port, at the end of each step:

``stiffness``
    ``K = -d effort / d position`` (N/m): the rope's spring as the port sees it;
``damping``
    ``D = -d effort / d velocity`` (N s/m): its Kelvin-Voigt damper;
``effort_rate``
    ``R = d effort / d t`` (N/s) with the port itself held still: how the effort
    moves with the other inputs (the heave at the rope's far end, a line paid out)
    and with the block train's own bodies (a hook, a sheave) moving on at their
    velocities;
``reference_position``, ``reference_velocity``
    ``x_0`` (m) and ``v_0`` (m/s): the port's position and velocity the effort and
    its derivatives were taken at, in the port's own variables (``payout`` and
    ``payout_rate`` of a line end, ``position`` and ``velocity`` of a driven body):
    the held input extrapolated to the step's end, which is where the flow side's
    own position is only to the extent that the extrapolation was right,

so that ``effort(x, v, t) ~ effort_0 - K (x - x_0) - D (v - v_0) + R (t - t_0)``
about the time ``t_0`` of the step's end. The derivatives are forward differences of
the model's own effort
(:meth:`~wire_fmu.core.units.block_train.model.BlockTrainModel.summary`); ``K`` and
``D`` with the internal state (blocks, sheaves) where it is: the instantaneous
stiffness, which is what the coupling needs over one step. Frozen in ``R`` too, a
moving hook's share of the rate would be lost: on the heave-compensated hoist that
drifted the hook by 0.08 m in 12 s, against 1.3e-3 m with it (and 1.1e-4 m with the
force held). A compiled block train takes them all in one call
(:mod:`.kernel_interface`, the same arithmetic).
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import astuple, dataclass

import numpy as np

from wire_fmu.core.units.block_train import kernel_interface
from wire_fmu.core.units.block_train.kernel import kernel_data
from wire_fmu.core.units.block_train.reeving import LINE_PORTS

__all__ = [
    "InterfacePlan",
    "PortLinearisation",
    "interface_plan",
    "linearisation_table",
    "port_linearisations",
]

RELATIVE_STEP = 1e-6
"""Differencing step of a position or velocity, relative to ``max(1, |value|)`` (m, m/s)."""
TIME_STEP = 1e-6
"""Differencing step of the time, s."""


@dataclass(frozen=True)
class PortLinearisation:
    """One port's effort linearised about the present state.

    Attributes
    ----------
    stiffness : float
        ``-d effort / d position``, N/m.
    damping : float
        ``-d effort / d velocity``, N s/m.
    effort_rate : float
        ``d effort / d t`` with the port held still, N/s.
    reference_position : float
        The port's position the effort was linearised at, in its own variable
        (``payout`` or ``position``), m.
    reference_velocity : float
        The port's velocity there (``payout_rate`` or ``velocity``), m/s.
    """

    stiffness: float
    damping: float
    effort_rate: float
    reference_position: float
    reference_velocity: float


@dataclass(frozen=True)
class _Slot:
    """Where a port sits in the held-input vector, and which output is its effort."""

    position: int
    rate: int
    acceleration: int  # the rate's ramp over the step
    sign: float  # held value = sign * the port's own variable (a line's payout)
    tension: int | None = None  # span, for a line end
    body: int | None = None  # body index, for a driven body


def _slots(model) -> dict[str, _Slot]:
    """The ports the reeving uses, by name, with their places in the held-input vector."""
    n_lines = len(LINE_PORTS)
    nd, nb = len(model.drivers), len(model.blocks)
    ramps = 1 + 2 * n_lines + 2 * nd
    slots = {}
    for k in (0, model.n_nodes - 1):
        node = model.nodes[k]
        if node.kind == "line_end":
            i = LINE_PORTS.index(node.name)
            span = 0 if k == 0 else len(model.spans) - 1
            sign = model.line_sign[i]
            slots[node.name] = _Slot(1 + i, 1 + n_lines + i, ramps + i, sign, tension=span)
    for j, body in enumerate(model.drivers):
        first = 1 + 2 * n_lines
        slots[body.port] = _Slot(first + j, first + nd + j, ramps + n_lines + j, 1.0, body=nb + j)
    return slots


def _efforts(model, t: float, x: np.ndarray, vector: np.ndarray) -> tuple:
    """Span tensions and body forces (N) at ``(t, x)`` with held inputs ``vector``."""
    with model.holding(vector):
        _, _, tension, body_force = model.summary(t, x.copy())
    return tension, body_force


def _effort(slot: _Slot, efforts: tuple) -> float:
    """The port's effort among :func:`_efforts`: a line end's tension or a body's force, N."""
    tension, body_force = efforts
    return float(tension[slot.tension] if slot.tension is not None else body_force[slot.body])


def _reference(held: np.ndarray, slot: _Slot, elapsed: float) -> tuple[float, float]:
    """The port's position (m) and velocity (m/s) at ``elapsed`` (s) into the held step,
    in the port's own variables (a held line payout is signed, see :class:`_Slot`); the
    rate ramps with its acceleration from the step's start."""
    rate, acceleration = held[slot.rate], held[slot.acceleration]
    position = held[slot.position] + (rate + 0.5 * acceleration * elapsed) * elapsed
    return slot.sign * position, slot.sign * (rate + acceleration * elapsed)


def _moved(model, x: np.ndarray) -> np.ndarray:
    """``x`` with the coordinates moved on at their velocities for :data:`TIME_STEP`."""
    n = model.n_coords
    later = x.copy()
    later[:n] += TIME_STEP * x[n : 2 * n]
    return later


def _linearise(model, slot: _Slot, t: float, x: np.ndarray, base: tuple) -> PortLinearisation:
    """One port's linearisation by forward differences from the efforts ``base`` at ``(t, x)``.

    Forward, not central: four evaluations a port instead of six, at every step end. The
    rope is linear in its stretch and the steps are 1e-6 of the motion, so the truncation
    (relative 1e-6 at most, from the geometry's curvature) is far below what a macro step
    of the coupling makes of the model.
    """
    held = model.held_vector
    elapsed = t - held[0]
    acceleration = held[slot.acceleration]
    rate = held[slot.rate] + acceleration * elapsed  # the held rate at t
    position, velocity = _reference(held, slot, elapsed)
    effort = _effort(slot, base)

    def change(vector: np.ndarray, at: float = t, state: np.ndarray = x) -> float:
        return _effort(slot, _efforts(model, at, state, vector)) - effort

    # d/d position: the held position moves, so the position at t does too
    step = RELATIVE_STEP * max(1.0, abs(position))
    up = held.copy()
    up[slot.position] += slot.sign * step
    d_position = change(up) / step
    # d/d velocity at the same position at t: the held position makes up for the rate
    step = RELATIVE_STEP * max(1.0, abs(rate))
    up = held.copy()
    up[slot.rate] += slot.sign * step
    up[slot.position] -= slot.sign * step * elapsed
    d_velocity = change(up) / step
    # d/d t with this port still where it is at t (still, not moving: its own base)
    still = held.copy()
    still[slot.position] += (held[slot.rate] + 0.5 * acceleration * elapsed) * elapsed
    still[slot.rate] = 0.0
    still[slot.acceleration] = 0.0
    return PortLinearisation(
        stiffness=-d_position,
        damping=-d_velocity,
        effort_rate=(change(still, t + TIME_STEP, _moved(model, x)) - change(still)) / TIME_STEP,
        reference_position=position,
        reference_velocity=velocity,
    )


@dataclass(frozen=True)
class InterfacePlan:
    """The ports a block train linearises, made once per model.

    Attributes
    ----------
    names : tuple of str
        The ports the reeving uses (``line_a``, ``mover_a``, ...).
    slots : tuple of _Slot
        Where each sits in the held-input vector, in the order of ``names``.
    rows : numpy.ndarray
        The slots as :func:`.kernel_interface.port_linearisations` takes them.
    """

    names: tuple[str, ...]
    slots: tuple[_Slot, ...]
    rows: np.ndarray


def interface_plan(model, ports: Collection[str] | None = None) -> InterfacePlan:
    """The ports ``model`` linearises (see :class:`InterfacePlan`).

    Parameters
    ----------
    model : BlockTrainModel
        The block train.
    ports : collection of str, optional
        Only these of its ports (the others are not evaluated); None: every port the
        reeving uses.
    """
    slots = _slots(model)
    if ports is not None:
        slots = {name: slot for name, slot in slots.items() if name in ports}
    rows = [
        (
            s.position,
            s.rate,
            s.sign,
            -1 if s.tension is None else s.tension,
            -1 if s.body is None else s.body,
            s.acceleration,
        )
        for s in slots.values()
    ]
    table = np.array(rows, dtype=float).reshape(len(rows), 6)
    return InterfacePlan(tuple(slots), tuple(slots.values()), table)


def linearisation_table(model, plan: InterfacePlan, t: float, x: np.ndarray) -> np.ndarray:
    """Every port's effort linearised at ``(t, x)``, one row a port.

    Parameters
    ----------
    model : BlockTrainModel
        The block train, holding the inputs of its last step.
    plan : InterfacePlan
        Its ports, from :func:`interface_plan`.
    t : float
        Time, s.
    x : numpy.ndarray
        State ``[q, v, dissipated, external work]``; left as it is.

    Returns
    -------
    numpy.ndarray
        In the order of ``plan.names``: stiffness (N/m), damping (N s/m), effort
        rate (N/s), reference position (m), reference velocity (m/s) (the fields of
        :class:`PortLinearisation`).
    """
    if model.compiled:
        kept = model.start_table  # the start's, evaluated with the first step's entry point
        if (
            kept is not None
            and kept[0] == t
            and kept[1] is x
            and np.array_equal(kept[2], plan.rows)
        ):
            return kept[3].reshape(len(plan.rows), 5)
        table = kernel_interface.port_linearisations(
            t, x, kernel_data(model), plan.rows, RELATIVE_STEP, TIME_STEP
        )
        # a finite table is returned, else the Python reference names what failed (the
        # check on a list of a few floats: cheaper than numpy's on the array)
        if all(map(math.isfinite, table.ravel().tolist())):
            return table
    base = _efforts(model, t, x, model.held_vector)
    rows = [astuple(_linearise(model, slot, t, x, base)) for slot in plan.slots]
    return np.array(rows, dtype=float).reshape(len(rows), 5)


def port_linearisations(model, t: float, x: np.ndarray) -> dict[str, PortLinearisation]:
    """Every port's effort linearised at ``(t, x)`` (see the module docstring).

    Parameters
    ----------
    model : BlockTrainModel
        The block train, holding the inputs of its last step.
    t : float
        Time, s.
    x : numpy.ndarray
        State ``[q, v, dissipated, external work]``; left as it is.

    Returns
    -------
    dict of str to PortLinearisation
        By port name (``line_a``, ``mover_a``, ...), for the ports the reeving uses.
    """
    plan = interface_plan(model)
    table = linearisation_table(model, plan, t, x)
    return {
        name: PortLinearisation(*row) for name, row in zip(plan.names, table.tolist(), strict=True)
    }
