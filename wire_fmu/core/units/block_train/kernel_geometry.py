"""The block train's moving geometry in compiled form: span lengths of a planar path.

:func:`segment_lengths` is :meth:`ReevedPath._planar_segment_lengths
<wire_fmu.core.units.block_train.path.ReevedPath._planar_segment_lengths>` (the
closed form of :func:`~wire_fmu.core.components.sheave_geometry.planar_path.planar_path_lengths`)
and :func:`span_geometry` is :meth:`BlockTrainModel.span_lengths
<wire_fmu.core.units.block_train.model.BlockTrainModel.span_lengths>`, operation
for operation: the central differences of the lengths amplify any rounding by
``L / (2 h)``, so the two kernels agree only if each segment length is computed
with the same operations in the same order. The arrays are indices 12-16 of the
tuple described in :mod:`~wire_fmu.core.units.block_train.kernel`.
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators

jit = kernel_decorators(__file__).jit

__all__ = ["segment_lengths", "span_geometry"]

_POS_TOL = 1e-9  # m: tangent existence, as ``sheave_geometry.circles._POS_TOL``
_TWO_PI = 2.0 * math.pi


@jit
def _wrap_2pi(angle: float) -> float:
    """Map an angle from atan2 into [0, 2 pi), rad (as ``sheave_geometry.circles``)."""
    if angle < 0.0:
        angle += _TWO_PI
    return 0.0 if angle >= _TWO_PI else angle


@jit
def segment_lengths(y: np.ndarray, path_nodes, carriers, body_dirs):
    """Segment lengths of a planar path, straight part plus half of each adjoining arc.

    :meth:`ReevedPath._planar_segment_lengths
    <wire_fmu.core.units.block_train.path.ReevedPath._planar_segment_lengths>` with
    the same operations in the same order.

    Parameters
    ----------
    y : numpy.ndarray
        Body displacements along their directions, m: the blocks, then the driven bodies.
    path_nodes, carriers, body_dirs : numpy.ndarray
        See the module docstring (indices 12-14).

    Returns
    -------
    lengths : numpy.ndarray
        Length of each segment, m.
    ok : bool
        False when a segment has no tangent (circles overlap, or a point lies inside
        a sheave); the lengths are then meaningless.
    """
    n_nodes = path_nodes.shape[0]
    seg = np.empty(n_nodes - 1)
    ok = _segment_lengths_into(seg, np.empty((4, n_nodes)), y, path_nodes, carriers, body_dirs)
    return seg, ok


@jit
def _segment_lengths_into(seg, work, y, path_nodes, carriers, body_dirs) -> bool:
    """:func:`segment_lengths` written into ``seg`` (one per segment), with ``work`` (4 rows
    of at least one per path node) as its scratch: no array made, which in a kernel that
    evaluates the path five times an evaluation costs more than the arithmetic."""
    n_nodes = path_nodes.shape[0]
    xs, zs, dir_x, dir_z = work[0], work[1], work[2], work[3]
    for k in range(n_nodes):
        shift_x = 0.0
        shift_z = 0.0
        for c in range(carriers.shape[1]):
            b = carriers[k, c]
            if b < 0:
                break
            shift_x += y[b] * body_dirs[b, 0]
            shift_z += y[b] * body_dirs[b, 1]
        xs[k] = path_nodes[k, 0] + shift_x
        zs[k] = path_nodes[k, 1] + shift_z
    n_seg = n_nodes - 1
    for i in range(n_seg):
        dx = xs[i + 1] - xs[i]
        dy = zs[i + 1] - zs[i]
        k = path_nodes[i + 1, 2] - path_nodes[i, 2]
        l2 = dx * dx + dy * dy
        if math.sqrt(l2) - abs(k) <= _POS_TOL:
            return False
        lt = math.sqrt(l2 - k * k)
        seg[i] = lt
        dir_x[i] = (lt * dx + k * dy) / l2
        dir_z[i] = (lt * dy - k * dx) / l2
    # each inner node's half arc, kept in xs (its position is not needed any more)
    half_arcs = xs
    for j in range(1, n_nodes - 1):
        ax, ay, bx, by = dir_x[j - 1], dir_z[j - 1], dir_x[j], dir_z[j]
        cr = ax * by - ay * bx
        dt = ax * bx + ay * by
        rho = path_nodes[j, 2]
        if rho == 0.0:
            wrap = abs(math.atan2(cr, dt))
        else:
            wrap = _wrap_2pi(math.atan2(cr if rho > 0.0 else -cr, dt))
        half_arcs[j - 1] = 0.5 * abs(rho) * wrap
    for i in range(n_seg - 1):
        seg[i] += half_arcs[i]
    for i in range(n_seg - 1):
        seg[i + 1] += half_arcs[i]
    return True


@jit
def span_geometry(y: np.ndarray, data):
    """Geometric span lengths (m) and their Jacobian w.r.t. body motion, moving geometry.

    :meth:`BlockTrainModel.span_lengths
    <wire_fmu.core.units.block_train.model.BlockTrainModel.span_lengths>`: central
    differences of :func:`segment_lengths` with the step ``data[16][0]``, then the
    segments summed into their spans.

    Parameters
    ----------
    y : numpy.ndarray
        Body displacements along their directions, m: the blocks, then the driven bodies.
    data : tuple
        See the module docstring.

    Returns
    -------
    lengths : numpy.ndarray
        Length of each span, m.
    jacobian : numpy.ndarray
        ``d lengths / d y``, one row per span and one column per body, 1.
    ok : bool
        False when a segment has no tangent at ``y`` or at a differencing point.
    """
    path_nodes, carriers, body_dirs, segment_span = data[12], data[13], data[14], data[15]
    h = data[16][0]
    n_spans = data[3].size
    n_bodies = y.size
    n_seg = path_nodes.shape[0] - 1
    work = np.empty((4, n_seg + 1))  # every evaluation's scratch, made once
    seg, plus, minus = np.empty(n_seg), np.empty(n_seg), np.empty(n_seg)
    ok = _segment_lengths_into(seg, work, y, path_nodes, carriers, body_dirs)
    jac = np.zeros((n_seg, n_bodies))
    y_plus = np.empty(n_bodies)
    y_minus = np.empty(n_bodies)
    for b in range(n_bodies):
        for j in range(n_bodies):
            step = h if j == b else 0.0
            y_plus[j] = y[j] + step
            y_minus[j] = y[j] - step
        ok_plus = _segment_lengths_into(plus, work, y_plus, path_nodes, carriers, body_dirs)
        ok_minus = _segment_lengths_into(minus, work, y_minus, path_nodes, carriers, body_dirs)
        ok = ok and ok_plus and ok_minus
        for i in range(n_seg):
            jac[i, b] = (plus[i] - minus[i]) / (2.0 * h)
    lengths = np.zeros(n_spans)
    span_jac = np.zeros((n_spans, n_bodies))
    for i in range(n_seg):
        span = segment_span[i]
        lengths[span] += seg[i]
        for b in range(n_bodies):
            span_jac[span, b] += jac[i, b]
    return lengths, span_jac, ok
