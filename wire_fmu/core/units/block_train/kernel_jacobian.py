"""The block train's Jacobian for ROS2 in time linear in the reeving's size.

Each rope coordinate (a rim, or the rope on its groove) acts on its neighbours
along the path only, through the springs of the spans it bounds and the friction
links of its sheave; the blocks act on, and feel, every span that ends on them.
:func:`jacobian_structure` writes this down once, when the block train is built,
as a :class:`~wire_fmu.core.framework.sparse_pattern.BandStructure`: positions and
velocities of the rope coordinates in a narrow band, the blocks' as its border,
and the band's columns coloured so that columns of one colour share no row and no
span. :func:`coloured_jacobian` then takes one evaluation per colour (a few, however
many lines) and one per block coordinate, instead of one per state:

- a band row reads its entry from the change of its own derivative;
- a block's acceleration row reads it from the change of each span's tension
  (``dF_b/dx_j = -sum_s dT_s/dx_j dL_s/dy_b``), since the span geometry depends
  on the bodies only;
- a block's column is a whole forward difference;
- the energy ledgers' rows (nothing depends on them, but their rate depends on
  everything) are sums of local pieces -- each span's damping loss and share of
  the port power, each friction link's loss -- and read from the pieces' changes.

The result is in the form :mod:`~wire_fmu.core.framework.bordered_band` factors
and solves, the ledgers as its tail.

The same function serves both kernels: compiled, over the compiled ``evaluate``;
as plain Python (``coloured_jacobian.py_func`` where numba is installed), over the
readable model's evaluation, so that the kernels take the same steps.
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.components.friction import GROUND
from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.framework.sparse_pattern import BandStructure

jit_inline = kernel_decorators(__file__).jit_inline

__all__ = ["coloured_jacobian", "jacobian_structure"]


def _link_groups(n: int, link_pairs: list[tuple[int, int]]) -> list[set[int]]:
    """Per coordinate, those it may be stuck to (its group under any links), itself included."""
    parent = list(range(n))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for body, other in link_pairs:
        if other != GROUND:
            parent[root(body)] = root(other)
    groups: dict[int, set[int]] = {}
    for i in range(n):
        groups.setdefault(root(i), set()).add(i)
    return [groups[root(i)] for i in range(n)]


def jacobian_structure(model) -> tuple:
    """The bordered band structure of ``model``'s Jacobian, as the kernel reads it.

    Parameters
    ----------
    model : BlockTrainModel
        A built block train (coordinates, spans, flow map and friction links).

    Returns
    -------
    tuple
        :meth:`BandStructure.arrays
        <wire_fmu.core.framework.sparse_pattern.BandStructure.arrays>` (its links:
        the spans, then the friction links) and, per border position, the block
        whose acceleration that row is (-1 for a block's position row).
    """
    n, nb = model.n_coords, len(model.blocks)
    flow = model.flow_matrix[:, :n]
    span_coords = [set(np.flatnonzero(row).tolist()) for row in flow]
    index = model.kernel_link_index
    direct = [set(np.flatnonzero(flow[:, i]).tolist()) for i in range(n)]
    for body, other, span_in, span_out in index:
        for coordinate in (body, other):
            if coordinate != GROUND:
                direct[coordinate] |= {int(span_in), int(span_out)}
    groups = _link_groups(n, [(int(k[0]), int(k[1])) for k in index])
    rows: list[set[int]] = [set() for _ in range(2 * n)]
    for i in range(n):
        rows[i] = {n + i}
        spans = set().union(*(direct[m] for m in groups[i]))
        coords = set().union(set(), *(span_coords[s] for s in spans))
        rows[n + i] = coords | {n + c for c in coords}
    links = [coords | {n + c for c in coords} for coords in span_coords]
    for body, other, span_in, span_out in index:
        coords = span_coords[span_in] | span_coords[span_out] | {int(body)}
        coords |= {int(other)} if other != GROUND else set()
        links.append(coords | {n + c for c in coords})
    border = [state for b in range(nb) for state in (b, n + b)]
    structure = BandStructure.build(rows, links, border)
    border_body = np.array([b if k else -1 for b in range(nb) for k in (0, 1)], dtype=np.int64)
    return (*structure.arrays(), border_body)


@jit_inline
def coloured_jacobian(evaluate, t: float, x: np.ndarray, data, s, masses: np.ndarray):
    """The Jacobian of the state derivative at ``(t, x)`` in bordered band form.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(t, x, data) -> (rhs, tension, span_loss, span_power, dL/dy,
        link_loss)``: the state derivative and its local pieces (the kernel's
        ``rhs_parts``).
    t : float
        Time, s.
    x : numpy.ndarray
        State ``[q, v, dissipated, external work]``.
    data : tuple
        What ``evaluate`` takes.
    s : tuple
        :func:`jacobian_structure`'s arrays.
    masses : numpy.ndarray
        Mass of each coordinate, kg.

    Returns
    -------
    tuple
        ``((band, cols, rows, corner, tail), evaluations)``: the Jacobian as
        :mod:`~wire_fmu.core.framework.bordered_band` takes it (1/s), and the
        number of evaluations made.
    """
    sizes, order, position, start, members, row_hit, link_hit, border_body = s
    mb, nb, kl, ku, colours, n_struct = sizes[0], sizes[1], sizes[2], sizes[3], sizes[4], sizes[5]
    band = np.zeros((mb, kl + ku + 1))
    cols = np.zeros((mb, nb))
    rows = np.zeros((nb, mb))
    corner = np.zeros((nb, nb))
    tail = np.zeros((x.size - n_struct, n_struct))
    f0, tension0, loss0, power0, dl_dy, link_loss0 = evaluate(t, x, data)
    n_spans = tension0.size
    step = np.empty(x.size)
    for j in range(x.size):
        step[j] = 1e-7 * max(1.0, abs(x[j]))
    for c in range(colours):
        xp = x.copy()
        for m in range(start[c], start[c + 1]):
            xp[members[m]] += step[members[m]]
        f, tension, loss, power, _, link_loss = evaluate(t, xp, data)
        first = members[start[c]]
        if position[first] >= mb:  # a block's state: its whole column
            col = position[first] - mb
            for p in range(mb):
                cols[p, col] = (f[order[p]] - f0[order[p]]) / step[first]
            for q in range(nb):
                corner[q, col] = (f[order[mb + q]] - f0[order[mb + q]]) / step[first]
            for r in range(tail.shape[0]):
                tail[r, position[first]] = (f[n_struct + r] - f0[n_struct + r]) / step[first]
            continue
        for p in range(mb):
            j = row_hit[p, c]
            if j >= 0:
                band[p, position[j] - p + kl] = (f[order[p]] - f0[order[p]]) / step[j]
        for k in range(link_hit.shape[0]):
            j = link_hit[k, c]
            if j < 0:
                continue
            if k >= n_spans:  # a friction link: its loss
                tail[0, position[j]] += (link_loss[k - n_spans] - link_loss0[k - n_spans]) / step[j]
                continue
            slope = (tension[k] - tension0[k]) / step[j]
            for q in range(nb):
                b = border_body[q]
                if b >= 0:
                    rows[q, position[j]] -= slope * dl_dy[k, b] / masses[b]
            tail[0, position[j]] += (loss[k] - loss0[k]) / step[j]
            tail[1, position[j]] += (power[k] - power0[k]) / step[j]
    return (band, cols, rows, corner, tail), colours + 1
