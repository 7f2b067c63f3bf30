"""Streaming statistics over Monte Carlo members, in bounded memory.

A Monte Carlo of 100,000 members over 7,200 time points would need 100,000 full
histories to compute statistics naively. :class:`StreamingStatistics` takes the
members chunk by chunk and keeps, per time point and channel, the count, mean and
sum of squared deviations (Chan et al.'s parallel merge of Welford's update), the
minimum and maximum, and a fixed-size uniform random sample of members (a
reservoir, chosen by the smallest of one seeded random key per member) from
which percentiles are taken. Percentiles are exact while the number of members
does not exceed the reservoir size, and estimates from a uniform sample beyond.
"""

from __future__ import annotations

import numpy as np

from schuler.exceptions import InvalidParameter


class StreamingStatistics:
    """Mean, standard deviation, extremes and percentiles of streamed samples.

    Parameters
    ----------
    shape : tuple of int
        Shape of one member's sample, e.g. ``(n_time, n_channels)``.
    reservoir_size : int
        Members kept for percentiles (memory: reservoir_size x prod(shape) floats,
        allocated up front; 0 keeps none and offers no percentiles).
    seed : int
        Seed of the reservoir's random keys.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> data = rng.normal(size=(1000, 3))
    >>> stats = StreamingStatistics((3,), reservoir_size=1000)
    >>> for chunk in np.array_split(data, 7):
    ...     stats.update(chunk)
    >>> bool(np.allclose(stats.mean, data.mean(axis=0)))
    True
    >>> bool(np.allclose(stats.std, data.std(axis=0, ddof=1)))
    True
    >>> bool(np.allclose(stats.percentile(50), np.percentile(data, 50, axis=0)))
    True
    """

    def __init__(self, shape: tuple[int, ...], reservoir_size: int = 2048, seed: int = 0):
        if not (isinstance(reservoir_size, (int, np.integer)) and reservoir_size >= 0):
            raise InvalidParameter("reservoir_size", f"must be a whole number >= 0, got {reservoir_size!r}")
        self.shape = tuple(shape)
        self.count = 0
        self._mean = np.zeros(self.shape)
        self._m2 = np.zeros(self.shape)
        self._min = np.full(self.shape, np.inf)
        self._max = np.full(self.shape, -np.inf)
        self._reservoir_size = int(reservoir_size)
        self._rng = np.random.default_rng(seed)
        self._keys = np.empty(self._reservoir_size)
        self._reservoir = np.empty((self._reservoir_size, *self.shape))
        self._kept = 0

    def update(self, samples: np.ndarray) -> None:
        """Add a chunk of members, shape ``(k, *shape)``.

        Parameters
        ----------
        samples : ndarray
            One sample per member, shape ``(k, *shape)``, in the unit of the statistic.
        """
        samples = np.asarray(samples, dtype=float)
        if samples.shape[1:] != self.shape:
            raise ValueError(f"samples of shape {samples.shape[1:]} do not match {self.shape}")
        k = samples.shape[0]
        if k == 0:
            return
        chunk_mean = samples.mean(axis=0)
        chunk_m2 = ((samples - chunk_mean) ** 2).sum(axis=0)
        total = self.count + k
        delta = chunk_mean - self._mean
        self._mean = self._mean + delta * (k / total)
        self._m2 = self._m2 + chunk_m2 + delta**2 * (self.count * k / total)
        self.count = total
        np.minimum(self._min, samples.min(axis=0), out=self._min)
        np.maximum(self._max, samples.max(axis=0), out=self._max)
        self._sample(samples)

    def _sample(self, samples: np.ndarray) -> None:
        """Keep the members with the smallest random keys, replacing others in place (no pool copy)."""
        size, kept = self._reservoir_size, self._kept
        keys = np.asarray(self._rng.random(samples.shape[0]))
        if kept + keys.size <= size:
            self._reservoir[kept : kept + keys.size] = samples
            self._keys[kept : kept + keys.size] = keys
            self._kept += keys.size
            return
        chosen = np.argpartition(np.concatenate([self._keys[:kept], keys]), size - 1)[:size]
        newcomers = chosen[chosen >= kept] - kept
        # slots of the members that lost their place, then the never-filled ones
        slots = np.concatenate([np.setdiff1d(np.arange(kept), chosen[chosen < kept]), np.arange(kept, size)])
        self._reservoir[slots] = samples[newcomers]
        self._keys[slots] = keys[newcomers]
        self._kept = size

    @property
    def mean(self) -> np.ndarray:
        """Mean over members."""
        return self._mean.copy()

    @property
    def std(self) -> np.ndarray:
        """Sample standard deviation over members (ddof = 1; 0 for one member)."""
        if self.count < 2:
            return np.zeros(self.shape)
        return np.sqrt(self._m2 / (self.count - 1))

    @property
    def rms(self) -> np.ndarray:
        """Root mean square over members."""
        if self.count == 0:
            return np.zeros(self.shape)
        return np.sqrt(self._mean**2 + self._m2 / self.count)

    @property
    def min(self) -> np.ndarray:
        return self._min.copy()

    @property
    def max(self) -> np.ndarray:
        return self._max.copy()

    @property
    def exact_percentiles(self) -> bool:
        """True while every member seen is in the reservoir."""
        return self.count <= self._reservoir_size

    def percentile(self, q) -> np.ndarray:
        """Percentile(s) ``q`` (0..100) over members, from the reservoir.

        Parameters
        ----------
        q : float or array_like
            Percentile(s), percent (0 to 100).
        """
        if self.count == 0:
            raise ValueError("no samples yet")
        if self._reservoir_size == 0:
            raise InvalidParameter("reservoir_size", "is 0: no members were kept for percentiles")
        return np.percentile(self._reservoir[: self._kept], q, axis=0)
