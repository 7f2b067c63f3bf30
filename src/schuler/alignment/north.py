"""North finding with a gyro (or a level IMU) on a turntable: two positions, four positions, carouseling.

A level IMU on a turntable turned by theta (clockwise seen from above, like a
heading) has its x axis at azimuth psi + theta; psi is what is sought. Its
horizontal gyros read (spec 06, "North finding with one gyro")

    S_x(theta) = Omega cos L cos(psi + theta) + b_x = A cos theta + B sin theta + b_x
    S_y(theta) = -Omega cos L sin(psi + theta) + b_y = B cos theta - A sin theta + b_y

with A = Omega cos L cos psi and B = -Omega cos L sin psi, so psi = atan2(-B, A)
whatever the gyro's scale factor. Each method is one schedule theta(t) and one
linear least-squares fit of (A, B, biases) to the samples; a sample is the mean
rate over its interval, so the regressors are the interval means of cos theta
and sin theta:

* ``two_position``: theta = 0 for the first half, 180 deg for the second. One gyro
  sees only A: cos psi = (S_0 - S_180) / (2 Omega cos L), the bias cancels, the
  sign of psi is ambiguous (reported in [0, 180] deg) and the scale factor does
  not cancel; with the y gyro too (``axes="xy"``) B comes from it.
* ``four_position``: 0, 90, 180, 270 deg for a quarter each:
  psi = atan2(-(S_90 - S_270), S_0 - S_180); bias and scale factor cancel.
* ``carousel``: continuous rotation at a constant rate; amplitude and phase of the
  sinusoid (Prikhodko et al. 2013).

Uncertainty: the fit's covariance sigma^2 (X^T X)^-1 with sigma^2 from the
residuals, carried to psi by its gradient (B, -A) / (A^2 + B^2). For white
noise of density N over a total time T (equal dwells; whole turns):

    two positions, one gyro: sigma_psi = N / (Omega cos L sqrt(T) |sin psi|)
    four positions or carousel, one gyro: sigma_psi = sqrt(2) N / (Omega cos L sqrt(T))
    with the y gyro as well (any method): sigma_psi = N / (Omega cos L sqrt(T))

(:func:`north_sigma`). Constant biases cancel; bias instability does not -- the
position methods see the bias change between dwells, carouseling modulates the
signal away from it.

References
----------
Prikhodko, I. P.; Zotov, S. A.; Trusov, A. A.; Shkel, A. M., "What is MEMS
gyrocompassing? Comparative analysis of maytagging and carouseling", Journal of
Microelectromechanical Systems 22(6), 2013, pp. 1257-1266.

Examples
--------
>>> import math
>>> import numpy as np
>>> start, end = schedule("four_position", samples=400, sample_interval=0.5)
>>> latitude, psi = math.radians(45.0), math.radians(-40.0)
>>> gyro = turntable_rates(latitude, psi, start, end, 0.5)
>>> estimate = find_north(gyro[None, :, :2], start, end, latitude, "four_position", axes="xy")
>>> round(float(np.degrees(estimate.heading_rad[0])), 9)
-40.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.alignment.limits import horizontal_rate
from schuler.core.attitude import wrap_angle
from schuler.core.earth import EARTH_RATE
from schuler.exceptions import InvalidParameter, renamed_keywords

NORTH_METHODS = ("two_position", "four_position", "carousel")
"""The turntable north finders."""

AXES = ("x", "xy")
"""A single gyro (x) or the two horizontal gyros of a level IMU (x and y)."""

DEFAULT_CAROUSEL_PERIOD = 60.0
"""One turn of the carousel, s."""


@renamed_keywords(sample_interval_s="sample_interval", carousel_period_s="carousel_period")
def schedule(method: str, *, samples: int, sample_interval: float,
             carousel_period: float = DEFAULT_CAROUSEL_PERIOD) -> tuple[np.ndarray, np.ndarray]:
    """Turntable angle at the start and the end of each sample interval, rad (each shape (samples,)).

    The turns between positions are taken as instantaneous (an ideal table).

    Parameters
    ----------
    method : {"two_position", "four_position", "carousel"}
        The north-finding schedule.
    samples : int
        Number of samples (at least 4); the positions get equal shares of them.
    sample_interval : float
        Sample interval dt, s.
    carousel_period : float
        One turn of the carousel, s (``carousel`` only).

    Returns
    -------
    start, end : ndarray of shape (samples,)
        Table angle theta at the start and the end of each interval, rad (clockwise seen from above).

    Raises
    ------
    InvalidParameter
        An unknown method, fewer than 4 samples or a carousel period not finite and positive.
    """
    if method not in NORTH_METHODS:
        raise InvalidParameter("method", f"{method!r} is not one of {', '.join(NORTH_METHODS)}")
    if samples < 4:
        raise InvalidParameter("duration", f"a north finder needs at least 4 samples, got {samples}")
    k = np.arange(samples)
    if method == "carousel":
        if not (math.isfinite(carousel_period) and carousel_period > 0):
            raise InvalidParameter("carousel_period", f"must be finite and > 0 s, got {carousel_period!r}")
        rate = 2.0 * math.pi / carousel_period
        return rate * sample_interval * k, rate * sample_interval * (k + 1)
    positions = 2 if method == "two_position" else 4
    angle = (k * positions // samples) * (2.0 * math.pi / positions)
    return angle.astype(float), angle.astype(float)


def _interval_means(start, end) -> tuple[np.ndarray, np.ndarray]:
    """Means of cos theta and sin theta over each interval (theta linear in time)."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    turn = end - start
    moving = np.abs(turn) > 1e-12
    safe = np.where(moving, turn, 1.0)
    cos_mean = np.where(moving, (np.sin(end) - np.sin(start)) / safe, np.cos(start))
    sin_mean = np.where(moving, (np.cos(start) - np.cos(end)) / safe, np.sin(start))
    return cos_mean, sin_mean


