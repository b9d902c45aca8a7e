"""Draw a block train's reeving to a PNG, so a user can see the geometry is what they meant.

:func:`draw_reeving` is what ``wire-fmu draw SCENE`` calls. It works in two
steps: :func:`~wire_fmu.tools.draw_geometry.reeving_drawing` turns a reeving
description into drawing primitives (:mod:`~wire_fmu.tools.draw_primitives`,
pure data: sheave outlines, rope spans and wrapped arcs, anchors, line ends,
body boxes, floors, in 2-D plane coordinates, m) using the core's own
geometry (:func:`~wire_fmu.core.units.block_train.reeving_parse.parse_reeving`,
:func:`~wire_fmu.core.components.sheave_geometry.path.path_geometry`,
:func:`~wire_fmu.core.components.sheave_geometry.planar_path.planar_frame`) -- no tangent is
re-derived there -- and a renderer (this module) draws those with matplotlib's Agg canvas on a
:class:`~matplotlib.figure.Figure` object (no pyplot, no global rcParams).

The view
--------
The drawing plane is the rope path's plane (from
:func:`~wire_fmu.core.components.sheave_geometry.planar_path.planar_frame`); a non-planar reeving is
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
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .draw_geometry import _unit, reeving_drawing
from .draw_labels import Label, along_line, around, around_box, drawing_points, place_labels
from .draw_primitives import ReevingDrawing

__all__ = ["draw_reeving"]

logger = logging.getLogger(__name__)

_ROPE_COLOUR = "#c0392b"
_SHEAVE_EDGE = "#4d4d4d"
_SHEAVE_FILL = "#e6e6e6"
_BODY_COLOUR = "#1f5fa8"
_FLOOR_COLOUR = "#5b4636"
_DPI = 110
_ARROW_FRACTION = 0.07  # line-end and direction arrows, fraction of the drawing's size


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


def _draw_sheaves(ax, drawing: ReevingDrawing, arcs_mid: dict[str, np.ndarray]) -> list:
    """Sheave outlines, centres, and names running outwards opposite the wrapped rope."""
    names = []
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
        name = ax.annotate(
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
        names.append(name)
    return names


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


def _draw_ends(ax, drawing: ReevingDrawing, arrow: float) -> tuple[list[Label], list]:
    """Anchors as triangles, line ends as labelled arrows; (movable labels, fixed labels)."""
    movable, fixed = [], []
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
        text = ax.annotate(
            label,
            a.point,
            xytext=(7, -10),
            textcoords="offset points",
            fontsize=8,
            bbox=_LABEL_BOX,
            zorder=7,
        )
        movable.append(Label(text, around(7.0)))
    for e in drawing.line_ends:
        tip = e.point + arrow * e.direction
        arrow_text = ax.annotate(
            "",
            xy=tip,
            xytext=e.point,
            zorder=7,
            arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.4},
        )
        ax.plot(*e.point, marker="o", markersize=5, color="black", zorder=7)
        fixed.append(arrow_text)
        port = ax.annotate(
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
        fixed.append(port)
    return movable, fixed


def _draw_bodies(ax, drawing: ReevingDrawing) -> list[Label]:
    """Dashed boxes, labels by them, a direction-of-motion arrow after each label."""
    from matplotlib.patches import Rectangle
    from matplotlib.text import OffsetFrom

    labels = []
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
        moves = np.linalg.norm(b.direction) > 1e-6
        labels.append(Label(label, around_box(b.lower, b.upper), extra=34.0 if moves else 0.0))
        if moves:
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
    return labels


def _draw_floors(ax, drawing: ReevingDrawing, arrow: float) -> list[Label]:
    """Floors as hatched lines, labelled with the travel to contact."""
    labels = []
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
        text = ax.annotate(
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
        labels.append(Label(text, along_line(f.start, f.end, -_unit(f.below))))
    return labels


def _legend(fig) -> None:
    from matplotlib.lines import Line2D
    from matplotlib.path import Path

    # an arrow drawn as a path: a mathtext marker (r"$\rightarrow$") would build
    # matplotlib's mathtext parser, a third of a second, for this one glyph
    arrow = Path(
        [(-1.0, 0.0), (1.0, 0.0), (0.35, 0.45), (1.0, 0.0), (0.35, -0.45)],
        [Path.MOVETO, Path.LINETO, Path.MOVETO, Path.LINETO, Path.LINETO],
    )

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
            marker=arrow,
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
    limits = None
    for _ in range(4):  # text sizes in data units change with the limits: until they settle
        now = (*ax.get_xlim(), *ax.get_ylim())
        if limits is not None and np.allclose(now, limits, rtol=1e-6, atol=0.0):
            break
        limits = now
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


def _render(drawing: ReevingDrawing, path: Path, title: str):
    """Draw ``drawing`` and save it to ``path``; returns the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    lower, upper = drawing.extent()
    arrow = _ARROW_FRACTION * float(np.max(upper - lower))
    fig = Figure(figsize=_figure_size(lower, upper), dpi=_DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    arcs_mid = {a.sheave: a.points[len(a.points) // 2] for a in drawing.arcs}
    fixed = _draw_sheaves(ax, drawing, arcs_mid)
    _draw_rope(ax, drawing, arrow)
    movable, ends = _draw_ends(ax, drawing, arrow)
    movable = _draw_bodies(ax, drawing) + _draw_floors(ax, drawing, arrow) + movable
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.0)
    ax.set_xlabel(drawing.axis_labels[0])
    ax.set_ylabel(drawing.axis_labels[1])
    ax.grid(True, linewidth=0.4, alpha=0.4)
    ax.set_title(title or drawing.title, fontsize=10)
    _legend(fig)
    fig.tight_layout(rect=(0.0, 0.04, 1.0, 1.0))
    _fit_limits(fig, ax, lower - 1.3 * arrow, upper + 1.3 * arrow)
    points = drawing_points(drawing)
    for _ in range(2):  # placing may widen the limits, which moves the labels a little
        place_labels(fig, ax, movable, fixed + ends, points)
        _fit_limits(fig, ax, lower - 1.3 * arrow, upper + 1.3 * arrow)
    fig.savefig(path, dpi=_DPI)
    return fig


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
