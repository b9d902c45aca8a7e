"""What a reeving drawing holds: its primitives, pure data in plane coordinates (m).

Built by :func:`~wire_fmu.tools.draw_geometry.reeving_drawing`, rendered by
:func:`~wire_fmu.tools.draw.draw_reeving`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "SheaveShape",
    "RopeSpan",
    "RopeArc",
    "AnchorMark",
    "LineEndArrow",
    "BodyBox",
    "FloorLine",
    "ReevingDrawing",
]


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
