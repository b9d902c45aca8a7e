"""Rigid bodies of the screw-nut system: mass properties, states and quaternion helpers."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["RigidBody", "BodyState", "rotation_from_quaternion"]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of two 3-vectors (``numpy.cross`` costs ~50 us a call)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def rotation_from_quaternion(q: np.ndarray) -> np.ndarray:
    """Rotation matrix of a unit quaternion ``[w, x, y, z]`` (normalised here).

    Parameters
    ----------
    q : array_like, shape (4,)
        Orientation ``[w, x, y, z]``, body to world.

    Returns
    -------
    ndarray, shape (3, 3)
        Rotation matrix body -> world.
    """
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
        """A body at ``position`` with orientation ``quaternion``, not moving.

        Parameters
        ----------
        position : array_like, shape (3,), optional
            Centre of mass, m.
        quaternion : array_like, shape (4,), optional
            Orientation ``[w, x, y, z]``, body to world.
        """
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
        """Inverse of :meth:`pack` (copies).

        Parameters
        ----------
        y : array_like, shape (13,)
            ``[position (m), quaternion, velocity (m/s), angular velocity (rad/s)]``.
        """
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


def _velocities(s1: BodyState, s2: BodyState) -> np.ndarray:
    return np.concatenate([s1.velocity, s1.angular_velocity, s2.velocity, s2.angular_velocity])
