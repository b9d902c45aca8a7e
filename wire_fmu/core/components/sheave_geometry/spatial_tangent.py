"""Tangents between circles whose axes are not parallel (eq. 26-31, and ours).

*Aligned* (eq. 26-31): the two sheave planes cut along a line at distance
``r`` from both centres; the tangent points are the feet of the
perpendiculars, the fleet angles 0. *General* (ours):
:func:`solve_fleet_tangent`, Newton iteration in the contact angles with an
analytic Jacobian, started from the planar solution in each circle's own
plane (the other circle projected into it).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from wire_fmu.core.components.sheave_geometry.circles import (
    _POS_TOL,
    _WHERE,
    Circle,
    PathNode,
    _cross,
    _dot,
    _fmt,
    _norm,
    _NoTangentError,
    _pair,
    _Segment,
    _sub,
    _unit_perpendicular,
    _vec,
)
from wire_fmu.core.components.sheave_geometry.planar_tangent import _parallel_tangent
from wire_fmu.core.errors import GeometryError

__all__ = ["FleetTangent", "solve_fleet_tangent"]

logger = logging.getLogger(__name__)

_NEWTON_TOL = 1e-12  # m: residual of the tangency conditions
_NEWTON_MAX_ITER = 50
_NEWTON_MAX_STEP = 0.5  # rad: largest contact-angle change per Newton step


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


def _general_segment(a: PathNode, b: PathNode) -> _Segment:
    try:
        sol = _newton(a, b, _NEWTON_TOL, _NEWTON_MAX_ITER)
    except _NoTangentError as exc:
        raise _NoTangentError(_inconsistent(a, b, str(exc))) from None
    return _Segment(_vec(sol.start), _vec(sol.end), *sol.fleet_angles, "general")
