"""Compiled loops of the linear-systems engine, on plain arrays written in place.

* :func:`propagate_steps`: the recursion x_(k+1) = Ad x_k + Bd u_k with an input
  that changes every step, sequential by nature, for every member.
* :func:`fill_blocks`: the samples of the block scheme, y = rows Phi^j Psi^b z0,
  which numpy would spread over many small matrix products per member.
* :func:`final_and_peak_blocks`: the same samples reduced to each member's
  last value and peak magnitude as they are made, never stored.
* :func:`final_and_peak`: a reducer's single pass over the histories
  (numpy would make a temporary |y| and read each history twice).

Everything else (discretisation, balancing, shapes, the choice of method) stays
in :mod:`schuler.core.propagation`.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def propagate_steps(Ad: np.ndarray, Bd: np.ndarray, kind: np.ndarray, x0: np.ndarray, u: np.ndarray,
                    out: np.ndarray) -> None:
    """Fill ``out`` with x_(k+1) = Ad[kind[k]] x_k + Bd[kind[k]] u_k for every member.

    Member-last layouts: the innermost loop runs over members, contiguous in
    memory, so a step of N members is a few vector operations, as a matrix
    product over members would be, without a Python loop over time.

    Parameters
    ----------
    Ad : ndarray, shape (n_kinds, n, n, 1 or N)
        Exact transition over each distinct step; a last axis of 1 shares it among members.
    Bd : ndarray, shape (n_kinds, n, m, 1 or N)
        Exact input matrix over each distinct step.
    kind : ndarray of int64, shape (n_time - 1,)
        Which distinct step each grid step is.
    x0 : ndarray, shape (n, N)
        States at the first time point.
    u : ndarray, shape (1 or n_time, m, 1 or N)
        Inputs held over each step; a time length of 1 holds them over the run.
    out : ndarray, shape (n_time, n, N)
        States at every time point (written).
    """
    n_time, n, members = out.shape
    m = u.shape[1]
    shared_model = Ad.shape[3] == 1
    shared_input = u.shape[2] == 1
    out[0] = x0
    for k in range(n_time - 1):
        s = kind[k]
        c = 0 if u.shape[0] == 1 else k
        for r in range(n):
            row = out[k + 1, r]
            row[:] = 0.0
            for j in range(n):
                previous = out[k, j]
                if shared_model:
                    a = Ad[s, r, j, 0]
                    for i in range(members):
                        row[i] += a * previous[i]
                else:
                    a_all = Ad[s, r, j]
                    for i in range(members):
                        row[i] += a_all[i] * previous[i]
            for j in range(m):
                b_all = Bd[s, r, j]
                held = u[c, j]
                if shared_model and shared_input:
                    forced = b_all[0] * held[0]
                    for i in range(members):
                        row[i] += forced
                elif shared_model:
                    b = b_all[0]
                    for i in range(members):
                        row[i] += b * held[i]
                elif shared_input:
                    for i in range(members):
                        row[i] += b_all[i] * held[0]
                else:
                    for i in range(members):
                        row[i] += b_all[i] * held[i]


@numba.njit(cache=True)
def _fine_rows(step: np.ndarray, rows: np.ndarray, a: int, g: int, gains: np.ndarray) -> None:
    """``gains[p, c, j] = (rows[g] Phi^j)[p, c]`` for j < L (Phi = step[a]): the fine rows of a block."""
    r, q, L = gains.shape
    for p in range(r):
        for c in range(q):
            gains[p, c, 0] = rows[g, p, c]
    for j in range(1, L):
        for p in range(r):
            for c in range(q):
                total = 0.0
                for k in range(q):
                    total += gains[p, k, j - 1] * step[a, k, c]
                gains[p, c, j] = total


@numba.njit(cache=True)
def _held_share(gains: np.ndarray, z: np.ndarray, n_moving: int, held: np.ndarray) -> None:
    """``held[p, j]``: the constant entries' (z[n_moving:]) share of sample j of every block."""
    r, q, L = gains.shape
    for p in range(r):
        for j in range(L):
            held[p, j] = 0.0
        for c in range(n_moving, q):
            s = z[c]
            for j in range(L):
                held[p, j] += s * gains[p, c, j]


@numba.njit(cache=True)
def _block_line(gains: np.ndarray, held: np.ndarray, start: np.ndarray, n_moving: int, p: int,
                line: np.ndarray) -> None:
    """Row p's L samples of the block beginning at ``start``: held share plus n_moving multiply-adds each."""
    L = line.shape[0]
    for j in range(L):
        line[j] = held[p, j]
    for c in range(n_moving):
        s = start[c]
        for j in range(L):
            line[j] += s * gains[p, c, j]


@numba.njit(cache=True)
def _next_start(block: np.ndarray, a: int, n_moving: int, start: np.ndarray, following: np.ndarray) -> None:
    """start <- Psi start for the moving entries (the constant ones keep their value)."""
    q = start.shape[0]
    for c in range(n_moving):
        total = 0.0
        for k in range(q):
            total += block[a, c, k] * start[k]
        following[c] = total
    for c in range(n_moving):
        start[c] = following[c]


