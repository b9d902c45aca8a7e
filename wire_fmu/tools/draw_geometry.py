"""From a reeving to drawing primitives, with the core's own geometry (no tangent re-derived).

See :mod:`wire_fmu.tools.draw` for the view (the drawing plane, up on the
page) and what is drawn.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from wire_fmu.core.components.sheave_geometry.circles import Circle, PathNode
from wire_fmu.core.components.sheave_geometry.path import PathGeometry, path_geometry
from wire_fmu.core.components.sheave_geometry.planar_path import planar_frame
from wire_fmu.core.errors import GeometryError
from wire_fmu.core.units.block_train.reeving import Reeving
from wire_fmu.core.units.block_train.reeving_parse import parse_reeving

from .draw_primitives import (
    AnchorMark,
    BodyBox,
    FloorLine,
    LineEndArrow,
    ReevingDrawing,
    RopeArc,
    RopeSpan,
    SheaveShape,
)

__all__ = ["reeving_drawing"]

logger = logging.getLogger(__name__)

_CIRCLE_SAMPLES = 181  # points on a full sheave outline
_ARC_SAMPLES_PER_TURN = 180
_AXIS_NAMES = ("x", "y", "z")


# ------------------------------------------------------------------ projection


@dataclass(frozen=True, eq=False)
class _View:
    """Page basis: ``u`` right, ``v`` up, ``normal`` towards the viewer (u x v = normal)."""

    u: np.ndarray
    v: np.ndarray
    normal: np.ndarray

    def project(self, points: Any) -> np.ndarray:
        """Page coordinates of 3-D points, shape (..., 2), m.

        Parameters
        ----------
        points : array_like, shape (..., 3)
            Points in 3-D, m.
        """
        p = np.asarray(points, dtype=float)
        return np.stack([p @ self.u, p @ self.v], axis=-1)


def _view(normal: Sequence[float], gravity: Sequence[float]) -> _View:
    """Page basis for a plane: seen from its dominant side, up against gravity."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    if n[int(np.argmax(np.abs(n)))] < 0.0:
        n = -n
    candidates = [-np.asarray(gravity, dtype=float), np.eye(3)[1], np.eye(3)[2], np.eye(3)[0]]
    for c in candidates:
        up = c - (c @ n) * n
        if np.linalg.norm(up) > 1e-6 * max(np.linalg.norm(c), 1.0):
            v = up / np.linalg.norm(up)
            return _View(np.cross(v, n), v, n)
    raise AssertionError("unreachable: the three axes cannot all be parallel to a normal")


def _axis_label(axis: np.ndarray) -> str:
    """``"x (m)"`` if the page axis is a coordinate axis, else its 3-D direction."""
    k = int(np.argmax(np.abs(axis)))
    if abs(abs(axis[k]) - 1.0) < 1e-9:
        sign = "" if axis[k] > 0 else "-"
        return f"{sign}{_AXIS_NAMES[k]} (m)"
    return "(" + ", ".join(f"{c + 0.0:.3f}" for c in np.round(axis, 3)) + ") (m)"


def _best_fit_normal(points: np.ndarray) -> np.ndarray:
    """Unit normal of the least-squares plane through points, shape (n, 3)."""
    centred = points - points.mean(axis=0)
    return np.linalg.svd(centred, full_matrices=False)[2][-1]


# --------------------------------------------------------------- geometry


def _path_nodes(r: Reeving) -> list[PathNode]:
    """The core's path nodes at zero body displacement, named as the block train names them."""
    nodes = []
    for node in r.path:
        if node.kind == "sheave":
            s = r.sheaves[node.name]
            nodes.append(PathNode(Circle(s.name, s.centre, s.axis, s.radius), node.sense))
        else:
            point = r.anchors[node.name].point if node.kind == "anchor" else node.point
            circle = Circle(f"{node.kind} {node.name!r}", point, (0.0, 0.0, 1.0), 0.0)
            nodes.append(PathNode(circle, 0))
    return nodes


def _plane_normal(r: Reeving, nodes: list[PathNode], geo: PathGeometry) -> tuple[Any, bool]:
    """Normal of the drawing plane and whether the path is planar."""
    try:
        return planar_frame(nodes, max_fleet_angle=r.max_fleet_angle).normal, True
    except GeometryError as err:  # the path is valid (checked before): it is not planar
        logger.info("reeving is not planar, drawing its best-fit plane: %s", err)
    pts = [n.circle.centre for n in nodes] + [p for seg in geo.points for p in seg]
    pts += [s.centre for s in r.sheaves.values()]
    return _best_fit_normal(np.array(pts, dtype=float)), False


