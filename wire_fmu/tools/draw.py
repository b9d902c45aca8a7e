"""Draw a block train's reeving to a PNG, so a user can see the geometry is what they meant.

:func:`draw_reeving` is what ``wire-fmu draw SCENE`` calls. It works in two
steps: :func:`reeving_drawing` turns a reeving description into drawing
primitives (pure data: sheave outlines, rope spans and wrapped arcs, anchors,
line ends, body boxes, floors, in 2-D plane coordinates, m) using the core's
own geometry (:func:`~wire_fmu.core.units.block_train.reeving.parse_reeving`,
:func:`~wire_fmu.core.components.sheave_geometry.path_geometry`,
:func:`~wire_fmu.core.components.sheave_geometry.planar_frame`) -- no tangent is re-derived
here -- and a renderer draws those with matplotlib's Agg canvas on a
:class:`~matplotlib.figure.Figure` object (no pyplot, no global rcParams).

The view
--------
The drawing plane is the rope path's plane (from
:func:`~wire_fmu.core.components.sheave_geometry.planar_frame`); a non-planar reeving is
projected onto its best-fit plane (least squares through the sheave centres,
points and tangent points) and the title says so. The plane is seen from the
side its normal's largest component points to (a reeving in the x-y plane is
seen from +z), "up" on the page is opposite to gravity where gravity has a
component in the plane, and the page coordinates are the 3-D coordinates
projected on the page axes (so for the x-y plane they are x and y, m).

What is drawn
-------------
* sheaves: working circles (grey), labelled with their name; a sheave that
  the path does not use is dashed and labelled "(not reeved)";
* rope: straight spans between the core's tangent points and the wrapped arc
  on each sheave, in one rope colour; an arrowhead at each span's middle
  shows the direction the path is written in (node 0 to the last node);
* anchors: triangles, labelled (hollow if no path end uses them);
* line ends: arrows pointing where the rope continues (to a winch, say),
  labelled with the port name;
* bodies that move: a dashed box round their sheaves, anchors and line ends,
  labelled with name, kind, mass and port, with an arrow along the body's
  direction of motion (+ direction);
* a block's floor: a hatched line across the block's travel, where the
  lowest drawn point of the block is when it lands (``floor.position -
  position`` of travel along its direction).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wire_fmu.core.components.sheave_geometry import (
    Circle,
    PathGeometry,
    PathNode,
    path_geometry,
    planar_frame,
)
from wire_fmu.core.errors import GeometryError
from wire_fmu.core.units.block_train.reeving import Reeving, parse_reeving

__all__ = [
    "SheaveShape",
    "RopeSpan",
    "RopeArc",
    "AnchorMark",
    "LineEndArrow",
    "BodyBox",
    "FloorLine",
    "ReevingDrawing",
    "reeving_drawing",
    "draw_reeving",
]

logger = logging.getLogger(__name__)

_ROPE_COLOUR = "#c0392b"
_SHEAVE_EDGE = "#4d4d4d"
_SHEAVE_FILL = "#e6e6e6"
_BODY_COLOUR = "#1f5fa8"
_FLOOR_COLOUR = "#5b4636"
_DPI = 110
_CIRCLE_SAMPLES = 181  # points on a full sheave outline
_ARC_SAMPLES_PER_TURN = 180
_ARROW_FRACTION = 0.07  # line-end and direction arrows, fraction of the drawing's size
_AXIS_NAMES = ("x", "y", "z")


# ------------------------------------------------------------------ primitives


@dataclass(frozen=True, eq=False)
class SheaveShape:
    """A sheave's working circle in the drawing plane.

    Attributes
    ----------
    name, body : str
        Sheave and body names.
    centre : ndarray, shape (2,)
        Centre in plane coordinates, m.
    radius : float
        Working radius, m.
    outline : ndarray, shape (n, 2)
        Closed outline (a projected circle; an ellipse if the sheave is tilted
        to the drawing plane), m.
    reeved : bool
        Whether the rope path goes over it.
    """

    name: str
    body: str
    centre: np.ndarray
    radius: float
    outline: np.ndarray
    reeved: bool


@dataclass(frozen=True, eq=False)
class RopeSpan:
    """A straight rope segment between two tangent points.

    Attributes
    ----------
    index : int
        Segment number along the path (segment ``k`` joins node ``k`` to node ``k + 1``).
    start, end : ndarray, shape (2,)
        Where the rope leaves node ``k`` and touches node ``k + 1``, m.
    """

    index: int
    start: np.ndarray
    end: np.ndarray


@dataclass(frozen=True, eq=False)
class RopeArc:
    """The rope wrapped on a sheave, from the incoming to the outgoing tangent point.

    Attributes
    ----------
    sheave : str
        Sheave name.
    wrap : str
        ``"ccw"`` or ``"cw"`` as written in the reeving (about the sheave's axis).
    wrap_angle : float
        Wrap angle from the core, rad.
    points : ndarray, shape (n, 2)
        The arc, from the incoming tangent point to the outgoing one, m.
    """

    sheave: str
    wrap: str
    wrap_angle: float
    points: np.ndarray


@dataclass(frozen=True, eq=False)
class AnchorMark:
    """An anchor (rope end clamped to a body).

    Attributes
    ----------
    name, body : str
        Anchor and body names.
    point : ndarray, shape (2,)
        Position, m.
    used : bool
        Whether a path end is this anchor.
    """

    name: str
    body: str
    point: np.ndarray
    used: bool


@dataclass(frozen=True, eq=False)
class LineEndArrow:
    """A line end: the rope continues through port ``port``.

    Attributes
    ----------
    port, body : str
        Port name (``line_a``/``line_b``) and body name.
    point : ndarray, shape (2,)
        The path's end point, m.
    direction : ndarray, shape (2,)
        Unit vector along which the rope leaves the path there.
    """

    port: str
    body: str
    point: np.ndarray
    direction: np.ndarray


@dataclass(frozen=True, eq=False)
class BodyBox:
    """A moving body, drawn as a dashed box round what it carries.

    Attributes
    ----------
    name, kind : str
        Body name and kind (``block`` or ``driven``).
    label : str
        Name, kind, mass and port.
    lower, upper : ndarray, shape (2,)
        Box corners, m.
    direction : ndarray, shape (2,)
        Direction of motion projected on the plane (zero if the body moves
        across the plane).
    """

    name: str
    kind: str
    label: str
    lower: np.ndarray
    upper: np.ndarray
    direction: np.ndarray


@dataclass(frozen=True, eq=False)
class FloorLine:
    """A block's floor.

    Attributes
    ----------
    body : str
        Block name.
    start, end : ndarray, shape (2,)
        The floor line, m.
    below : ndarray, shape (2,)
        Unit vector towards the floor's solid side (against the block's
        direction), for the hatching.
    travel : float
        Block travel to contact, m (negative: the block moves against its direction).
    """

    body: str
    start: np.ndarray
    end: np.ndarray
    below: np.ndarray
    travel: float


@dataclass(frozen=True, eq=False)
class ReevingDrawing:
    """Everything :func:`draw_reeving` draws, in plane coordinates (m).

    Attributes
    ----------
    title : str
        Default title (reeving name; says so if the reeving is not planar).
    planar : bool
        False if the reeving was projected onto its best-fit plane.
    normal : ndarray, shape (3,)
        Unit normal of the drawing plane, pointing at the viewer.
    u, v : ndarray, shape (3,)
        Page axes (right, up) in 3-D.
    axis_labels : tuple of str
        Labels of the page axes.
    sheaves, spans, arcs, anchors, line_ends, bodies, floors : tuple
        The primitives.
    """

    title: str
    planar: bool
    normal: np.ndarray
    u: np.ndarray
    v: np.ndarray
    axis_labels: tuple[str, str]
    sheaves: tuple[SheaveShape, ...]
    spans: tuple[RopeSpan, ...]
    arcs: tuple[RopeArc, ...]
    anchors: tuple[AnchorMark, ...]
    line_ends: tuple[LineEndArrow, ...]
    bodies: tuple[BodyBox, ...]
    floors: tuple[FloorLine, ...]

    def extent(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower-left and upper-right corners of everything drawn, m."""
        pts = [s.outline for s in self.sheaves] + [a.points for a in self.arcs]
        pts += [np.array([s.start, s.end]) for s in self.spans]
        pts += [np.array([f.start, f.end]) for f in self.floors]
        pts += [np.array([b.lower, b.upper]) for b in self.bodies]
        pts += [a.point[None, :] for a in self.anchors] + [e.point[None, :] for e in self.line_ends]
        allp = np.vstack(pts)
        return allp.min(axis=0), allp.max(axis=0)


