"""Where the rope leaves a sheave: tangent points, straight lengths, wrap and fleet angles.

SPEC section 6 (paper 000, eq. 13-31). A rope *path* is an ordered sequence of
:class:`~wire_fmu.core.components.sheave_geometry.circles.PathNode` s. Each node is a
:class:`~wire_fmu.core.components.sheave_geometry.circles.Circle`: a sheave's working circle
(radius > 0) or a point (radius 0: an anchor or a free rope end). Between two
consecutive nodes the rope runs straight, from the point where it leaves the
first circle to the point where it touches the second.

Sign convention for ``sense``
-----------------------------
``sense = +1``: travelling along the path (from node ``i`` towards node
``i + 1``) the rope wraps the sheave counter-clockwise seen from the tip of
``+axis``; rope moving forward turns the sheave positively by the right-hand
rule about ``+axis``. ``sense = -1``: clockwise. ``sense = 0``: a point.
At every tangent point ``P`` of a sheave (centre ``C``, radius ``r``), with
``d`` the rope direction there (pointing forward along the path)::

    ((P - C) x d) . axis  =  sense * r * |d_in_plane|        (sign = sense)

Hand example (axis +z, sheave at the origin, r = 1): a rope from the point
(1, -5) runs up to (1, 0) (there (1, 0, 0) x (0, 1, 0) = +z), over the top,
and leaves at (-1, 0) running down to (-1, -5) ((-1, 0, 0) x (0, -1, 0) = +z):
``sense = +1``, wrap angle pi. The paper's orientation checks (30, 31),
``AB x C1A || +A1``, are this rule with sense -1 (they fix the sign of the
axis instead of carrying a sense). Two sheaves whose senses agree about a
common axis get an outer tangent; opposite senses get a crossed tangent.

Cases
-----
* **Parallel axes** (planar, eq. 16-25, and the parallel fleet-angle case):
  closed form with signed radii ``rho = sense * r``: with ``D`` the centre
  offset projected on the sheave plane, ``L = |D|`` and ``k = rho_b - rho_a``
  the rope's in-plane direction is ``(sqrt(L^2 - k^2) D - k (A x D)) / L^2``,
  the in-plane tangent length ``sqrt(L^2 - k^2)``, and ``P = C - rho n`` with
  ``n = A x d``. No division by ``r1 - r2`` (equal radii, eq. 24, need no
  special case). An offset ``h`` along the axis leaves the in-plane problem
  unchanged (the radii have no axial part), so this form is exact there too;
  the fleet angle is ``atan2(|h|, sqrt(L^2 - k^2))``. A point to a sheave of
  any orientation is the same form: the point's projection on the sheave plane
  has the same tangent point.
* **Spatial, aligned** (eq. 26-31): non-parallel axes whose planes cut along a
  line at distance ``r`` from both centres: tangent points are the feet of
  the perpendiculars, fleet angles 0.
* **General** (ours):
  :func:`~wire_fmu.core.components.sheave_geometry.spatial_tangent.solve_fleet_tangent`,
  Newton iteration in the contact angles with an analytic Jacobian, from the
  planar solution of each circle's own plane (the other circle projected into
  it).

Speed
-----
Measured (Python 3.11, numpy 2.4, AMD EPYC, best of 5 ``timeit`` runs) for one
12-node planar block-train path (11 segments, 10 interior sheaves):
``path_geometry(..., validate=True)`` 130 us per call (of which the whole-path
checks are about 65 us), ``path_geometry(..., validate=False)`` 60 us (about
half of it building the numpy result), ``planar_path_lengths`` 6.5 us.
Validate once (``path_geometry`` or ``planar_frame``), then inside an
ODE right-hand side call ``planar_path_lengths`` with the moved centres'
plane coordinates (``frame.project`` costs about 0.5 us per node, or keep 2-D
coordinates directly), or ``path_geometry(..., validate=False)`` for paths

Modules
-------
:mod:`~wire_fmu.core.components.sheave_geometry.circles`
    Circles and path nodes, the small vector and message helpers.
:mod:`~wire_fmu.core.components.sheave_geometry.planar_tangent`
    The closed-form tangent between circles in parallel planes.
:mod:`~wire_fmu.core.components.sheave_geometry.spatial_tangent`
    The aligned spatial case and the general Newton solver.
:mod:`~wire_fmu.core.components.sheave_geometry.path`
    One segment, the checks of a whole path, and
    :func:`~wire_fmu.core.components.sheave_geometry.path.path_geometry`.
:mod:`~wire_fmu.core.components.sheave_geometry.planar_path`
    The lean planar form for ODE right-hand sides.
"""