@renamed_keywords(sample_interval_s="sample_interval")
def turntable_rates(latitude: float, heading: float, start, end, sample_interval: float) -> np.ndarray:
    """True mean angular rates (n, 3) of a level IMU on the table: Earth rate plus the table's rate about z (down).

    Parameters
    ----------
    latitude, heading : float
        L and the azimuth psi of the x axis at theta = 0, rad.
    start, end : ndarray (n,)
        Table angle at each interval's start and end, rad (:func:`schedule`).
    sample_interval : float
        dt, s.
    """
    cos_mean, sin_mean = _interval_means(start, end)
    horizontal, vertical = EARTH_RATE * math.cos(latitude), EARTH_RATE * math.sin(latitude)
    c, s = math.cos(heading), math.sin(heading)
    rates = np.empty((np.size(cos_mean), 3))
    # cos(psi + theta) = c cos theta - s sin theta; sin(psi + theta) = s cos theta + c sin theta
    rates[:, 0] = horizontal * (c * cos_mean - s * sin_mean)
    rates[:, 1] = -horizontal * (s * cos_mean + c * sin_mean)
    rates[:, 2] = -vertical + (np.asarray(end) - np.asarray(start)) / sample_interval
    return rates


@dataclass
class TurntableNorthEstimate:
    """North from a turntable record, for every record of a batch.

    Attributes
    ----------
    method, axes : str
    heading_rad : ndarray (m,)
        Azimuth psi of the x axis at theta = 0, clockwise from north, rad.
    sigma_rad : ndarray (m,)
        Its 1-sigma from the fit's residuals, rad.
    ambiguous : bool
        True when the sign of psi is unknown (two positions, one gyro: psi in [0, pi]).
    bias_rad_s : ndarray (m, k)
        Estimated gyro biases, rad/s.
    """

    method: str
    axes: str
    heading_rad: np.ndarray
    sigma_rad: np.ndarray
    ambiguous: bool
    bias_rad_s: np.ndarray


