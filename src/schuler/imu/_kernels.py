"""numba kernels of the IMU layer: the time loops that cannot be vectorised, on plain arrays.

Every kernel is sequential in time and carries its state in and out, so a
record cut into windows gives bit-for-bit the samples of one long run.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def recurse(phi: float, drive: float, normals: np.ndarray, last: float, out: np.ndarray) -> None:
    """First-order recursion out[k] = phi out[k-1] + drive normals[k], starting from ``last``."""
    value = last
    for k in range(normals.size):
        value = phi * value + drive * normals[k]
        out[k] = value


@numba.njit(cache=True, nogil=True)
def add_interpolated(target: np.ndarray, coarse: np.ndarray, first_coarse: int, step: int, start: int) -> None:
    """target[i] += linear interpolation at fine sample start + i of ``coarse`` (index first_coarse, spacing step).

    Sample n = j step + r (0 <= r < step) gets coarse[j] + (coarse[j + 1] - coarse[j]) r / step.
    """
    i = 0
    n = target.size
    while i < n:
        fine = start + i
        j = fine // step
        k = j - first_coarse
        left = coarse[k]
        slope = (coarse[k + 1] - left) / step
        r = fine - j * step
        count = min(step - r, n - i)
        for q in range(count):
            target[i + q] += left + slope * (r + q)
        i += count


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
