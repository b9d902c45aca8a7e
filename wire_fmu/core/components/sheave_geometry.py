"""Where the rope leaves a sheave: tangent points, straight lengths, wrap and fleet angles.

SPEC section 6 (paper 000, eq. 13-31). A rope *path* is an ordered sequence of
:class:`PathNode` s. Each node is a :class:`Circle`: a sheave's working circle
(radius > 0) or a point (radius 0: an anchor or a free rope end). Between two
consecutive nodes the rope runs straight, from the point where it leaves the
first circle to the point where it touches the second.

Sign convention for ``sense``
-----------------------------
``sense = +1``: travelling along the path (from node ``i`` towards node
``i + 1``) the rope wraps the sheave counter-clockwise seen from the tip of
``+axis``; rope moving forward turns the sheave positively by the right-hand
rule about ``+axis``. ``sense = -1``: clockwise. ``sense = 0``: a point.
At every tangent point ``P`` of a sheave (centre ``C``, radius ``r``), with
``d`` the rope direction there (pointing forward along the path)::

    ((P - C) x d) . axis  =  sense * r * |d_in_plane|        (sign = sense)

Hand example (axis +z, sheave at the origin, r = 1): a rope from the point
(1, -5) runs up to (1, 0) (there (1, 0, 0) x (0, 1, 0) = +z), over the top,
and leaves at (-1, 0) running down to (-1, -5) ((-1, 0, 0) x (0, -1, 0) = +z):
``sense = +1``, wrap angle pi. The paper's orientation checks (30, 31),
``AB x C1A || +A1``, are this rule with sense -1 (they fix the sign of the
axis instead of carrying a sense). Two sheaves whose senses agree about a
common axis get an outer tangent; opposite senses get a crossed tangent.

Cases
-----
* **Parallel axes** (planar, eq. 16-25, and the parallel fleet-angle case):
  closed form with signed radii ``rho = sense * r``: with ``D`` the centre
  offset projected on the sheave plane, ``L = |D|`` and ``k = rho_b - rho_a``
  the rope's in-plane direction is ``(sqrt(L^2 - k^2) D - k (A x D)) / L^2``,
  the in-plane tangent length ``sqrt(L^2 - k^2)``, and ``P = C - rho n`` with
  ``n = A x d``. No division by ``r1 - r2`` (equal radii, eq. 24, need no
  special case). An offset ``h`` along the axis leaves the in-plane problem
  unchanged (the radii have no axial part), so this form is exact there too;
  the fleet angle is ``atan2(|h|, sqrt(L^2 - k^2))``. A point to a sheave of
  any orientation is the same form: the point's projection on the sheave plane
  has the same tangent point.
* **Spatial, aligned** (eq. 26-31): non-parallel axes whose planes cut along a
  line at distance ``r`` from both centres: tangent points are the feet of
  the perpendiculars, fleet angles 0.
* **General** (ours): :func:`solve_fleet_tangent`, Newton iteration in the
  contact angles with an analytic Jacobian, from the planar solution of each
  circle's own plane (the other circle projected into it).

Speed
-----
Measured (Python 3.11, numpy 2.4, AMD EPYC, best of 5 ``timeit`` runs) for one
12-node planar block-train path (11 segments, 10 interior sheaves):
``path_geometry(..., validate=True)`` 130 us per call (of which the whole-path
checks are about 65 us), ``path_geometry(..., validate=False)`` 60 us (about
half of it building the numpy result), :func:`planar_path_lengths` 6.5 us.
Validate once (:func:`path_geometry` or :func:`planar_frame`), then inside an
ODE right-hand side call :func:`planar_path_lengths` with the moved centres'
plane coordinates (``frame.project`` costs about 0.5 us per node, or keep 2-D
coordinates directly), or ``path_geometry(..., validate=False)`` for paths
that are not planar.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from wire_fmu.core.errors import GeometryError

__all__ = [
    "DEFAULT_MAX_FLEET_ANGLE",
    "Circle",
    "PathNode",
    "PathGeometry",
    "FleetTangent",
    "PlanarFrame",
    "segment_tangent_points",
    "solve_fleet_tangent",
    "path_geometry",
    "check_path",
    "planar_frame",
    "planar_path_lengths",
]

logger = logging.getLogger(__name__)

DEFAULT_MAX_FLEET_ANGLE: float = math.radians(2.5)
"""Default largest fleet angle a segment may have, rad."""

_WHERE = "rope path"
_TWO_PI = 2.0 * math.pi
_UNIT_TOL = 1e-9  # | |axis| - 1 |
_PARALLEL_TOL = 1e-9  # |A_a x A_b| below which axes count as parallel
_POS_TOL = 1e-9  # m: coplanarity, same place, aligned-case distances, tangent existence
_NEWTON_TOL = 1e-12  # m: residual of the tangency conditions
_NEWTON_MAX_ITER = 50
_NEWTON_MAX_STEP = 0.5  # rad: largest contact-angle change per Newton step

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
        Unit axis vector (validated by :func:`check_path`, not normalised).
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


@dataclass(frozen=True, eq=False)
class PathGeometry:
    """Geometry of a whole rope path.

    Attributes
    ----------
    points : tuple of (ndarray, ndarray)
        Per segment, where the rope leaves the start node and touches the end
        node, m.
    lengths : ndarray
        Straight length of each segment, m.
    directions : ndarray, shape (n_segments, 3)
        Unit vectors from start point to end point.
    wrap_angles : ndarray
        Per interior node, rad, in [0, 2 pi): arc from the incoming to the
        outgoing tangent point in the node's sense; for an interior point the
        turning angle of the rope.
    arc_lengths : ndarray
        Per interior node, radius * wrap angle, m.
    fleet_angles : ndarray, shape (n_segments, 2)
        Angle between each segment and the plane of its start / end circle,
        rad (0 at points).
    kinds : tuple of str
        Per segment, how it was solved: ``"straight"`` (point to point),
        ``"planar"``, ``"offset"`` (parallel axes, offset along them),
        ``"aligned"`` (eq. 26-31) or ``"general"`` (Newton).
    """

    points: tuple[tuple[np.ndarray, np.ndarray], ...]
    lengths: np.ndarray
    directions: np.ndarray
    wrap_angles: np.ndarray
    arc_lengths: np.ndarray
    fleet_angles: np.ndarray
    kinds: tuple[str, ...]


@dataclass(frozen=True, eq=False)
class FleetTangent:
    """Result of the general (Newton) tangent solver.

    Attributes
    ----------
    start, end : ndarray
        Where the rope leaves the start circle and touches the end circle, m.
    fleet_angles : tuple of float
        Angle between the rope and the start / end circle's plane, rad.
    iterations : int
        Newton iterations taken.
    residual : float
        Largest radius component along the rope at the solution, m.
    """

    start: np.ndarray
    end: np.ndarray
    fleet_angles: tuple[float, float]
    iterations: int
    residual: float


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
        """Plane coordinates (x, y) of a 3-D point, m."""
        rel = _sub(_vec(point), self.origin)
        return _dot(rel, self.u), _dot(rel, self.v)


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


# ------------------------------------------------------------ parallel closed form


def _parallel_tangent(
    ca: Vec3, cb: Vec3, axis: Vec3, rho_a: float, rho_b: float
) -> tuple[Vec3, Vec3, float, float] | None:
    """Tangent between two circles in parallel planes (normal ``axis``).

    ``rho`` is ``sense * r`` about ``axis`` (0 for a point). Returns the
    tangent points, the in-plane tangent length (m) and the offset of ``cb``
    along ``axis`` (m), or None if no tangent exists.
    """
    ax, ay, az = axis
    dx, dy, dz = cb[0] - ca[0], cb[1] - ca[1], cb[2] - ca[2]
    h = dx * ax + dy * ay + dz * az
    px, py, pz = dx - h * ax, dy - h * ay, dz - h * az
    l2 = px * px + py * py + pz * pz
    k = rho_b - rho_a
    if math.sqrt(l2) - abs(k) <= _POS_TOL:
        return None
    lt = math.sqrt(l2 - k * k)
    # n = A x d_in, d_in = (lt D - k A x D) / L^2  =>  n = (lt A x D + k D) / L^2
    cx, cy, cz = ay * pz - az * py, az * px - ax * pz, ax * py - ay * px
    nx, ny, nz = (lt * cx + k * px) / l2, (lt * cy + k * py) / l2, (lt * cz + k * pz) / l2
    pa = (ca[0] - rho_a * nx, ca[1] - rho_a * ny, ca[2] - rho_a * nz)
    pb = (cb[0] - rho_b * nx, cb[1] - rho_b * ny, cb[2] - rho_b * nz)
    return pa, pb, lt, h


def _parallel_setup(a: PathNode, b: PathNode) -> tuple[Vec3, float, float] | None:
    """Reference axis and signed radii if the closed form applies, else None."""
    ca, cb = a.circle, b.circle
    if ca.radius == 0.0:
        return cb.axis, 0.0, b.sense * cb.radius
    if cb.radius == 0.0:
        return ca.axis, a.sense * ca.radius, 0.0
    cos = _dot(ca.axis, cb.axis)
    if _norm(_cross(ca.axis, cb.axis)) > _PARALLEL_TOL:
        return None
    return ca.axis, a.sense * ca.radius, math.copysign(1.0, cos) * b.sense * cb.radius


def _parallel_problem(a: PathNode, b: PathNode, axis: Vec3, rho_a: float, rho_b: float) -> str:
    """Explain why the closed-form tangent does not exist."""
    ca, cb = a.circle, b.circle
    d = _sub(cb.centre, ca.centre)
    h = _dot(d, axis)
    dist = _norm(_sub(d, (h * axis[0], h * axis[1], h * axis[2])))
    note = "" if abs(h) <= _POS_TOL else f" (in the sheave plane; offset {abs(h):.3f} m along axis)"
    pair = _pair(ca, cb)
    if ca.radius == 0.0 or cb.radius == 0.0:
        pt, sh = (ca, cb) if ca.radius == 0.0 else (cb, ca)
        return (
            f"{pair}: point '{pt.name}' lies inside sheave '{sh.name}': centre distance "
            f"{dist:.3f} m <= radius {sh.radius:.3f} m{note} (no tangent from the point)"
        )
    if rho_a * rho_b < 0.0:
        return (
            f"{pair}: crossed tangent needs centre distance {dist:.3f} m > r1 + r2 = "
            f"{ca.radius + cb.radius:.3f} m{note} (the sheaves overlap)"
        )
    return (
        f"{pair}: outer tangent needs centre distance {dist:.3f} m > |r1 - r2| = "
        f"{abs(ca.radius - cb.radius):.3f} m{note} (one sheave lies inside the other)"
    )


# -------------------------------------------------------------- spatial, aligned


def _aligned_tangent(a: PathNode, b: PathNode) -> _Segment | None:
    """Eq. (26-31): the tangent as the intersection of the two sheave planes, or None."""
    ca, cb = a.circle, b.circle
    na, nb = ca.axis, cb.axis
    w = _cross(na, nb)
    w2 = _dot(w, w)
    ha, hb = _dot(na, ca.centre), _dot(nb, cb.centre)
    s1, s2 = _cross(nb, w), _cross(w, na)
    x0 = tuple((ha * s1[i] + hb * s2[i]) / w2 for i in range(3))
    wn = math.sqrt(w2)
    wu = (w[0] / wn, w[1] / wn, w[2] / wn)
    feet = []
    for c in (ca, cb):
        t = _dot(_sub(c.centre, x0), wu)
        foot = (x0[0] + t * wu[0], x0[1] + t * wu[1], x0[2] + t * wu[2])
        if abs(_norm(_sub(foot, c.centre)) - c.radius) > _POS_TOL:  # eq. (27, 28)
            return None
        feet.append(foot)
    d = _sub(feet[1], feet[0])
    if _norm(d) <= _POS_TOL:
        return None
    for node, foot in ((a, feet[0]), (b, feet[1])):  # eq. (30, 31), in our sense convention
        c = node.circle
        if _dot(_cross(_sub(foot, c.centre), d), c.axis) * node.sense <= 0.0:
            return None
    return _Segment(feet[0], feet[1], 0.0, 0.0, "aligned")


# ---------------------------------------------------------------- general: Newton


def _initial_angle(own: PathNode, other: PathNode, own_is_start: bool) -> float | None:
    """Contact angle on ``own`` from the planar tangent in its plane, rad, or None."""
    c, o = own.circle, other.circle
    rho_own = own.sense * c.radius
    u = _unit_perpendicular(c.axis)
    v = _cross(c.axis, u)
    for scale in (_dot(o.axis, c.axis), 0.0):  # other projected; then other as a point
        rho_other = other.sense * o.radius * scale
        if own_is_start:
            sol = _parallel_tangent(c.centre, o.centre, c.axis, rho_own, rho_other)
        else:
            sol = _parallel_tangent(o.centre, c.centre, c.axis, rho_other, rho_own)
        if sol is not None:
            rel = _sub(sol[0] if own_is_start else sol[1], c.centre)
            return math.atan2(_dot(rel, v), _dot(rel, u))
    return None


def _contact(circle: Circle, theta: float) -> tuple[np.ndarray, np.ndarray]:
    """Radius vector and its derivative d/dtheta at contact angle ``theta``, m."""
    u = np.array(_unit_perpendicular(circle.axis))
    v = np.cross(np.array(circle.axis), u)
    c, s = math.cos(theta), math.sin(theta)
    return circle.radius * (c * u + s * v), circle.radius * (-s * u + c * v)


def _newton_step(f: np.ndarray, jac: np.ndarray, active: tuple[bool, bool]) -> np.ndarray:
    """Newton step for the active contact angles (a point has none), rad."""
    step = np.zeros(2)
    if active[0] and active[1]:
        det = jac[0, 0] * jac[1, 1] - jac[0, 1] * jac[1, 0]
        if det == 0.0:
            raise _NoTangentError("singular Jacobian")
        step[0] = (f[0] * jac[1, 1] - f[1] * jac[0, 1]) / det
        step[1] = (jac[0, 0] * f[1] - jac[1, 0] * f[0]) / det
    else:
        i = 0 if active[0] else 1
        if jac[i, i] == 0.0:
            raise _NoTangentError("singular Jacobian")
        step[i] = f[i] / jac[i, i]
    biggest = float(np.max(np.abs(step)))
    if biggest > _NEWTON_MAX_STEP:
        step *= _NEWTON_MAX_STEP / biggest
    return step


def _newton(a: PathNode, b: PathNode, tol: float, max_iter: int) -> FleetTangent:
    """Solve the tangency conditions (P_b - P_a) . (P_i - C_i) = 0; raise _NoTangentError."""
    ca, cb = a.circle, b.circle
    active = (ca.radius > 0.0, cb.radius > 0.0)
    theta = [0.0, 0.0]
    for i, (own, other) in enumerate(((a, b), (b, a))):
        if active[i]:
            guess = _initial_angle(own, other, own_is_start=i == 0)
            if guess is None:
                raise _NoTangentError("no planar starting guess: a centre projects inside a sheave")
            theta[i] = guess
    centre_a, centre_b = np.array(ca.centre), np.array(cb.centre)
    for it in range(max_iter + 1):
        rho_a, t_a = _contact(ca, theta[0])
        rho_b, t_b = _contact(cb, theta[1])
        d = centre_b + rho_b - centre_a - rho_a
        dist = float(np.linalg.norm(d))
        if dist <= _POS_TOL:
            raise _NoTangentError("the tangent points coincide")
        f = np.array([d @ rho_a, d @ rho_b])
        residual = float(np.max(np.abs(f))) / dist
        if residual <= tol:
            return _finish_newton(a, b, centre_a + rho_a, centre_b + rho_b, it, residual)
        jac = np.array([[d @ t_a, t_b @ rho_a], [-(t_a @ rho_b), d @ t_b]])
        step = _newton_step(f, jac, active)
        theta = [theta[0] - step[0], theta[1] - step[1]]
    raise _NoTangentError(
        f"Newton did not converge in {max_iter} iterations, residual {residual:.3g} m"
    )


def _finish_newton(
    a: PathNode, b: PathNode, pa: np.ndarray, pb: np.ndarray, iterations: int, residual: float
) -> FleetTangent:
    """Check the wrap senses of a converged Newton solution and package it."""
    d = pb - pa
    du = d / np.linalg.norm(d)
    fleet = []
    for node, p in ((a, pa), (b, pb)):
        c = node.circle
        if c.radius == 0.0:
            fleet.append(0.0)
            continue
        axis = np.array(c.axis)
        if float(np.cross(p - np.array(c.centre), d) @ axis) * node.sense <= 0.0:
            raise _NoTangentError(f"converged to a tangent wrapping '{c.name}' the wrong way")
        fleet.append(math.asin(min(1.0, abs(float(du @ axis)))))
    logger.debug("fleet tangent %s -> %s: %d iterations", a.circle.name, b.circle.name, iterations)
    return FleetTangent(pa, pb, (fleet[0], fleet[1]), iterations, residual)


def solve_fleet_tangent(
    a: PathNode, b: PathNode, *, tol: float = _NEWTON_TOL, max_iter: int = _NEWTON_MAX_ITER
) -> FleetTangent:
    """General tangent between two circles of any orientation, by Newton iteration.

    Unknowns are the contact angles theta_a, theta_b, with
    ``P = C + r (cos(theta) u + sin(theta) v)`` in each circle's plane. The
    conditions ``(P_b - P_a) . (P_a - C_a) = 0`` and
    ``(P_b - P_a) . (P_b - C_b) = 0`` are solved with the analytic Jacobian
    from the planar solution in each circle's own plane (the other circle's
    centre projected into it, its radius scaled by the cosine between the
    axes). A point (radius 0) has no unknown: a 1-D iteration remains.

    Parameters
    ----------
    a, b : PathNode
        Start and end node of the segment (the rope runs from a to b).
    tol : float, optional
        Convergence limit on ``max |(P_b - P_a) . (P_i - C_i)| / |P_b - P_a|``, m.
    max_iter : int, optional
        Largest number of Newton iterations.

    Returns
    -------
    FleetTangent
        Tangent points (m), fleet angles (rad), iterations and residual (m).

    Raises
    ------
    GeometryError
        If Newton does not converge, or converges to a tangent with the wrong
        wrap sense; the message names both nodes.
    """
    try:
        return _newton(a, b, tol, max_iter)
    except _NoTangentError as exc:
        raise GeometryError(_WHERE, [_inconsistent(a, b, str(exc))]) from None


def _inconsistent(a: PathNode, b: PathNode, why: str) -> str:
    ca, cb = a.circle, b.circle
    return (
        f"{_pair(ca, cb)}: inconsistent axes {_fmt(ca.axis)} and {_fmt(cb.axis)}: "
        f"no rope tangent with the requested wrap senses ({why})"
    )


# ------------------------------------------------------------------- one segment


def _solve_segment(a: PathNode, b: PathNode) -> _Segment:
    """Tangent points and fleet angles of the segment a -> b; raise _NoTangentError."""
    ca, cb = a.circle, b.circle
    if _norm(_sub(cb.centre, ca.centre)) <= _POS_TOL:
        raise _NoTangentError(
            f"{_pair(ca, cb)}: consecutive nodes at the same place {_fmt(ca.centre)} m "
            "(zero-length segment)"
        )
    if ca.radius == 0.0 and cb.radius == 0.0:
        return _Segment(ca.centre, cb.centre, 0.0, 0.0, "straight")
    setup = _parallel_setup(a, b)
    if setup is None:
        return _aligned_tangent(a, b) or _general_segment(a, b)
    axis, rho_a, rho_b = setup
    sol = _parallel_tangent(ca.centre, cb.centre, axis, rho_a, rho_b)
    if sol is None:
        raise _NoTangentError(_parallel_problem(a, b, axis, rho_a, rho_b))
    pa, pb, lt, h = sol
    fleet = math.atan2(abs(h), lt)
    kind = "planar" if abs(h) <= _POS_TOL else "offset"
    fa = fleet if ca.radius > 0.0 else 0.0
    fb = fleet if cb.radius > 0.0 else 0.0
    return _Segment(pa, pb, fa, fb, kind)


def _general_segment(a: PathNode, b: PathNode) -> _Segment:
    try:
        sol = _newton(a, b, _NEWTON_TOL, _NEWTON_MAX_ITER)
    except _NoTangentError as exc:
        raise _NoTangentError(_inconsistent(a, b, str(exc))) from None
    return _Segment(_vec(sol.start), _vec(sol.end), *sol.fleet_angles, "general")


def _fleet_problem(a: PathNode, b: PathNode, seg: _Segment, limit: float) -> str | None:
    """Message if the segment's fleet angle exceeds ``limit`` (rad), else None."""
    worst, where = max((seg.fleet_start, a.circle.name), (seg.fleet_end, b.circle.name))
    if worst <= limit:
        return None
    return (
        f"{_pair(a.circle, b.circle)}: fleet angle {math.degrees(worst):.2f} deg at "
        f"'{where}' exceeds the limit {math.degrees(limit):.2f} deg"
    )


