"""Tangent points, lengths, wrap and fleet angles against hand-derived closed forms.

Coordinates are in metres, angles in radians. Unless stated otherwise every
sheave lies in the plane z = 0 with axis +z, so ``sense = +1`` means the rope
wraps it counter-clockwise seen from above.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wire_fmu.core.components.sheave_geometry.circles import Circle, PathNode
from wire_fmu.core.components.sheave_geometry.path import (
    check_path,
    path_geometry,
    segment_tangent_points,
)
from wire_fmu.core.components.sheave_geometry.planar_path import planar_frame, planar_path_lengths
from wire_fmu.core.components.sheave_geometry.spatial_tangent import solve_fleet_tangent
from wire_fmu.core.errors import GeometryError

Z = (0.0, 0.0, 1.0)
PI = math.pi


def sheave(name, x, y, r, sense, z=0.0, axis=Z):
    """A sheave node."""
    return PathNode(Circle(name, (x, y, z), axis, r), sense)


def point(name, x, y, z=0.0):
    """A point node (anchor or rope end)."""
    return PathNode(Circle(name, (x, y, z), Z, 0.0), 0)


def assert_tangent(p, node, d):
    """P lies on the node's circle and the rope direction d is perpendicular to the radius."""
    c = node.circle
    rad = np.asarray(p) - np.array(c.centre)
    assert np.linalg.norm(rad) == pytest.approx(c.radius, abs=1e-12)
    assert rad @ np.array(c.axis) == pytest.approx(0.0, abs=1e-12)
    assert rad @ np.asarray(d) == pytest.approx(0.0, abs=1e-11)


def wrap_sign(p, node, d):
    """Sign of ((P - C) x d) . axis, which the convention says equals the node's sense."""
    c = node.circle
    return np.sign(np.cross(np.asarray(p) - np.array(c.centre), d) @ np.array(c.axis))


# ------------------------------------------------------------- two circles, planar


