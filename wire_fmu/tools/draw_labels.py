"""Labels of a reeving drawing placed where they overprint neither each other nor the drawing.

A label (a body's name and port, a floor's travel to contact, an anchor's
name) is an annotation offset in points from the point it names. Its
position is chosen among a few candidate offsets around that point: the
first with no overlap with a label already placed and the fewest points of
the drawing (rope, sheave outlines, body boxes, other labels' arrows) under
it. Labels that are not moved (sheave names, line-end ports) are placed
first and count as placed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .draw_primitives import ReevingDrawing

__all__ = ["Label", "place_labels", "drawing_points", "around", "around_box", "along_line"]

_TEXT_OVERLAP = 1000.0
"""Cost of overlapping a placed label, in drawing points covered (never chosen if avoidable)."""


@dataclass
class Label:
    """A movable label.

    Attributes
    ----------
    text : matplotlib.text.Annotation
        The annotation (``textcoords="offset points"``).
    candidates : sequence of (xy, dx, dy, ha, va)
        Points named (data coordinates; None keeps the annotation's), offsets
        from them (points) and alignments to try, the preferred first.
    extra : float
        Points of room the label needs to its right beyond its text (an arrow
        drawn after it).
    """

    text: object
    candidates: Sequence[tuple[tuple[float, float] | None, float, float, str, str]]
    extra: float = 0.0


def drawing_points(drawing: ReevingDrawing) -> np.ndarray:
    """Points along everything drawn (rope, sheaves, body boxes, floors), plane coordinates (m).

    Parameters
    ----------
    drawing : ReevingDrawing
        The drawing's primitives.

    Returns
    -------
    ndarray, shape (n, 2)
        Points about 1/400 of the drawing's size apart.
    """
    lower, upper = drawing.extent()
    step = float(np.max(upper - lower)) / 400.0 or 1e-3
    parts = [_along(s.start, s.end, step) for s in drawing.spans]
    parts += [a.points for a in drawing.arcs]
    parts += [s.outline for s in drawing.sheaves]
    for b in drawing.bodies:
        corners = [b.lower, (b.upper[0], b.lower[1]), b.upper, (b.lower[0], b.upper[1]), b.lower]
        corners = [np.asarray(c, float) for c in corners]
        parts += [_along(a, c, step) for a, c in zip(corners[:-1], corners[1:], strict=True)]
    parts += [_along(f.start, f.end, step) for f in drawing.floors]
    parts += [e.point[None, :] for e in drawing.line_ends]
    return np.vstack(parts) if parts else np.zeros((0, 2))


def _along(a: np.ndarray, b: np.ndarray, step: float) -> np.ndarray:
    n = max(2, int(np.linalg.norm(np.asarray(b) - np.asarray(a)) / step) + 1)
    return np.linspace(np.asarray(a, float), np.asarray(b, float), n)


def place_labels(fig, ax, labels: Sequence[Label], fixed: Sequence[object], points) -> None:
    """Move each label to its best candidate offset (see the module docstring).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (with a canvas).
    ax : matplotlib.axes.Axes
        The drawing's axes, limits already set.
    labels : sequence of Label
        The labels to place, in order of importance.
    fixed : sequence of matplotlib.text.Text
        Labels that stay where they are.
    points : ndarray, shape (n, 2)
        Points of the drawing in data coordinates (:func:`drawing_points`).
    """
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    screen = ax.transData.transform(points) if len(points) else np.zeros((0, 2))
    placed = [t.get_window_extent(renderer) for t in fixed if t.get_text()]
    arrows = [_arrow_box(t, renderer) for t in fixed]
    placed += [a for a in arrows if a is not None]
    for label in labels:
        best, best_cost = None, np.inf
        for candidate in label.candidates:
            box = _try(label, candidate, renderer)
            cost = _cost(box, placed, screen)
            if cost < best_cost:
                best, best_cost = candidate, cost
            if cost == 0.0:
                break
        _try(label, best, renderer)
        placed.append(_box(label, renderer))


def _try(label: Label, candidate, renderer):
    xy, dx, dy, ha, va = candidate
    text = label.text
    if xy is not None:
        text.xy = tuple(xy)
    text.xyann = (dx, dy)
    text.set_ha(ha)
    text.set_va(va)
    return _box(label, renderer)


def _box(label: Label, renderer):
    from matplotlib.transforms import Bbox

    box = label.text.get_window_extent(renderer)
    points_to_pixels = renderer.points_to_pixels(1.0)
    return Bbox.from_extents(
        box.x0 - 2.0,
        box.y0 - 2.0,
        box.x1 + 2.0 + label.extra * points_to_pixels,
        box.y1 + 2.0,
    )


def _arrow_box(text, renderer):
    arrow = getattr(text, "arrow_patch", None)
    return None if arrow is None else arrow.get_window_extent(renderer)


def _cost(box, placed, screen: np.ndarray) -> float:
    overlaps = sum(box.overlaps(other) for other in placed)
    inside = (
        (screen[:, 0] >= box.x0)
        & (screen[:, 0] <= box.x1)
        & (screen[:, 1] >= box.y0)
        & (screen[:, 1] <= box.y1)
    )
    return _TEXT_OVERLAP * overlaps + float(np.count_nonzero(inside))


def around(gap: float = 4.0) -> list[tuple[None, float, float, str, str]]:
    """Candidate offsets around a point, the first below-right.

    Parameters
    ----------
    gap : float
        Distance from the point, points.
    """
    return [
        (None, gap, -gap, "left", "top"),
        (None, -gap, -gap, "right", "top"),
        (None, gap, gap, "left", "bottom"),
        (None, -gap, gap, "right", "bottom"),
        (None, 3 * gap, 0.0, "left", "center"),
        (None, -3 * gap, 0.0, "right", "center"),
        (None, 0.0, -3 * gap, "center", "top"),
        (None, 0.0, 3 * gap, "center", "bottom"),
    ]


def around_box(lower: np.ndarray, upper: np.ndarray, gap: float = 3.0) -> list[tuple]:
    """Candidate places for a box's label: under it, over it, beside it; left edge first.

    Parameters
    ----------
    lower, upper : ndarray, shape (2,)
        Corners of the box, data coordinates.
    gap : float
        Distance from the box, points.
    """
    (x0, y0), (x1, y1) = lower, upper
    middle = 0.5 * (y0 + y1)
    return [
        ((x0, y0), 0.0, -gap, "left", "top"),
        ((x0, y1), 0.0, gap, "left", "bottom"),
        ((x1, y0), 0.0, -gap, "right", "top"),
        ((x1, y1), 0.0, gap, "right", "bottom"),
        ((x1, middle), gap, 0.0, "left", "center"),
        ((x0, middle), -gap, 0.0, "right", "center"),
        ((x0, y0), 0.0, -6 * gap, "left", "top"),
        ((x1, y0), 0.0, -6 * gap, "right", "top"),
    ]


def along_line(start: np.ndarray, end: np.ndarray, side: np.ndarray, gap: float = 4.0) -> list:
    """Candidate places for a line's label: its middle, then its ends, on ``side`` then across.

    Parameters
    ----------
    start, end : ndarray, shape (2,)
        The line, data coordinates.
    side : ndarray, shape (2,)
        Unit vector to the preferred side of the line.
    gap : float
        Distance from the line, points.
    """
    places = []
    for sign in (1.0, -1.0):
        dx, dy = sign * gap * side[0], sign * gap * side[1]
        va = "bottom" if sign * side[1] > 0.3 else "top" if sign * side[1] < -0.3 else "center"
        places += [
            (tuple(0.5 * (start + end)), dx, dy, "center", va),
            (tuple(start), dx, dy, "left", va),
            (tuple(end), dx, dy, "right", va),
        ]
    return places
