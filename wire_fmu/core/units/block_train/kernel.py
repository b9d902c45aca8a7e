"""The block train's compiled kernel: its equations as plain functions over flat arrays.

The same physics as :meth:`BlockTrainModel.evaluate
<wire_fmu.core.units.block_train.model.BlockTrainModel.evaluate>` (the readable
numpy reference), for block trains without friction links (no
``bearing_friction``, no ``rope_slip``) whose segment lengths are either linear in
the body motion (no ``moving_geometry``) or follow the planar tangent geometry
(``moving_geometry`` without ``spatial_geometry``); other block trains run the
Python kernel. Everything a step needs is in one tuple of arrays, built by
:func:`kernel_data`:

=====  ==================  ==================================================
index  name                contents
=====  ==================  ==================================================
0      ``sizes``           int: coordinates ``n``, blocks ``nb``, driven bodies,
                           moving geometry (1: lengths from :func:`span_geometry`,
                           0: linear in the body motion)
1      ``rope``            float: ``EA`` (N), damping ``c`` (N s), breaking load (N)
2      ``masses``          per coordinate, kg
3      ``span_length0``    geometric span lengths with every body at 0, m
4      ``span_jacobian``   ``dL/dy`` (spans x bodies), 1
5      ``flow``            unstretched lengths ``l = offsets + flow @ [q, s_a, s_b]``
6      ``blocks``          per block: weight along its direction (N), position (m),
                           floor position (m), stiffness (N/m), damping (N s/m)
7      ``offsets``         per span, m
8      ``taut``            per span: mode
9      ``broken``          per span: mode
10     ``contact``         per block: on its floor
11     ``held``            time the inputs hold from (s), line rope positions
                           ``s`` (m) and rates (m/s), mover positions (m) and
                           velocities (m/s)
12     ``path_nodes``      moving geometry, per path node: plane coordinates
                           ``x``, ``z`` of its centre with every body at 0 (m),
                           signed radius ``sense * r`` (m); else empty
13     ``carriers``        int, per path node: the bodies (index into ``y``)
                           that carry it, in the order their motions are
                           summed, padded with -1
14     ``body_dirs``       per body: its direction in plane coordinates, 1
15     ``segment_span``    int, per segment: the span it belongs to
16     ``geometry_step``   float: the central-difference step of the lengths
                           with respect to the body motion, m
=====  ==================  ==================================================

With moving geometry, :func:`segment_lengths` is
:meth:`ReevedPath._planar_segment_lengths
<wire_fmu.core.units.block_train.path.ReevedPath._planar_segment_lengths>` (the
closed form of :func:`~wire_fmu.core.components.sheave_geometry.planar_path.planar_path_lengths`)
and :func:`span_geometry` is :meth:`BlockTrainModel.span_lengths
<wire_fmu.core.units.block_train.model.BlockTrainModel.span_lengths>`, operation
for operation: the central differences of the lengths amplify any rounding by
``L / (2 h)``, so the two kernels agree only if each segment length is computed
with the same operations in the same order.

The guards are in the order of :meth:`ModeSwitching.guards
<wire_fmu.core.units.block_train.modes.ModeSwitching.guards>` (friction links
first: none here).
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.framework.compiled import jit
from wire_fmu.core.framework.compiled_step import STATUS_DONE, STATUS_PYTHON, advance_to_event

__all__ = [
    "advance",
    "evaluate",
    "guards",
    "kernel_data",
    "project",
    "quiet_step",
    "rhs",
    "segment_lengths",
    "span_geometry",
    "summary",
]

N_LINES = 2
_POS_TOL = 1e-9  # m: tangent existence, as ``sheave_geometry.circles._POS_TOL``
_TWO_PI = 2.0 * math.pi


def kernel_data(model) -> tuple:
    """The tuple of arrays the kernel functions take, from ``model``'s present values.

    Parameters
    ----------
    model : BlockTrainModel
        A model whose kernel is compiled (see the module docstring).
    """
    return (
        model.kernel_sizes,
        model.kernel_rope,
        model.masses,
        model.span_length0,
        model.span_jacobian,
        model.flow_matrix,
        model.kernel_blocks,
        model.offsets,
        model.taut_mask,
        model.broken_mask,
        model.contact_mask,
        model.held_vector,
        model.kernel_path_nodes,
        model.kernel_carriers,
        model.kernel_body_dirs,
        model.kernel_segment_span,
        model.kernel_geometry_step,
    )


@jit
def _matvec(a: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``a @ v`` by loops (sizes of a few; no BLAS call for empty shapes)."""
    out = np.zeros(a.shape[0])
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            out[i] += a[i, j] * v[j]
    return out


