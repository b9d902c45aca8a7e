"""A whole rope path: each segment solved, every problem found, lengths and angles.

:func:`path_geometry` solves each segment by the case that fits (point to
point, the closed form of :mod:`~wire_fmu.core.components.sheave_geometry.planar_tangent`,
or the spatial cases of :mod:`~wire_fmu.core.components.sheave_geometry.spatial_tangent`)
and assembles lengths, wrap and fleet angles; :func:`check_path` lists every
problem of a path at once.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wire_fmu.core.components.sheave_geometry.circles import (
    _PARALLEL_TOL,
    _POS_TOL,
    _WHERE,
    DEFAULT_MAX_FLEET_ANGLE,
    Circle,
    PathNode,
    Vec3,
    _cross,
    _dot,
    _fmt,
    _label,
    _norm,
    _NoTangentError,
    _pair,
    _Segment,
    _sub,
    _wrap_2pi,
)
from wire_fmu.core.components.sheave_geometry.planar_tangent import (
    _parallel_problem,
    _parallel_setup,
    _parallel_tangent,
)
from wire_fmu.core.components.sheave_geometry.spatial_tangent import (
    _aligned_tangent,
    _general_segment,
)
from wire_fmu.core.errors import GeometryError

__all__ = ["PathGeometry", "segment_tangent_points", "check_path", "path_geometry"]

_UNIT_TOL = 1e-9  # | |axis| - 1 |


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
    if dist <= _POS_TOL and abs(p.radius - q.radius) <= _POS_TOL:
        # One disc: the same sheave met again along the path (the pairs compare every two
        # nodes, so a node is no overlap of itself), else two sheaves in one place. Sheaves
        # side by side on one shaft are offset along the axis, so never get here.
        if p == q:
            return None
        return (
            f"{_pair(p, q)}: discs coincide in the same plane: same centre {_fmt(p.centre)} m "
            f"and radius {p.radius:.3f} m"
        )
    if dist >= p.radius + q.radius:
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
