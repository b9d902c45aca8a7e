"""``(I - g h J)`` of a bordered band Jacobian: factored and solved in time linear in its size.

A unit whose state couples along a chain (a rope path: each coordinate to its
neighbours) and to a few bodies that touch much of the chain (the blocks) has a
Jacobian that, in a suitable order, is a band with a dense border::

    J = [ A  B ]    A: band, ``kl`` below and ``ku`` above the diagonal (mb x mb)
        [ C  D ]    B, C, D: the border's columns, rows and corner (nb wide)

This module takes ``J`` in that form -- the tuple ``(band, cols, rows, corner,
tail)`` with ``band[p, c - p + kl] = A[p, c]`` -- and factors ``W = I - g h J`` by
Gaussian elimination without pivoting (no fill outside the band and the border)
in ``O(mb (kl ku + nb (kl + ku + nb)))`` operations, then solves with it in
``O(mb (kl + ku + nb))``. ``W`` of a stable mechanical system is close to the
identity scaled by positive masses, so its pivots stay near 1; should one come
within :data:`PIVOT_FLOOR` of zero (or not be finite), the factorisation falls
back to the dense inverse of the same matrix and says so in the factors.

The structure tuple ``s`` both functions take (built by
:func:`~wire_fmu.core.framework.sparse_pattern.BandStructure.arrays`):

=====  ================  ===================================================
index  name              contents
=====  ================  ===================================================
0      ``sizes``         int: ``mb``, ``nb``, ``kl``, ``ku``, colours,
                         structured states ``mb + nb``
1      ``order``         int: position -> state index
2      ``position``      int: state index -> position
=====  ================  ===================================================

States past ``mb + nb`` (the energy ledgers) are ones nothing depends on: their
columns of ``J`` are zero and their rows are ``tail`` (in structured order), so
``W`` is block lower triangular and they follow the others by one product.

Every function is compiled with :func:`~wire_fmu.core.framework.compiled.jit` and,
without numba, runs as the same plain Python.
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators

jit = kernel_decorators(__file__).jit

__all__ = ["PIVOT_FLOOR", "empty_factors", "empty_jacobian", "factor", "solve", "to_dense"]

PIVOT_FLOOR = 1e-12
"""A pivot smaller than this (``W`` is dimensionless near 1) sends the factorisation dense."""


@jit
def empty_jacobian() -> tuple:
    """A Jacobian of no size, of the type :func:`factor` takes (a placeholder before the first)."""
    e = np.zeros((0, 0))
    return e, e.copy(), e.copy(), e.copy(), e.copy()


@jit
def empty_factors() -> tuple:
    """Factors of no size, of the type :func:`factor` returns."""
    e = np.zeros((0, 0))
    return e, e.copy(), e.copy(), e.copy(), e.copy(), e.copy()


@jit
def to_dense(jac: tuple, s: tuple) -> np.ndarray:
    """The bordered band matrix ``jac`` as a dense matrix in structured order.

    Parameters
    ----------
    jac : tuple
        ``(band, cols, rows, corner, tail)`` (see the module docstring); the tail
        is left out.
    s : tuple
        The structure (see the module docstring).
    """
    band, cols, rows, corner = jac[0], jac[1], jac[2], jac[3]
    mb, nb, kl, ku = s[0][0], s[0][1], s[0][2], s[0][3]
    out = np.zeros((mb + nb, mb + nb))
    for p in range(mb):
        for c in range(max(0, p - kl), min(mb, p + ku + 1)):
            out[p, c] = band[p, c - p + kl]
        for q in range(nb):
            out[p, mb + q] = cols[p, q]
    for q in range(nb):
        for c in range(mb):
            out[mb + q, c] = rows[q, c]
        for r in range(nb):
            out[mb + q, mb + r] = corner[q, r]
    return out


@jit
def _pivot_ok(pivot: float) -> bool:
    return math.isfinite(pivot) and abs(pivot) >= PIVOT_FLOOR


@jit
def _eliminate_band(a, b, c, d, mb: int, nb: int, kl: int, ku: int) -> bool:
    """LU of ``[[a, b], [c, d]]`` in place over the band's columns; False on a bad pivot."""
    for k in range(mb):
        pivot = a[k, kl]
        if not _pivot_ok(pivot):
            return False
        for i in range(k + 1, min(k + kl + 1, mb)):
            f = a[i, k - i + kl] / pivot
            a[i, k - i + kl] = f
            if f == 0.0:
                continue
            for j in range(k + 1, min(k + ku + 1, mb)):
                a[i, j - i + kl] -= f * a[k, j - k + kl]
            for q in range(nb):
                b[i, q] -= f * b[k, q]
        for q in range(nb):
            f = c[q, k] / pivot
            c[q, k] = f
            if f == 0.0:
                continue
            for j in range(k + 1, min(k + ku + 1, mb)):
                c[q, j] -= f * a[k, j - k + kl]
            for r in range(nb):
                d[q, r] -= f * b[k, r]
    return True


