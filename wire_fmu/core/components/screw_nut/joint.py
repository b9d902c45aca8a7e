"""The screw pair between two rigid bodies: five constraints, their Jacobian and reactions."""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.components.screw_nut.bodies import (
    BodyState,
    _cross,
    _perpendicular_pair,
    _velocities,
)
from wire_fmu.core.components.screw_nut.thread import ScrewThread

__all__ = ["ScrewNutJoint"]

_TWO_PI = 2.0 * math.pi


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
        """Columns ``e1, e2, c`` in the world frame (they turn with body 1).

        Parameters
        ----------
        s1 : BodyState
            State of body 1, the screw.
        """
        return s1.rotation @ self.frame_1

    def relative_angle(self, s1: BodyState, s2: BodyState) -> float:
        """Angle of the nut relative to the screw about the axis, unwrapped, rad.

        Parameters
        ----------
        s1 : BodyState
            State of body 1, the screw.
        s2 : BodyState
            State of body 2, the nut.
        """
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

        Parameters
        ----------
        s1 : BodyState
            State of body 1, the screw.
        s2 : BodyState
            State of body 2, the nut.
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

        Parameters
        ----------
        s1 : BodyState
            State of body 1, the screw.
        s2 : BodyState
            State of body 2, the nut.
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
        """``G v`` (rad/s, rad/s, m/s, m/s, m/s): the paper's velocity equations.

        Parameters
        ----------
        s1 : BodyState
            State of body 1, the screw.
        s2 : BodyState
            State of body 2, the nut.
        """
        g, _ = self.jacobian(s1, s2)
        return g @ _velocities(s1, s2)

    def wrenches(self, s1: BodyState, s2: BodyState, multipliers: np.ndarray) -> dict:
        """Reaction on each body from the multipliers (``G^T lambda``), split physically.

        Parameters
        ----------
        s1 : BodyState
            State of body 1, the screw.
        s2 : BodyState
            State of body 2, the nut.
        multipliers : array_like, shape (5,)
            The joint's multipliers (rows of :meth:`jacobian`): two bending
            moments (N m) and the reaction force along ``e1, e2, c`` (N).

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