# ------------------------------------------------------------------ projection


@dataclass(frozen=True, eq=False)
class _View:
    """Page basis: ``u`` right, ``v`` up, ``normal`` towards the viewer (u x v = normal)."""

    u: np.ndarray
    v: np.ndarray
    normal: np.ndarray

    def project(self, points: Any) -> np.ndarray:
        """Page coordinates of 3-D points, shape (..., 2), m."""
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
        From :func:`~wire_fmu.core.units.block_train.reeving.parse_reeving` (every problem of
        the description) or :func:`~wire_fmu.core.components.sheave_geometry.path_geometry`
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


# ------------------------------------------------------------------ rendering


def _figure_size(lower: np.ndarray, upper: np.ndarray) -> tuple[float, float]:
    """Figure size (in) following the drawing's aspect, long side 9 in."""
    width, height = np.maximum(upper - lower, 1e-3)
    aspect = float(height / width)
    if aspect >= 1.0:
        return float(np.clip(9.0 / aspect + 2.0, 6.0, 9.0)), 9.0
    return 10.0, float(np.clip(10.0 * aspect + 2.0, 5.0, 9.0))


_LABEL_BOX = {
    "boxstyle": "square,pad=0.1",
    "facecolor": "white",
    "alpha": 0.75,
    "edgecolor": "none",
}


