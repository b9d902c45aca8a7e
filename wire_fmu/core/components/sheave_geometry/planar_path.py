"""The lean planar form: a path validated once, then lengths and wrap angles from 2-D centres.

For a path whose circles all lie in one plane, :func:`planar_frame`
validates it once and gives its plane coordinates and signed radii;
:func:`planar_path_lengths` then evaluates the same closed form as
:func:`~wire_fmu.core.components.sheave_geometry.path.path_geometry` on scalars, fast
enough for an ODE right-hand side (speeds in :mod:`wire_fmu.core.components.sheave_geometry`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from wire_fmu.core.components.sheave_geometry.circles import (
    _PARALLEL_TOL,
    _POS_TOL,
    _WHERE,
    DEFAULT_MAX_FLEET_ANGLE,
    PathNode,
    Vec3,
    _cross,
    _dot,
    _fmt,
    _label,
    _norm,
    _sub,
    _unit_perpendicular,
    _vec,
    _wrap_2pi,
)
from wire_fmu.core.components.sheave_geometry.path import path_geometry
from wire_fmu.core.errors import GeometryError

__all__ = ["PlanarFrame", "planar_frame", "planar_path_lengths"]


@dataclass(frozen=True)
class PlanarFrame:
    """2-D coordinates of a path whose circles all lie in one plane.

    Attributes
    ----------
    origin : tuple of 3 float
        Origin of the plane coordinates, m.
    u, v : tuple of 3 float
        In-plane orthonormal basis, ``u x v = normal``.
    normal : tuple of 3 float
        Unit normal of the plane.
    signed_radii : tuple of float
        Per node ``sense * radius`` about ``+normal``, m (positive:
        counter-clockwise in the (u, v) coordinates).
    names : tuple of str
        Node names, for error messages.
    """

    origin: Vec3
    u: Vec3
    v: Vec3
    normal: Vec3
    signed_radii: tuple[float, ...]
    names: tuple[str, ...]

    def project(self, point: Sequence[float]) -> tuple[float, float]:
        """Plane coordinates (x, y) of a 3-D point, m.

        Parameters
        ----------
        point : sequence of 3 float
            A point in 3-D, m.
        """
        rel = _sub(_vec(point), self.origin)
        return _dot(rel, self.u), _dot(rel, self.v)


# ------------------------------------------------------------------- planar, lean


def _path_normal(nodes: Sequence[PathNode]) -> Vec3:
    """Normal of the plane of a path: first sheave's axis, else from the points."""
    for node in nodes:
        if node.circle.radius > 0.0:
            return node.circle.axis
    c0 = nodes[0].circle.centre
    rels = [_sub(n.circle.centre, c0) for n in nodes[1:]]
    for i, p in enumerate(rels):
        for q in rels[i + 1 :]:
            w = _cross(p, q)
            n = _norm(w)
            if n > _POS_TOL * max(_norm(p), _norm(q), 1.0):
                return (w[0] / n, w[1] / n, w[2] / n)
    d = rels[-1]
    n = _norm(d)
    return _unit_perpendicular((d[0] / n, d[1] / n, d[2] / n))