@jit
def _vecmat(v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``v @ a`` by loops."""
    out = np.zeros(a.shape[1])
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            out[j] += v[i] * a[i, j]
    return out


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
    xs = np.empty(n_nodes)
    zs = np.empty(n_nodes)
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
    seg = np.empty(n_seg)
    dir_x = np.empty(n_seg)
    dir_z = np.empty(n_seg)
    for i in range(n_seg):
        dx = xs[i + 1] - xs[i]
        dy = zs[i + 1] - zs[i]
        k = path_nodes[i + 1, 2] - path_nodes[i, 2]
        l2 = dx * dx + dy * dy
        if math.sqrt(l2) - abs(k) <= _POS_TOL:
            return seg, False
        lt = math.sqrt(l2 - k * k)
        seg[i] = lt
        dir_x[i] = (lt * dx + k * dy) / l2
        dir_z[i] = (lt * dy - k * dx) / l2
    half_arcs = np.empty(max(n_nodes - 2, 0))
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
    return seg, True


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
    seg, ok = segment_lengths(y, path_nodes, carriers, body_dirs)
    n_seg = seg.size
    jac = np.zeros((n_seg, n_bodies))
    y_plus = np.empty(n_bodies)
    y_minus = np.empty(n_bodies)
    for b in range(n_bodies):
        for j in range(n_bodies):
            step = h if j == b else 0.0
            y_plus[j] = y[j] + step
            y_minus[j] = y[j] - step
        plus, ok_plus = segment_lengths(y_plus, path_nodes, carriers, body_dirs)
        minus, ok_minus = segment_lengths(y_minus, path_nodes, carriers, body_dirs)
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


@jit
def evaluate(t: float, x: np.ndarray, data):
    """Forces, tensions, energies and guard inputs at ``(t, x)``.

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State ``[q, v, dissipated, external work]`` (m, m/s, J, J).
    data : tuple
        See the module docstring.

    Returns
    -------
    tuple
        ``forces`` on the coordinates (N), span ``tension``, ``trial`` tension and
        ``elastic`` tension (N), ``stretch`` (m), ``line_force`` (N), ``body_force`` (N),
        floor ``depth`` (m) and ``trial_contact`` (N), ``span_energy`` (J), ``potential``
        (J), ``loss`` (W), external ``power`` (W), and ``ok`` (False when a span has no
        unstretched rope left, or a segment no tangent).
    """
    sizes, rope, masses, len0, jac0, flow, blocks = data[:7]
    offsets, taut, broken, contact, held = data[7:12]
    n, nb, nd = sizes[0], sizes[1], sizes[2]
    ea, damping = rope[0], rope[1]
    n_spans = len0.size
    dt = t - held[0]
    line_rate = held[3 : 3 + N_LINES]
    mover_v = held[3 + N_LINES + nd : 3 + N_LINES + 2 * nd]
    y = np.empty(nb + nd)
    ydot = np.empty(nb + nd)
    for j in range(nb):
        y[j] = x[j]
        ydot[j] = x[n + j]
    for j in range(nd):
        y[nb + j] = held[3 + N_LINES + j] + mover_v[j] * dt
        ydot[nb + j] = mover_v[j]
    flow_q = np.empty(n + N_LINES)
    flow_v = np.empty(n + N_LINES)
    for i in range(n):
        flow_q[i] = x[i]
        flow_v[i] = x[n + i]
    for i in range(N_LINES):
        flow_q[n + i] = held[1 + i] + line_rate[i] * dt
        flow_v[n + i] = line_rate[i]
    if sizes[3]:
        big_l, jac, ok = span_geometry(y, data)
    else:
        big_l, jac, ok = len0 + _matvec(jac0, y), jac0, True
    big_l_rate = _matvec(jac, ydot)
    small_l = offsets + _matvec(flow, flow_q)
    small_l_rate = _matvec(flow, flow_v)
    tension = np.zeros(n_spans)
    trial = np.empty(n_spans)
    elastic = np.empty(n_spans)
    on_unstretched = np.zeros(n_spans)
    energy = np.zeros(n_spans)
    loss = 0.0
    for i in range(n_spans):
        if small_l[i] <= 0.0:
            ok = False
        stretch = big_l[i] - small_l[i]
        eps = stretch / small_l[i]
        t_el = ea * eps
        eps_rate = 0.0
        t_d = 0.0
        if damping != 0.0:
            eps_rate = (big_l_rate[i] - (1.0 + eps) * small_l_rate[i]) / small_l[i]
            t_d = damping * eps_rate
        trial[i] = t_el + t_d
        elastic[i] = t_el
        if broken[i]:
            continue
        if taut[i]:
            tension[i] = t_el + t_d
            on_unstretched[i] = t_el * (1.0 + 0.5 * eps) + t_d * (1.0 + eps)
            energy[i] = 0.5 * t_el * stretch
            loss += t_d * small_l[i] * eps_rate
        elif stretch > 0.0:  # slack but still stretched: its strain drains, never negative
            energy[i] = 0.5 * t_el * stretch
            strain_rate = t_el * big_l_rate[i] - t_el * (1.0 + 0.5 * eps) * small_l_rate[i]
            loss += max(-strain_rate, 0.0)
    body_force = -_vecmat(tension, jac)
    generalised = _vecmat(on_unstretched, flow)
    forces = generalised[:n].copy()
    potential = 0.0
    depth = np.zeros(nb)
    trial_contact = np.zeros(nb)
    for j in range(nb):
        weight = blocks[j, 0]
        forces[j] += body_force[j] + weight
        potential -= weight * x[j]
        stiffness = blocks[j, 3]
        if stiffness > 0.0:
            depth[j] = blocks[j, 2] - (blocks[j, 1] + x[j])
            elastic_force = stiffness * depth[j]
            damping_force = -blocks[j, 4] * x[n + j]
            trial_contact[j] = elastic_force + damping_force
            if contact[j]:
                forces[j] += trial_contact[j]
                potential += 0.5 * elastic_force * depth[j]
                loss += -damping_force * x[n + j]
            elif depth[j] > 0.0:  # lifting off faster than the pad recovers: it drains
                potential += 0.5 * elastic_force * depth[j]
                loss += stiffness * depth[j] * x[n + j]
    line_force = generalised[n:]
    power = -(line_force[0] * line_rate[0] + line_force[1] * line_rate[1])
    for j in range(nd):
        power -= body_force[nb + j] * ydot[nb + j]
    return (
        forces,
        tension,
        trial,
        elastic,
        big_l - small_l,
        line_force,
        body_force,
        depth,
        trial_contact,
        energy,
        potential,
        loss,
        power,
        ok,
    )


@jit
def rhs(t: float, x: np.ndarray, data) -> np.ndarray:
    """State derivative ``[q', v', dissipated', external work']``; NaN where a span runs out.

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State (see :func:`evaluate`).
    data : tuple
        See the module docstring.
    """
    n = data[0][0]
    masses = data[2]
    result = evaluate(t, x, data)
    forces, loss, power = result[0], result[11], result[12]
    out = np.empty_like(x)
    for i in range(n):
        out[i] = x[n + i]
        out[n + i] = forces[i] / masses[i]
    out[2 * n] = loss
    out[2 * n + 1] = power
    if not result[13]:
        out[:] = math.nan
    return out


@jit
def guards(t: float, x: np.ndarray, data) -> np.ndarray:
    """Slack/taut ropes, floor contact and rope break, each firing below zero (N).

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State (see :func:`evaluate`).
    data : tuple
        See the module docstring.
    """
    breaking_load = data[1][2]
    blocks, taut, broken, contact = data[6], data[8], data[9], data[10]
    result = evaluate(t, x, data)
    tension, trial, elastic, depth, trial_contact = (
        result[1],
        result[2],
        result[3],
        result[7],
        result[8],
    )
    n_spans, nb = tension.size, depth.size
    out = np.empty(2 * n_spans + nb)
    for i in range(n_spans):
        if broken[i]:
            out[i] = 1.0
        elif taut[i]:
            out[i] = trial[i]
        else:
            out[i] = max(-elastic[i], -trial[i])
        margin = breaking_load - tension[i]
        out[n_spans + nb + i] = margin if math.isfinite(margin) else 1.0
    for j in range(nb):
        stiffness = blocks[j, 3]
        if stiffness <= 0.0:
            out[n_spans + j] = 1.0
        elif contact[j]:
            out[n_spans + j] = trial_contact[j]
        else:
            out[n_spans + j] = max(-stiffness * depth[j], -trial_contact[j])
    return out


@jit
def summary(t: float, x: np.ndarray, data) -> np.ndarray:
    """What the outputs need, in one array (one crossing back to Python).

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State (see :func:`evaluate`).
    data : tuple
        See the module docstring.

    Returns
    -------
    numpy.ndarray
        Rope strain energy (J), potential energy (J), span tensions (N), forces on the
        bodies (N); the first entry is NaN when a span has no unstretched rope left
        (or a segment no tangent).
    """
    result = evaluate(t, x, data)
    tension, body_force, energy = result[1], result[6], result[9]
    out = np.empty(2 + tension.size + body_force.size)
    out[0] = energy.sum() if result[13] else math.nan
    out[1] = result[10]
    out[2 : 2 + tension.size] = tension
    out[2 + tension.size :] = body_force
    return out


@jit
def project(x: np.ndarray, data) -> np.ndarray:
    """No invariants without friction links: ``x`` as it is.

    Parameters
    ----------
    x : numpy.ndarray
        State.
    data : tuple
        See the module docstring.
    """
    return x


@jit
def advance(method, t0, t1, n, k, t, x, directions, tol, data):
    """:func:`~wire_fmu.core.framework.compiled_step.advance_to_event` over this kernel.

    Parameters
    ----------
    method, t0, t1, n, k, t, x, directions, tol, data
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    """
    return advance_to_event(rhs, guards, project, method, t0, t1, n, k, t, x, directions, tol, data)


@jit
def quiet_step(method, t0, t1, n, tol, x, directions, data, held):
    """A whole communication step in one call, when the new inputs switch no mode.

    What :meth:`BlockTrainModel.advance
    <wire_fmu.core.units.block_train.model.BlockTrainModel.advance>` does, in the same
    order and with the same arithmetic: the strain energy the inputs' jump puts into
    the rope booked as external work, then the loop of :func:`advance` up to the end
    of the step or its first event, then the outputs' :func:`summary` at the end.
    It changes nothing it was given.

    Parameters
    ----------
    method, t0, t1, n, tol, directions
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them
        (the loop starts at ``t0``, interval 0).
    x : numpy.ndarray
        State at ``t0``.
    data : tuple
        See the module docstring; its held inputs are those of the last step.
    held : numpy.ndarray
        The held inputs from ``t0`` on (layout of ``data[11]``).

    Returns
    -------
    tuple
        The loop's ``(status, x, t, k, fired, steps, rhs_calls, h)`` and the
        :func:`summary` at ``t1`` (empty unless the status is ``STATUS_DONE``). The
        status is :data:`STATUS_PYTHON`, and nothing else meaningful, when a span or
        floor is in the wrong mode for the new inputs, a span has no unstretched
        rope or a segment no tangent: Python then takes the step.
    """
    new = (
        data[0],
        data[1],
        data[2],
        data[3],
        data[4],
        data[5],
        data[6],
        data[7],
        data[8],
        data[9],
        data[10],
        held,
        data[12],
        data[13],
        data[14],
        data[15],
        data[16],
    )
    no_fire = np.zeros(directions.size, dtype=np.bool_)
    no_summary = np.zeros(0)
    before = evaluate(t0, x, data)
    after = evaluate(t0, x, new)
    if not (before[13] and after[13]):
        return STATUS_PYTHON, x, t0, 0, no_fire, 0, 0, 0.0, no_summary
    g = guards(t0, x, new)
    for i in range(data[3].size + data[0][1]):  # the spans' and floors' mode guards
        if g[i] < 0.0:
            return STATUS_PYTHON, x, t0, 0, no_fire, 0, 0, 0.0, no_summary
    x = x.copy()
    x[2 * data[0][0] + 1] += after[9].sum() - before[9].sum()
    status, x, t, k, fired, steps, calls, h = advance_to_event(
        rhs, guards, project, method, t0, t1, n, 0, t0, x, directions, tol, new
    )
    if status == STATUS_DONE:
        return status, x, t, k, fired, steps, calls, h, summary(t1, x, new)
    return status, x, t, k, fired, steps, calls, h, no_summary