def _radial_text(direction: np.ndarray) -> tuple[float, str]:
    """Rotation (deg) and horizontal alignment for text running outwards along ``direction``."""
    angle = math.degrees(math.atan2(direction[1], direction[0]))
    if -90.0 < angle <= 90.0:
        return angle, "left"
    return (angle + 180.0 + 180.0) % 360.0 - 180.0, "right"


def _draw_sheaves(ax, drawing: ReevingDrawing, arcs_mid: dict[str, np.ndarray]) -> None:
    """Sheave outlines, centres, and names running outwards opposite the wrapped rope."""
    for s in drawing.sheaves:
        style = "-" if s.reeved else "--"
        ax.fill(
            s.outline[:, 0],
            s.outline[:, 1],
            facecolor=_SHEAVE_FILL,
            edgecolor=_SHEAVE_EDGE,
            linewidth=1.0,
            linestyle=style,
            zorder=2,
        )
        ax.plot(*s.centre, marker="+", color=_SHEAVE_EDGE, markersize=4, zorder=3)
        away = _unit(s.centre - arcs_mid[s.name]) if s.name in arcs_mid else np.array([0.0, -1.0])
        rotation, ha = _radial_text(away)
        text = s.name if s.reeved else f"{s.name} (not reeved)"
        ax.annotate(
            text,
            s.centre + away * s.radius * 1.15,
            rotation=rotation,
            rotation_mode="anchor",
            ha=ha,
            va="center",
            fontsize=7,
            color=_SHEAVE_EDGE,
            bbox=_LABEL_BOX,
            zorder=6,
        )


def _h_align(x: float) -> str:
    return "left" if x > 0.3 else "right" if x < -0.3 else "center"


def _v_align(y: float) -> str:
    return "bottom" if y > 0.3 else "top" if y < -0.3 else "center"