@jit
def _eliminate_corner(d, nb: int) -> bool:
    """LU of the border's Schur complement ``d`` in place; False on a bad pivot."""
    for k in range(nb):
        pivot = d[k, k]
        if not _pivot_ok(pivot):
            return False
        for q in range(k + 1, nb):
            f = d[q, k] / pivot
            d[q, k] = f
            for r in range(k + 1, nb):
                d[q, r] -= f * d[k, r]
    return True


@jit
def factor(jac: tuple, gh: float, s: tuple) -> tuple:
    """Factors of ``W = I - gh J`` for :func:`solve`.

    Parameters
    ----------
    jac : tuple
        ``(band, cols, rows, corner, tail)`` of ``J`` (see the module docstring), 1/s.
    gh : float
        ``g h`` (s); NaN gives :func:`empty_factors`.
    s : tuple
        The structure.

    Returns
    -------
    tuple
        ``(L\\U band, cols, rows, corner, dense, gh tail)``: the factored parts, the
        dense inverse of ``W``'s structured part where a pivot was too small (else
        of no size), and ``gh`` times the tail's rows.
    """
    if math.isnan(gh):
        return empty_factors()
    mb, nb, kl, ku = s[0][0], s[0][1], s[0][2], s[0][3]
    a = -gh * jac[0]
    b = -gh * jac[1]
    c = -gh * jac[2]
    d = -gh * jac[3]
    for p in range(mb):
        a[p, kl] += 1.0
    for q in range(nb):
        d[q, q] += 1.0
    tail = gh * jac[4]
    if _eliminate_band(a, b, c, d, mb, nb, kl, ku) and _eliminate_corner(d, nb):
        return a, b, c, d, np.zeros((0, 0)), tail
    w = np.eye(mb + nb) - gh * to_dense(jac, s)
    dense = np.ascontiguousarray(np.linalg.solve(w, np.eye(mb + nb)))
    return a, b, c, d, dense, tail


@jit
def solve(fac: tuple, rhs: np.ndarray, s: tuple) -> np.ndarray:
    """``W^-1 rhs`` with the factors of :func:`factor`.

    Parameters
    ----------
    fac : tuple
        :func:`factor`'s answer.
    rhs : numpy.ndarray
        A vector over the whole state (states past the structured ones pass through).
    s : tuple
        The structure.
    """
    mb, nb, kl, ku = s[0][0], s[0][1], s[0][2], s[0][3]
    order = s[1]
    a, b, c, d, dense, tail = fac
    z = np.empty(mb + nb)
    for p in range(mb + nb):
        z[p] = rhs[order[p]]
    if dense.shape[0] > 0:
        z = dense @ z
    else:
        for k in range(mb):  # L of the band and of the border's rows
            zk = z[k]
            for i in range(k + 1, min(k + kl + 1, mb)):
                z[i] -= a[i, k - i + kl] * zk
            for q in range(nb):
                z[mb + q] -= c[q, k] * zk
        for k in range(nb):  # L of the corner
            for q in range(k + 1, nb):
                z[mb + q] -= d[q, k] * z[mb + k]
        for q in range(nb - 1, -1, -1):  # U of the corner
            acc = z[mb + q]
            for r in range(q + 1, nb):
                acc -= d[q, r] * z[mb + r]
            z[mb + q] = acc / d[q, q]
        for k in range(mb - 1, -1, -1):  # U of the band, with the border's columns
            acc = z[k]
            for j in range(k + 1, min(k + ku + 1, mb)):
                acc -= a[k, j - k + kl] * z[j]
            for q in range(nb):
                acc -= b[k, q] * z[mb + q]
            z[k] = acc / a[k, kl]
    out = rhs.copy()
    for p in range(mb + nb):
        out[order[p]] = z[p]
    for r in range(tail.shape[0]):  # the tail: W's rows there are [-gh tail, I]
        acc = rhs[mb + nb + r]
        for p in range(mb + nb):
            acc += tail[r, p] * z[p]
        out[mb + nb + r] = acc
    return out
