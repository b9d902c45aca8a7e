"""Matrix products summed term after term, in the order the compiled kernel sums them."""

from __future__ import annotations

import numpy as np

__all__ = ["ordered_matmul", "ordered_matvec", "ordered_vecmat"]

# The products below are summed term after term, as the compiled kernel sums them, not
# in the blocked order of BLAS: the two kernels then agree to the last bit, which matters
# because the solvers' finite-difference Jacobians turn a last-bit difference of the
# right-hand side into a difference of 1e-9 of the Jacobian.


def ordered_matvec(a: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``a @ v``, summed over the columns in order."""
    if a.shape[1] == 0:
        return np.zeros(a.shape[0])
    return np.cumsum(a * v, axis=1)[:, -1]


def ordered_vecmat(v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``v @ a``, summed over the rows in order."""
    if a.shape[0] == 0:
        return np.zeros(a.shape[1])
    return np.cumsum(v[:, None] * a, axis=0)[-1]


def ordered_matmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b``, summed over the inner index in order."""
    if a.shape[1] == 0:
        return np.zeros((a.shape[0], b.shape[1]))
    return np.cumsum(a[:, :, None] * b[None, :, :], axis=1)[:, -1, :]
