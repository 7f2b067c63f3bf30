"""Addressed random numbers: a draw depends on (seed, stream, member, index), never on chunking.

Monte Carlo members, sweep cases and long sensor records are evaluated in
chunks whose size depends on memory, executor and resumption. So that results
never depend on how the work was cut, every random number is addressed:

* ``seed``: the study's seed (a non-negative integer);
* ``stream``: what the number is for (``"drift_east"``, ``"gyro_x/white"``);
* ``member``: the case or Monte Carlo member number (global, not within a chunk);
* ``index``: the position within that member's draws (a vector element or a sample).

Two generators serve two shapes of need:

* :meth:`RandomStreams.normal` / :meth:`RandomStreams.uniform`: a few numbers per
  member for very many members (parameter draws of a sweep). Each number is a
  hash (SplitMix64; Steele, Lea and Flood, "Fast splittable pseudorandom number
  generators", OOPSLA 2014) of its address, fully vectorised.
* :meth:`RandomStreams.normal_series`: long series per member (sensor noise),
  drawn in compiled code (:mod:`schuler.core._normal_kernels`): the normal at
  sample index n of a member is a ziggurat over the SplitMix64 words of its
  address (stream key, member, block b = n // :data:`BLOCK`, position n mod
  BLOCK), about three times as fast per core as numpy's generators. Any time
  window ``[start, stop)`` therefore gets the same numbers whichever windows
  came before, and any thread may draw any member.
* :meth:`RandomStreams.normal_block`: the first n numbers of one such block, n
  not limited to :data:`BLOCK` (positions beyond the block's length are
  addresses of their own); a series of several processes on grids coarser
  than the samples (the IMU layer's slow noise) draws from block b exactly what
  the samples of block b need, addressed by (seed, stream, member, b, position).

Examples
--------
>>> streams = RandomStreams(7)
>>> a = streams.normal("drift_east", np.arange(10))
>>> b = streams.normal("drift_east", np.arange(4, 10))
>>> bool(np.array_equal(a[4:], b))
True
>>> whole = streams.normal_series("gyro_x", np.array([3]), 0, 100_000)
>>> part = streams.normal_series("gyro_x", np.array([3]), 70_000, 100_000)
>>> bool(np.array_equal(whole[:, 70_000:], part))
True
"""

from __future__ import annotations

import zlib

import numpy as np
from scipy.special import ndtri

from schuler.core import _normal_kernels
from schuler.exceptions import InvalidParameter

_BLOCK_BITS = 16
BLOCK = 1 << _BLOCK_BITS
"""Samples per block of :meth:`RandomStreams.normal_series` (65,536)."""

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)
_MEMBER_GAMMA = np.uint64(0xD1B54A32D192ED03)
"""The odd increment that spreads members' keys (not the counters' golden ratio, so the two never align)."""
_MASK64 = (1 << 64) - 1
_LARGEST_BLOCK = 1 << 27


def _mix(z: np.ndarray) -> np.ndarray:
    """The SplitMix64 finaliser (integer arrays wrap modulo 2**64, as it needs)."""
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


def _stream_key(seed: int, stream: str) -> int:
    """A 64-bit key for (seed, stream)."""
    mixed = _mix(np.array([seed & _MASK64], dtype=np.uint64) ^ np.uint64(zlib.crc32(stream.encode())))
    return int(mixed[0])


