"""Small rotation helpers shared by the 3-D models (pure numpy)."""

from __future__ import annotations

import numpy as np


def skew(vector) -> np.ndarray:
    """The cross-product matrix [a x] of a 3-vector: ``skew(a) @ b == np.cross(a, b)``; rows of a batch alike.

    Parameters
    ----------
    vector : array_like, shape ([N,] 3)
        a, in any unit (the matrix carries it); a batch gives one matrix per row.

    Returns
    -------
    ndarray, shape ([N,] 3, 3)
        Skew-symmetric [[0, -a3, a2], [a3, 0, -a1], [-a2, a1, 0]].

    Examples
    --------
    >>> skew([1.0, 2.0, 3.0]) @ np.array([4.0, 5.0, 6.0])
    array([-3.,  6., -3.])
    >>> skew(np.ones((2, 3))).shape
    (2, 3, 3)
    """
    a = np.asarray(vector, dtype=float)
    out = np.zeros(a.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -a[..., 2], a[..., 1]
    out[..., 1, 0], out[..., 1, 2] = a[..., 2], -a[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -a[..., 1], a[..., 0]
    return out
