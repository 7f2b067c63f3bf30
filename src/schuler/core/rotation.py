"""Small rotation helpers shared by the 3-D models (pure numpy)."""

from __future__ import annotations

import numpy as np


def skew(vector) -> np.ndarray:
    """The cross-product matrix [a x] of a 3-vector: ``skew(a) @ b == np.cross(a, b)``.

    Parameters
    ----------
    vector : array_like, shape (3,)
        a, in any unit (the matrix carries it).

    Returns
    -------
    ndarray, shape (3, 3)
        Skew-symmetric [[0, -a3, a2], [a3, 0, -a1], [-a2, a1, 0]].

    Examples
    --------
    >>> skew([1.0, 2.0, 3.0]) @ np.array([4.0, 5.0, 6.0])
    array([-3.,  6., -3.])
    """
    a1, a2, a3 = vector
    return np.array([[0.0, -a3, a2], [a3, 0.0, -a1], [-a2, a1, 0.0]])