def planar_frame(
    nodes: Sequence[PathNode], *, max_fleet_angle: float = DEFAULT_MAX_FLEET_ANGLE
) -> PlanarFrame:
    """Validate a path that lies in one plane and return its 2-D frame.

    Use once, then call :func:`planar_path_lengths` with
    ``[frame.project(c) for c in centres]`` and ``frame.signed_radii``
    whenever centres move within the plane.

    Parameters
    ----------
    nodes : sequence of PathNode
        The path.
    max_fleet_angle : float, optional
        Largest allowed fleet angle, rad.

    Returns
    -------
    PlanarFrame
        Origin, basis and signed radii (m) of the path's plane.

    Raises
    ------
    GeometryError
        If the path is invalid or not planar (names the nodes off the plane).
    """
    path_geometry(nodes, max_fleet_angle=max_fleet_angle)
    normal = _path_normal(nodes)
    origin = nodes[0].circle.centre
    problems = []
    signed = []
    for node in nodes:
        c = node.circle
        off = _dot(_sub(c.centre, origin), normal)
        tilted = c.radius > 0.0 and _norm(_cross(c.axis, normal)) > _PARALLEL_TOL
        if abs(off) > _POS_TOL or tilted:
            problems.append(
                f"{_label(c)}: not in the path plane through {_fmt(origin)} m with normal "
                f"{_fmt(normal)} (offset {off:.3g} m, axis {_fmt(c.axis)})"
            )
        signed.append(node.sense * c.radius * math.copysign(1.0, _dot(c.axis, normal)))
    if problems:
        raise GeometryError(_WHERE, problems)
    u = _unit_perpendicular(normal)
    v = _cross(normal, u)
    names = tuple(n.circle.name for n in nodes)
    return PlanarFrame(origin, u, v, normal, tuple(signed), names)


def planar_path_lengths(
    xy: Sequence[Sequence[float]],
    signed_radii: Sequence[float],
    *,
    names: Sequence[str] | None = None,
) -> tuple[list[float], list[float]]:
    """Straight lengths and wrap angles of a planar path, scalar fast path.

    No validation beyond tangent existence: use after one validated call
    (:func:`planar_frame`). Same closed form as :func:`path_geometry`.

    Parameters
    ----------
    xy : sequence of (float, float)
        Node centres in the plane, m.
    signed_radii : sequence of float
        Per node ``sense * radius`` about the plane normal, m (0 for points).
    names : sequence of str, optional
        Node names for error messages (default: node indices).

    Returns
    -------
    lengths : list of float
        Straight length of each segment, m.
    wrap_angles : list of float
        Per interior node, rad, in [0, 2 pi); for a point the turning angle.
        Arc lengths are ``abs(signed_radii[j]) * wrap_angles[j - 1]``.

    Raises
    ------
    GeometryError
        If a segment has no tangent (circles overlap or a point lies inside).
    """
    lengths: list[float] = []
    dirs: list[tuple[float, float]] = []
    for i in range(len(xy) - 1):
        dx, dy = xy[i + 1][0] - xy[i][0], xy[i + 1][1] - xy[i][1]
        k = signed_radii[i + 1] - signed_radii[i]
        l2 = dx * dx + dy * dy
        if math.sqrt(l2) - abs(k) <= _POS_TOL:
            raise GeometryError(_WHERE, [_planar_problem(i, xy, signed_radii, names)])
        lt = math.sqrt(l2 - k * k)
        lengths.append(lt)
        dirs.append(((lt * dx + k * dy) / l2, (lt * dy - k * dx) / l2))
    wraps = []
    for j in range(1, len(xy) - 1):
        (ax, ay), (bx, by) = dirs[j - 1], dirs[j]
        cr, dt = ax * by - ay * bx, ax * bx + ay * by
        rho = signed_radii[j]
        if rho == 0.0:
            wraps.append(abs(math.atan2(cr, dt)))
        else:
            wraps.append(_wrap_2pi(math.atan2(cr if rho > 0.0 else -cr, dt)))
    return lengths, wraps


def _planar_problem(
    i: int,
    xy: Sequence[Sequence[float]],
    signed_radii: Sequence[float],
    names: Sequence[str] | None,
) -> str:
    na, nb = (names[i], names[i + 1]) if names is not None else (f"#{i}", f"#{i + 1}")
    dist = math.hypot(xy[i + 1][0] - xy[i][0], xy[i + 1][1] - xy[i][1])
    ra, rb = signed_radii[i], signed_radii[i + 1]
    return (
        f"nodes '{na}' and '{nb}': no tangent, centre distance {dist:.3f} m <= "
        f"|rho2 - rho1| = {abs(rb - ra):.3f} m (signed radii {ra:.3f} m, {rb:.3f} m)"
    )
