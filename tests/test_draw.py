"""The reeving drawing: primitives against the core's geometry, then the PNG.

Lengths in m, angles in rad. The drilling block train lies in the x-y plane
with y up, so its page coordinates are x and y themselves.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import matplotlib
import numpy as np
import pytest

from wire_fmu.core.components.sheave_geometry.circles import Circle, PathNode
from wire_fmu.core.components.sheave_geometry.path import path_geometry
from wire_fmu.core.errors import ConfigurationError, GeometryError
from wire_fmu.core.units.block_train.reevings import drilling_block_train, single_fall
from wire_fmu.tools.draw import draw_reeving
from wire_fmu.tools.draw_geometry import reeving_drawing

from .test_block_train_fmu import tensioner_like

R = 0.762  # m, sheave radius of drilling_block_train
FLOOR = {"position": 2.0, "stiffness": 5e8, "damping": 2e6}


def core_geometry(reeving: dict):
    """Tangent points from the core, with path nodes built straight from the dict."""
    nodes = []
    for node in reeving["path"]:
        if "sheave" in node:
            s = reeving["sheaves"][node["sheave"]]
            sense = 1 if node["wrap"] == "ccw" else -1
            nodes.append(
                PathNode(Circle(node["sheave"], s["centre"], s["axis"], s["radius"]), sense)
            )
        else:
            point = node.get("point") or reeving["anchors"][node["anchor"]]["point"]
            nodes.append(PathNode(Circle(str(node), point, (0, 0, 1), 0.0), 0))
    return path_geometry(nodes)


def png_size(path: Path) -> tuple[int, int]:
    """Width and height of a PNG from its IHDR chunk, px."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


# ---------------------------------------------------------------- primitives


def test_spans_end_at_the_core_tangent_points():
    reeving = drilling_block_train(4)
    drawing = reeving_drawing(reeving)
    geo = core_geometry(reeving)
    assert drawing.planar
    assert np.allclose(drawing.u, [1, 0, 0]) and np.allclose(drawing.v, [0, 1, 0])
    assert drawing.axis_labels == ("x (m)", "y (m)")
    assert len(drawing.spans) == len(geo.points) == 6
    for span, (start, end) in zip(drawing.spans, geo.points, strict=True):
        assert np.allclose(span.start, start[:2], atol=1e-12)
        assert np.allclose(span.end, end[:2], atol=1e-12)
    # by hand: the fast line rises on the left of crown_0, the dead line falls right of crown_2
    assert np.allclose(drawing.spans[0].end, [-R, 45.0])
    assert np.allclose(drawing.spans[-1].start, [4 * 2 * R + R, 45.0])