def segment_tangent_points(
    a: PathNode, b: PathNode, *, max_fleet_angle: float = DEFAULT_MAX_FLEET_ANGLE
) -> tuple[np.ndarray, np.ndarray]:
    """Where the rope, travelling from node a to node b, leaves a and touches b.

    Parameters
    ----------
    a, b : PathNode
        Start and end node.
    max_fleet_angle : float, optional
        Largest allowed fleet angle, rad.

    Returns
    -------
    P_a, P_b : ndarray
        Tangent points on circle a and circle b, m.

    Raises
    ------
    GeometryError
        With every problem of the two nodes and the segment.
    """
    problems, segments = _analyse([a, b], max_fleet_angle)
    if problems:
        raise GeometryError(_WHERE, problems)
    seg = segments[0]
    return np.array(seg.start), np.array(seg.end)


# --------------------------------------------------------------------- validation


def _node_problems(node: PathNode) -> list[str]:
    """Problems of one node on its own."""
    c = node.circle
    label = _label(c)
    if len(c.centre) != 3 or len(c.axis) != 3:
        return [f"{label}: centre and axis need 3 components each"]
    if not all(math.isfinite(x) for x in (*c.centre, *c.axis, c.radius)):
        return [f"{label}: non-finite centre {c.centre}, axis {c.axis} or radius {c.radius}"]
    problems = []
    if c.radius < 0.0:
        problems.append(f"{label}: radius {c.radius:.3f} m is negative")
    n = _norm(c.axis)
    if n == 0.0:
        problems.append(f"{label}: axis is zero, expected a unit vector")
    elif abs(n - 1.0) > _UNIT_TOL:
        problems.append(f"{label}: axis {_fmt(c.axis)} has length {n:.9g}, expected 1")
    if c.radius > 0.0 and node.sense not in (1, -1):
        problems.append(f"{label}: sense {node.sense!r} must be +1 (ccw about +axis) or -1 (cw)")
    if c.radius == 0.0 and node.sense != 0:
        problems.append(f"{label}: sense {node.sense!r} must be 0 for a point (radius 0)")
    return problems


