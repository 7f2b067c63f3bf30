"""The matrix exponential of a stack of small matrices, in numpy's batched products and solves.

The covariance analysis needs thousands of exponentials of 13 x 13 and
14 x 14 matrices per mission (one per step and member). ``scipy.linalg.expm``
factors each one by its own LAPACK call, and OpenBLAS's worker threads make
each such call cost 10 to 40 times its arithmetic on a busy machine (measured:
30 exponentials of a 120-step mission 0.34 s of CPU with one thread, 12 s with
the default threads); numpy's stacked ``matmul`` and ``solve`` here do the
whole stack in one call each, at the single-thread cost.

The method is scaling and squaring with the [13/13] Pade approximant
(Higham 2005, Algorithm 2.3, the degree it uses for every norm above
theta_13 = 5.37): e^A = (r_13(A / 2^s))^(2^s), s the smallest whole number
with ||A||_1 / 2^s <= theta_13, per matrix.

References
----------
N. J. Higham, "The scaling and squaring method for the matrix exponential revisited",
SIAM Journal on Matrix Analysis and Applications 26(4), 1179-1193, 2005.
"""

from __future__ import annotations

import numpy as np

PADE_13 = (64764752532480000.0, 32382376266240000.0, 7771770303897600.0, 1187353796428800.0, 129060195264000.0,
           10559470521600.0, 670442572800.0, 33522128640.0, 1323241920.0, 40840800.0, 960960.0, 16380.0, 182.0, 1.0)
"""Coefficients b_0 .. b_13 of the [13/13] Pade approximant of the exponential (Higham 2005, Table 2.3)."""

THETA_13 = 5.371920351148152
"""Largest 1-norm for which the [13/13] approximant is exact to double precision (Higham 2005, Table 2.3)."""


BLOCK = 512
"""Matrices per block: a block's temporaries (a few hundred kB each) stay in cache instead of being mapped afresh."""


def expm_stack(matrices: np.ndarray) -> np.ndarray:
    """e^A of every matrix of a stack.

    Parameters
    ----------
    matrices : ndarray
        Shape (..., n, n), plain numbers (a system matrix times a step: its entries per unit of the states).

    Returns
    -------
    ndarray
        e^A, shape (..., n, n).

    Examples
    --------
    >>> e = expm_stack(np.array([[[0.0, 1.0], [0.0, 0.0]], [[1.0, 0.0], [0.0, 2.0]]]))
    >>> e[0].tolist(), bool(np.allclose(np.diag(e[1]), np.exp([1.0, 2.0]), rtol=1e-14))
    ([[1.0, 1.0], [0.0, 1.0]], True)
    """
    matrices = np.asarray(matrices, dtype=float)
    shape, n = matrices.shape, matrices.shape[-1]
    flat = matrices.reshape(-1, n, n)
    result = np.empty_like(flat)
    for start in range(0, flat.shape[0], BLOCK):
        result[start:start + BLOCK] = _expm_block(flat[start:start + BLOCK])
    return result.reshape(shape)


def _expm_block(A: np.ndarray) -> np.ndarray:
    n = A.shape[-1]
    norm = np.abs(A).sum(axis=1).max(axis=1)
    squarings = np.zeros(norm.shape, dtype=np.int64)
    large = norm > THETA_13
    squarings[large] = np.ceil(np.log2(norm[large] / THETA_13)).astype(np.int64)
    A = A / (2.0 ** squarings)[:, None, None]
    b = PADE_13
    identity = np.eye(n)
    A2 = A @ A
    A4 = A2 @ A2
    A6 = A4 @ A2
    U = A @ (A6 @ (b[13] * A6 + b[11] * A4 + b[9] * A2) + b[7] * A6 + b[5] * A4 + b[3] * A2 + b[1] * identity)
    V = A6 @ (b[12] * A6 + b[10] * A4 + b[8] * A2) + b[6] * A6 + b[4] * A4 + b[2] * A2 + b[0] * identity
    result = np.linalg.solve(V - U, V + U)
    for round_ in range(int(squarings.max(initial=0))):
        more = squarings > round_
        if more.all():  # the usual case: the matrices of one mission's steps share their norm
            result = result @ result
        else:
            result[more] = result[more] @ result[more]
    return result


__all__ = ["expm_stack"]