def test_arcs_wrap_from_tangent_point_to_tangent_point_in_the_written_sense():
    drawing = reeving_drawing(drilling_block_train(4))
    centres = {s.name: s.centre for s in drawing.sheaves}
    assert [a.sheave for a in drawing.arcs] == [
        "crown_0",
        "travel_0",
        "crown_1",
        "travel_1",
        "crown_2",
    ]
    for k, arc in enumerate(drawing.arcs):
        assert np.allclose(arc.points[0], drawing.spans[k].end, atol=1e-12)
        assert np.allclose(arc.points[-1], drawing.spans[k + 1].start, atol=1e-12)
        assert arc.wrap_angle == pytest.approx(math.pi)
        radius = np.linalg.norm(arc.points - centres[arc.sheave], axis=1)
        assert np.allclose(radius, R)
        mid = arc.points[len(arc.points) // 2] - centres[arc.sheave]
        if arc.sheave.startswith("crown"):  # cw: over the top
            assert arc.wrap == "cw" and mid == pytest.approx([0.0, R], abs=0.02)
        else:  # ccw: round the bottom
            assert arc.wrap == "ccw" and mid == pytest.approx([0.0, -R], abs=0.02)


def test_sheaves_anchors_line_ends_bodies_and_floor():
    drawing = reeving_drawing(drilling_block_train(4, floor=FLOOR))
    assert len(drawing.sheaves) == 5 and all(s.reeved for s in drawing.sheaves)
    for s in drawing.sheaves:
        assert np.allclose(np.linalg.norm(s.outline - s.centre, axis=1), s.radius)
    (anchor,) = drawing.anchors
    assert anchor.name == "deadline" and anchor.used and np.allclose(anchor.point, [9 * R, 0])
    (line_end,) = drawing.line_ends
    assert line_end.port == "line_a" and np.allclose(line_end.direction, [0, -1])
    (box,) = drawing.bodies
    assert box.name == "travelling_block" and box.kind == "block"
    assert "120 t" in box.label and "port block_a" in box.label
    assert np.allclose(box.direction, [0, 1])
    travel = [s for s in drawing.sheaves if s.body == "travelling_block"]
    assert len(travel) == 2
    for s in travel:
        assert np.all(s.outline >= box.lower) and np.all(s.outline <= box.upper)
    (floor,) = drawing.floors
    # the block's lowest point (15 - R) lands after 2 - 15 = -13 m of travel
    assert floor.travel == pytest.approx(-13.0)
    assert floor.start[1] == pytest.approx(2.0 - R) and floor.end[1] == pytest.approx(2.0 - R)
    assert np.allclose(floor.below, [0, -1])


def test_tensioner_like_quarter_wrap_and_two_moving_bodies():
    drawing = reeving_drawing(tensioner_like())
    (arc,) = drawing.arcs
    assert arc.wrap == "cw" and arc.wrap_angle == pytest.approx(math.pi / 2)
    assert np.allclose(arc.points[0], [2.0, 5.5]) and np.allclose(arc.points[-1], [2.5, 5.0])
    mid = arc.points[len(arc.points) // 2]
    assert np.allclose(
        mid, [2 + 0.5 * math.cos(math.pi / 4), 5 + 0.5 * math.sin(math.pi / 4)], atol=0.01
    )
    assert np.allclose(drawing.line_ends[0].direction, [-1, 0])
    boxes = {b.name: b for b in drawing.bodies}
    assert set(boxes) == {"rod", "riser"}
    assert boxes["rod"].kind == "driven" and "port mover_a" in boxes["rod"].label
    assert np.allclose(boxes["rod"].direction, [1, 0])
    assert drawing.floors == ()


def test_non_planar_reeving_is_projected_and_says_so():
    reeving = tensioner_like()
    reeving["path"][0]["point"] = [-3.0, 5.5, 0.2]  # 0.2 m out of the sheave's plane
    drawing = reeving_drawing(reeving)
    assert not drawing.planar
    assert "not planar" in drawing.title and "best-fit plane" in drawing.title
    assert abs(drawing.normal[2]) > 0.99


def test_unused_sheaves_and_anchors_are_marked():
    reeving = tensioner_like()
    reeving["sheaves"]["spare"] = {"centre": [-1.0, 3.0, 0.0], "radius": 0.3}
    drawing = reeving_drawing(reeving)
    assert {s.name: s.reeved for s in drawing.sheaves} == {"moving": True, "spare": False}
    anchors = {a.name: a.used for a in reeving_drawing(single_fall()).anchors}
    assert anchors == {"top": False, "hook": True}


def test_invalid_reeving_lists_every_problem():
    reeving = drilling_block_train(4)
    reeving["sheaves"]["crown_1"]["radius"] = -1.0
    reeving["path"][2]["wrap"] = "sideways"
    with pytest.raises(ConfigurationError) as err:
        reeving_drawing(reeving)
    assert len(err.value.problems) == 2
    overlapping = drilling_block_train(4)
    overlapping["sheaves"]["crown_1"]["centre"] = [0.5, 45.0, 0.0]  # overlaps crown_0
    with pytest.raises(GeometryError, match="crown_0"):
        reeving_drawing(overlapping)


# ---------------------------------------------------------------- rendering


def test_png_is_written_with_the_right_size(tmp_path):
    before = dict(matplotlib.rcParams)
    tall = draw_reeving(drilling_block_train(4, floor=FLOOR), tmp_path / "tall.png")
    square = draw_reeving(tensioner_like(), tmp_path / "square.png", title="tensioner-like")
    assert tall == tmp_path / "tall.png" and square == tmp_path / "square.png"
    width, height = png_size(tall)
    assert 600 <= width < height <= 1000  # portrait, long side 9 in at 110 dpi
    width, height = png_size(square)
    assert 900 <= width <= 1100 and 900 <= height <= 1000
    assert tall.stat().st_size > 20_000 and square.stat().st_size > 20_000
    assert dict(matplotlib.rcParams) == before


def test_invalid_reeving_writes_nothing(tmp_path):
    with pytest.raises(ConfigurationError):
        draw_reeving({"path": []}, tmp_path / "bad.png")
    assert not (tmp_path / "bad.png").exists()


@pytest.mark.parametrize("scene", ["drawworks", "riser_tensioner", "heave_compensated_hoist"])
def test_no_label_of_a_shipped_reeving_overprints_another(scene, tmp_path):
    """Sheave names, body and floor labels, anchors and line ends: no two boxes overlap."""
    from wire_fmu.master.run import shipped_scenes
    from wire_fmu.master.scene import load_scene
    from wire_fmu.tools.draw import _render

    reeving = load_scene(shipped_scenes()[scene]).units["rope"].parameters["reeving"]
    fig = _render(reeving_drawing(reeving), tmp_path / "r.png", scene)
    renderer = fig.canvas.get_renderer()
    (ax,) = [a for a in fig.axes if a.texts]
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in ax.texts if t.get_text()]
    assert len(boxes) >= 5
    for i, (text, box) in enumerate(boxes):
        for other, second in boxes[i + 1 :]:
            assert not box.overlaps(second), f"{scene}: {text!r} overprints {other!r}"


def test_a_drawing_sets_no_text_in_mathtext(tmp_path, monkeypatch):
    # matplotlib builds its mathtext parser at the first formula a process draws: a third
    # of a second of every run's report, for a legend's one arrow
    from matplotlib import mathtext

    def refuse(self, text, *args, **kwargs):
        raise AssertionError(f"mathtext parsed {text!r}")

    monkeypatch.setattr(mathtext.MathTextParser, "parse", refuse)
    out = draw_reeving(drilling_block_train(4, floor=FLOOR), tmp_path / "plain.png")
    assert out.stat().st_size > 10_000