def _overlap_problem(p: Circle, q: Circle) -> str | None:
    """Message if two sheaves' discs overlap in one plane, else None."""
    if p.radius <= 0.0 or q.radius <= 0.0:
        return None
    if _norm(_cross(p.axis, q.axis)) > _PARALLEL_TOL:
        return None
    d = _sub(q.centre, p.centre)
    if abs(_dot(d, p.axis)) > _POS_TOL:
        return None
    dist = _norm(d)
    same = dist <= _POS_TOL and abs(p.radius - q.radius) <= _POS_TOL
    if same or dist >= p.radius + q.radius:
        return None
    return (
        f"{_pair(p, q)}: discs overlap in the same plane: centre distance {dist:.3f} m "
        f"< r1 + r2 = {p.radius + q.radius:.3f} m"
    )


def _pair_problems(nodes: Sequence[PathNode], skip: set[tuple[int, int]]) -> list[str]:
    """Overlapping coplanar sheaves anywhere in the path, and clashing names.

    Pairs in ``skip`` (invalid nodes, neighbours already reported) are left out.
    """
    problems = []
    n = len(nodes)
    for i in range(n):
        for j in range(i + 1, n):
            if (i, j) in skip:
                continue
            p, q = nodes[i].circle, nodes[j].circle
            if p.name == q.name and p != q:
                problems.append(f"{_pair(p, q)}: two different circles share the name")
            msg = _overlap_problem(p, q)
            if msg is not None:
                problems.append(msg)
    return problems