def find_north(rates, start, end, latitude: float, method: str, axes: str = "x") -> TurntableNorthEstimate:
    """North from gyro samples on a turntable schedule, every record at once (module notes).

    Parameters
    ----------
    rates : ndarray (m, n, k)
        Mean rates of the x gyro (k = 1) or the x and y gyros (k = 2) over each sample interval, rad/s.
    start, end : ndarray (n,)
        Table angle at each interval's start and end, rad.
    latitude : float
        L, rad.
    method : {"two_position", "four_position", "carousel"}
    axes : {"x", "xy"}

    Returns
    -------
    TurntableNorthEstimate
    """
    if axes not in AXES:
        raise InvalidParameter("axes", f"{axes!r} is not one of {', '.join(AXES)}")
    if method not in NORTH_METHODS:
        raise InvalidParameter("method", f"{method!r} is not one of {', '.join(NORTH_METHODS)}")
    rates = np.asarray(rates, dtype=float)
    channels = len(axes)
    if rates.ndim != 3 or rates.shape[2] != channels or rates.shape[1] != np.size(start):
        raise InvalidParameter("rates", f"shape {rates.shape} must be (members, {np.size(start)}, {channels})")
    horizontal = float(horizontal_rate(latitude))
    cos_mean, sin_mean = _interval_means(start, end)
    n = cos_mean.size
    single_two = method == "two_position" and axes == "x"
    # unknowns: A, (B,) bias_x, (bias_y); rows: the x samples, then the y samples
    columns = 1 + (0 if single_two else 1) + channels
    X = np.zeros((channels * n, columns))
    X[:n, 0] = cos_mean
    if not single_two:
        X[:n, 1] = sin_mean
    bias_column = columns - channels
    X[:n, bias_column] = 1.0
    if channels == 2:
        X[n:, 0] = -sin_mean
        X[n:, 1] = cos_mean
        X[n:, bias_column + 1] = 1.0
    y = np.concatenate([rates[:, :, c] for c in range(channels)], axis=1).T   # (channels n, m)
    solution, _, rank, _ = np.linalg.lstsq(X, y, rcond=None)
    if rank < columns:
        raise InvalidParameter("method", f"{method} with axes {axes!r} does not determine the fit (rank {rank})")
    residual = y - X @ solution
    variance = (residual**2).sum(axis=0) / max(1, X.shape[0] - columns)
    covariance = np.linalg.inv(X.T @ X)
    a = solution[0]
    if single_two:
        ratio = np.clip(a / horizontal, -1.0, 1.0)
        heading = np.arccos(ratio)
        sine = np.maximum(np.sqrt(1.0 - ratio**2), 1e-12)
        sigma = np.sqrt(variance * covariance[0, 0]) / (horizontal * sine)
    else:
        b = solution[1]
        heading = wrap_angle(np.arctan2(-b, a))
        norm = a**2 + b**2
        gradient = np.stack([b, -a]) / norm
        sigma = np.sqrt(variance * np.einsum("im,ij,jm->m", gradient, covariance[:2, :2], gradient))
    return TurntableNorthEstimate(method, axes, heading, sigma, single_two, solution[bias_column:].T)


def north_sigma(method: str, axes: str, random_walk, latitude: float, duration, heading: float = math.pi / 2):
    """Closed-form 1-sigma of psi for white gyro noise (module notes), rad.

    Parameters
    ----------
    method : {"two_position", "four_position", "carousel"}
    axes : {"x", "xy"}
    random_walk : float
        N of the gyros, rad/sqrt(s).
    latitude : float
        L, rad.
    duration : float or ndarray
        Total time T, s.
    heading : float
        psi (matters for two positions with one gyro only), rad.
    """
    if method not in NORTH_METHODS:
        raise InvalidParameter("method", f"{method!r} is not one of {', '.join(NORTH_METHODS)}")
    if axes not in AXES:
        raise InvalidParameter("axes", f"{axes!r} is not one of {', '.join(AXES)}")
    base = random_walk / (float(horizontal_rate(latitude)) * np.sqrt(np.asarray(duration, dtype=float)))
    if axes == "xy":
        return base
    if method == "two_position":
        return base / max(abs(math.sin(heading)), 1e-12)
    return math.sqrt(2.0) * base
