"""Compiled time loop of the linear-systems engine: exact zero-order-hold steps on plain arrays.

A recursion x_(k+1) = Ad x_k + Bd u_k with an input that changes every step
is sequential by nature; this kernel runs it for every member at machine speed
and writes into a preallocated array. Everything else (discretisation, shapes,
the choice of method) stays in :mod:`schuler.core._propagation`.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def propagate_steps(Ad: np.ndarray, Bd: np.ndarray, kind: np.ndarray, x0: np.ndarray, u: np.ndarray,
                    out: np.ndarray) -> None:
    """Fill ``out`` with x_(k+1) = Ad[kind[k], a] x_k + Bd[kind[k], a] u[w, c] for every member.

    Parameters
    ----------
    Ad : ndarray, shape (n_kinds, 1 or N, n, n)
        Exact transition over each distinct step; a leading 1 shares it among members.
    Bd : ndarray, shape (n_kinds, 1 or N, n, m)
        Exact input matrix over each distinct step.
    kind : ndarray of int64, shape (n_time - 1,)
        Which distinct step each grid step is.
    x0 : ndarray, shape (N, n)
        States at the first time point.
    u : ndarray, shape (1 or N, 1 or n_time, m)
        Inputs held over each step; a time length of 1 holds them over the run.
    out : ndarray, shape (N, n_time, n)
        States at every time point (written).
    """
    members, n_time, n = out.shape
    m = u.shape[2]
    for i in range(members):
        a = 0 if Ad.shape[1] == 1 else i
        w = 0 if u.shape[0] == 1 else i
        for r in range(n):
            out[i, 0, r] = x0[i, r]
        for k in range(n_time - 1):
            s = kind[k]
            c = 0 if u.shape[1] == 1 else k
            for r in range(n):
                total = 0.0
                for j in range(n):
                    total += Ad[s, a, r, j] * out[i, k, j]
                for j in range(m):
                    total += Bd[s, a, r, j] * u[w, c, j]
                out[i, k + 1, r] = total