def _segment_problems(
    nodes: Sequence[PathNode], bad: set[int], limit: float
) -> tuple[list[str], list[_Segment | None]]:
    problems: list[str] = []
    segments: list[_Segment | None] = []
    for i in range(len(nodes) - 1):
        a, b = nodes[i], nodes[i + 1]
        if i in bad or i + 1 in bad:
            segments.append(None)
            continue
        try:
            seg = _solve_segment(a, b)
        except _NoTangentError as exc:
            problems.append(str(exc))
            segments.append(None)
            continue
        msg = _fleet_problem(a, b, seg, limit)
        if msg is not None:
            problems.append(msg)
        segments.append(seg)
    return problems, segments


def _analyse(
    nodes: Sequence[PathNode], max_fleet_angle: float
) -> tuple[list[str], list[_Segment | None]]:
    """Every problem of a path, and the segments that could be solved."""
    if len(nodes) < 2:
        return [f"a rope path needs at least 2 nodes, got {len(nodes)}"], []
    problems: list[str] = []
    if not (math.isfinite(max_fleet_angle) and max_fleet_angle >= 0.0):
        problems.append(f"max_fleet_angle {max_fleet_angle!r} rad must be finite and >= 0")
        max_fleet_angle = math.inf
    bad: set[int] = set()
    for i, node in enumerate(nodes):
        node_problems = _node_problems(node)
        if node_problems:
            bad.add(i)
            problems.extend(node_problems)
    seg_problems, segments = _segment_problems(nodes, bad, max_fleet_angle)
    problems.extend(seg_problems)
    n = len(nodes)
    skip = {(i, j) for i in range(n) for j in range(i + 1, n) if i in bad or j in bad}
    skip.update((i, i + 1) for i, seg in enumerate(segments) if seg is None)
    problems.extend(_pair_problems(nodes, skip))
    return problems, segments


