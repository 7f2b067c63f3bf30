"""IEEE Std 952 noise terms from an Allan curve: weighted least squares with uncertainties and resolvability.

The Allan variance of the rate is linear in the squared coefficients
c = (Q^2, N^2, B^2, K^2, R^2) (IEEE Std 952-1997, Annex C, eq. C.30)::

    sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2

so they are fitted by non-negative least squares (``scipy.optimize.nnls``) with
weights from the estimator's variance, var(sigma^2) = 2 sigma^4 / edf, the
sigma^2 taken from the model itself in a few reweighting passes (weights from
the measured values would favour points that happen to fall low). The
covariance of the active coefficients is (A^T W A)^-1; a term's standard
uncertainty follows by the delta method, u(N) = u(N^2) / (2 N).

When chi^2 per point exceeds 2 the five terms do not describe the curve (a
vehicle's sway, periodic disturbances); a relative uncertainty ``model_floor``
is then added to every point, the smallest that brings chi^2 per point to 1
(an extra-variance, Birge-ratio treatment), and the terms are to be read as a
description of the curve, not of the sensor.

The overlapping estimates at neighbouring tau are correlated (they share
data), which the weights ignore: the formal uncertainties are too small. Over
16 seeds x 3 axes of one-hour 100 Hz records (Q, N, flicker B, K all present,
two lags per octave) the rms of (identified - expected) / formal sigma was
4.2 for Q, 2.1 for N, 1.8 for B and 4.5 for K; the reported sigma is the formal
one times :data:`SIGMA_INFLATION` (4, 2, 2, 4, 4 for Q, N, B, K, R), which
brings those rms values to about 1 (tests/test_imu_identify.py checks the
coverage on fresh seeds).

A term is **resolved** when its squared coefficient is at least twice its own
uncertainty (the value is known to about 25 % or better); otherwise the record
is too short (K, R need long tau) or too noisy at its scales (B hidden under N),
and ``upper_bound`` gives the value the fit can exclude at about 2 sigma.
``dominant_tau_s`` says where on the tau axis each term makes at least a
quarter of the model variance.

The bias instability B of this fit is a flicker coefficient; a first-order
Gauss-Markov bias of standard deviation sigma has an Allan-deviation bump of
height 0.6174 sigma at tau = 1.893 T, read as B ~ 0.93 sigma
(:mod:`~schuler.imu.error_model`).

References
----------
IEEE Std 952-1997, Annex C. N. El-Sheimy, H. Hou, X. Niu, IEEE Trans. Instrum.
Meas. 57(1), 2008 (the read-offs N = sigma(1 s), K = sigma(3 s), B = sigma_min / 0.664).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import nnls

from schuler.exceptions import IdentificationError
from schuler.imu.allan import AllanCurve
from schuler.imu.error_model import FLICKER_FLOOR

TERMS = ("Q", "N", "B", "K", "R")
"""Quantisation, (angle/velocity) random walk, bias instability, rate random walk, rate ramp."""

SIGMA_INFLATION = {"Q": 4.0, "N": 2.0, "B": 2.0, "K": 4.0, "R": 4.0}
"""Factor from the weighted-least-squares sigma to the reported one (correlated overlapping estimates)."""

SLOPES = {"Q": -1.0, "N": -0.5, "B": 0.0, "K": 0.5, "R": 1.0}
"""Log-log slope of each term's Allan deviation."""


def term_basis(tau) -> np.ndarray:
    """Columns of sigma^2(tau) per unit squared coefficient: (3/tau^2, 1/tau, 2 ln2/pi, tau/3, tau^2/2).

    Parameters
    ----------
    tau : ndarray
        Averaging times, s.
    """
    tau = np.asarray(tau, dtype=float)
    return np.column_stack([3.0 / tau**2, 1.0 / tau, np.full(tau.size, FLICKER_FLOOR**2), tau / 3.0, tau**2 / 2.0])


def term_allan_deviations(values: dict[str, float], tau) -> dict[str, np.ndarray]:
    """Each term's own Allan deviation at ``tau`` (the slope lines of the plot).

    Parameters
    ----------
    values : dict of str to float
        The terms Q, N, B, K, R in SI (rad, rad/sqrt(s), rad/s ... for a gyro).
    tau : ndarray
        Averaging times, s.
    """
    basis = term_basis(tau)
    return {term: np.sqrt(basis[:, i]) * values[term] for i, term in enumerate(TERMS)}


def model_allan_deviation(values: dict[str, float], tau) -> np.ndarray:
    """The Allan deviation of the terms together at ``tau`` (eq. C.30), in the channel's rate unit.

    Parameters
    ----------
    values : dict of str to float
        The terms Q, N, B, K, R in SI (rad, rad/sqrt(s), rad/s ... for a gyro).
    tau : float or ndarray
        Averaging times, s.
    """
    return np.sqrt(term_basis(tau) @ np.array([values[t] ** 2 for t in TERMS]))


