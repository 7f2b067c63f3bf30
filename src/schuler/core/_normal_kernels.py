"""Compiled standard normals at addresses: a counter hash feeding a ziggurat.

The normal at address (member key ``k``, counter ``c``) is drawn from the 64-bit
words ``s_0 = mix(k + (c + 1) gamma)``, ``s_{i+1} = mix(s_i + gamma)`` (SplitMix64's
finaliser ``mix`` and golden-ratio increment ``gamma``; Steele, Lea and Flood,
"Fast splittable pseudorandom number generators", OOPSLA 2014): a counter-based
generator, so every normal depends on its address alone, never on how a series
is cut or on which thread drew it.

Each word gives a normal by the ziggurat method (Marsaglia and Tsang, "The
ziggurat method for generating random variables", J. Stat. Software 5(8), 2000)
with :data:`LAYERS` layers of equal area V under f(x) = exp(-x^2 / 2): the word's
low 8 bits pick a layer k, bit 8 the sign and its top 53 bits a uniform U; the
point x = U X_k is returned when it lies inside the layer's part wholly under
the curve (x < X_{k+1}, about 99 % of draws, one word per normal). Otherwise the
next words decide: in a wedge, a uniform height against f(x); in the base layer
beyond R, Marsaglia's exact tail (x = R - ln(U1) / R, accepted when
-2 ln(U2) > (x - R)^2). The boundaries X_1 = R > X_2 > ... > X_LAYERS = 0 satisfy
f(X_{k+1}) = f(X_k) + V / X_k; the base layer's width X_0 = V / f(R) makes its
area, R f(R) plus the tail, V too; R solves f(X_{LAYERS-1}) + V / X_{LAYERS-1} = 1
(the top layer reaches the peak), found here by root finding and checked against
Marsaglia and Tsang's R = 3.6541528853610088 for 256 layers in the tests.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy.optimize import brentq
from scipy.special import erfc

LAYERS = 256
"""Layers of the ziggurat (the word's low 8 bits)."""

GAMMA = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)
_UNIT = 2.0**-53


def _layer_area(tail_start: float) -> float:
    """V for a base layer from the tail start R: R f(R) plus the tail's area."""
    return tail_start * math.exp(-0.5 * tail_start**2) + math.sqrt(math.pi / 2) * erfc(tail_start / math.sqrt(2))


def _boundaries(tail_start: float, layers: int) -> tuple[np.ndarray, float]:
    """X_0 .. X_layers for the tail start R, and the top layer's overshoot f(X_{n-1}) + V / X_{n-1} - 1."""
    area = _layer_area(tail_start)
    x = np.zeros(layers + 1)
    x[0], x[1] = area / math.exp(-0.5 * tail_start**2), tail_start
    for k in range(1, layers - 1):
        height = math.exp(-0.5 * x[k] ** 2) + area / x[k]
        if height >= 1.0:  # R too small: the layers reach the peak before the last one
            return x, height - 1.0 + (layers - 1 - k)
        x[k + 1] = math.sqrt(-2.0 * math.log(height))
    return x, math.exp(-0.5 * x[layers - 1] ** 2) + area / x[layers - 1] - 1.0


def ziggurat_tables(layers: int = LAYERS) -> tuple[float, float, np.ndarray, np.ndarray]:
    """The ziggurat for ``layers`` layers: R, V, the boundaries X (layers + 1,) and f(X).

    Parameters
    ----------
    layers : int
        Number of layers (256 for the kernels; 128 is Marsaglia and Tsang's other table).
    """
    tail_start = brentq(lambda r: _boundaries(r, layers)[1], 2.0, 5.0, xtol=1e-15, maxiter=200)
    x, _ = _boundaries(tail_start, layers)
    return tail_start, _layer_area(tail_start), x, np.exp(-0.5 * x**2)


_R, _V, _X, _F = ziggurat_tables()


@numba.njit(nogil=True)
def _mix(z):
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


@numba.njit(nogil=True)
def _uniform(word):
    """A uniform in (0, 1) from a word's top 53 bits."""
    return (float(np.int64(word >> np.uint64(11))) + 0.5) * _UNIT


@numba.njit(nogil=True)
def _layer_point(word, x_table):
    """The word's layer, sign and point x = U X_layer."""
    layer = int(word & np.uint64(LAYERS - 1))
    negative = (word >> np.uint64(8)) & np.uint64(1)
    return layer, negative, float(np.int64(word >> np.uint64(11))) * _UNIT * x_table[layer]


@numba.njit(cache=True, nogil=True)
def _beyond_the_core(word, layer, negative, x, x_table, f_table, tail_start):
    """The normal when a word's point lies outside its layer's core: the tail, the wedge or the next word."""
    while True:
        word = _mix(word + GAMMA)
        if layer == 0:  # beyond R in the base layer: the exact tail
            while True:
                excess = -math.log(_uniform(word)) / tail_start
                word = _mix(word + GAMMA)
                accept = -2.0 * math.log(_uniform(word)) > excess * excess
                word = _mix(word + GAMMA)
                if accept:
                    return -(tail_start + excess) if negative else tail_start + excess
        height = f_table[layer] + _uniform(word) * (f_table[layer + 1] - f_table[layer])
        if height < math.exp(-0.5 * x * x):
            return -x if negative else x
        word = _mix(word + GAMMA)
        layer, negative, x = _layer_point(word, x_table)
        if x < x_table[layer + 1]:
            return -x if negative else x


@numba.njit(cache=True, nogil=True)
def _fill_run(key, first, out, x_table, f_table, tail_start):
    """``out[j]`` = the normal of member key ``key`` at counter ``first + j``."""
    for j in range(out.size):
        # the core test inline, the rest (about 1 % of draws) out of line: the loop stays tight
        word = _mix(key + (first + np.uint64(j + 1)) * GAMMA)
        layer, negative, x = _layer_point(word, x_table)
        if x < x_table[layer + 1]:
            out[j] = -x if negative else x
        else:
            out[j] = _beyond_the_core(word, layer, negative, x, x_table, f_table, tail_start)


@numba.njit(cache=True, nogil=True)
def fill_series(keys, start, stop, block_bits, out, x_table, f_table, tail_start):
    """``out[m, i]`` = the normal of member key ``keys[m]`` at series index ``start + i``.

    Series index n is the counter (n >> block_bits) << 32 | (n mod 2**block_bits): block b of
    2**block_bits samples starts at counter b << 32, which :func:`fill_block` continues past the block's end.
    """
    size = 1 << block_bits
    for m in range(keys.size):
        n = start
        while n < stop:
            block, position = n >> block_bits, n & (size - 1)
            end = min(stop, (block + 1) << block_bits)
            _fill_run(keys[m], np.uint64((block << 32) | position), out[m, n - start:end - start],
                      x_table, f_table, tail_start)
            n = end


@numba.njit(cache=True, nogil=True)
def fill_block(key, block, out, x_table, f_table, tail_start):
    """``out[j]`` = the normal of member key ``key`` at counter ``block << 32 | j``."""
    _fill_run(key, np.uint64(block) << np.uint64(32), out, x_table, f_table, tail_start)


def tables() -> tuple[np.ndarray, np.ndarray, float]:
    """The kernels' ziggurat tables: X, f(X) and R."""
    return _X, _F, _R