@numba.njit(cache=True)
def fill_blocks(step: np.ndarray, block: np.ndarray, rows: np.ndarray, z0: np.ndarray, n_moving: int,
                substeps: int, out: np.ndarray) -> None:
    """Fill ``out[i, p, b L + j] = rows[p] Phi^j Psi^b z0[i]`` (Phi = step, Psi = block, L = substeps).

    The samples of block b are the fine rows rows Phi^j (j < L) times the
    block's start Psi^b z0. Only the first ``n_moving`` entries of a start
    change from block to block (the states; the rest are constant inputs), so
    the inputs' share of every sample is computed once per member and each
    sample costs ``n_moving`` multiply-adds, the inner loop running over
    contiguous samples. Fine rows are computed once for a shared model and
    again for every member of a batch.

    Parameters
    ----------
    step : ndarray, shape (1 or N, q, q)
        Transition over one sample step.
    block : ndarray, shape (1 or N, q, q)
        Transition over one block of ``substeps`` steps.
    rows : ndarray, shape (1 or N, r, q)
        Rows wanted.
    z0 : ndarray, shape (N, q)
        Initial vectors.
    n_moving : int
        Entries of z that change in time (the rest stay at their initial value).
    substeps : int
        L, samples per block.
    out : ndarray, shape (N, r, n_blocks L)
        Samples (written).
    """
    members, r, capacity = out.shape
    q = z0.shape[1]
    gains = np.empty((r, q, substeps))
    held = np.empty((r, substeps))
    start = np.empty(q)
    following = np.empty(q)
    for i in range(members):
        a = 0 if step.shape[0] == 1 else i
        if i == 0 or step.shape[0] > 1 or rows.shape[0] > 1:
            _fine_rows(step, rows, a, 0 if rows.shape[0] == 1 else i, gains)
        _held_share(gains, z0[i], n_moving, held)
        start[:] = z0[i]
        for base in range(0, capacity, substeps):
            for p in range(r):
                _block_line(gains, held, start, n_moving, p, out[i, p, base : base + substeps])
            _next_start(block, a, n_moving, start, following)


@numba.njit(cache=True, fastmath=True)
def final_and_peak_blocks(step: np.ndarray, block: np.ndarray, rows: np.ndarray, z0: np.ndarray, n_moving: int,
                          substeps: int, n_time: int, final: np.ndarray, peak: np.ndarray) -> None:
    """Each member's last sample and largest magnitude of the block scheme's samples, never storing a history.

    The samples are those of :func:`fill_blocks`, computed a block at a time
    and reduced as they are made: nothing of the N r T samples is written to
    memory. For up to three moving entries (the single-channel and
    gyrocompassing models) a sample is one pass of four loads, three
    multiply-adds and a running maximum; larger models go through a block
    buffer that stays in cache. Fast-math lets the running maximum vectorise;
    the inputs are finite (checked by the engine), so it changes the result
    by rounding only.

    Parameters
    ----------
    step, block, rows, z0, n_moving, substeps
        As in :func:`fill_blocks`.
    n_time : int
        Samples per member (the last block may be partly past it).
    final, peak : ndarray, shape (N, r)
        Written: the sample at n_time - 1 and max over time of |sample|.
    """
    members, r = final.shape
    q = z0.shape[1]
    few = n_moving <= 3  # one loop of three zero-padded terms: four loads per sample, nothing stored
    gains = np.empty((r, q, substeps))
    padded = np.zeros((r, 3, substeps))
    held = np.empty((r, substeps))
    start = np.empty(q)
    following = np.empty(q)
    line = np.empty(substeps)
    for i in range(members):
        a = 0 if step.shape[0] == 1 else i
        if i == 0 or step.shape[0] > 1 or rows.shape[0] > 1:
            _fine_rows(step, rows, a, 0 if rows.shape[0] == 1 else i, gains)
            if few:
                padded[:, :n_moving] = gains[:, :n_moving]
        _held_share(gains, z0[i], n_moving, held)
        start[:] = z0[i]
        for p in range(r):
            peak[i, p] = 0.0
        for base in range(0, n_time, substeps):
            count = min(substeps, n_time - base)
            for p in range(r):
                largest = peak[i, p]
                if few:
                    h, g0, g1, g2 = held[p], padded[p, 0], padded[p, 1], padded[p, 2]
                    s0 = start[0]
                    s1 = start[1] if n_moving > 1 else 0.0
                    s2 = start[2] if n_moving > 2 else 0.0
                    for j in range(count):
                        value = abs(h[j] + s0 * g0[j] + s1 * g1[j] + s2 * g2[j])
                        largest = value if value > largest else largest
                    j = count - 1
                    last = h[j] + s0 * g0[j] + s1 * g1[j] + s2 * g2[j]
                else:
                    _block_line(gains, held, start, n_moving, p, line)
                    for j in range(count):
                        value = abs(line[j])
                        largest = value if value > largest else largest
                    last = line[count - 1]
                peak[i, p] = largest
                if base + count == n_time:
                    final[i, p] = last
            _next_start(block, a, n_moving, start, following)


@numba.njit(cache=True)
def final_and_peak(outputs: np.ndarray, final: np.ndarray, peak: np.ndarray) -> None:
    """Write each member's last sample and its largest magnitude over time, in one pass.

    Parameters
    ----------
    outputs : ndarray, shape (k, T, p)
        Histories (any strides; the engine's are contiguous along T).
    final, peak : ndarray, shape (k, p)
        Written: ``outputs[:, -1]`` and ``max_t |outputs[:, t]|``.
    """
    members, samples, channels = outputs.shape
    for i in range(members):
        for c in range(channels):
            largest = 0.0
            for t in range(samples):
                value = abs(outputs[i, t, c])
                if value > largest:
                    largest = value
            peak[i, c] = largest
            final[i, c] = outputs[i, samples - 1, c]
