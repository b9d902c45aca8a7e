"""The block train's compiled kernel: its equations as plain functions over flat arrays.

The same physics as :meth:`BlockTrainModel.evaluate
<wire_fmu.core.units.block_train.model.BlockTrainModel.evaluate>` and ``rhs`` (the
readable numpy reference), for block trains whose segment lengths are either linear
in the body motion (no ``moving_geometry``) or follow the planar tangent geometry
(``moving_geometry`` without ``spatial_geometry``, :mod:`.kernel_geometry`), with or
without friction links (``bearing_friction``, ``rope_slip``:
:mod:`.kernel_friction`); block trains with spatial moving geometry run the Python
kernel. Everything a step needs is in one tuple of arrays, built by
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
                           velocities (m/s), the line rates' and the mover
                           velocities' accelerations (m/s², a ramped flow)
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
17-24  friction links      see :mod:`.kernel_friction`
25     ``jacobian``        the Jacobian's bordered band structure
                           (:func:`.kernel_jacobian.jacobian_structure`)
26     ``flow_columns``    int, per span: the columns of ``flow`` that are not
                           zero (at most one per span end), padded with -1
27     ``flow_values``     per span: those entries of ``flow``
=====  ==================  ==================================================

ROS2 runs on that structure (:func:`linearise`, :func:`factor`, :func:`solve`): a
few evaluations and a banded solve per Jacobian, whatever the number of lines.

The guards are in the order of :meth:`ModeSwitching.guards
<wire_fmu.core.units.block_train.modes.ModeSwitching.guards>`: friction links
first, then spans, floors and breaking loads. Mode switches are Python's: the
kernel reads the present modes from the tuple.
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.framework import bordered_band
from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.framework.compiled_step import STATUS_DONE, STATUS_PYTHON, advance_structured
from wire_fmu.core.units.block_train.kernel_friction import (
    friction_data,
    link_guards,
    link_losses,
    loss_power,
    stick_slip,
)
from wire_fmu.core.units.block_train.kernel_geometry import segment_lengths, span_geometry
from wire_fmu.core.units.block_train.kernel_jacobian import coloured_jacobian

jit, jit_inline = kernel_decorators(__file__)

__all__ = [
    "advance",
    "evaluate",
    "factor",
    "guards",
    "held_motion",
    "kernel_data",
    "linearise",
    "project",
    "quiet_step",
    "rhs",
    "rhs_parts",
    "solve",
    "segment_lengths",
    "span_geometry",
    "summary",
]

N_LINES = 2


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
        *friction_data(model),
        model.kernel_jacobian_structure,
        model.kernel_flow_columns,
        model.kernel_flow_values,
    )


@jit
def _matvec_into(out: np.ndarray, a: np.ndarray, v: np.ndarray) -> None:
    """``out += a @ v`` by loops (sizes of a few; no BLAS call for empty shapes): ``a @ v``
    into ``out`` of zeros."""
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            out[i] += a[i, j] * v[j]


@jit
def _flow_matvec_into(out: np.ndarray, columns: np.ndarray, values: np.ndarray, v: np.ndarray):
    """``out += flow @ v`` over the non-zero entries of ``flow`` (the same sums as
    :func:`_matvec_into`)."""
    for i in range(columns.shape[0]):
        for k in range(columns.shape[1]):
            if columns[i, k] >= 0:
                out[i] += values[i, k] * v[columns[i, k]]


@jit
def _flow_vecmat_into(out: np.ndarray, w: np.ndarray, columns: np.ndarray, values: np.ndarray):
    """``out += w @ flow`` over the non-zero entries of ``flow`` (the same sums as
    :func:`_vecmat_into`)."""
    for i in range(columns.shape[0]):
        for k in range(columns.shape[1]):
            if columns[i, k] >= 0:
                out[columns[i, k]] += w[i] * values[i, k]


@jit
def _vecmat_into(out: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
    """``out += v @ a`` by loops."""
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            out[j] += v[i] * a[i, j]


@jit
def held_motion(held: np.ndarray, port: int, mover: bool, nd: int, dt: float) -> tuple:
    """A held port input's position and rate ``dt`` into the step (one port of
    :meth:`BlockTrainModel.held_motion`, without an array).

    Parameters
    ----------
    held : numpy.ndarray
        The held inputs (the module docstring's index 11).
    port : int
        The line (0, 1) or the driven body (0 .. ``nd`` - 1).
    mover : bool
        Whether ``port`` is a driven body.
    nd : int
        Number of driven bodies.
    dt : float
        Time since the inputs hold, s.

    Returns
    -------
    tuple of float
        Its position (m) and rate (m/s): the rate ramps with its acceleration from the
        step's start, the position advances with the rate.
    """
    if mover:
        at, rate_at = 1 + 2 * N_LINES + port, 1 + 2 * N_LINES + nd + port
        ramp_at = 1 + 2 * N_LINES + 2 * nd + N_LINES + port
    else:
        at, rate_at, ramp_at = 1 + port, 1 + N_LINES + port, 1 + 2 * N_LINES + 2 * nd + port
    rate, acceleration = held[rate_at], held[ramp_at]
    return held[at] + (rate + 0.5 * acceleration * dt) * dt, rate + acceleration * dt


@jit
def _row(rows: np.ndarray, start: int, length: int, i: int) -> np.ndarray:
    """Row ``i`` of the block of rows of ``length`` entries from ``start`` in ``rows``:
    ``rows[start:].reshape((-1, length))[i]`` as a slice."""
    return rows[start + i * length : start + (i + 1) * length]


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
        (J), ``loss`` (W), external ``power`` (W), ``ok`` (False when a span has no
        unstretched rope left, or a segment no tangent), the span lengths' Jacobian
        ``dL/dy`` (spans x bodies, 1), each span's share of ``loss`` (W) and its force
        on the unstretched rope (N).
    """
    sizes, rope, len0, jac0, blocks = data[0], data[1], data[3], data[4], data[6]
    flow_columns, flow_values = data[26], data[27]
    offsets, taut, broken, contact, held = data[7:12]
    n, nb, nd = sizes[0], sizes[1], sizes[2]
    ea, damping = rope[0], rope[1]
    n_spans = len0.size
    dt = t - held[0]
    # one array of rows rather than a score of small arrays (each costs more to make and
    # free than its arithmetic), in four blocks: per body, per rope coordinate, per span,
    # per block; each row a slice of it (a reshape is a call into numba's runtime)
    nbd, nf = nb + nd, n + N_LINES
    rows = np.zeros(3 * nbd + 3 * nf + 11 * n_spans + 2 * nb)
    at_flows, at_spans = 3 * nbd, 3 * (nbd + nf)
    at_contacts = at_spans + 11 * n_spans
    y, ydot, body_force = _row(rows, 0, nbd, 0), _row(rows, 0, nbd, 1), _row(rows, 0, nbd, 2)
    for j in range(nb):
        y[j] = x[j]
        ydot[j] = x[n + j]
    for j in range(nd):
        y[nb + j], ydot[nb + j] = held_motion(held, j, True, nd, dt)
    flow_q, flow_v = _row(rows, at_flows, nf, 0), _row(rows, at_flows, nf, 1)
    generalised = _row(rows, at_flows, nf, 2)
    for i in range(n):
        flow_q[i] = x[i]
        flow_v[i] = x[n + i]
    for i in range(N_LINES):
        flow_q[n + i], flow_v[n + i] = held_motion(held, i, False, nd, dt)
    big_l_rate, small_l = _row(rows, at_spans, n_spans, 1), _row(rows, at_spans, n_spans, 2)
    small_l_rate = _row(rows, at_spans, n_spans, 3)
    stretch_of, tension = _row(rows, at_spans, n_spans, 4), _row(rows, at_spans, n_spans, 5)
    trial, elastic = _row(rows, at_spans, n_spans, 6), _row(rows, at_spans, n_spans, 7)
    on_unstretched = _row(rows, at_spans, n_spans, 8)
    energy, span_loss = _row(rows, at_spans, n_spans, 9), _row(rows, at_spans, n_spans, 10)
    if sizes[3]:
        big_l, jac, ok = span_geometry(y, data)
    else:
        big_l, jac, ok = _row(rows, at_spans, n_spans, 0), jac0, True
        _matvec_into(big_l, jac0, y)
        for i in range(n_spans):
            big_l[i] = len0[i] + big_l[i]
    _matvec_into(big_l_rate, jac, ydot)
    _flow_matvec_into(small_l, flow_columns, flow_values, flow_q)
    for i in range(n_spans):
        small_l[i] = offsets[i] + small_l[i]
    _flow_matvec_into(small_l_rate, flow_columns, flow_values, flow_v)
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
            span_loss[i] = t_d * small_l[i] * eps_rate
            loss += span_loss[i]
        elif stretch > 0.0:  # slack but still stretched: its strain drains, never negative
            energy[i] = 0.5 * t_el * stretch
            strain_rate = t_el * big_l_rate[i] - t_el * (1.0 + 0.5 * eps) * small_l_rate[i]
            span_loss[i] = max(-strain_rate, 0.0)
            loss += span_loss[i]
    _vecmat_into(body_force, tension, jac)
    for j in range(nb + nd):
        body_force[j] = -body_force[j]
    _flow_vecmat_into(generalised, on_unstretched, flow_columns, flow_values)
    forces = generalised[:n]  # the line ends' part is read as it is, below
    potential = 0.0
    depth, trial_contact = _row(rows, at_contacts, nb, 0), _row(rows, at_contacts, nb, 1)
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
    power = -(line_force[0] * flow_v[n] + line_force[1] * flow_v[n + 1])
    for j in range(nd):
        power -= body_force[nb + j] * ydot[nb + j]
    for i in range(n_spans):
        stretch_of[i] = big_l[i] - small_l[i]
    return (
        forces,
        tension,
        trial,
        elastic,
        stretch_of,
        line_force,
        body_force,
        depth,
        trial_contact,
        energy,
        potential,
        loss,
        power,
        ok,
        jac,
        span_loss,
        on_unstretched,
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
    return _rhs_of(evaluate(t, x, data), x, data)[0]


@jit
def rhs_parts(t: float, x: np.ndarray, data):
    """:func:`rhs` and the local pieces its coupled rows are sums of, from one evaluation.

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
    tuple
        The state derivative; per span its tension (N), its share of the dissipated
        power and of the external power (W); ``dL/dy`` (spans x bodies); per friction
        link the power it dissipates (W).
    """
    n, nb, nd = data[0][0], data[0][1], data[0][2]
    flow, held = data[5], data[11]
    result = evaluate(t, x, data)
    tension, jac, on_unstretched = result[1], result[14], result[16]
    dt = t - held[0]
    line_rate = np.empty(N_LINES)
    for line in range(N_LINES):
        line_rate[line] = held_motion(held, line, False, nd, dt)[1]
    mover_v = np.empty(nd)
    for j in range(nd):
        mover_v[j] = held_motion(held, j, True, nd, dt)[1]
    span_power = np.empty(tension.size)
    for i in range(tension.size):
        p = 0.0
        for line in range(N_LINES):
            p -= on_unstretched[i] * flow[i, n + line] * line_rate[line]
        for j in range(nd):
            p += tension[i] * jac[i, nb + j] * mover_v[j]
        span_power[i] = p
    out, link_force, _ = _rhs_of(result, x, data)
    link_loss = np.zeros(link_force.size)
    link_losses(x, n, link_force, link_loss, data)
    return out, tension, result[15], span_power, jac, link_loss


@jit
def _rhs_of(result, x: np.ndarray, data):
    """:func:`rhs` from :func:`evaluate`'s ``result`` at state ``x``, and the link forces
    and capacities (N; none without friction links)."""
    n = data[0][0]
    masses = data[2]
    forces, loss, power = result[0], result[11], result[12]
    out = np.empty_like(x)
    for i in range(n):
        out[i] = x[n + i]
    if data[17].shape[0] == 0:
        link_force = caps = out[:0]  # no links, no forces: a view, nothing made
        for i in range(n):
            out[n + i] = forces[i] / masses[i]
    else:
        caps, link_force = stick_slip(out[n : 2 * n], forces, result[1], masses, data)
        for i in data[24]:
            out[i] = 0.0
        loss = loss + loss_power(x, n, link_force, data)
    out[2 * n] = loss
    out[2 * n + 1] = power
    if not result[13]:
        out[:] = math.nan
    return out, link_force, caps


@jit
def rhs_guards(t: float, x: np.ndarray, data) -> tuple:
    """:func:`rhs` and :func:`guards` at ``(t, x)`` from one :func:`evaluate` and one
    solve of the friction links.

    Parameters
    ----------
    t, x, data
        As :func:`rhs` takes them.
    """
    result = evaluate(t, x, data)
    out, link_force, caps = _rhs_of(result, x, data)
    return out, _guards_with(result, x, data, caps, link_force)


@jit
def guards(t: float, x: np.ndarray, data) -> np.ndarray:
    """Friction links, slack/taut ropes, floor contact and rope break, each firing below zero.

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State (see :func:`evaluate`).
    data : tuple
        See the module docstring.
    """
    return _guards_of(evaluate(t, x, data), x, data)


@jit
def _guards_of(result, x: np.ndarray, data) -> np.ndarray:
    """:func:`guards` from :func:`evaluate`'s ``result`` at state ``x``."""
    tension = result[1]
    if data[17].shape[0] == 0:
        return _guards_with(result, x, data, tension[:0], tension[:0])
    scratch = np.empty(data[0][0])  # the accelerations, not needed here
    caps, link_force = stick_slip(scratch, result[0], tension, data[2], data)
    return _guards_with(result, x, data, caps, link_force)


@jit
def _guards_with(
    result, x: np.ndarray, data, caps: np.ndarray, link_force: np.ndarray
) -> np.ndarray:
    """:func:`guards` from :func:`evaluate`'s ``result`` at state ``x`` and the friction
    links' capacities and forces there (N; empty without links)."""
    breaking_load = data[1][2]
    blocks, taut, broken, contact = data[6], data[8], data[9], data[10]
    tension, trial, elastic, depth, trial_contact = (
        result[1],
        result[2],
        result[3],
        result[7],
        result[8],
    )
    n_links, n_spans, nb = data[17].shape[0], tension.size, depth.size
    out = np.empty(n_links + 2 * n_spans + nb)
    if n_links:
        link_guards(x, data[0][0], link_force, caps, out, data)
    for i in range(n_spans):
        if broken[i]:
            out[n_links + i] = 1.0
        elif taut[i]:
            out[n_links + i] = trial[i]
        else:
            out[n_links + i] = max(-elastic[i], -trial[i])
        margin = breaking_load - tension[i]
        out[n_links + n_spans + nb + i] = margin if math.isfinite(margin) else 1.0
    for j in range(nb):
        stiffness = blocks[j, 3]
        if stiffness <= 0.0:
            out[n_links + n_spans + j] = 1.0
        elif contact[j]:
            out[n_links + n_spans + j] = trial_contact[j]
        else:
            out[n_links + n_spans + j] = max(-stiffness * depth[j], -trial_contact[j])
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
    """Hold the coordinates stuck to the ground where they stuck, at rest (in place).

    Parameters
    ----------
    x : numpy.ndarray
        State.
    data : tuple
        See the module docstring.
    """
    n = data[0][0]
    held_positions = data[23]
    for i in data[24]:
        x[i] = held_positions[i]
        x[n + i] = 0.0
    return x


@jit_inline
def linearise(rhs_function, t: float, x: np.ndarray, data):
    """The Jacobian in bordered band form and its evaluations (:func:`.coloured_jacobian`).

    Parameters
    ----------
    rhs_function : callable
        Unused: the Jacobian is taken from :func:`rhs_parts`.
    t, x, data
        As :func:`rhs` takes them.
    """
    return coloured_jacobian(rhs_parts, t, x, data, data[25], data[2])


@jit
def unlinearised(data) -> tuple:
    """No Jacobian yet, of the type :func:`linearise` gives."""
    return bordered_band.empty_jacobian()


@jit
def factor(jac: tuple, gh: float, data) -> tuple:
    """Factors of ``I - gh J`` (:func:`~wire_fmu.core.framework.bordered_band.factor`)."""
    return bordered_band.factor(jac, gh, data[25])


@jit
def solve(fac: tuple, b: np.ndarray, data) -> np.ndarray:
    """``(I - gh J)^-1 b`` (:func:`~wire_fmu.core.framework.bordered_band.solve`)."""
    return bordered_band.solve(fac, b, data[25])


@jit
def advance(method, t0, t1, n, k, t, x, directions, tol, data):
    """:func:`~wire_fmu.core.framework.compiled_step.advance_structured` over this kernel.

    Parameters
    ----------
    method, t0, t1, n, k, t, x, directions, tol, data
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    """
    return advance_structured(
        rhs,
        guards,
        rhs_guards,
        project,
        linearise,
        unlinearised,
        factor,
        solve,
        method,
        t0,
        t1,
        n,
        k,
        t,
        x,
        directions,
        tol,
        data,
    )


@jit
def quiet_step(method, t0, t1, n, tol, x, directions, data, held, k, t, resume):
    """A whole communication step in one call, when the new inputs switch no mode.

    What :meth:`BlockTrainModel.advance
    <wire_fmu.core.units.block_train.model.BlockTrainModel.advance>` does, in the same
    order and with the same arithmetic: the strain energy the inputs' jump puts into
    the rope booked as external work, the coordinates stuck to the ground held where
    they are, then the loop of :func:`advance` up to the end
    of the step or its first event, then the outputs' :func:`summary` at the end.
    It changes nothing it was given.

    With ``resume`` it is :func:`advance` from ``(k, t, x)`` instead, without the
    summary (the loop going on after an event Python switched, ``data`` as the model
    holds it, ``held`` unused). Python calls it for both through the block train's one
    entry point, :func:`.kernel_outputs.quiet_step_outputs`, so that one compiled
    function is loaded from the cache, not two.

    Parameters
    ----------
    method, t0, t1, n, tol, directions
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    x : numpy.ndarray
        State at ``t0`` (at ``t`` with ``resume``).
    data : tuple
        See the module docstring; its held inputs are those of the last step.
    held : numpy.ndarray
        The held inputs from ``t0`` on (layout of ``data[11]``).
    k : int
        With ``resume``: the interval ``t`` lies in (else 0).
    t : float
        With ``resume``: the time the loop goes on from, s (else ``t0``).
    resume : bool
        Go on with :func:`advance` from ``(k, t, x)``, nothing else.

    Returns
    -------
    tuple
        The loop's ``(status, x, t, k, fired, steps, rhs_calls, h)`` and the
        :func:`summary` at ``t1`` (empty unless the status is ``STATUS_DONE``). The
        status is :data:`STATUS_PYTHON`, and nothing else meaningful, when a span or
        floor is in the wrong mode for the new inputs, a stuck link cannot hold under
        them, a span has no unstretched rope or a segment no tangent: Python then
        takes the step.
    """
    if resume:
        status, x, t, k, fired, steps, calls, h = advance(
            method, t0, t1, n, k, t, x, directions, tol, data
        )
        return status, x, t, k, fired, steps, calls, h, np.zeros(0)
    n_coords, n_links = data[0][0], data[17].shape[0]
    # the held inputs from t0 on, and a stuck coordinate held where the step starts
    # data as the model holds it after the step's start: held inputs (11), held positions (23)
    new = data[:11] + (held,) + data[12:23] + (x[:n_coords].copy(),) + data[24:]
    no_fire = np.zeros(directions.size, dtype=np.bool_)
    no_summary = np.zeros(0)
    before = evaluate(t0, x, data)
    after = evaluate(t0, x, new)
    if not (before[13] and after[13]):
        return STATUS_PYTHON, x, t0, 0, no_fire, 0, 0, 0.0, no_summary
    g = _guards_of(after, x, new)  # guards(t0, x, new), from the evaluation just made
    for i in range(n_links + data[3].size + data[0][1]):  # links, spans and floors
        if g[i] < 0.0 and (i >= n_links or data[19][i] == 0):
            return STATUS_PYTHON, x, t0, 0, no_fire, 0, 0, 0.0, no_summary
    x = x.copy()
    x[2 * n_coords + 1] += after[9].sum() - before[9].sum()
    x = project(x, new)
    status, x, t, k, fired, steps, calls, h = advance(
        method, t0, t1, n, 0, t0, x, directions, tol, new
    )
    if status == STATUS_DONE:
        return status, x, t, k, fired, steps, calls, h, summary(t1, x, new)
    return status, x, t, k, fired, steps, calls, h, no_summary
