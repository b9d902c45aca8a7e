"""The closed-form tangent between two circles in parallel planes (eq. 16-25).

Signed radii ``rho = sense * r``: with ``D`` the centre offset projected on
the sheave plane, ``L = |D|`` and ``k = rho_b - rho_a`` the rope's in-plane
direction is ``(sqrt(L^2 - k^2) D - k (A x D)) / L^2``, the in-plane tangent
length ``sqrt(L^2 - k^2)``, and ``P = C - rho n`` with ``n = A x d``. An
offset along the axis leaves the in-plane problem unchanged, and a point to
a sheave of any orientation is the same form (:mod:`wire_fmu.core.components.sheave_geometry`).
"""

from __future__ import annotations

import math

from wire_fmu.core.components.sheave_geometry.circles import (
    _PARALLEL_TOL,
    _POS_TOL,
    PathNode,
    Vec3,
    _cross,
    _dot,
    _norm,
    _pair,
    _sub,
)

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