@dataclass
class NoiseTerms:
    """IEEE 952 coefficients of one channel, SI, with standard uncertainties.

    Attributes
    ----------
    values : dict
        Q (rad or m/s), N (rad/sqrt(s) or m/s/sqrt(s)), B (rad/s or m/s^2),
        K (rad/s/sqrt(s) or m/s^2/sqrt(s)), R (rad/s^2 or m/s^3).
    sigma : dict
        Standard uncertainty of each value (nan for a term at zero).
    upper_bound : dict
        About 2-sigma upper bound of each value (the value itself for a resolved term).
    resolved : dict of bool
    dominant_tau_s : dict
        (first, last) tau where the term makes >= 1/4 of the model variance, or None.
    chi2_per_point : float
        Mean squared normalised residual of the plain weighted fit (about 1 when the terms describe the curve).
    model_floor : float
        Relative uncertainty added to every point when they do not (chi2_per_point > 2): the smallest
        that brings chi^2 per point to 1, so that no short-tau point with a huge edf rules the fit.
    """

    values: dict[str, float]
    sigma: dict[str, float]
    upper_bound: dict[str, float]
    resolved: dict[str, bool]
    dominant_tau_s: dict[str, tuple[float, float] | None]
    chi2_per_point: float
    model_floor: float = 0.0

    def model_adev(self, tau) -> np.ndarray:
        """The fitted model's Allan deviation at ``tau``.

        Parameters
        ----------
        tau : float or ndarray
            Averaging times, s.
        """
        return model_allan_deviation(self.values, tau)


def no_terms() -> NoiseTerms:
    """The terms of a channel without noise (a constant signal): all zero, none resolved."""
    zero = {term: 0.0 for term in TERMS}
    return NoiseTerms(values=dict(zero), sigma={t: math.nan for t in TERMS}, upper_bound=dict(zero),
                      resolved={t: False for t in TERMS}, dominant_tau_s={t: None for t in TERMS},
                      chi2_per_point=0.0)


def identify_terms(curve: AllanCurve, terms=TERMS, passes: int = 4) -> NoiseTerms:
    """Fit the IEEE 952 terms to an Allan curve.

    Parameters
    ----------
    curve : AllanCurve
        With finite ``edf`` (from :func:`~schuler.imu.allan.confidence`).
    terms : sequence of str
        Terms to fit (others are held at zero), default all five.
    passes : int
        Reweighting passes.

    Returns
    -------
    NoiseTerms

    Raises
    ------
    IdentificationError
        Fewer than two points, or an all-zero curve.
    """
    tau, avar, edf = curve.tau_s, curve.avar, curve.edf
    keep = np.isfinite(avar) & (avar > 0) & np.isfinite(edf) & (edf > 0)
    tau, avar, edf = tau[keep], avar[keep], edf[keep]
    if tau.size < 2:
        raise IdentificationError(f"an Allan curve with {tau.size} usable point(s) cannot be fitted")
    unknown = set(terms) - set(TERMS)
    if unknown:
        raise IdentificationError(f"unknown term {sorted(unknown)[0]!r}; terms are {', '.join(TERMS)}")
    chosen = np.array([t in terms for t in TERMS])
    basis = term_basis(tau)[:, chosen]
    floor = 0.0
    coefficients, fitted, spread, chi2 = _weighted_fit(basis, avar, edf, floor, passes)
    plain_chi2 = chi2
    if chi2 > 2.0:  # the five terms do not describe the curve (motion, periodic disturbances)
        for floor in np.geomspace(1e-3, 3.0, 36):
            coefficients, fitted, spread, chi2 = _weighted_fit(basis, avar, edf, floor, passes)
            if chi2 <= 1.0:
                break
    information = (basis / spread[:, None]).T @ (basis / spread[:, None])
    active = coefficients > 0
    covariance = np.full(information.shape, np.nan)
    if active.any():
        covariance[np.ix_(active, active)] = np.linalg.pinv(information[np.ix_(active, active)])
    full = np.linalg.pinv(information)

    values: dict[str, float] = {}
    sigma: dict[str, float] = {}
    upper: dict[str, float] = {}
    resolved: dict[str, bool] = {}
    dominant: dict[str, tuple[float, float] | None] = {}
    shares = basis * coefficients / np.maximum(fitted, 1e-300)[:, None]
    index = 0
    for term, used in zip(TERMS, chosen):
        if not used:
            values[term], sigma[term], upper[term], resolved[term], dominant[term] = 0.0, math.nan, 0.0, False, None
            continue
        c = float(coefficients[index])
        c_sigma = SIGMA_INFLATION[term] * (float(math.sqrt(max(covariance[index, index], 0.0)))
                                           if active[index] else math.nan)
        values[term] = math.sqrt(c)
        sigma[term] = c_sigma / (2.0 * math.sqrt(c)) if c > 0 else math.nan
        bound_sigma = SIGMA_INFLATION[term] * math.sqrt(max(full[index, index], 0.0))
        upper[term] = math.sqrt(c + 2.0 * (c_sigma if c > 0 else bound_sigma))
        where = tau[shares[:, index] >= 0.25]
        dominant[term] = (float(where[0]), float(where[-1])) if where.size else None
        resolved[term] = bool(c > 0 and c >= 2.0 * c_sigma)
        index += 1
    return NoiseTerms(values=values, sigma=sigma, upper_bound=upper, resolved=resolved, dominant_tau_s=dominant,
                      chi2_per_point=plain_chi2,
                      model_floor=float(floor))


def _weighted_fit(basis, avar, edf, floor: float, passes: int):
    """NNLS with weights 1 / (model sigma^2 sqrt(2/edf + floor^2)), reweighted ``passes`` times.

    Returns coefficients, fitted variance, point spreads and chi^2 per point.
    """
    scale = np.sqrt(np.mean(basis**2, axis=0)) / np.sqrt(np.mean(avar**2))  # columns of comparable size
    relative = np.sqrt(2.0 / edf + floor**2)
    model = avar.copy()
    for _ in range(max(1, passes)):
        spread = model * relative
        solution, _ = nnls(basis / scale / spread[:, None], avar / spread, maxiter=50 * basis.shape[1])
        coefficients = solution / scale
        fitted = basis @ coefficients
        model = np.where(fitted > 0, fitted, avar)
    spread = model * relative
    return coefficients, fitted, spread, float(np.mean(((avar - fitted) / spread) ** 2))