def _circle_points(
    centre: Sequence[float], axis: Sequence[float], radius_vector: np.ndarray, angles: np.ndarray
) -> np.ndarray:
    """Points ``C + R(axis, angle) radius_vector`` for ``radius_vector`` normal to ``axis``, m."""
    a = np.asarray(axis, dtype=float)
    side = np.cross(a, radius_vector)
    return (
        np.asarray(centre, dtype=float)
        + np.outer(np.cos(angles), radius_vector)
        + np.outer(np.sin(angles), side)
    )


def _sheave_outline(centre: Sequence[float], axis: Sequence[float], radius: float) -> np.ndarray:
    """Closed 3-D outline of a sheave's working circle, shape (n, 3), m."""
    a = np.asarray(axis, dtype=float)
    e = np.eye(3)[int(np.argmin(np.abs(a)))]
    radial = np.cross(a, e)
    radial *= radius / np.linalg.norm(radial)
    return _circle_points(centre, a, radial, np.linspace(0.0, 2.0 * math.pi, _CIRCLE_SAMPLES))


def _arc(node: PathNode, p_in: np.ndarray, wrap_angle: float) -> np.ndarray:
    """3-D rope arc on a sheave from the incoming tangent point, in the node's sense, m."""
    c = node.circle
    n = max(8, int(math.ceil(wrap_angle / (2.0 * math.pi) * _ARC_SAMPLES_PER_TURN)))
    angles = node.sense * np.linspace(0.0, wrap_angle, n + 1)
    return _circle_points(c.centre, c.axis, p_in - np.asarray(c.centre), angles)


def _unit(vector: np.ndarray, fallback: Sequence[float] = (0.0, -1.0)) -> np.ndarray:
    """``vector`` normalised, or ``fallback`` if it is (nearly) zero."""
    norm = float(np.linalg.norm(vector))
    return vector / norm if norm > 1e-12 else np.asarray(fallback, dtype=float)


# ------------------------------------------------------------------ builders


def _sheave_shapes(r: Reeving, view: _View) -> tuple[SheaveShape, ...]:
    reeved = {e.name for e in r.path if e.kind == "sheave"}
    return tuple(
        SheaveShape(
            s.name,
            s.body,
            view.project(s.centre),
            s.radius,
            view.project(_sheave_outline(s.centre, s.axis, s.radius)),
            s.name in reeved,
        )
        for s in r.sheaves.values()
    )


def _rope(r: Reeving, nodes: list[PathNode], geo: PathGeometry, view: _View):
    """Spans and arcs of the rope."""
    spans = tuple(
        RopeSpan(k, view.project(a), view.project(b)) for k, (a, b) in enumerate(geo.points)
    )
    arcs = []
    for j in range(1, len(nodes) - 1):
        wrap_angle = float(geo.wrap_angles[j - 1])
        points = _arc(nodes[j], np.asarray(geo.points[j - 1][1]), wrap_angle)
        wrap = "ccw" if r.path[j].sense > 0 else "cw"
        arcs.append(RopeArc(r.path[j].name, wrap, wrap_angle, view.project(points)))
    return spans, tuple(arcs)


def _anchors(r: Reeving, view: _View) -> tuple[AnchorMark, ...]:
    used = {e.name for e in r.path if e.kind == "anchor"}
    return tuple(
        AnchorMark(a.name, a.body, view.project(a.point), a.name in used)
        for a in r.anchors.values()
    )


def _line_ends(r: Reeving, geo: PathGeometry, view: _View) -> tuple[LineEndArrow, ...]:
    ends = []
    last = len(r.path) - 1
    for k, outward in ((0, -geo.directions[0]), (last, geo.directions[-1])):
        node = r.path[k]
        if node.kind == "line_end":
            direction = _unit(view.project(outward))
            ends.append(LineEndArrow(node.name, node.body, view.project(node.point), direction))
    return tuple(ends)


def _body_parts(drawing_parts: dict[str, list[np.ndarray]], body: str) -> np.ndarray | None:
    parts = drawing_parts.get(body)
    return np.vstack(parts) if parts else None


def _parts_by_body(sheaves, anchors, line_ends) -> dict[str, list[np.ndarray]]:
    """Points of everything each body carries, m."""
    parts: dict[str, list[np.ndarray]] = {}
    for s in sheaves:
        parts.setdefault(s.body, []).append(s.outline)
    for a in anchors:
        parts.setdefault(a.body, []).append(a.point[None, :])
    for e in line_ends:
        parts.setdefault(e.body, []).append(e.point[None, :])
    return parts