class RandomStreams:
    """Addressed random numbers for one study seed.

    Parameters
    ----------
    seed : int
        Non-negative study seed.
    """

    def __init__(self, seed: int):
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise InvalidParameter("seed", f"{seed!r} must be a whole number >= 0")
        self.seed = int(seed)

    def __repr__(self) -> str:
        return f"RandomStreams(seed={self.seed})"

    def uniform(self, stream: str, members, size: int | None = None) -> np.ndarray:
        """Uniform numbers in (0, 1): shape (n,) or (n, size) for ``members`` of length n.

        Parameters
        ----------
        stream : str
            Name of the stream (one per random term).
        members : array_like of int
            Member numbers: the addresses of the draws.
        size : int, optional
            Number of draws per member (None: one, shape (n,)).
        """
        members = np.asarray(members, dtype=np.int64)
        if members.size and members.min() < 0:
            raise InvalidParameter("member", "member numbers must be >= 0")
        width = 1 if size is None else int(size)
        key = np.uint64(_stream_key(self.seed, stream))
        counter = members.astype(np.uint64)[:, None] * np.uint64(width) + np.arange(width, dtype=np.uint64)[None, :]
        state = key + (counter + np.uint64(1)) * _GOLDEN
        u = ((_mix(state) >> np.uint64(11)).astype(float) + 0.5) * 2.0**-53
        return u[:, 0] if size is None else u

    def normal(self, stream: str, members, size: int | None = None) -> np.ndarray:
        """Standard normal numbers (inverse CDF of :meth:`uniform`), shape (n,) or (n, size).

        Parameters
        ----------
        stream : str
            Name of the stream (one per random term).
        members : array_like of int
            Member numbers: the addresses of the draws.
        size : int, optional
            Number of draws per member (None: one, shape (n,)).
        """
        return ndtri(self.uniform(stream, members, size))

    def normal_series(self, stream: str, members, start: int, stop: int) -> np.ndarray:
        """Standard normal samples ``start .. stop-1`` of each member: shape (n, stop - start).

        Parameters
        ----------
        stream : str
            Name of the stream (one per random term).
        members : array_like of int
            Member numbers: the addresses of the draws.
        start, stop : int
            Index range of the samples (sample k of a member is the same however the series is cut).
        """
        members = np.asarray(members, dtype=np.int64).reshape(-1)
        start, stop = int(start), int(stop)
        if start < 0 or stop < start:
            raise InvalidParameter("samples", f"window [{start}, {stop}) must satisfy 0 <= start <= stop")
        out = np.empty((members.size, stop - start))
        if stop == start:
            return out
        keys = _member_keys(_stream_key(self.seed, stream), members)
        _normal_kernels.fill_series(keys, start, stop, _BLOCK_BITS, out, *_normal_kernels.tables())
        return out

    def normal_block(self, stream: str, member: int, block: int, size: int) -> np.ndarray:
        """The first ``size`` standard normals of one block of a member's stream, shape (size,).

        Block ``block`` is the generator of samples ``block * BLOCK ..`` of
        :meth:`normal_series`, drawn here for any ``size`` (also beyond
        :data:`BLOCK`): ``normal_block(s, m, b, n)`` equals
        ``normal_series(s, [m], b * BLOCK, b * BLOCK + n)[0]`` for n <= BLOCK.

        Parameters
        ----------
        stream : str
            Name of the stream.
        member : int
            Member number, index >= 0.
        block : int
            Block number, index >= 0 (block b starts at sample index b BLOCK of the series).
        size : int
            Number of normals drawn from the block's start (>= 0).

        Examples
        --------
        >>> streams = RandomStreams(7)
        >>> block = streams.normal_block("gyro_x/slow", 3, 1, 10)
        >>> bool(np.array_equal(block, streams.normal_series("gyro_x/slow", [3], BLOCK, BLOCK + 10)[0]))
        True
        """
        if member < 0 or block < 0 or size < 0:
            raise InvalidParameter("block", f"member {member}, block {block} and size {size} must be >= 0")
        if size > _LARGEST_BLOCK:
            raise InvalidParameter("block", f"size {size:,} is above {_LARGEST_BLOCK:,} normals (1 GiB) per block")
        out = np.empty(int(size))
        key = _member_keys(_stream_key(self.seed, stream), np.array([member]))[0]
        _normal_kernels.fill_block(key, int(block), out, *_normal_kernels.tables())
        return out


def _member_keys(stream_key: int, members: np.ndarray) -> np.ndarray:
    """Each member's 64-bit key within a stream, uint64 (n,)."""
    return _mix(np.uint64(stream_key) + (np.asarray(members).astype(np.uint64) + np.uint64(1)) * _MEMBER_GAMMA)
