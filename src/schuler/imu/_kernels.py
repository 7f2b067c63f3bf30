"""numba kernels of the IMU layer: the time loops that cannot be vectorised, on plain arrays.

Every kernel is sequential in time and carries its state in and out, so a
record cut into windows gives bit-for-bit the samples of one long run
(:func:`store` only fuses a channel's last passes into one).
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def slow_block(normals: np.ndarray, phis: np.ndarray, drives: np.ndarray, sigmas: np.ndarray, levels: np.ndarray,
               block: int, first: bool, left: np.ndarray, scratch: np.ndarray, target: np.ndarray, lo: int) -> int:
    """Add the sum of a channel's slow processes over a block of ``block`` samples to ``target``; returns normals used.

    Process j lives on a grid of step D_j = 2**levels[j] samples (D_j <= ``block``):
    x_{i+1} = phis[j] x_i + drives[j] w. ``left[j]`` holds its value at the block's
    first sample and is advanced to the next block's. With ``first`` (the record's
    first block) ``left[j] = sigmas[j] w`` is drawn first, one normal per process.
    Each process's block_size / D_j innovations follow, process by process.

    The levels are summed from the coarsest down: a level's grid points (block / D
    + 1 of them, the last shared with the next block) get the coarser levels'
    sum refined a midpoint at a time, then the recursions of its own processes.
    Each sample thus gets the sum of the processes interpolated linearly between
    their grid points in about 2 ``block`` operations whatever the number of
    processes. ``target[i]`` gets the sum at sample ``lo + i`` of the block;
    ``scratch`` holds at least 2 ``block`` + 17 values.
    """
    used = levels.size if first else 0
    offsets = np.empty(levels.size, dtype=np.int64)  # each process's first innovation in ``normals``
    top = 0
    for j in range(levels.size):
        if first:
            left[j] = sigmas[j] * normals[j]
        offsets[j] = used
        used += block >> levels[j]
        top = max(top, levels[j])
    base = 0
    for level in range(top):
        base += (block >> level) + 1
    n = block >> top
    scratch[base:base + n + 1] = 0.0
    for level in range(top, -1, -1):
        if level < top:  # refine the coarser sum (at ``base``, n + 1 points) onto this level's 2 n + 1 points
            fine = base - (2 * n + 1)
            for i in range(n):
                scratch[fine + 2 * i] = scratch[base + i]
                scratch[fine + 2 * i + 1] = 0.5 * (scratch[base + i] + scratch[base + i + 1])
            scratch[fine + 2 * n] = scratch[base + n]
            base, n = fine, 2 * n
        for j in range(levels.size):
            if levels[j] == level:
                value = left[j]
                phi, drive, k = phis[j], drives[j], offsets[j]
                scratch[base] += value
                for i in range(1, n + 1):
                    value = phi * value + drive * normals[k]
                    k += 1
                    scratch[base + i] += value
                left[j] = value
    for i in range(target.size):
        target[i] += scratch[lo + i]
    return used


@numba.njit(cache=True, nogil=True)
def store(values: np.ndarray, offset: np.ndarray, factor: float, out: np.ndarray) -> None:
    """out[k] = (values[k] - offset[k]) factor in one pass; ``out`` may be strided, an ``offset`` of size 1 constant."""
    stride = 1 if offset.size > 1 else 0
    for k in range(values.size):
        out[k] = (values[k] - offset[k * stride]) * factor


@numba.njit(cache=True, nogil=True)
def quantize(increments: np.ndarray, quantum: float, residual: float) -> float:
    """Replace increments by whole quanta of the accumulated sum (in place); return the carried residual.

    out_k = quantum floor((residual + increment_k) / quantum); the residual stays in [0, quantum) up to
    the rounding of the reciprocal.
    """
    inverse = 1.0 / quantum
    for k in range(increments.size):
        total = residual + increments[k]
        count = math.floor(total * inverse)
        increments[k] = count * quantum
        residual = total - count * quantum
    return residual


@numba.njit(cache=True, nogil=True)
def accumulate(samples: np.ndarray, offset: float, scale: float, last: float, out: np.ndarray) -> float:
    """Running sum out[k] = last + sum_{i<=k} (samples[i] - offset), times ``scale`` on output; returns the raw sum.

    The sum is sequential (numpy's cumsum order), so chunked and whole-record sums agree bit for bit.
    """
    total = last
    for k in range(samples.size):
        total += samples[k] - offset
        out[k] = total * scale
    return total


@numba.njit(cache=True, nogil=True)
def second_difference_sums(phase: np.ndarray, first: int, lags: np.ndarray, sums: np.ndarray,
                           counts: np.ndarray) -> None:
    """Add sum_k (x[k+2m] - 2 x[k+m] + x[k])^2 over every k with k + 2m >= first, for each lag m.

    ``phase`` holds the previous tail followed by new samples starting at index
    ``first``; each triple is counted once, when its last point arrives. Partial
    sums are kept per block of 4096 terms and added at the end of each block
    (error growth like pairwise summation, not like a running sum).
    """
    for index in range(lags.size):
        m = lags[index]
        begin = max(0, first - 2 * m)
        stop = phase.size - 2 * m
        if stop <= begin:
            continue
        total = 0.0
        block = 0.0
        count = 0
        for k in range(begin, stop):
            d = phase[k + 2 * m] - 2.0 * phase[k + m] + phase[k]
            block += d * d
            count += 1
            if count % 4096 == 0:
                total += block
                block = 0.0
        sums[index] += total + block
        counts[index] += stop - begin