def _draw_rope(ax, drawing: ReevingDrawing, arrow: float) -> None:
    """Straight spans with a path-direction arrowhead at each middle, and wrapped arcs."""
    for span in drawing.spans:
        xs, ys = np.array([span.start, span.end]).T
        ax.plot(xs, ys, color=_ROPE_COLOUR, linewidth=1.8, solid_capstyle="round", zorder=4)
        mid, d = 0.5 * (span.start + span.end), _unit(span.end - span.start)
        ax.annotate(
            "",
            xy=mid + 0.25 * arrow * d,
            xytext=mid - 0.25 * arrow * d,
            zorder=5,
            arrowprops={"arrowstyle": "-|>", "color": _ROPE_COLOUR, "lw": 0, "mutation_scale": 12},
        )
    for arc in drawing.arcs:
        ax.plot(
            arc.points[:, 0],
            arc.points[:, 1],
            color=_ROPE_COLOUR,
            linewidth=2.6,
            solid_capstyle="round",
            zorder=4,
        )


def _draw_ends(ax, drawing: ReevingDrawing, arrow: float) -> None:
    """Anchors as triangles, line ends as labelled arrows."""
    for a in drawing.anchors:
        face = "black" if a.used else "white"
        ax.plot(
            *a.point,
            marker="^",
            markersize=11,
            markerfacecolor=face,
            markeredgecolor="black",
            zorder=7,
        )
        label = a.name if a.used else f"{a.name} (unused)"
        ax.annotate(
            label,
            a.point,
            xytext=(7, -10),
            textcoords="offset points",
            fontsize=8,
            bbox=_LABEL_BOX,
            zorder=7,
        )
    for e in drawing.line_ends:
        tip = e.point + arrow * e.direction
        ax.annotate(
            "",
            xy=tip,
            xytext=e.point,
            zorder=7,
            arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.4},
        )
        ax.plot(*e.point, marker="o", markersize=5, color="black", zorder=7)
        ax.annotate(
            e.port,
            tip,
            xytext=(4 * e.direction[0], 4 * e.direction[1]),
            textcoords="offset points",
            ha=_h_align(e.direction[0]),
            va=_v_align(e.direction[1]),
            fontsize=9,
            fontweight="bold",
            zorder=7,
        )


def _draw_bodies(ax, drawing: ReevingDrawing) -> None:
    """Dashed boxes, labels under them, a direction-of-motion arrow after each label."""
    from matplotlib.patches import Rectangle
    from matplotlib.text import OffsetFrom

    for b in drawing.bodies:
        size = b.upper - b.lower
        ax.add_patch(
            Rectangle(
                tuple(b.lower),
                size[0],
                size[1],
                fill=False,
                linestyle="--",
                edgecolor=_BODY_COLOUR,
                linewidth=1.2,
                zorder=1,
            )
        )
        label = ax.annotate(
            b.label,
            (b.lower[0], b.lower[1]),
            xytext=(0, -3),
            textcoords="offset points",
            fontsize=8,
            color=_BODY_COLOUR,
            va="top",
            bbox=_LABEL_BOX,
            zorder=6,
        )
        if np.linalg.norm(b.direction) > 1e-6:
            d = _unit(b.direction)  # equal aspect: the same direction on screen
            centre = np.array([16.0, 0.0])  # points right of the label's right edge
            anchor = OffsetFrom(label, (1.0, 0.5), unit="points")
            ax.annotate(
                "",
                xy=tuple(centre + 9.0 * d),
                xycoords=anchor,
                xytext=tuple(centre - 9.0 * d),
                textcoords=anchor,
                zorder=6,
                arrowprops={"arrowstyle": "-|>", "color": _BODY_COLOUR, "lw": 1.6},
            )


def _draw_floors(ax, drawing: ReevingDrawing, arrow: float) -> None:
    """Floors as hatched lines, labelled with the travel to contact."""
    for f in drawing.floors:
        xs, ys = np.array([f.start, f.end]).T
        ax.plot(xs, ys, color=_FLOOR_COLOUR, linewidth=2.0, zorder=3)
        along = f.end - f.start
        tick = 0.18 * arrow * _unit(f.below - 0.8 * _unit(along))
        for s in np.linspace(0.0, 1.0, 16):
            p = f.start + s * along
            ax.plot(
                [p[0], p[0] + tick[0]],
                [p[1], p[1] + tick[1]],
                color=_FLOOR_COLOUR,
                linewidth=0.8,
                zorder=3,
            )
        ax.annotate(
            f"floor of {f.body}\ncontact after {f.travel:+.2f} m travel",
            0.5 * (f.start + f.end),
            xytext=(-4.0 * f.below[0], -4.0 * f.below[1]),
            textcoords="offset points",
            ha="center",
            va=_v_align(-f.below[1]),
            fontsize=7,
            color=_FLOOR_COLOUR,
            bbox=_LABEL_BOX,
            zorder=6,
        )


