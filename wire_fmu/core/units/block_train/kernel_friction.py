"""The block train's friction links in compiled form: bearings and grooves that stick.

The arithmetic of :class:`~wire_fmu.core.components.friction.StickSlip` (its
``accelerations``, ``loss_power`` and ``guards``) with the capacities of
:meth:`BlockTrainModel._capacities
<wire_fmu.core.units.block_train.model.BlockTrainModel._capacities>`, operation for
operation, over the flat arrays :func:`friction_data` adds to the kernel's tuple
(indices 17-24 of :mod:`~wire_fmu.core.units.block_train.kernel`):

=====  ===================  =================================================
index  name                 contents
=====  ===================  =================================================
17     ``link_index``       int, per link: body, partner (-1: ground), span
                            running onto and off its sheave
18     ``link_params``      per link: bearing torque over radius (N), bearing
                            coefficient ``(1 - e) / (1 + e)``, capstan factor
                            ``exp(mu theta) - 1`` (1)
19     ``link_mode``        int, per link: 0 stuck, +1/-1 sliding direction
20     ``clusters``         int, per group of coordinates joined by stuck links:
                            first and end member, first and end edge, grounded
21     ``members``          int: the groups' coordinates, each group sorted
22     ``edges``            int, per stuck link: link, child, parent (-1: the
                            ground), leaves first within each group
23     ``held_positions``   per coordinate, where it stuck (m)
24     ``grounded``         int: coordinates held to the ground, sorted
=====  ===================  =================================================

The groups and their edges are :func:`~wire_fmu.core.components.friction.StickSlip`'s
plan for the present modes; they change only when a mode switches, which Python does.
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators

jit = kernel_decorators(__file__).jit

__all__ = [
    "friction_data",
    "link_guards",
    "link_losses",
    "loss_power",
    "stick_slip",
]

GROUND = -1


def friction_data(model) -> tuple:
    """Indices 17-24 of the kernel's tuple, from ``model``'s present links and modes.

    Parameters
    ----------
    model : BlockTrainModel
        The block train.
    """
    clusters, members, edges, grounded = model.friction.plan_arrays()
    return (
        model.kernel_link_index,
        model.kernel_link_params,
        model.friction.mode,
        clusters,
        members,
        edges,
        model._held_positions,
        grounded,
    )


@jit
def stick_slip(acc: np.ndarray, forces: np.ndarray, tension: np.ndarray, masses: np.ndarray, data):
    """The links' capacities and forces (N), and the accelerations (m/s^2) into ``acc``, in
    the present modes, with one array made for all the scratch they need.

    Parameters
    ----------
    acc : numpy.ndarray
        Where the acceleration of each coordinate goes (a coordinate's row of the state
        derivative, or scratch), m/s^2.
    forces : numpy.ndarray
        All forces on the coordinates but the links' friction, N.
    tension : numpy.ndarray
        Span tensions, N.
    masses : numpy.ndarray
        Mass of each coordinate, kg.
    data : tuple
        The kernel's tuple (see the module docstring).

    Returns
    -------
    tuple of numpy.ndarray
        The holding capacity of every link and the force of every link, N.
    """
    index, params, mode, clusters, members, edges = data[17:23]
    n_links, n = index.shape[0], forces.size
    # each array made costs more than the sums it holds: one for the four
    work = np.empty(2 * n_links + 2 * n)
    caps, link_force = work[:n_links], work[n_links : 2 * n_links]
    total, required = work[2 * n_links : 2 * n_links + n], work[2 * n_links + n :]
    # the callees take the arrays they read, not the tuple: a call that is not inlined
    # passes every array of its arguments
    _capacities_into(caps, tension, index, params)
    _accelerations_into(
        acc,
        link_force,
        total,
        required,
        forces,
        caps,
        masses,
        index,
        mode,
        clusters,
        members,
        edges,
    )
    return caps, link_force


@jit
def _capacities_into(
    caps: np.ndarray, tension: np.ndarray, index: np.ndarray, params: np.ndarray
) -> None:
    """Holding capacity of every link from the tensions of its two spans into ``caps``, N
    (``index`` and ``params``: the module docstring's 17 and 18)."""
    for k in range(index.shape[0]):
        t_in = tension[index[k, 2]]
        t_out = tension[index[k, 3]]
        caps[k] = params[k, 0] + params[k, 1] * (t_in + t_out) + params[k, 2] * min(t_in, t_out)


@jit
def _accelerations_into(
    acc: np.ndarray,
    link_force: np.ndarray,
    total: np.ndarray,
    required: np.ndarray,
    forces: np.ndarray,
    caps: np.ndarray,
    masses: np.ndarray,
    index: np.ndarray,
    mode: np.ndarray,
    clusters: np.ndarray,
    members: np.ndarray,
    edges: np.ndarray,
) -> None:
    """Accelerations (m/s^2) into ``acc`` and the link forces (N) into ``link_force``, in
    the present modes (``total`` and ``required``: scratch, one entry per coordinate;
    ``index`` to ``edges``: the module docstring's 17 and 19 to 22)."""
    total[:] = forces
    required[:] = 0.0
    link_force[:] = 0.0
    for k in range(index.shape[0]):
        if mode[k] != 0:
            f = -mode[k] * caps[k]
            link_force[k] = f
            total[index[k, 0]] += f
            if index[k, 1] != GROUND:
                total[index[k, 1]] -= f
    for i in range(forces.size):
        acc[i] = total[i] / masses[i]
    for c in range(clusters.shape[0]):
        first, end = clusters[c, 0], clusters[c, 1]
        a = 0.0
        if not clusters[c, 4]:
            force_sum = 0.0
            mass_sum = 0.0
            for m in range(first, end):
                force_sum += total[members[m]]
            for m in range(first, end):
                mass_sum += masses[members[m]]
            a = force_sum / mass_sum
        for m in range(first, end):
            i = members[m]
            acc[i] = a
            required[i] = masses[i] * a - total[i]
        for e in range(clusters[c, 2], clusters[c, 3]):
            k, child, parent = edges[e, 0], edges[e, 1], edges[e, 2]
            carried = required[child]
            link_force[k] = carried if index[k, 0] == child else -carried
            if parent != GROUND:
                required[parent] += carried


@jit
def _relative_velocity(x: np.ndarray, n: int, index: np.ndarray, k: int) -> float:
    """Velocity of link ``k``'s body relative to its partner, m/s."""
    rel = x[n + index[k, 0]]
    if index[k, 1] != GROUND:
        rel -= x[n + index[k, 1]]
    return rel


@jit
def loss_power(x: np.ndarray, n: int, link_force: np.ndarray, data) -> float:
    """Power dissipated by the sliding links, W.

    Parameters
    ----------
    x : numpy.ndarray
        State ``[q, v, ...]``.
    n : int
        Number of coordinates.
    link_force : numpy.ndarray
        Link forces from :func:`accelerations_into`, N.
    data : tuple
        The kernel's tuple (see the module docstring).
    """
    index, mode = data[17], data[19]
    total = 0.0
    for k in range(index.shape[0]):
        if mode[k] != 0:
            total -= link_force[k] * _relative_velocity(x, n, index, k)
    return total


@jit
def link_losses(x: np.ndarray, n: int, link_force: np.ndarray, out: np.ndarray, data) -> None:
    """Write the power each link dissipates into ``out`` (W; 0 while stuck).

    Parameters
    ----------
    x : numpy.ndarray
        State ``[q, v, ...]``.
    n : int
        Number of coordinates.
    link_force : numpy.ndarray
        Link forces from :func:`accelerations_into`, N.
    out : numpy.ndarray
        One entry per link, written in place.
    data : tuple
        The kernel's tuple (see the module docstring).
    """
    index, mode = data[17], data[19]
    for k in range(index.shape[0]):
        out[k] = 0.0
        if mode[k] != 0:
            out[k] = -link_force[k] * _relative_velocity(x, n, index, k)


@jit
def link_guards(x: np.ndarray, n: int, link_force: np.ndarray, caps: np.ndarray, out, data):
    """Write each link's guard into ``out[:links]``: capacity left if stuck, else slip speed.

    Parameters
    ----------
    x : numpy.ndarray
        State ``[q, v, ...]``.
    n : int
        Number of coordinates.
    link_force, caps : numpy.ndarray
        Link forces and capacities, N.
    out : numpy.ndarray
        The guards, written in place (N for stuck links, m/s for sliding ones).
    data : tuple
        The kernel's tuple (see the module docstring).
    """
    index, mode = data[17], data[19]
    for k in range(index.shape[0]):
        if mode[k] == 0:
            out[k] = caps[k] - abs(link_force[k])
        else:
            out[k] = mode[k] * _relative_velocity(x, n, index, k)
