"""A Jacobian's sparsity, ordered as a bordered band and coloured for finite differences.

Built once, when a unit is built, from which state each derivative depends on:
:class:`BandStructure` orders the states that couple locally by reverse
Cuthill-McKee (SciPy) so that they form a narrow band, puts the few states that
couple to everything (the border) last, and colours the band's columns so that
columns of one colour share no row and no *link* -- an intermediate quantity
(a rope span's force) through which the border's rows are reached. One
evaluation per colour then gives every band entry of the Jacobian, and the
border rows follow from the links' changes (see the block train's
:mod:`~wire_fmu.core.units.block_train.kernel_jacobian`). The numbers of colours
and the band's widths do not grow with the size of the chain, so neither does the
work per state.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import reverse_cuthill_mckee

__all__ = ["BandStructure"]


@dataclass(frozen=True)
class BandStructure:
    """A bordered band order of a Jacobian and a colouring of its band columns.

    Attributes
    ----------
    order : numpy.ndarray of int
        Position -> state index: the band's states, then the border's.
    band_size : int
        Number of band states ``mb``.
    kl, ku : int
        The band's widths below and above the diagonal, in the order.
    colours : tuple of tuple of int
        State indices perturbed together: the band's colours, then one colour per
        border state.
    row_hit : numpy.ndarray of int, shape (mb, colours)
        For the band row at each position and each colour, the state index of the
        colour's column that row depends on (-1: none).
    link_hit : numpy.ndarray of int, shape (links, colours)
        The same for each link.
    """

    order: np.ndarray
    band_size: int
    kl: int
    ku: int
    colours: tuple[tuple[int, ...], ...]
    row_hit: np.ndarray
    link_hit: np.ndarray

    @classmethod
    def build(
        cls,
        rows: Sequence[set[int]],
        links: Sequence[set[int]],
        border: Sequence[int],
    ) -> BandStructure:
        """Order and colour a Jacobian from its dependencies.

        Parameters
        ----------
        rows : sequence of set of int
            For each state, the states its derivative depends on (the border's
            rows may be left empty: they are reached through the links).
        links : sequence of set of int
            For each link, the states it depends on (border states are ignored).
        border : sequence of int
            The states that couple to (nearly) everything, in the order wanted.
        """
        n = len(rows)
        border = [int(i) for i in border]
        is_border = np.zeros(n, dtype=bool)
        is_border[border] = True
        band = [i for i in range(n) if not is_border[i]]
        order = np.array([*_band_order(rows, band), *border], dtype=np.int64)
        position = np.empty(n, dtype=np.int64)
        position[order] = np.arange(n)
        mb = len(band)
        kl = ku = 0
        for p in range(mb):
            for j in rows[order[p]] | {int(order[p])}:
                if not is_border[j]:
                    kl = max(kl, p - int(position[j]))
                    ku = max(ku, int(position[j]) - p)
        colour_of = _colour(order[:mb], rows, links, is_border)
        count = max(colour_of.values(), default=-1) + 1
        band_colours = [tuple(j for j in order[:mb] if colour_of[j] == c) for c in range(count)]
        colours = (*(tuple(int(j) for j in c) for c in band_colours), *((j,) for j in border))
        row_hit = np.full((mb, len(colours)), -1, dtype=np.int64)
        link_hit = np.full((len(links), len(colours)), -1, dtype=np.int64)
        for p in range(mb):
            for j in rows[order[p]]:
                if not is_border[j]:
                    row_hit[p, colour_of[j]] = j
        for k, link in enumerate(links):
            for j in link:
                if not is_border[j]:
                    link_hit[k, colour_of[j]] = j
        for c in range(count, len(colours)):
            row_hit[:, c] = colours[c][0]
        return cls(order, mb, kl, ku, colours, row_hit, link_hit)

    def arrays(self) -> tuple:
        """The structure as :mod:`~wire_fmu.core.framework.bordered_band` and the colouring
        read it: ``(sizes, order, position, colour_start, colour_members, row_hit,
        link_hit)``."""
        n = self.order.size
        position = np.empty(n, dtype=np.int64)
        position[self.order] = np.arange(n)
        sizes = np.array(
            [self.band_size, n - self.band_size, self.kl, self.ku, len(self.colours), n],
            dtype=np.int64,
        )
        start = np.cumsum([0, *(len(c) for c in self.colours)]).astype(np.int64)
        members = np.array([j for c in self.colours for j in c], dtype=np.int64)
        return sizes, self.order, position, start, members, self.row_hit, self.link_hit


def _band_order(rows: Sequence[set[int]], band: list[int]) -> list[int]:
    """The band's states in reverse Cuthill-McKee order of their (symmetrised) coupling."""
    if not band:
        return []
    local = {state: i for i, state in enumerate(band)}
    r, c = [], []
    for state in band:
        for j in rows[state]:
            if j in local:
                r += [local[state], local[j]]
                c += [local[j], local[state]]
    graph = csr_matrix((np.ones(len(r)), (r, c)), shape=(len(band), len(band)))
    return [band[i] for i in reverse_cuthill_mckee(graph, symmetric_mode=True)]


def _colour(
    band: np.ndarray, rows: Sequence[set[int]], links: Sequence[set[int]], is_border: np.ndarray
) -> dict[int, int]:
    """Greedy colouring of the band's columns: no two of a colour share a band row or a link."""
    users: dict[int, list[set[int]]] = {int(j): [] for j in band}
    for state in band:
        for j in rows[state]:
            if not is_border[j]:
                users[j].append(rows[state])
    for link in links:
        for j in link:
            if not is_border[j]:
                users[j].append(link)
    colour_of: dict[int, int] = {}
    for j in (int(s) for s in band):
        taken = {colour_of[k] for group in users[j] for k in group if k in colour_of}
        colour_of[j] = next(c for c in range(len(taken) + 1) if c not in taken)
    return colour_of