def _body_label(body) -> str:
    """Two lines: the name; kind, mass (block) and port."""
    parts = [body.kind]
    if body.kind == "block":
        parts.append(f"{body.mass / 1000.0:g} t" if body.mass >= 1000.0 else f"{body.mass:g} kg")
    if body.port:
        parts.append(f"port {body.port}")
    return f"{body.name}\n{', '.join(parts)}"


def _bodies(r: Reeving, parts: dict[str, list[np.ndarray]], view: _View, pad: float):
    boxes = []
    for body in r.bodies.values():
        pts = _body_parts(parts, body.name)
        if body.kind == "ground" or pts is None:
            continue
        direction = view.project(body.direction)
        label = _body_label(body)
        if np.linalg.norm(direction) < 1e-6:
            label += ", moves across the page"
        boxes.append(
            BodyBox(
                body.name, body.kind, label, pts.min(axis=0) - pad, pts.max(axis=0) + pad, direction
            )
        )
    return tuple(boxes)


def _floor(body, pts: np.ndarray, view: _View, pad: float) -> FloorLine | None:
    """The floor line of a block carrying ``pts`` (m), or None if it moves across the page."""
    d = view.project(body.direction)
    if np.linalg.norm(d) < 1e-6:
        logger.info("floor of %r not drawn: the block moves across the drawing plane", body.name)
        return None
    d = d / np.linalg.norm(d)
    across = np.array([-d[1], d[0]])
    travel = body.floor.position - body.position
    base = pts[np.argmin(pts @ d)] + travel * d
    along = pts @ across
    lo, hi = along.min() - 2.0 * pad, along.max() + 2.0 * pad
    shift = base - (base @ across) * across
    return FloorLine(body.name, shift + lo * across, shift + hi * across, -d, travel)


def _floors(r: Reeving, parts: dict[str, list[np.ndarray]], view: _View, pad: float):
    floors = []
    for body in r.bodies.values():
        pts = _body_parts(parts, body.name)
        if body.kind == "block" and body.floor is not None and pts is not None:
            line = _floor(body, pts, view, pad)
            if line is not None:
                floors.append(line)
    return tuple(floors)


def _title(r: Reeving, planar: bool, normal: np.ndarray) -> str:
    name = str(r.source.get("name", "reeving"))
    if planar:
        return name
    n = ", ".join(f"{c:.3f}" for c in normal)
    return f"{name}\nnot planar: projected onto its best-fit plane (normal ({n}))"


def reeving_drawing(reeving: Mapping[str, Any]) -> ReevingDrawing:
    """Drawing primitives of a reeving, from the core's geometry.

    Parameters
    ----------
    reeving : mapping
        JSON-compatible reeving description (see :mod:`wire_fmu.core.units.block_train.reeving`).

    Returns
    -------
    ReevingDrawing
        Sheaves, rope spans (between the core's tangent points), wrapped
        arcs, anchors, line ends, body boxes and floors, in page coordinates
        (m); see the module docstring for the view.

    Raises
    ------
    ConfigurationError
        From :func:`~wire_fmu.core.units.block_train.reeving_parse.parse_reeving` (every problem of
        the description) or :func:`~wire_fmu.core.components.sheave_geometry.path.path_geometry`
        (a :class:`~wire_fmu.core.errors.GeometryError` with every geometric
        problem).
    """
    r = parse_reeving(reeving)
    nodes = _path_nodes(r)
    geo = path_geometry(nodes, max_fleet_angle=r.max_fleet_angle)
    normal, planar = _plane_normal(r, nodes, geo)
    view = _view(normal, r.gravity)
    sheaves = _sheave_shapes(r, view)
    spans, arcs = _rope(r, nodes, geo, view)
    anchors = _anchors(r, view)
    line_ends = _line_ends(r, geo, view)
    parts = _parts_by_body(sheaves, anchors, line_ends)
    radii = [s.radius for s in sheaves]
    pad = 0.5 * max(radii) if radii else 0.02 * max(float(np.sum(geo.lengths)), 1.0)
    return ReevingDrawing(
        title=_title(r, planar, view.normal),
        planar=planar,
        normal=view.normal,
        u=view.u,
        v=view.v,
        axis_labels=(_axis_label(view.u), _axis_label(view.v)),
        sheaves=sheaves,
        spans=spans,
        arcs=arcs,
        anchors=anchors,
        line_ends=line_ends,
        bodies=_bodies(r, parts, view, pad),
        floors=_floors(r, parts, view, pad),
    )
