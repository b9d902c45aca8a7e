"""Circles and path nodes of a rope path, and the small helpers every solver shares.

The sign convention for a node's ``sense`` is the package's
(:mod:`wire_fmu.core.components.sheave_geometry`). Vectors are plain 3-tuples of float
here: the solvers work on scalars (numpy costs more than it saves for
3-vectors).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

__all__ = ["DEFAULT_MAX_FLEET_ANGLE", "Circle", "PathNode"]

DEFAULT_MAX_FLEET_ANGLE: float = math.radians(2.5)
"""Default largest fleet angle a segment may have, rad."""

_WHERE = "rope path"
_TWO_PI = 2.0 * math.pi
_PARALLEL_TOL = 1e-9  # |A_a x A_b| below which axes count as parallel
_POS_TOL = 1e-9  # m: coplanarity, same place, aligned-case distances, tangent existence

Vec3 = tuple[float, float, float]


# --------------------------------------------------------------------------- data


@dataclass(frozen=True)
class Circle:
    """A sheave's working circle, or a rope anchor point (radius 0), in 3-D.

    Parameters
    ----------
    name : str
        Name used in error messages.
    centre : tuple of 3 float
        Centre, m. Any sequence is stored as a tuple of floats.
    axis : tuple of 3 float
        Unit axis vector (validated by
        :func:`~wire_fmu.core.components.sheave_geometry.path.check_path`, not normalised).
    radius : float
        Working radius, m, >= 0 (0 = anchor or rope end point).
    """

    name: str
    centre: Vec3
    axis: Vec3
    radius: float

    def __post_init__(self) -> None:
        """Store centre and axis as tuples of float and radius as float."""
        object.__setattr__(self, "centre", tuple(float(x) for x in self.centre))
        object.__setattr__(self, "axis", tuple(float(x) for x in self.axis))
        object.__setattr__(self, "radius", float(self.radius))


@dataclass(frozen=True)
class PathNode:
    """One node of a rope path: a circle and the sense the rope wraps it in.

    Parameters
    ----------
    circle : Circle
        The sheave or point.
    sense : int
        +1: the rope, travelling along the path, wraps the sheave
        counter-clockwise about ``+axis`` (right-hand rule); -1: clockwise;
        0 only for a point (radius 0).
    """

    circle: Circle
    sense: int


class _Segment(NamedTuple):
    start: Vec3
    end: Vec3
    fleet_start: float
    fleet_end: float
    kind: str


class _NoTangentError(Exception):
    """Internal: a segment has no valid tangent; the message names both nodes."""


# ------------------------------------------------------------------ small vectors


def _vec(x: Sequence[float]) -> Vec3:
    return (float(x[0]), float(x[1]), float(x[2]))


def _sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


def _norm(a: Vec3) -> float:
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def _unit_perpendicular(axis: Vec3) -> Vec3:
    """A unit vector perpendicular to a unit ``axis``."""
    i = min(range(3), key=lambda j: abs(axis[j]))
    e = tuple(1.0 if j == i else 0.0 for j in range(3))
    w = _cross(axis, e)
    n = _norm(w)
    return (w[0] / n, w[1] / n, w[2] / n)


def _wrap_2pi(angle: float) -> float:
    """Map an angle from atan2 into [0, 2 pi), rad."""
    if angle < 0.0:
        angle += _TWO_PI
    return 0.0 if angle >= _TWO_PI else angle


# ------------------------------------------------------------------- messages


def _kind(circle: Circle) -> str:
    if circle.radius > 0.0:
        return "sheave"
    return "point" if circle.radius == 0.0 else "circle"


def _label(circle: Circle) -> str:
    return f"{_kind(circle)} '{circle.name}'"


def _pair(a: Circle, b: Circle) -> str:
    ka, kb = _kind(a), _kind(b)
    if ka == kb:
        return f"{ka}s '{a.name}' and '{b.name}'"
    return f"{ka} '{a.name}' and {kb} '{b.name}'"


def _fmt(v: Sequence[float]) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in v) + ")"