def check_path(
    nodes: Sequence[PathNode], *, max_fleet_angle: float = DEFAULT_MAX_FLEET_ANGLE
) -> list[str]:
    """Every problem of a rope path, empty if it is valid.

    Checks each node (finite values, unit axis, radius >= 0, sense +1/-1 for a
    sheave and 0 for a point), each segment (a tangent exists with the
    requested senses, no zero-length segment, fleet angle within the limit)
    and every pair of sheaves (no discs overlapping in one plane). Segments
    touching an invalid node are not checked further.

    Parameters
    ----------
    nodes : sequence of PathNode
        The path, in the rope's direction of travel.
    max_fleet_angle : float, optional
        Largest allowed fleet angle, rad.

    Returns
    -------
    list of str
        One sentence per problem, naming the nodes involved.
    """
    return _analyse(nodes, max_fleet_angle)[0]


# --------------------------------------------------------------------- whole path


def _wrap_angle(node: PathNode, p_in: Vec3, p_out: Vec3, d_in: Vec3, d_out: Vec3) -> float:
    """Wrap angle at an interior node, rad, in [0, 2 pi)."""
    c = node.circle
    if c.radius == 0.0:  # turning angle of the rope
        return math.atan2(_norm(_cross(d_in, d_out)), _dot(d_in, d_out))
    r_in, r_out = _sub(p_in, c.centre), _sub(p_out, c.centre)
    s = node.sense * _dot(c.axis, _cross(r_in, r_out))
    return _wrap_2pi(math.atan2(s, _dot(r_in, r_out)))


