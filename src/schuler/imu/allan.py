"""Overlapping Allan deviation, streamed in chunks, with confidence intervals from equivalent degrees of freedom.

For rate samples y_k (k = 1..n, interval tau0) the angle (phase) series is
theta_0 = 0, theta_k = tau0 sum_{i<=k} (y_i - c), c a constant offset (the mean
of the first chunk: a constant leaves the Allan variance unchanged, and removing
it keeps theta small, so that the second differences do not cancel digits).
The overlapping estimator at tau = m tau0 (IEEE Std 952 Annex C; Riley, NIST
SP 1065, eq. 14) is::

    sigma^2(tau) = sum_{k=0}^{n-2m} (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2 / (2 tau^2 (n + 1 - 2m))

:class:`AllanAccumulator` takes the samples chunk by chunk and keeps only the
last 2 m_max + 1 angles, so a record of 10^8 samples needs memory for its
largest lag, not for the record; every second difference is counted once, when
its last point arrives. The sums are those of allantools' ``oadev`` (which
subtracts the mean and integrates in the same order), to about 1e-13 relative
(tests/test_imu_allan.py checks 1e-12).

Confidence intervals: chi-square with Greenhall's equivalent degrees of freedom
(``allantools.edf_greenhall``; C. A. Greenhall, W. J. Riley, "Uncertainty of
stability variances based on finite differences", PTTI 2003) for the power-law
noise type alpha read from the local slope of the curve: sigma^2 ~ tau^mu with
alpha = -mu - 1 rounded into [-2, 0] (angle random walk: alpha = 0; flicker: -1;
rate random walk: -2), and alpha = 2 (white angle noise, quantisation) where
mu < -1.5; alpha may only decrease with tau (the dominant noise gets redder), so
that a steep stretch of a noisy long-tau tail does not get white-noise edf.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu import _kernels

DEFAULT_MAX_FRACTION = 0.125
"""Largest lag as a fraction of the sample count: at least ~6 non-overlapping differences at the longest tau."""


def allan_lags(samples: int, per_octave: int = 2, max_fraction: float = DEFAULT_MAX_FRACTION) -> np.ndarray:
    """Lags m (in samples), ``per_octave`` per octave from 1 up to ``max_fraction`` x samples.

    Parameters
    ----------
    samples : int
        Number of samples in the record.
    per_octave : int
        Number of lags per octave.
    max_fraction : float
        Largest lag as a fraction of the record (dimensionless).

    Examples
    --------
    >>> allan_lags(100, per_octave=1).tolist()
    [1, 2, 4, 8]
    """
    if samples < 4:
        raise InvalidParameter("samples", f"an Allan deviation needs at least 4 samples, got {samples}")
    if not 0 < max_fraction <= 0.5:
        raise InvalidParameter("max_fraction", f"{max_fraction!r} must be in (0, 0.5]")
    largest = max(1, int(samples * max_fraction))
    count = int(math.floor(math.log2(largest) * per_octave)) + 1
    return np.unique(np.round(2.0 ** (np.arange(count) / per_octave)).astype(np.int64))


@dataclass
class AllanCurve:
    """Overlapping Allan deviation of one channel with its confidence interval.

    Attributes
    ----------
    tau_s : ndarray
        Averaging times, s.
    adev : ndarray
        Allan deviation, in the channel's rate unit (rad/s or m/s^2).
    adev_lower, adev_upper : ndarray
        The 68.3 % confidence interval.
    edf : ndarray
        Equivalent degrees of freedom.
    alpha : ndarray
        Power-law noise type used for each edf.
    terms : ndarray
        Number of second differences summed at each tau.
    samples : int
    sample_interval_s : float
    offset : float
        The constant removed before integrating (rate unit).
    """

    tau_s: np.ndarray
    adev: np.ndarray
    adev_lower: np.ndarray
    adev_upper: np.ndarray
    edf: np.ndarray
    alpha: np.ndarray
    terms: np.ndarray = field(repr=False)
    samples: int = 0
    sample_interval_s: float = 1.0
    offset: float = 0.0

    @property
    def avar(self) -> np.ndarray:
        """Allan variance."""
        return self.adev**2


def noise_types(tau, avar) -> np.ndarray:
    """alpha per tau from the local log-log slope of the Allan variance over about +/- one octave, non-increasing.

    Parameters
    ----------
    tau : ndarray
        Averaging times, s.
    avar : ndarray
        Allan variance at ``tau``, in the channel's rate unit squared.
    """
    log_tau, log_avar = np.log(np.asarray(tau, float)), np.log(np.maximum(np.asarray(avar, float), 1e-300))
    alpha = np.zeros(log_tau.size, dtype=int)
    for i in range(log_tau.size):
        near = np.abs(log_tau - log_tau[i]) <= math.log(2.0) + 1e-9
        if near.sum() < 2:
            near = np.abs(np.arange(log_tau.size) - i) <= 1
        slope = np.polyfit(log_tau[near], log_avar[near], 1)[0] if near.sum() >= 2 else -1.0
        # mu = -2 is white (or flicker) angle noise: quantisation, alpha = 2
        alpha[i] = 2 if slope < -1.5 else int(np.clip(round(-slope - 1.0), -2, 0))
    # noise gets redder with tau: a steep stretch of a noisy long-tau tail is not white angle noise,
    # whose edf would be far larger (a point with a false huge edf would rule the term fit)
    return np.minimum.accumulate(alpha)


def confidence(adev, alpha, lags, phase_points: int, confidence_level: float = 0.6826894921370859):
    """Greenhall edf and the chi-square interval of each deviation: (edf, lower, upper).

    Parameters
    ----------
    adev : ndarray
        Allan deviation, in the channel's rate unit (rad/s or m/s^2).
    alpha : ndarray
        Power-law noise type at each lag (dimensionless exponent).
    lags : ndarray of int
        Lags m, in samples.
    phase_points : int
        Number of integrated (phase) samples.
    confidence_level : float
        Probability covered by the interval (dimensionless, 0.683: 1 sigma).
    """
    import allantools

    edf = np.array([allantools.edf_greenhall(alpha=int(a), d=2, m=int(m), N=int(phase_points), overlapping=True,
                                             modified=False) for a, m in zip(alpha, lags)], dtype=float)
    lower, upper = np.empty_like(edf), np.empty_like(edf)
    for i, (dev, dof) in enumerate(zip(adev, edf)):
        lower[i], upper[i] = allantools.confidence_interval(dev, dof, ci=confidence_level)
    return edf, lower, upper


class AllanAccumulator:
    """Streams rate samples of one or more channels into overlapping Allan variances.

    Parameters
    ----------
    sample_interval_s : float
        tau0, s.
    lags : array_like of int
        Lags m (samples); see :func:`allan_lags`.
    channels : int
        Columns of each chunk.
    offsets : array_like, optional
        The constant c per channel removed before integrating (default: the
        mean of the first chunk). Any constant gives the same Allan variance in
        exact arithmetic; the whole record's mean, when known, gives allantools'
        phase bit for bit.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> y = rng.normal(size=(20_000, 1))
    >>> acc = AllanAccumulator(1.0, allan_lags(20_000), channels=1)
    >>> for part in np.array_split(y, 3):
    ...     acc.update(part)
    >>> curve = acc.curves()[0]
    >>> bool(abs(curve.adev[0] - 1.0) < 0.02)   # white noise: sigma(tau0) = sigma
    True
    """

    @renamed_keywords(sample_interval_s="sample_interval")
    def __init__(self, sample_interval: float, lags, channels: int = 6, offsets=None):
        self.dt = float(sample_interval)
        if not (math.isfinite(self.dt) and self.dt > 0):
            raise InvalidParameter("sample_interval_s", f"must be finite and > 0, got {sample_interval!r}")
        self.lags = np.asarray(lags, dtype=np.int64)
        if self.lags.ndim != 1 or self.lags.size == 0 or self.lags.min() < 1:
            raise InvalidParameter("lags", "give one or more lags >= 1")
        self.channels = int(channels)
        self.samples = 0
        self._span = 2 * int(self.lags.max())
        self._tails = [np.zeros(1) for _ in range(self.channels)]  # theta_0 = 0
        self._totals = np.zeros(self.channels)
        self._offsets = None if offsets is None else np.asarray(offsets, dtype=float).reshape(self.channels)
        self._sums = np.zeros((self.channels, self.lags.size))
        self._counts = np.zeros((self.channels, self.lags.size), dtype=np.int64)

    def update(self, chunk) -> None:
        """Add rate samples, shape (L, channels) (or (L,) for one channel).

        Parameters
        ----------
        chunk : ndarray, shape (L, channels) or (L,)
            Rate samples, rad/s or m/s^2.
        """
        chunk = np.asarray(chunk, dtype=float)
        if chunk.ndim == 1:
            chunk = chunk[:, None]
        if chunk.ndim != 2 or chunk.shape[1] != self.channels:
            raise InvalidParameter("chunk", f"shape {chunk.shape} must be (L, {self.channels})")
        if chunk.shape[0] == 0:
            return
        if not np.all(np.isfinite(chunk)):
            raise InvalidParameter("chunk", "samples must be finite")
        if self._offsets is None:
            self._offsets = chunk.mean(axis=0)
        for c in range(self.channels):
            tail = self._tails[c]
            phase = np.empty(tail.size + chunk.shape[0])
            phase[:tail.size] = tail
            column = np.ascontiguousarray(chunk[:, c])
            self._totals[c] = _kernels.accumulate(column, self._offsets[c], self.dt, self._totals[c],
                                                  phase[tail.size:])
            _kernels.second_difference_sums(phase, tail.size, self.lags, self._sums[c], self._counts[c])
            self._tails[c] = phase[-min(phase.size, self._span + 1):].copy()
        self.samples += chunk.shape[0]

    def curves(self, with_confidence: bool = True, max_lag: int | None = None) -> list[AllanCurve]:
        """One :class:`AllanCurve` per channel, over the lags (up to ``max_lag``) with a second difference.

        Parameters
        ----------
        with_confidence : bool
            Compute the edf and the confidence interval.
        max_lag : int, optional
            Largest lag, in samples.
        """
        valid = self._counts[0] > 0
        offsets = [0.0] * self.channels if self._offsets is None else [float(v) for v in self._offsets]
        if max_lag is not None:
            valid &= self.lags <= max(1, int(max_lag))
        lags = self.lags[valid]
        tau = lags * self.dt
        out = []
        for c in range(self.channels):
            avar = self._sums[c, valid] / (2.0 * tau**2 * self._counts[c, valid])
            adev = np.sqrt(avar)
            alpha = noise_types(tau, avar) if tau.size else np.zeros(0, dtype=int)
            if with_confidence and tau.size:
                edf, lower, upper = confidence(adev, alpha, lags, self.samples + 1)
            else:
                edf, lower, upper = (np.full(tau.size, np.nan) for _ in range(3))
            out.append(AllanCurve(tau_s=tau, adev=adev, adev_lower=lower, adev_upper=upper, edf=edf, alpha=alpha,
                                  terms=self._counts[c, valid].copy(), samples=self.samples,
                                  sample_interval_s=self.dt, offset=offsets[c]))
        return out


@renamed_keywords(sample_interval_s="sample_interval")
def allan_deviation(rates, sample_interval: float, lags=None, chunk: int = 1 << 20) -> AllanCurve:
    """Overlapping Allan deviation of one channel of rate samples (an array), with confidence intervals.

    Parameters
    ----------
    rates : array_like, shape (n,)
        Rate samples (rad/s or m/s^2), mean over each interval.
    sample_interval : float
        tau0, s.
    lags : array_like of int, optional
        Lags m, number of samples (default :func:`allan_lags`: two per octave, up to n / 8).
    chunk : int
        Samples per streamed chunk (the result does not depend on it beyond rounding).
    """
    rates = np.asarray(rates, dtype=float).reshape(-1)
    lags = allan_lags(rates.size) if lags is None else lags
    accumulator = AllanAccumulator(sample_interval, lags, channels=1, offsets=[np.mean(rates)])
    for start in range(0, rates.size, chunk):
        accumulator.update(rates[start:start + chunk])
    return accumulator.curves()[0]
