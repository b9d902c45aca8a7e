"""Paper 003: the screw-nut connection, in vector form, with dry friction in the thread.

Two rigid bodies are joined by a screw pair (SPEC section 10): body 1 carries
the screw, body 2 the nut. The joint's parameters are constant in body 1's
frame: a point ``P`` on the screw axis, the axis direction ``c`` (unit
vector) and the lead per radian ``h = lead / (2 pi)`` (m/rad). The paper's
equations, written as vectors (world frame, ``w = w2 - w1`` the relative
angular velocity):

* the relative angular velocity lies along the axis:
  ``w - (c . w) c = 0``;
* the nut's point at ``P`` moves along the axis by the lead:
  ``(v2 + w2 x r2) - (v1 + w1 x r1) = h (c . w) c`` with ``r1``, ``r2`` the
  radius vectors from each body's centre of mass to ``P``;
* the reaction force ``F`` (on the nut; ``-F`` on the screw) creates the
  moments ``r2 x F`` and ``-r1 x F``, a reaction moment perpendicular to the
  axis acts on each body, and the axial force gives the torque
  ``M_a = h (c . F)`` about the axis -- the pair converts axial force to
  torque through the lead.

Both defects the paper names are avoided here. (1) The paper picks two of the
three angular-velocity components by dividing by the direction cosine
``c_x``; here the two conditions are the projections of ``w`` on a pair of
unit vectors ``e1, e2`` perpendicular to ``c`` and fixed in body 1 (chosen
once by cross products, never by dividing by a component), so any axis
direction works. (2) The paper's equations are velocity-level only, so body
positions drift apart over long runs; here the same five conditions are also
imposed at position level (axis alignment, the nut's point on the axis,
axial offset ``= h`` times the relative angle) and
:class:`ScrewNutSystem` projects positions and velocities back onto them
after every step.

Dry friction in the thread (paper 003, section 4)
-------------------------------------------------
A torque about the axis, opposing relative rotation, bounded by
``M1 = r_mean mu |F_axial|`` (the paper: mean thread radius 0.01 m, mu 0.1
for steel on steel). The paper regularises it: linear in the relative
speed inside ``|w| < w1`` (``w1 = 1e-6`` rad/s) and saturated outside.
Such a torque never truly holds: a held load creeps at the speed where the
regularised torque balances it, ``w1 x`` for the linear form and
``w1 atanh(x)`` for the ``tanh`` form, ``x = |M_load| / M1``
(:meth:`ScrewThread.creep_speed`). :class:`ScrewThread` offers both
regularised forms; the exact one (a stuck thread does not move at all) is
used twice: by :class:`ScrewNutSystem` in 3-D, where a stuck thread adds a
sixth constraint and a sliding one a torque solved together with the axial
force it depends on, and -- along the joint's one degree of freedom, the
relative angle -- with :class:`~wire_fmu.core.components.friction.StickSlip` by the
scissor jack's kinematic reduction (:mod:`wire_fmu.core.units.scissor_jack.model`).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

__all__ = [
    "ScrewThread",
    "REGULARISATIONS",
    "RigidBody",
    "BodyState",
    "ScrewNutJoint",
    "ScrewNutSystem",
    "rotation_from_quaternion",
]

logger = logging.getLogger(__name__)

_TWO_PI = 2.0 * math.pi


# ============================================================== the thread
def _linear_saturated(x: float) -> float:
    return min(1.0, max(-1.0, x))


def _linear_inverse(x: float) -> float:
    return x


REGULARISATIONS: Mapping[str, tuple[Callable[[float], float], Callable[[float], float]]] = (
    MappingProxyType(
        {
            "linear": (_linear_saturated, _linear_inverse),  # paper 003, Fig. 7
            "tanh": (math.tanh, math.atanh),
        }
    )
)
"""Regularised friction shapes ``s(w / w1)`` and the inverse used for creep speeds."""


@dataclass(frozen=True)
class ScrewThread:
    """The thread of a screw pair: lead and dry friction.

    Parameters
    ----------
    lead : float
        Axial travel per turn, m (paper 003's jack: 2 mm per turn).
    mean_radius : float
        Mean thread radius ``r_mean``, m (paper: 0.01 m).
    friction : float
        Friction coefficient ``mu`` (paper: 0.1, steel on steel).
    """

    lead: float
    mean_radius: float = 0.01
    friction: float = 0.1

    @property
    def lead_per_radian(self) -> float:
        """``h = lead / (2 pi)``, m/rad."""
        return self.lead / _TWO_PI

    def axial_travel(self, relative_angle: float) -> float:
        """Axial travel of the nut for a relative angle (rad), m."""
        return self.lead_per_radian * relative_angle

    def lead_torque(self, axial_force: float) -> float:
        """Torque ``M_a = h F_axial`` the axial force exerts about the axis, N m."""
        return self.lead_per_radian * axial_force

    def friction_capacity(self, axial_force: float) -> float:
        """``M1 = r_mean mu |F_axial|``, N m."""
        return self.mean_radius * self.friction * abs(axial_force)

    def self_locking(self) -> bool:
        """Whether no axial load can back-drive the thread (``h < r_mean mu``)."""
        return self.lead_per_radian < self.mean_radius * self.friction

    def regularised_torque(
        self, relative_speed: float, axial_force: float, speed_scale: float, shape: str = "linear"
    ) -> float:
        """The paper's regularised friction torque on the nut, N m (opposes ``relative_speed``).

        Parameters
        ----------
        relative_speed : float
            Nut speed relative to the screw about the axis, rad/s.
        axial_force : float
            Axial force in the thread, N.
        speed_scale : float
            ``w1``, rad/s (paper: 1e-6).
        shape : str
            ``"linear"`` (linear inside ``|w| < w1``, saturated outside) or ``"tanh"``.
        """
        s, _ = REGULARISATIONS[shape]
        return -self.friction_capacity(axial_force) * s(relative_speed / speed_scale)

    def creep_speed(
        self, held_torque: float, axial_force: float, speed_scale: float, shape: str = "linear"
    ) -> float:
        """Steady creep speed of a regularised thread holding ``held_torque`` (N m), rad/s.

        The speed at which the regularised torque balances the torque that
        drives the thread (sign: that torque's); ``inf`` when the torque
        exceeds the capacity (the thread slides).
        """
        capacity = self.friction_capacity(axial_force)
        ratio = abs(held_torque) / capacity if capacity > 0.0 else math.inf
        if ratio >= 1.0:
            return math.copysign(math.inf, held_torque)
        _, inverse = REGULARISATIONS[shape]
        return math.copysign(speed_scale * inverse(ratio), held_torque)

    def problems(self) -> list[str]:
        """Every problem with the thread's numbers, as sentences."""
        out = []
        for name, value in (("lead", self.lead), ("mean_radius", self.mean_radius)):
            if not (value > 0.0 and math.isfinite(value)):
                out.append(f"thread {name} must be a positive number of metres, got {value}")
        if not (self.friction >= 0.0 and math.isfinite(self.friction)):
            out.append(f"thread friction coefficient must be >= 0, got {self.friction}")
        return out


# ============================================================== rigid bodies
def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two 3-vectors (``numpy.cross`` costs ~50 us a call)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def rotation_from_quaternion(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion ``[w, x, y, z]`` (normalised here)."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _quaternion_rate(q: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """``dq/dt`` for angular velocity ``omega`` in the world frame."""
    w, x, y, z = q
    ox, oy, oz = omega
    return 0.5 * np.array(
        [  # [0, omega] * q: omega in the world frame
            -x * ox - y * oy - z * oz,
            w * ox + oy * z - oz * y,
            w * oy + oz * x - ox * z,
            w * oz + ox * y - oy * x,
        ]
    )


def _rotate_quaternion(q: np.ndarray, rotation_vector: np.ndarray) -> np.ndarray:
    """``q`` turned by a small rotation vector (world frame), normalised."""
    angle = float(np.linalg.norm(rotation_vector))
    if angle == 0.0:
        return q
    axis = rotation_vector / angle
    half = 0.5 * angle
    dw, (dx, dy, dz) = math.cos(half), math.sin(half) * axis
    w, x, y, z = q
    out = np.array(
        [
            dw * w - dx * x - dy * y - dz * z,
            dw * x + dx * w + dy * z - dz * y,
            dw * y - dx * z + dy * w + dz * x,
            dw * z + dx * y - dy * x + dz * w,
        ]
    )
    return out / np.linalg.norm(out)


@dataclass(frozen=True)
class RigidBody:
    """Mass properties of a rigid body.

    Parameters
    ----------
    mass : float
        kg.
    inertia : array_like, shape (3, 3)
        Inertia tensor about the centre of mass in the body frame, kg m^2.
    fixed : bool
        A fixed body (the ground) does not move and takes any reaction.
    """

    mass: float
    inertia: np.ndarray = field(default_factory=lambda: np.eye(3))
    fixed: bool = False


@dataclass
class BodyState:
    """Pose and velocities of a rigid body (world frame).

    Attributes
    ----------
    position : ndarray, shape (3,)
        Centre of mass, m.
    quaternion : ndarray, shape (4,)
        Orientation ``[w, x, y, z]`` (body to world).
    velocity : ndarray, shape (3,)
        Of the centre of mass, m/s.
    angular_velocity : ndarray, shape (3,)
        rad/s, world frame.
    """

    position: np.ndarray
    quaternion: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray

    @property
    def rotation(self) -> np.ndarray:
        """Rotation matrix body -> world."""
        return rotation_from_quaternion(self.quaternion)

    @classmethod
    def at_rest(cls, position=(0.0, 0.0, 0.0), quaternion=(1.0, 0.0, 0.0, 0.0)) -> BodyState:
        """A body at ``position`` with orientation ``quaternion``, not moving."""
        return cls(
            np.array(position, dtype=float),
            np.array(quaternion, dtype=float),
            np.zeros(3),
            np.zeros(3),
        )

    def pack(self) -> np.ndarray:
        """``[position, quaternion, velocity, angular velocity]``, shape (13,)."""
        return np.concatenate(
            [self.position, self.quaternion, self.velocity, self.angular_velocity]
        )

    @classmethod
    def unpack(cls, y: np.ndarray) -> BodyState:
        """Inverse of :meth:`pack` (copies)."""
        y = np.asarray(y, dtype=float)
        return cls(y[0:3].copy(), y[3:7].copy(), y[7:10].copy(), y[10:13].copy())


def _perpendicular_pair(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors ``e1, e2`` with ``(e1, e2, axis)`` right-handed and orthonormal.

    ``e1`` is the cross product of the axis with the coordinate axis least
    aligned with it -- a choice by comparison, not by division, so no
    direction cosine is ever a divisor.
    """
    helper = np.zeros(3)
    helper[int(np.argmin(np.abs(axis)))] = 1.0
    e1 = _cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    return e1, _cross(axis, e1)


# ============================================================== the joint
class ScrewNutJoint:
    """The screw pair between body 1 (screw) and body 2 (nut), five constraints.

    Rows, in this order: ``e1 . w = 0``, ``e2 . w = 0`` (relative rotation
    only about the axis), then ``d . (u - h (c . w) c) = 0`` for ``d = e1,
    e2, c`` with ``u`` the velocity of the nut's point at ``P`` relative to
    the screw's (the nut moves along the axis by the lead).

    Parameters
    ----------
    thread : ScrewThread
        Lead (and friction data, unused by the frictionless 3-D joint).
    point : array_like, shape (3,)
        ``P`` on the screw axis, in body 1's frame, m.
    axis : array_like, shape (3,)
        Screw axis direction in body 1's frame (normalised here).
    state_1, state_2 : BodyState
        Poses at assembly: the nut's material point at ``P``, its axis and a
        reference direction perpendicular to it are frozen in body 2's frame,
        and the relative angle counts from 0 there.
    """

    N_CONSTRAINTS = 5

    def __init__(
        self, thread: ScrewThread, point, axis, state_1: BodyState, state_2: BodyState
    ) -> None:
        self.thread = thread
        self.h = thread.lead_per_radian
        axis = np.asarray(axis, dtype=float)
        norm = float(np.linalg.norm(axis))
        if not norm > 0.0:
            raise ValueError(f"screw axis must be a non-zero vector, got {axis}")
        self.axis_1 = axis / norm
        self.point_1 = np.asarray(point, dtype=float)
        e1, e2 = _perpendicular_pair(self.axis_1)
        self.frame_1 = np.column_stack([e1, e2, self.axis_1])  # body 1 frame: e1, e2, c
        r1, r2 = state_1.rotation, state_2.rotation
        p_world = state_1.position + r1 @ self.point_1
        self.point_2 = r2.T @ (p_world - state_2.position)
        self.axis_2 = r2.T @ (r1 @ self.axis_1)
        self.reference_2 = r2.T @ (r1 @ e1)
        self.angle = 0.0  # unwrapped relative angle, rad

    # -- frames ---------------------------------------------------------------
    def frame(self, s1: BodyState) -> np.ndarray:
        """Columns ``e1, e2, c`` in the world frame (they turn with body 1)."""
        return s1.rotation @ self.frame_1

    def relative_angle(self, s1: BodyState, s2: BodyState) -> float:
        """Angle of the nut relative to the screw about the axis, unwrapped, rad."""
        frame = self.frame(s1)
        u = s2.rotation @ self.reference_2
        wrapped = math.atan2(float(u @ frame[:, 1]), float(u @ frame[:, 0]))
        turns = round((self.angle - wrapped) / _TWO_PI)
        return wrapped + _TWO_PI * turns

    # -- constraints ------------------------------------------------------------
    def jacobian(self, s1: BodyState, s2: BodyState) -> tuple[np.ndarray, np.ndarray]:
        """``G`` (5 x 12, columns ``[v1, w1, v2, w2]``) and ``gamma`` with ``G a = gamma``.

        ``gamma`` collects the velocity-product terms of the constraints'
        time derivatives (``G`` depends on the poses).
        """
        frame = self.frame(s1)
        e1, e2, c = frame.T
        r1 = s1.rotation @ self.point_1
        p = s1.position + r1
        r2 = p - s2.position
        w1, w2 = s1.angular_velocity, s2.angular_velocity
        dw = w2 - w1
        g = np.zeros((5, 12))
        g[0, 3:6], g[0, 9:12] = -e1, e1
        g[1, 3:6], g[1, 9:12] = -e2, e2
        for row, d in zip((2, 3, 4), (e1, e2, c), strict=True):
            g[row, 0:3] = -d
            g[row, 3:6] = -_cross(r1, d) + self.h * (d @ c) * c
            g[row, 6:9] = d
            g[row, 9:12] = _cross(r2, d) - self.h * (d @ c) * c
        u = (s2.velocity + _cross(w2, r2)) - (s1.velocity + _cross(w1, r1)) - self.h * (c @ dw) * c
        r2_rate = s1.velocity + _cross(w1, r1) - s2.velocity
        c_rate = _cross(w1, c)
        quadratic = (
            _cross(w2, r2_rate)
            - _cross(w1, _cross(w1, r1))
            - self.h * ((c_rate @ dw) * c + (c @ dw) * c_rate)
        )
        gamma = np.empty(5)
        gamma[0] = -_cross(w1, e1) @ dw
        gamma[1] = -_cross(w1, e2) @ dw
        for row, d in zip((2, 3, 4), (e1, e2, c), strict=True):
            gamma[row] = -(_cross(w1, d) @ u + d @ quadratic)
        return g, gamma

    def position_residual(self, s1: BodyState, s2: BodyState) -> np.ndarray:
        """The five constraints at position level (rad, rad, m, m, m); zero on the joint.

        Their gradients coincide with the rows of :meth:`jacobian` on the
        constraint manifold (so the velocity Jacobian serves for projection).
        """
        frame = self.frame(s1)
        e1, e2, c = frame.T
        c2 = s2.rotation @ self.axis_2
        gap = (s2.position + s2.rotation @ self.point_2) - (
            s1.position + s1.rotation @ self.point_1
        )
        angle = self.relative_angle(s1, s2)
        return np.array([-(e2 @ c2), e1 @ c2, e1 @ gap, e2 @ gap, c @ gap - self.h * angle])

    def velocity_residual(self, s1: BodyState, s2: BodyState) -> np.ndarray:
        """``G v`` (rad/s, rad/s, m/s, m/s, m/s): the paper's velocity equations."""
        g, _ = self.jacobian(s1, s2)
        return g @ _velocities(s1, s2)

    def wrenches(self, s1: BodyState, s2: BodyState, multipliers: np.ndarray) -> dict:
        """Reaction on each body from the multipliers (``G^T lambda``), split physically.

        Returns
        -------
        dict
            ``force`` (on the nut, N; the screw gets ``-force``),
            ``moment_1``/``moment_2`` (N m about each centre of mass),
            ``axial_force`` (``c . force``, N), ``axis_torque`` (the lead
            torque ``h c . force`` on the screw about the axis, N m) and
            ``bending_moment`` (the perpendicular reaction moment on the nut, N m).
        """
        frame = self.frame(s1)
        e1, e2, c = frame.T
        r1 = s1.rotation @ self.point_1
        r2 = s1.position + r1 - s2.position
        lam = np.asarray(multipliers, dtype=float)
        force = lam[2] * e1 + lam[3] * e2 + lam[4] * c
        bending = lam[0] * e1 + lam[1] * e2
        axial = float(c @ force)
        lead = self.h * axial
        return {
            "force": force,
            "moment_2": _cross(r2, force) + bending - lead * c,
            "moment_1": -_cross(r1, force) - bending + lead * c,
            "axial_force": axial,
            "axis_torque": lead,
            "bending_moment": bending,
        }


def _velocities(s1: BodyState, s2: BodyState) -> np.ndarray:
    return np.concatenate([s1.velocity, s1.angular_velocity, s2.velocity, s2.angular_velocity])


# ============================================================== the system
class ScrewNutSystem:
    """Two rigid bodies joined by a :class:`ScrewNutJoint`, stepped in time.

    Each body keeps its own full state (as in paper 003's general-purpose
    formulation); the joint enters as Lagrange multipliers from
    ``[[M, -G^T], [G, 0]] [a; lambda] = [f; gamma]``. After each RK4 step
    positions and velocities are projected onto the joint (mass-weighted
    least change), unless ``stabilise`` is False -- which is the paper's
    velocity-level model, and drifts.

    Thread friction (``thread_friction=True``) is exact dry friction about
    the axis, bounded by ``r_mean mu |F_axial|`` with ``F_axial`` the joint's
    own axial multiplier. Modes as in :class:`~wire_fmu.core.components.friction.StickSlip`:
    *stuck* adds a sixth constraint, no relative rotation (the pair is a
    weld; its multiplier is the holding torque, and the relative angle is
    held at position level too), *sliding* in direction ``sigma`` applies
    ``-sigma r_mean mu |F_axial|``, solved together with the axial force it
    depends on. Guards (holding margin, ``sigma`` times the relative speed)
    are located within a step by bisection to ``event_tolerance``; a thread
    that stops sticks if it can hold, else slides back.

    Parameters
    ----------
    body_1, body_2 : RigidBody
        Screw and nut; ``body_1.fixed`` makes the screw the ground.
    joint : ScrewNutJoint
        The screw pair.
    state_1, state_2 : BodyState
        Initial states; velocities are made consistent with the joint.
    gravity : array_like, shape (3,)
        m/s^2.
    stabilise : bool
        Project onto the position-level constraints after every step.
    thread_friction : bool
        Dry friction in the thread (``joint.thread``'s radius and coefficient).
    event_tolerance : float
        Stick/slip transitions are located to within this time, s.
    """

    def __init__(
        self,
        body_1: RigidBody,
        body_2: RigidBody,
        joint: ScrewNutJoint,
        state_1: BodyState,
        state_2: BodyState,
        gravity=(0.0, 0.0, 0.0),
        stabilise: bool = True,
        thread_friction: bool = False,
        event_tolerance: float = 1e-10,
    ) -> None:
        if body_2.fixed:
            raise ValueError("the nut (body 2) must be free; fix the screw (body 1) instead")
        self.bodies = (body_1, body_2)
        self.joint = joint
        self.gravity = np.asarray(gravity, dtype=float)
        self.stabilise = stabilise
        self.thread_friction = thread_friction
        self.event_tolerance = event_tolerance
        self.r_mu = joint.thread.mean_radius * joint.thread.friction
        self.states = [state_1, state_2]
        self.time = 0.0
        self.mode = 0  # thread: 0 stuck, +1/-1 sliding (relative rotation about c)
        self.held_angle = 0.0
        self.events: list[tuple[float, str]] = []
        self.last_multipliers = np.zeros(ScrewNutJoint.N_CONSTRAINTS)
        self.friction_torque = 0.0
        self._free = np.r_[
            np.zeros(6, bool) if body_1.fixed else np.ones(6, bool), np.ones(6, bool)
        ]
        self.project()

    # -- dynamics -----------------------------------------------------------------
    def _mass_matrix(self, states: list[BodyState]) -> np.ndarray:
        m = np.zeros((12, 12))
        for i, (body, s) in enumerate(zip(self.bodies, states, strict=True)):
            r = s.rotation
            m[6 * i : 6 * i + 3, 6 * i : 6 * i + 3] = body.mass * np.eye(3)
            m[6 * i + 3 : 6 * i + 6, 6 * i + 3 : 6 * i + 6] = r @ body.inertia @ r.T
        return m[np.ix_(self._free, self._free)]

    def _forces(self, states: list[BodyState]) -> np.ndarray:
        f = np.zeros(12)
        for i, (body, s) in enumerate(zip(self.bodies, states, strict=True)):
            r = s.rotation
            inertia = r @ body.inertia @ r.T
            w = s.angular_velocity
            f[6 * i : 6 * i + 3] = body.mass * self.gravity
            f[6 * i + 3 : 6 * i + 6] = -_cross(w, inertia @ w)
        return f[self._free]

    def _axis_row(self, states: list[BodyState]) -> tuple[np.ndarray, float]:
        """Relative rotation about the axis: row ``c . (w2 - w1)`` and its ``gamma``."""
        c = self.joint.frame(states[0])[:, 2]
        row = np.zeros(12)
        row[3:6], row[9:12] = -c, c
        dw = states[1].angular_velocity - states[0].angular_velocity
        return row, -float(_cross(states[0].angular_velocity, c) @ dw)

    def relative_speed(self, states: list[BodyState] | None = None) -> float:
        """``c . (w2 - w1)``: the nut's speed relative to the screw about the axis, rad/s."""
        states = self.states if states is None else states
        row, _ = self._axis_row(states)
        return float(row @ _velocities(*states))

    def _rows(self, states: list[BodyState], stuck: bool) -> tuple[np.ndarray, np.ndarray]:
        g, gamma = self.joint.jacobian(*states)
        if stuck:
            row, extra = self._axis_row(states)
            g, gamma = np.vstack([g, row]), np.r_[gamma, extra]
        return g, gamma

    def _solve(self, states: list[BodyState], mode: int) -> tuple[np.ndarray, np.ndarray, float]:
        """Accelerations, multipliers and the friction torque on the nut in ``mode``."""
        stuck = self.thread_friction and mode == 0
        g, gamma = self._rows(states, stuck)
        g = g[:, self._free]
        m = self._mass_matrix(states)
        n, rows = m.shape[0], g.shape[0]
        k = np.zeros((n + rows, n + rows))
        k[:n, :n], k[:n, n:], k[n:, :n] = m, -g.T, g
        rhs = np.r_[self._forces(states), gamma]
        if not self.thread_friction or stuck:
            sol = np.linalg.solve(k, rhs)
            torque = float(sol[n + 5]) if stuck else 0.0
        else:
            sol, torque = self._sliding(states, k, rhs, n, mode)
        acc = np.zeros(12)
        acc[self._free] = sol[:n]
        return acc, sol[n:], torque

    def _sliding(self, states, k, rhs, n, mode) -> tuple[np.ndarray, float]:
        """Solve with the torque ``-mode r mu |lambda_axial|`` consistent with its axial force."""
        row, _ = self._axis_row(states)
        unit = np.r_[row[self._free], np.zeros(k.shape[0] - n)]
        base, per_torque = np.linalg.solve(k, np.column_stack([rhs, unit])).T
        axial = n + 4
        for sign in (1.0, -1.0):
            denominator = 1.0 + mode * self.r_mu * sign * per_torque[axial]
            if denominator <= 0.0:
                continue
            torque = -mode * self.r_mu * sign * base[axial] / denominator
            sol = base + torque * per_torque
            if sign * sol[axial] >= 0.0:
                return sol, torque
        raise ArithmeticError("thread friction has no consistent solution (Painleve's paradox)")

    def accelerations(self, states: list[BodyState]) -> tuple[np.ndarray, np.ndarray]:
        """Accelerations ``[a1, alpha1, a2, alpha2]`` (zeros for a fixed body) and multipliers.

        The multipliers are the joint's five (bending moments, reaction
        force); a stuck thread's holding torque is :attr:`friction_torque`.
        """
        acc, lam, _ = self._solve(states, self.mode)
        return acc, lam[: ScrewNutJoint.N_CONSTRAINTS]

    def _rate(self, y: np.ndarray) -> np.ndarray:
        states = [BodyState.unpack(y[:13]), BodyState.unpack(y[13:])]
        acc, _ = self.accelerations(states)
        out = np.zeros(26)
        for i, s in enumerate(states):
            if self.bodies[i].fixed:
                continue
            o = 13 * i
            out[o : o + 3] = s.velocity
            out[o + 3 : o + 7] = _quaternion_rate(s.quaternion, s.angular_velocity)
            out[o + 7 : o + 10] = acc[6 * i : 6 * i + 3]
            out[o + 10 : o + 13] = acc[6 * i + 3 : 6 * i + 6]
        return out

    # -- stepping ---------------------------------------------------------------------
    def _rk4(self, y: np.ndarray, h: float) -> list[BodyState]:
        k1 = self._rate(y)
        k2 = self._rate(y + 0.5 * h * k1)
        k3 = self._rate(y + 0.5 * h * k2)
        k4 = self._rate(y + h * k3)
        y = y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        states = [BodyState.unpack(y[:13]), BodyState.unpack(y[13:])]
        for s in states:
            s.quaternion /= np.linalg.norm(s.quaternion)
        return states

    def _adopt(self, states: list[BodyState], h: float) -> None:
        self.states = states
        self.time += h
        self.joint.angle = self.joint.relative_angle(*self.states)
        if self.stabilise:
            self._project_positions(self._stuck())
            self._project_velocities(self._stuck())

    def guard(self, states: list[BodyState] | None = None) -> float:
        """Thread guard, >= 0 inside the mode: holding margin (N m) or ``sigma`` times speed."""
        states = self.states if states is None else states
        if not self.thread_friction:
            return 1.0
        if self.mode != 0:
            return self.mode * self.relative_speed(states)
        _, lam, torque = self._solve(states, 0)
        return self.r_mu * abs(lam[4]) - abs(torque)

    def step(self, h: float) -> None:
        """Advance ``h`` seconds: RK4, stick/slip events located, projection onto the joint."""
        remaining, guard = h, self.guard()
        for _ in range(1000):
            if remaining <= 0.0:
                break
            y = np.r_[self.states[0].pack(), self.states[1].pack()]
            states = self._rk4(y, remaining)
            if guard >= 0.0 and self.guard(states) < 0.0:
                taken, states = self._locate(y, remaining)
                self._adopt(states, taken)
                self._settle(self.states, fired=True)
                remaining -= taken
            else:
                self._adopt(states, remaining)
                remaining = 0.0
            guard = self.guard()
        acc, lam, self.friction_torque = self._solve(self.states, self.mode)
        self.last_multipliers = lam[: ScrewNutJoint.N_CONSTRAINTS]

    def _locate(self, y: np.ndarray, h: float) -> tuple[float, list[BodyState]]:
        """Bisection for the first time the guard turns negative: (time taken, states just past)."""
        lo, hi = 0.0, h
        past = self._rk4(y, h)
        while hi - lo > self.event_tolerance:
            mid = 0.5 * (lo + hi)
            states = self._rk4(y, mid)
            if self.guard(states) < 0.0:
                hi, past = mid, states
            else:
                lo = mid
        return hi, past

    def _settle(
        self, states: list[BodyState], fired: bool = False, before: int | None = None
    ) -> None:
        """Make the thread's mode fit the state (StickSlip's rules); log a change."""
        before = self.mode if before is None else before
        if self.mode != 0 and (fired or self.relative_speed(states) == 0.0):
            self.mode = 0
            self.held_angle = self.joint.relative_angle(*states)
            self._project_velocities(True)  # the relative rotation stops, momentum kept
        if self.mode == 0:
            _, lam, torque = self._solve(self.states, 0)
            if abs(torque) > self.r_mu * abs(lam[4]):
                self.mode = -1 if torque > 0.0 else 1  # slides against the needed hold
            else:
                self.held_angle = self.joint.relative_angle(*self.states)
        if self.mode != before:
            words = {0: "stuck", 1: "sliding +", -1: "sliding -"}
            self.events.append((self.time, f"thread {words[self.mode]}"))
            logger.debug("t = %.9g s: thread %s", self.time, words[self.mode])

    # -- projection ------------------------------------------------------------------
    def project(self) -> None:
        """Put the bodies exactly on the joint (least change) and choose the thread's mode.

        Call after changing states by hand (e.g. setting initial velocities):
        the thread slides in the direction of the relative rotation, or, at
        relative rest, sticks if it can hold.
        """
        self._project_positions(False)
        self._project_velocities(False)
        if self.thread_friction:
            previous, self.mode = self.mode, int(np.sign(self.relative_speed()))
            self._settle(self.states, before=previous)
            if self.mode == 0:
                self._project_positions(True)

    def _stuck(self) -> bool:
        return self.thread_friction and self.mode == 0

    def _correction(self, g: np.ndarray, residual: np.ndarray) -> np.ndarray:
        """Mass-weighted least change ``-M^-1 G^T (G M^-1 G^T)^-1 residual``."""
        m_inv = np.linalg.inv(self._mass_matrix(self.states))
        gf = g[:, self._free]
        mu = np.linalg.solve(gf @ m_inv @ gf.T, residual)
        out = np.zeros(12)
        out[self._free] = -m_inv @ gf.T @ mu
        return out

    def _position_residual(self, stuck: bool) -> np.ndarray:
        residual = self.joint.position_residual(*self.states)
        if stuck:
            residual = np.r_[residual, self.joint.relative_angle(*self.states) - self.held_angle]
        return residual

    def _project_positions(
        self, stuck: bool, iterations: int = 4, tolerance: float = 1e-15
    ) -> None:
        for _ in range(iterations):
            residual = self._position_residual(stuck)
            if np.max(np.abs(residual)) <= tolerance:
                break
            g, _ = self._rows(self.states, stuck)
            delta = self._correction(g, residual)
            for i, s in enumerate(self.states):
                if not self.bodies[i].fixed:
                    s.position = s.position + delta[6 * i : 6 * i + 3]
                    s.quaternion = _rotate_quaternion(s.quaternion, delta[6 * i + 3 : 6 * i + 6])
            self.joint.angle = self.joint.relative_angle(*self.states)

    def _project_velocities(self, stuck: bool) -> None:
        g, _ = self._rows(self.states, stuck)
        delta = self._correction(g, g @ _velocities(*self.states))
        for i, s in enumerate(self.states):
            if not self.bodies[i].fixed:
                s.velocity = s.velocity + delta[6 * i : 6 * i + 3]
                s.angular_velocity = s.angular_velocity + delta[6 * i + 3 : 6 * i + 6]

    # -- invariants ----------------------------------------------------------------
    def kinetic_energy(self) -> float:
        """J."""
        total = 0.0
        for body, s in zip(self.bodies, self.states, strict=True):
            if body.fixed:
                continue
            r = s.rotation
            w = s.angular_velocity
            total += 0.5 * body.mass * float(s.velocity @ s.velocity)
            total += 0.5 * float(w @ (r @ body.inertia @ r.T) @ w)
        return total

    def potential_energy(self) -> float:
        """Gravitational energy ``-m g . x``, J."""
        return -sum(
            b.mass * float(self.gravity @ s.position)
            for b, s in zip(self.bodies, self.states, strict=True)
            if not b.fixed
        )

    def momentum(self) -> tuple[np.ndarray, np.ndarray]:
        """Linear momentum (kg m/s) and angular momentum about the origin (kg m^2/s)."""
        p, ang = np.zeros(3), np.zeros(3)
        for body, s in zip(self.bodies, self.states, strict=True):
            if body.fixed:
                continue
            r = s.rotation
            p += body.mass * s.velocity
            ang += body.mass * _cross(s.position, s.velocity)
            ang += (r @ body.inertia @ r.T) @ s.angular_velocity
        return p, ang