def _assemble(nodes: Sequence[PathNode], segments: Sequence[_Segment]) -> PathGeometry:
    vecs = [_sub(s.end, s.start) for s in segments]
    lengths = [_norm(v) for v in vecs]
    wraps = [
        _wrap_angle(nodes[j], segments[j - 1].end, segments[j].start, vecs[j - 1], vecs[j])
        for j in range(1, len(nodes) - 1)
    ]
    arcs = [n.circle.radius * w for n, w in zip(nodes[1:-1], wraps, strict=True)]
    starts, ends = np.array([s.start for s in segments]), np.array([s.end for s in segments])
    length_arr = np.array(lengths)
    return PathGeometry(
        points=tuple(zip(starts, ends, strict=True)),
        lengths=length_arr,
        directions=(ends - starts) / length_arr[:, None],
        wrap_angles=np.array(wraps),
        arc_lengths=np.array(arcs),
        fleet_angles=np.array([(s.fleet_start, s.fleet_end) for s in segments]),
        kinds=tuple(s.kind for s in segments),
    )


def _solve_all(nodes: Sequence[PathNode]) -> list[_Segment]:
    """Solve every segment without whole-path validation; raise on the first failure."""
    segments = []
    for i in range(len(nodes) - 1):
        try:
            segments.append(_solve_segment(nodes[i], nodes[i + 1]))
        except _NoTangentError as exc:
            raise GeometryError(_WHERE, [str(exc)]) from None
    return segments


def path_geometry(
    nodes: Sequence[PathNode],
    *,
    max_fleet_angle: float = DEFAULT_MAX_FLEET_ANGLE,
    validate: bool = True,
) -> PathGeometry:
    """Tangent points, straight lengths, wrap and fleet angles of a rope path.

    Parameters
    ----------
    nodes : sequence of PathNode
        The path, in the rope's direction of travel (at least 2 nodes).
    max_fleet_angle : float, optional
        Largest allowed fleet angle, rad (checked only when validating).
    validate : bool, optional
        If True (default) run :func:`check_path` and raise with every problem.
        If False skip the node, overlap and fleet-angle checks (for repeated
        calls on a path validated once); a segment without a tangent still
        raises.

    Returns
    -------
    PathGeometry
        Per segment points (m), lengths (m), directions, fleet angles (rad);
        per interior node wrap angles (rad) and arc lengths (m).

    Raises
    ------
    GeometryError
        ``where = "rope path"``, with all problems found.
    """
    if validate:
        problems, segments = _analyse(nodes, max_fleet_angle)
        if problems:
            raise GeometryError(_WHERE, problems)
    else:
        segments = _solve_all(nodes)
    return _assemble(nodes, segments)


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