def test_equal_circles_outer_tangents():
    # Circles r = 1 at (0, 0) and (4, 0): outer tangents at y = -1 and y = +1 (eq. 24).
    a, b = sheave("a", 0, 0, 1.0, +1), sheave("b", 4, 0, 1.0, +1)
    pa, pb = segment_tangent_points(a, b)
    np.testing.assert_allclose(pa, [0, -1, 0], atol=1e-15)
    np.testing.assert_allclose(pb, [4, -1, 0], atol=1e-15)
    a, b = sheave("a", 0, 0, 1.0, -1), sheave("b", 4, 0, 1.0, -1)
    pa, pb = segment_tangent_points(a, b)
    np.testing.assert_allclose(pa, [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(pb, [4, 1, 0], atol=1e-15)


# r1 = 2 at (0, 0), r2 = 1 at (5, 0).
# Outer: the line tilts by sin g = (r1 - r2)/5 = 0.2; bottom tangent (both ccw): radius
# direction (s, -c) at both circles, P1 = 2 (s, -c), P2 = (5, 0) + (s, -c); length sqrt(24).
# Crossed: sin g = (r1 + r2)/5 = 3/5, direction (4/5, 3/5); for (+1, -1) the rope leaves the
# bottom of circle 1 at P1 = 2 (3/5, -4/5) and meets the top of circle 2 at
# P2 = (5, 0) - (3/5, -4/5); length 4. The other two are mirror images in y = 0.
_S, _C = 0.2, math.sqrt(0.96)
FOUR_TANGENTS = [
    ((+1, +1), (2 * _S, -2 * _C), (5 + _S, -_C), math.sqrt(24.0)),
    ((-1, -1), (2 * _S, 2 * _C), (5 + _S, _C), math.sqrt(24.0)),
    ((+1, -1), (1.2, -1.6), (4.4, 0.8), 4.0),
    ((-1, +1), (1.2, 1.6), (4.4, -0.8), 4.0),
]


@pytest.mark.parametrize(("senses", "p1", "p2", "length"), FOUR_TANGENTS)
def test_four_tangents_chosen_by_sense(senses, p1, p2, length):
    a, b = sheave("big", 0, 0, 2.0, senses[0]), sheave("small", 5, 0, 1.0, senses[1])
    pa, pb = segment_tangent_points(a, b)
    np.testing.assert_allclose(pa, [*p1, 0], atol=1e-14)
    np.testing.assert_allclose(pb, [*p2, 0], atol=1e-14)
    d = pb - pa
    assert np.linalg.norm(d) == pytest.approx(length, rel=1e-14)
    assert_tangent(pa, a, d)
    assert_tangent(pb, b, d)
    assert wrap_sign(pa, a, d) == senses[0]
    assert wrap_sign(pb, b, d) == senses[1]


@pytest.mark.parametrize("senses", [(+1, +1), (-1, -1), (+1, -1), (-1, +1)])
def test_tangent_lengths_and_homothety_centres(senses):
    # Outer tangents pass through p1 = (r1 C2 - r2 C1)/(r1 - r2) (eq. 16, 17), crossed
    # through p2 = (r1 C2 + r2 C1)/(r1 + r2) (eq. 22, 23).
    c1, c2, r1, r2 = np.array([1.0, -2.0, 0.0]), np.array([8.0, 1.5, 0.0]), 1.1, 0.4
    a = sheave("a", *c1[:2], r1, senses[0])
    b = sheave("b", *c2[:2], r2, senses[1])
    pa, pb = segment_tangent_points(a, b)
    d = pb - pa
    dist = np.linalg.norm(c2 - c1)
    crossed = senses[0] != senses[1]
    k = r1 + r2 if crossed else r1 - r2
    assert np.linalg.norm(d) == pytest.approx(math.sqrt(dist**2 - k**2), rel=1e-13)
    centre = (r1 * c2 + r2 * c1) / (r1 + r2) if crossed else (r1 * c2 - r2 * c1) / (r1 - r2)
    assert np.cross(d, centre - pa)[2] == pytest.approx(0.0, abs=1e-12)
    assert_tangent(pa, a, d)
    assert_tangent(pb, b, d)


def test_opposite_axis_with_opposite_sense_is_the_same_wrap():
    # Sense -1 about -z is counter-clockwise about +z.
    a = sheave("a", 0, 0, 2.0, +1)
    b_up = sheave("b", 5, 0, 1.0, +1)
    b_down = sheave("b", 5, 0, 1.0, -1, axis=(0.0, 0.0, -1.0))
    np.testing.assert_allclose(
        segment_tangent_points(a, b_down), segment_tangent_points(a, b_up), atol=1e-15
    )


def test_point_to_circle_and_circle_to_point():
    # d = 5, r = 3: tangent length 4; from the origin the line to the bottom tangent point
    # has direction (4/5, -3/5), so P = 4 (4/5, -3/5) = (3.2, -2.4).
    for sense, sign in ((+1, -1), (-1, +1)):
        p, s = point("anchor", 0, 0), sheave("s", 5, 0, 3.0, sense)
        pa, pb = segment_tangent_points(p, s)
        np.testing.assert_allclose(pa, [0, 0, 0])
        np.testing.assert_allclose(pb, [3.2, sign * 2.4, 0], atol=1e-14)
        assert np.linalg.norm(pb - pa) == pytest.approx(math.sqrt(5**2 - 3**2))
        # Leaving a sheave at the origin for a point at (5, 0): P = (1.8, -/+2.4).
        s, q = sheave("s", 0, 0, 3.0, sense), point("end", 5, 0)
        pa, pb = segment_tangent_points(s, q)
        np.testing.assert_allclose(pa, [1.8, sign * 2.4, 0], atol=1e-14)
        np.testing.assert_allclose(pb, [5, 0, 0])
        assert wrap_sign(pa, s, pb - pa) == sense


def test_point_to_point():
    g = path_geometry([point("a", 1, 2, 3), point("b", 4, 6, 15)])
    assert g.lengths[0] == pytest.approx(13.0)
    np.testing.assert_allclose(g.directions[0], [3 / 13, 4 / 13, 12 / 13])
    assert g.kinds == ("straight",)
    np.testing.assert_array_equal(g.fleet_angles, [[0.0, 0.0]])


# ----------------------------------------------------------------------- wrap angles

# Sheave r = 1 at the origin. Rope ends chosen so the tangents are axis-parallel lines:
# from (1, -5) the rope runs up x = 1 to (1, 0) (ccw); from (-1, -5) up x = -1 to (-1, 0) (cw).
WRAPS = [
    (+1, (1, -5), (-1, -5), (1, 0), (-1, 0), PI),  # over the top, down both sides
    (+1, (1, -5), (-5, 1), (1, 0), (0, 1), PI / 2),  # 90 deg turn, leaves the top to the left
    (+1, (1, -5), (5, -1), (1, 0), (0, -1), 3 * PI / 2),  # round to the bottom
    (-1, (-1, -5), (1, -5), (-1, 0), (1, 0), PI),
    (-1, (-1, -5), (5, 1), (-1, 0), (0, 1), PI / 2),
    (-1, (-1, -5), (-5, -1), (-1, 0), (0, -1), 3 * PI / 2),
]


@pytest.mark.parametrize(("sense", "start", "end", "p_in", "p_out", "alpha"), WRAPS)
def test_wrap_angle_over_one_sheave(sense, start, end, p_in, p_out, alpha):
    s = sheave("s", 0, 0, 1.0, sense)
    g = path_geometry([point("a", *start), s, point("b", *end)])
    np.testing.assert_allclose(g.points[0][1], [*p_in, 0], atol=1e-14)
    np.testing.assert_allclose(g.points[1][0], [*p_out, 0], atol=1e-14)
    assert g.wrap_angles[0] == pytest.approx(alpha, abs=1e-14)
    assert g.arc_lengths[0] == pytest.approx(alpha, abs=1e-14)
    assert g.lengths[0] == pytest.approx(5.0)


def test_half_wrap_of_a_larger_sheave_gives_pi_r():
    s = sheave("s", 0, 0, 2.0, +1)
    g = path_geometry([point("a", 2, -30), s, point("b", -2, -30)])
    assert g.wrap_angles[0] == pytest.approx(PI, abs=1e-14)
    assert g.arc_lengths[0] == pytest.approx(2 * PI, abs=1e-13)
    np.testing.assert_allclose(g.lengths, [30.0, 30.0])


def test_interior_point_turning_angle():
    g = path_geometry([point("a", 0, 0), point("fairlead", 1, 0), point("b", 1, 1)])
    assert g.wrap_angles[0] == pytest.approx(PI / 2)
    assert g.arc_lengths[0] == 0.0


# --------------------------------------------------------------------- spatial cases


def test_aligned_spatial_tangent_and_newton_agree():
    # Sheave a in z = 0 (axis z, r = 1), sheave b in x = 1 (axis x, r = 0.5, centre
    # (1, 5, 0.5)). Planes cut along the line x = 1, z = 0, at distance 1 from C_a and 0.5
    # from C_b: tangent points are the feet (1, 0, 0) and (1, 5, 0), rope along +y.
    # ((1,0,0) x (0,1,0)) . z = 1 > 0 and ((0,0,-0.5) x (0,1,0)) . x = 0.5 > 0: both +1.
    a = sheave("a", 0, 0, 1.0, +1)
    b = PathNode(Circle("b", (1.0, 5.0, 0.5), (1.0, 0.0, 0.0), 0.5), +1)
    g = path_geometry([a, b])
    assert g.kinds == ("aligned",)
    np.testing.assert_allclose(g.points[0][0], [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(g.points[0][1], [1, 5, 0], atol=1e-15)
    np.testing.assert_array_equal(g.fleet_angles, [[0.0, 0.0]])
    sol = solve_fleet_tangent(a, b)
    np.testing.assert_allclose(sol.start, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(sol.end, [1, 5, 0], atol=1e-12)
    assert sol.residual <= 1e-12


@pytest.mark.parametrize("tilt", [1e-3, 0.02])
def test_general_solver_on_tilted_sheave(tilt):
    # Tilting b's axis about y moves b's plane off the foot (1, 5, 0): the planes no longer
    # cut along a common tangent. Newton must find a tangent that satisfies the defining
    # conditions, with the requested senses, close to the aligned one.
    a = sheave("a", 0, 0, 1.0, +1)
    axis = (math.cos(tilt), 0.0, math.sin(tilt))
    b = PathNode(Circle("b", (1.0, 5.0, 0.5), axis, 0.5), +1)
    g = path_geometry([a, b], max_fleet_angle=math.radians(5))
    assert g.kinds == ("general",)
    pa, pb = g.points[0]
    d = pb - pa
    assert_tangent(pa, a, d)
    assert_tangent(pb, b, d)
    assert wrap_sign(pa, a, d) == 1
    assert wrap_sign(pb, b, d) == 1
    assert np.linalg.norm(pa - [1, 0, 0]) < 5 * tilt
    assert np.linalg.norm(pb - [1, 5, 0]) < 5 * tilt
    assert solve_fleet_tangent(a, b).residual <= 1e-12


@pytest.mark.parametrize("sense_b", [+1, -1])
def test_general_solver_on_skew_sheaves(sense_b):
    # No symmetry: Newton has to iterate. Check the defining conditions, the senses and the
    # reported fleet angles asin(|d . A| / |d|).
    a = sheave("a", 0, 0, 1.0, +1)
    axis = np.array([0.2, 0.1, 1.0]) / math.sqrt(1.05)
    b = PathNode(Circle("b", (4.0, 1.0, 0.3), axis, 0.5), sense_b)
    sol = solve_fleet_tangent(a, b)
    assert sol.iterations >= 2
    assert sol.residual <= 1e-12
    d = sol.end - sol.start
    assert_tangent(sol.start, a, d)
    assert_tangent(sol.end, b, d)
    assert wrap_sign(sol.start, a, d) == 1
    assert wrap_sign(sol.end, b, d) == sense_b
    g = path_geometry([a, b], max_fleet_angle=math.radians(30))
    assert g.kinds == ("general",)
    np.testing.assert_allclose(g.points[0][0], sol.start, atol=1e-12)
    for end, node in ((0, a), (1, b)):
        expected = math.asin(abs(d @ np.array(node.circle.axis)) / np.linalg.norm(d))
        assert g.fleet_angles[0, end] == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize(
    ("senses", "in_plane"), [((+1, +1), 10.0), ((+1, -1), math.sqrt(10.0**2 - 1.0**2))]
)
def test_fleet_angle_of_parallel_offset_sheaves(senses, in_plane):
    # Parallel axes, centres D = 10 apart and e = 0.3 along the axis: the radii have no axial
    # part, so the in-plane tangent is the planar one and the fleet angle is atan(e / L_t).
    e = 0.3
    a = sheave("crown_1", 0, 0, 0.5, senses[0])
    b = sheave("travel_1", 10, 0, 0.5, senses[1], z=e)
    g = path_geometry([a, b])
    assert g.kinds == ("offset",)
    np.testing.assert_allclose(g.fleet_angles[0], [math.atan(e / in_plane)] * 2, rtol=1e-13)
    assert g.lengths[0] == pytest.approx(math.hypot(in_plane, e), rel=1e-14)
    sol = solve_fleet_tangent(a, b)
    assert sol.residual <= 1e-12
    np.testing.assert_allclose(sol.start, g.points[0][0], atol=1e-11)
    np.testing.assert_allclose(sol.end, g.points[0][1], atol=1e-11)
    np.testing.assert_allclose(sol.fleet_angles, g.fleet_angles[0], atol=1e-12)


def test_point_off_the_sheave_plane_and_one_sided_newton():
    # The tangent point from an out-of-plane point is that of its projection: (3.2, -2.4, 0);
    # the fleet angle at the sheave is atan(3 / 4) (height 3 over in-plane length 4).
    p, s = point("anchor", 0, 0, 3.0), sheave("s", 5, 0, 3.0, +1)
    limit = math.radians(40)
    g = path_geometry([p, s], max_fleet_angle=limit)
    np.testing.assert_allclose(g.points[0][1], [3.2, -2.4, 0], atol=1e-14)
    np.testing.assert_allclose(g.fleet_angles[0], [0.0, math.atan(3 / 4)], rtol=1e-14)
    sol = solve_fleet_tangent(p, s)
    np.testing.assert_allclose(sol.end, [3.2, -2.4, 0], atol=1e-12)
    assert sol.residual <= 1e-12


def test_fleet_angle_above_limit_names_both_sheaves():
    # e = 1 over 10 m: atan(0.1) = 5.71 deg > 2.5 deg.
    a = sheave("crown_1", 0, 0, 0.5, +1)
    b = sheave("travel_1", 10, 0, 0.5, +1, z=1.0)
    with pytest.raises(GeometryError) as info:
        path_geometry([a, b])
    (msg,) = info.value.problems
    assert "'crown_1'" in msg and "'travel_1'" in msg
    assert "5.71 deg" in msg and "2.50 deg" in msg
    with pytest.raises(GeometryError):
        segment_tangent_points(a, b)
    path_geometry([a, b], max_fleet_angle=math.radians(6))  # within a wider limit


# -------------------------------------------------------------------- invalid input


def only_problem(nodes):
    """The single problem of a path, checked to be raised by path_geometry too."""
    problems = check_path(nodes)
    with pytest.raises(GeometryError) as info:
        path_geometry(nodes)
    assert info.value.problems == problems
    assert info.value.where == "rope path"
    assert len(problems) == 1, problems
    return problems[0]


def test_crossed_tangent_of_overlapping_sheaves():
    msg = only_problem([sheave("crown_2", 0, 0, 0.6, -1), sheave("travel_1", 0.9, 0, 0.6, +1)])
    assert msg == (
        "sheaves 'crown_2' and 'travel_1': crossed tangent needs centre distance "
        "0.900 m > r1 + r2 = 1.200 m (the sheaves overlap)"
    )


def test_outer_tangent_sheave_inside_another():
    msg = only_problem([sheave("big", 0, 0, 2.0, +1), sheave("small", 0.5, 0, 1.0, +1)])
    assert "'big'" in msg and "'small'" in msg
    assert "outer tangent" in msg and "0.500 m" in msg and "1.000 m" in msg


def test_outer_tangent_of_overlapping_discs():
    msg = only_problem([sheave("s1", 0, 0, 1.0, +1), sheave("s2", 1.5, 0, 1.0, +1)])
    assert "'s1'" in msg and "'s2'" in msg and "overlap" in msg
    assert "1.500 m" in msg and "2.000 m" in msg


def test_point_inside_sheave():
    msg = only_problem([point("anchor", 0.5, 0), sheave("s", 0, 0, 1.0, +1)])
    assert "'anchor'" in msg and "'s'" in msg and "inside" in msg


def test_overlap_of_sheaves_that_are_not_neighbours():
    nodes = [
        point("anchor", -1, -10),
        sheave("A", 0, 0, 1.0, -1),
        sheave("B", 5, -10, 1.0, +1),
        sheave("C", 1, 0.5, 1.0, -1),
        point("end", 2, -10),
    ]
    msg = only_problem(nodes)
    assert msg == (
        "sheaves 'A' and 'C': discs overlap in the same plane: centre distance 1.118 m "
        "< r1 + r2 = 2.000 m"
    )


def test_coincident_sheaves_in_one_plane_are_refused():
    """Two sheaves with the same centre and radius in one plane are one disc: refused like
    overlapping ones (the exemption is only for the same sheave met again)."""
    nodes = [
        point("anchor", -1, -10),
        sheave("A", 0, 0, 1.0, -1),
        sheave("B", 5, -10, 1.0, +1),
        sheave("C", 0, 0, 1.0, -1),
        point("end", 1, -10),
    ]
    msg = only_problem(nodes)
    assert msg == (
        "sheaves 'A' and 'C': discs coincide in the same plane: same centre (0, 0, 0) m "
        "and radius 1.000 m"
    )


def test_sheaves_side_by_side_on_one_shaft_are_not_an_overlap():
    """Same centre line and radius, offset along the axis: two grooves on one shaft."""
    nodes = [
        point("anchor", -1, -10),
        sheave("A", 0, 0, 1.0, -1),
        sheave("B", 5, -10, 1.0, +1),
        sheave("C", 0, 0, 1.0, -1, z=0.3),
        point("end", 1, -10, 0.3),
    ]
    assert check_path(nodes) == []


def test_zero_length_segment():
    msg = only_problem([point("a", 1, 2), point("b", 1, 2)])
    assert "'a'" in msg and "'b'" in msg and "same place" in msg


def test_inconsistent_axes():
    # b's centre projects onto a's centre: no tangent leaves a in its own plane.
    a = sheave("a", 0, 0, 1.0, +1)
    b = PathNode(Circle("b", (0.0, 0.0, 2.0), (1.0, 0.0, 0.0), 0.5), +1)
    msg = only_problem([a, b])
    assert "'a'" in msg and "'b'" in msg and "inconsistent axes" in msg
    with pytest.raises(GeometryError, match="inconsistent axes"):
        solve_fleet_tangent(a, b)


@pytest.mark.parametrize(
    ("node", "words"),
    [
        (PathNode(Circle("s", (0, 0, 0), (0, 0, 2), 1.0), 1), ["axis", "length 2"]),
        (PathNode(Circle("s", (0, 0, 0), (0, 0, 0), 1.0), 1), ["axis is zero"]),
        (PathNode(Circle("s", (0, 0, 0), Z, -1.0), 1), ["radius -1.000 m is negative"]),
        (PathNode(Circle("s", (math.nan, 0, 0), Z, 1.0), 1), ["non-finite"]),
        (PathNode(Circle("s", (0, 0, 0), Z, 1.0), 0), ["sense 0", "+1"]),
        (PathNode(Circle("s", (0, 0, 0), Z, 0.0), 1), ["sense 1", "must be 0"]),
    ],
)
def test_invalid_node(node, words):
    msg = only_problem([node, point("far", 10, 10)])
    assert "'s'" in msg
    for word in words:
        assert word in msg


def test_all_problems_reported_at_once():
    nodes = [
        point("anchor", -5, -10),
        PathNode(Circle("bad_axis", (-5, 0, 0), (0, 0, 0.5), 1.0), -1),
        sheave("crown_2", 0, 0, 0.6, -1),
        sheave("travel_1", 0.9, 0, 0.6, +1),
        sheave("crown_3", 10, 0, 0.5, +1),
        sheave("travel_2", 20, 0, 0.5, +1, z=2.0),
        point("dead_1", 40, 0, 2.0),
        point("dead_2", 40, 0, 2.0),
    ]
    problems = check_path(nodes)
    with pytest.raises(GeometryError) as info:
        path_geometry(nodes)
    assert info.value.problems == problems
    assert len(problems) == 4, problems
    text = "\n".join(problems)
    assert "'bad_axis'" in text
    assert "'crown_2' and 'travel_1': crossed tangent" in text
    assert "'crown_3' and 'travel_2': fleet angle" in text
    assert "'dead_1' and 'dead_2'" in text and "same place" in text
    assert "4 problems" in str(info.value)


def test_valid_path_has_no_problems():
    assert check_path(block_train()) == []


# -------------------------------------------------------------- block train, speed path


def block_train():
    """A 10-line planar block train: drum, 5 crown (cw) and 5 travelling (ccw) sheaves, anchor.

    Crown sheaves at y = 40 and travelling sheaves at y = 10, 1.2 m apart in x, r = 0.5.
    """
    nodes = [point("drum", -3, 0)]
    for i in range(5):
        nodes.append(sheave(f"crown_{i + 1}", 2.4 * i, 40, 0.5, -1))
        nodes.append(sheave(f"travel_{i + 1}", 2.4 * i + 1.2, 10, 0.5, +1))
    nodes.append(point("deadline", 12, 45))
    return nodes


def test_block_train_lines_against_closed_form():
    # Each crown -> travelling line is a crossed tangent between r = 0.5 sheaves whose centres
    # are sqrt(1.2^2 + 30^2) apart: length sqrt(30^2 + 1.2^2 - 1^2).
    g = path_geometry(block_train())
    np.testing.assert_allclose(g.lengths[1:-1], math.sqrt(30**2 + 1.2**2 - 1.0), rtol=1e-14)
    assert len(g.wrap_angles) == 10
    assert np.all(np.abs(g.wrap_angles - PI) < 0.1)
    assert set(g.kinds) == {"planar"}


def rotate(nodes, rot, shift):
    """The same path rotated by matrix ``rot`` and translated by ``shift``."""
    out = []
    for n in nodes:
        c = n.circle
        centre = rot @ np.array(c.centre) + shift
        axis = rot @ np.array(c.axis)
        out.append(PathNode(Circle(c.name, centre, axis, c.radius), n.sense))
    return out


def rotation(axis, angle):
    """Rodrigues rotation matrix about a unit axis."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def test_rotation_and_translation_invariance():
    nodes = block_train()
    g0 = path_geometry(nodes)
    rot = rotation((1.0, -2.0, 0.7), 1.1)
    g1 = path_geometry(rotate(nodes, rot, np.array([3.0, -7.5, 12.0])))
    np.testing.assert_allclose(g1.lengths, g0.lengths, rtol=1e-12)
    np.testing.assert_allclose(g1.wrap_angles, g0.wrap_angles, atol=1e-12)
    np.testing.assert_allclose(g1.arc_lengths, g0.arc_lengths, atol=1e-12)
    np.testing.assert_allclose(g1.fleet_angles, 0.0, atol=1e-9)
    np.testing.assert_allclose(g1.points[3][0], rot @ g0.points[3][0] + [3.0, -7.5, 12.0])


def test_lean_planar_path_matches_path_geometry():
    nodes = rotate(block_train(), rotation((0.3, 1.0, 0.2), 0.8), np.array([1.0, 2.0, 3.0]))
    frame = planar_frame(nodes)
    xy = [frame.project(n.circle.centre) for n in nodes]
    lengths, wraps = planar_path_lengths(xy, frame.signed_radii, names=frame.names)
    g = path_geometry(nodes, validate=False)
    np.testing.assert_allclose(lengths, g.lengths, rtol=1e-12)
    np.testing.assert_allclose(wraps, g.wrap_angles, atol=1e-12)


def test_lean_paths_still_reject_impossible_geometry():
    nodes = [sheave("crown_2", 0, 0, 0.6, -1), sheave("travel_1", 0.9, 0, 0.6, +1)]
    with pytest.raises(GeometryError, match="crossed tangent"):
        path_geometry(nodes, validate=False)
    with pytest.raises(GeometryError, match="'crown_2' and 'travel_1'"):
        planar_path_lengths([(0, 0), (0.9, 0)], [-0.6, 0.6], names=["crown_2", "travel_1"])


def test_planar_frame_rejects_a_path_out_of_plane():
    nodes = block_train()
    nodes[4] = sheave("travel_2", 3.6, 10, 0.5, +1, z=0.01)
    with pytest.raises(GeometryError, match="'travel_2': not in the path plane"):
        planar_frame(nodes)