def _legend(fig) -> None:
    from matplotlib.lines import Line2D

    handles = [
        Line2D(
            [], [], color=_ROPE_COLOUR, linewidth=2, marker=">", label="rope (arrow: path order)"
        ),
        Line2D(
            [],
            [],
            color=_SHEAVE_EDGE,
            marker="o",
            markerfacecolor=_SHEAVE_FILL,
            linestyle="",
            markersize=9,
            label="sheave",
        ),
        Line2D([], [], color="black", marker="^", linestyle="", markersize=9, label="anchor"),
        Line2D(
            [],
            [],
            color="black",
            marker=r"$\rightarrow$",
            linestyle="",
            markersize=12,
            label="line end",
        ),
        Line2D([], [], color=_BODY_COLOUR, linestyle="--", label="moving body"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=8, frameon=False)


def _fit_limits(fig, ax, lower: np.ndarray, upper: np.ndarray) -> None:
    """Limits that show the drawing and every label, with equal aspect filling the axes."""
    ax.update_datalim([tuple(lower), tuple(upper)])
    ax.autoscale_view()
    for _ in range(4):  # text sizes in data units change with the limits
        fig.draw_without_rendering()
        to_data = ax.transData.inverted()
        renderer = fig.canvas.get_renderer()
        for text in ax.texts:
            if text.get_text():
                ax.update_datalim(to_data.transform(text.get_window_extent().padded(6.0)))
            arrow = getattr(text, "arrow_patch", None)
            if arrow is not None:
                ax.update_datalim(to_data.transform(arrow.get_window_extent(renderer).padded(4.0)))
        ax.autoscale_view()


def _render(drawing: ReevingDrawing, path: Path, title: str) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    lower, upper = drawing.extent()
    arrow = _ARROW_FRACTION * float(np.max(upper - lower))
    fig = Figure(figsize=_figure_size(lower, upper), dpi=_DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    arcs_mid = {a.sheave: a.points[len(a.points) // 2] for a in drawing.arcs}
    _draw_sheaves(ax, drawing, arcs_mid)
    _draw_rope(ax, drawing, arrow)
    _draw_ends(ax, drawing, arrow)
    _draw_bodies(ax, drawing)
    _draw_floors(ax, drawing, arrow)
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.0)
    ax.set_xlabel(drawing.axis_labels[0])
    ax.set_ylabel(drawing.axis_labels[1])
    ax.grid(True, linewidth=0.4, alpha=0.4)
    ax.set_title(title or drawing.title, fontsize=10)
    _legend(fig)
    fig.tight_layout(rect=(0.0, 0.04, 1.0, 1.0))
    _fit_limits(fig, ax, lower - 1.3 * arrow, upper + 1.3 * arrow)
    fig.savefig(path, dpi=_DPI)


def draw_reeving(reeving: Mapping[str, Any], path: Path, *, title: str = "") -> Path:
    """Render a reeving to a PNG file.

    Parameters
    ----------
    reeving : mapping
        JSON-compatible reeving description (see :mod:`wire_fmu.core.units.block_train.reeving`).
    path : Path
        PNG file to write (its folder must exist).
    title : str, optional
        Figure title; default the reeving's ``name`` (plus a note if the
        reeving is not planar and was projected).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ConfigurationError
        If the reeving is invalid (lists every problem).
    """
    drawing = reeving_drawing(reeving)
    if title and not drawing.planar:
        title = f"{title}\n{drawing.title.splitlines()[-1]}"
    path = Path(path)
    _render(drawing, path, title)
    logger.info("drew reeving %r to %s", title or drawing.title, path)
    return path
