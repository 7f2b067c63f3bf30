"""Sensor error models per axis, in SI, and the Allan variance each term produces.

Measured output of one triad (gyros: angular rate; accelerometers: specific
force), body axes, as simulated by :mod:`~schuler.imu.simulate`::

    y = (I + S + M) u + b + G f + x_GM + sum_j x_j + r + n,   then quantised

* ``u`` the true input, ``f`` the true specific force (g-sensitivity ``G``, gyros only);
* ``S = diag(s)`` scale-factor errors, ``M`` small misalignment / non-orthogonality
  (off-diagonal; row i holds the sensitivity of sensor i to the other axes), both dimensionless;
* ``b`` the constant (turn-on) bias; these four are drawn once per Monte Carlo member
  from normal laws with the model's 1-sigma values;
* ``x_GM`` a first-order Gauss-Markov bias, x_{k+1} = e^{-dt/T} x_k + sigma sqrt(1 - e^{-2dt/T}) w_k;
* ``x_j`` Gauss-Markov terms whose sum approximates flicker (bias-instability) noise
  of coefficient B over a stated tau range (:func:`flicker_terms`);
* ``r`` rate random walk, r_{k+1} = r_k + K sqrt(dt) w_k;
* ``n`` white noise of density N: per-sample standard deviation N / sqrt(dt)
  (the sample is the mean of the rate over dt);
* quantisation: the accumulated increment is output in steps q = sqrt(12) Q
  (white angle noise of standard deviation Q, IEEE Std 952's Q).

The white noise is the mean over each sample interval; the Gauss-Markov terms
and the rate random walk are point samples held over it, so at the shortest
lags their Allan variance exceeds the continuous formulas below by the
point-sampling factor (1 + 1 / (2 m^2)) at tau = m dt (1.5 at m = 1, < 2 % from m = 5).

Allan variance of the rate (IEEE Std 952-1997, Annex C; El-Sheimy et al. 2008)::

    sigma^2(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2

Continuous PSD vs samples: N is the square root of the two-sided rate PSD, so
N in rad/sqrt(s) (= rad/s/sqrt(Hz)); a sample averaged over dt has standard
deviation sigma_d = N / sqrt(dt) (:func:`white_noise_sample_std`). Spec sheets
write 0.125 deg/sqrt(h) (ARW), 7.5 deg/h/sqrt(Hz) (= 0.125 deg/sqrt(h): divide by
60) or 0.005 deg/s/sqrt(Hz); all are read by :mod:`schuler.units`.

A first-order Gauss-Markov bias of standard deviation sigma and correlation time
T has the Allan variance (:func:`gauss_markov_allan_variance`)
``(2 sigma^2 T / tau) [1 - (T / 2 tau)(3 - 4 e^{-tau/T} + e^{-2 tau/T})]``,
which peaks at sigma_A = 0.6174 sigma at tau = 1.893 T; reading that peak as
the flicker floor 0.6643 B gives **B = 0.9294 sigma**
(:data:`GAUSS_MARKOV_PEAK`). This is how an identified B maps to a
Gauss-Markov simulation model (:func:`gauss_markov_for_bias_instability`).

References
----------
IEEE Std 952-1997, "IEEE Standard Specification Format Guide and Test Procedure
for Single-Axis Interferometric Fiber Optic Gyros", Annex C, 1998.
N. El-Sheimy, H. Hou, X. Niu, "Analysis and modeling of inertial sensors using
Allan variance", IEEE Trans. Instrum. Meas. 57(1), 2008.
P. D. Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
Navigation Systems", 2nd ed., Artech House, 2013, ch. 4.4.

Examples
--------
>>> round(white_noise_sample_std(2.9088820866572e-4, 0.01), 8)   # 1 deg/sqrt(h) at 100 Hz
0.00290888
>>> sigma = 1e-5
>>> peak = max(gauss_markov_allan_variance(np.geomspace(1, 1e4, 4001), sigma, 100.0)) ** 0.5
>>> round(float(peak / sigma), 4)
0.6174
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

import numpy as np

from schuler.exceptions import InvalidParameter

FLICKER_FLOOR = math.sqrt(2.0 * math.log(2.0) / math.pi)
"""sigma_A / B on the flat part of a flicker (bias-instability) Allan deviation: 0.6643."""


def _gm_peak() -> tuple[float, float]:
    from scipy.optimize import minimize_scalar

    best = minimize_scalar(lambda x: -gauss_markov_allan_variance(x, 1.0, 1.0), bounds=(0.5, 5.0), method="bounded",
                           options={"xatol": 1e-10})
    return float(best.x), float(math.sqrt(-best.fun))


def gauss_markov_allan_variance(tau, sigma: float, correlation_time: float):
    """Allan variance of a first-order Gauss-Markov rate, (units of sigma)^2.

    Parameters
    ----------
    tau : float or ndarray
        Averaging time, s (> 0).
    sigma : float
        Stationary standard deviation of the process, in the rate's unit (rad/s for a gyro, m/s^2 for an
        accelerometer); the result is in its square.
    correlation_time : float
        T, s.

    Returns
    -------
    float or ndarray
        sigma_A^2 at each ``tau``, (units of sigma)^2, the shape of ``tau``.

    Notes
    -----
    From the autocorrelation sigma^2 e^{-|t|/T}:
    sigma_A^2 = (2 sigma^2 T / tau) [1 - (T / 2 tau)(3 - 4 e^{-tau/T} + e^{-2 tau/T})];
    K^2 tau / 3 with K^2 = 2 sigma^2 / T for tau << T, N^2 / tau with N^2 = 2 sigma^2 T for tau >> T.
    """
    x = np.asarray(tau, dtype=float) / correlation_time
    small = x < 1e-3
    safe = np.where(small, 1.0, x)
    bracket = 1.0 - (3.0 - 4.0 * np.exp(-safe) + np.exp(-2.0 * safe)) / (2.0 * safe)
    value = np.where(small, 2.0 * x / 3.0 * (1.0 - 0.75 * x), 2.0 * bracket / safe)
    return sigma**2 * value


GAUSS_MARKOV_PEAK = _gm_peak()
"""(tau / T, sigma_A / sigma) at the Allan-deviation peak of a first-order Gauss-Markov process: (1.893, 0.6174)."""


def gauss_markov_for_bias_instability(bias_instability: float) -> float:
    """The Gauss-Markov sigma whose Allan-deviation peak equals the flicker floor of B: sigma = B 0.6643 / 0.6174.

    Parameters
    ----------
    bias_instability : float
        B (IEEE 952), rad/s (gyro) or m/s^2 (accelerometer).

    Returns
    -------
    float
        Stationary standard deviation sigma of the Gauss-Markov bias, in the unit of ``bias_instability``.

    Notes
    -----
    The peak ratio sigma_A / sigma = 0.6174 does not depend on the correlation time T (the peak only
    moves to tau = 1.893 T), so T is chosen separately and does not enter.

    Examples
    --------
    >>> round(1.0 / gauss_markov_for_bias_instability(1.0), 4)
    0.9294
    """
    return bias_instability * FLICKER_FLOOR / GAUSS_MARKOV_PEAK[1]


def white_noise_sample_std(density: float, sample_interval: float) -> float:
    """Per-sample standard deviation of white noise of density N averaged over dt: N / sqrt(dt).

    Parameters
    ----------
    density : float
        N, rad/sqrt(s) (gyro) or m/s/sqrt(s) (accelerometer).
    sample_interval : float
        dt, s.
    """
    return density / math.sqrt(sample_interval)


FLICKER_TERMS_PER_DECADE = 2
"""Gauss-Markov terms per decade of correlation time in the flicker approximation."""


def flicker_terms(bias_instability: float, tau_range: tuple[float, float],
                  per_decade: int = FLICKER_TERMS_PER_DECADE) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Markov terms (sigma_j, T_j) whose summed Allan deviation is flat at 0.6643 B over ``tau_range``.

    Parameters
    ----------
    bias_instability : float
        B (IEEE 952), rad/s or m/s^2.
    tau_range : (float, float)
        Averaging times, s, over which the Allan deviation should be flat.
    per_decade : int
        Terms per decade of correlation time, number of.

    Returns
    -------
    sigmas, correlation_times : ndarray
        Equal variances sigma_j^2 = B^2 ln(r) / pi for ratio r = 10^(1/per_decade)
        between neighbouring T_j, which spread from tau_lo / 15 to 3 tau_hi.

    Notes
    -----
    A Gauss-Markov term has the two-sided PSD 2 sigma^2 T / (1 + (2 pi f T)^2); a
    sum with log-uniform T and equal variances integrates to sigma^2 / (2 f ln r),
    equal to flicker's B^2 / (2 pi f) (IEEE 952 C.1) for sigma^2 = B^2 ln r / pi.
    The terms extend half a decade and more beyond the range so that its edges
    do not roll off: the Allan deviation stays within 3 % of 0.6643 B inside ``tau_range``
    (tests/test_imu_error_model.py).
    """
    low, high = (float(v) for v in tau_range)
    if not (0 < low < high and math.isfinite(high)):
        raise InvalidParameter("flicker_tau_range", f"({low:g}, {high:g}) s must satisfy 0 < low < high")
    ratio = 10.0 ** (1.0 / per_decade)
    first, last = math.log10(low / 15.0), math.log10(high * 3.0)
    count = max(2, int(math.ceil((last - first) * per_decade)) + 1)
    times = np.logspace(first, first + (count - 1) / per_decade, count)
    sigma = bias_instability * math.sqrt(math.log(ratio) / math.pi)
    return np.full(count, sigma), times


@dataclass(frozen=True)
class SensorErrors:
    """Error terms of one triad, SI, per axis (x, y, z body).

    Parameters
    ----------
    bias : ndarray (3,)
        1-sigma constant (turn-on) bias b, rad/s or m/s^2.
    bias_instability : ndarray (3,)
        Flicker coefficient B (IEEE 952), rad/s or m/s^2; simulated over ``flicker_tau_range_s``.
    flicker_tau_range_s : (float, float)
        Averaging times over which the flicker Allan deviation is flat, s.
    gm_sigma : ndarray (3,)
        Standard deviation of a first-order Gauss-Markov bias, rad/s or m/s^2.
    gm_correlation_time_s : ndarray (3,)
        Its correlation time T, s.
    random_walk : ndarray (3,)
        N: angle random walk, rad/sqrt(s), or velocity random walk, m/s/sqrt(s).
    rate_random_walk : ndarray (3,)
        K: rad/s/sqrt(s) or m/s^2/sqrt(s).
    quantization : ndarray (3,)
        Q (IEEE 952), rad or m/s; the output step is sqrt(12) Q.
    scale_factor : ndarray (3,)
        1-sigma scale-factor error (dimensionless; 1e-6 = 1 ppm).
    misalignment : ndarray (3, 3)
        1-sigma of each off-diagonal entry of M, rad (the diagonal is unused).
    g_sensitivity : ndarray (3, 3)
        1-sigma of each entry of G, rad/s per m/s^2 (gyros; zero for accelerometers).
    """

    bias: np.ndarray = field(default_factory=lambda: np.zeros(3))
    bias_instability: np.ndarray = field(default_factory=lambda: np.zeros(3))
    flicker_tau_range_s: tuple[float, float] = (1.0, 1000.0)
    gm_sigma: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gm_correlation_time_s: np.ndarray = field(default_factory=lambda: np.full(3, 100.0))
    random_walk: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rate_random_walk: np.ndarray = field(default_factory=lambda: np.zeros(3))
    quantization: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale_factor: np.ndarray = field(default_factory=lambda: np.zeros(3))
    misalignment: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    g_sensitivity: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def __post_init__(self):
        for f in fields(self):
            if f.name == "flicker_tau_range_s":
                low, high = (float(v) for v in self.flicker_tau_range_s)
                if not (0 < low < high and math.isfinite(high)):
                    raise InvalidParameter(f.name, f"({low:g}, {high:g}) s must satisfy 0 < low < high")
                object.__setattr__(self, f.name, (low, high))
                continue
            shape = (3, 3) if f.name in ("misalignment", "g_sensitivity") else (3,)
            value = np.asarray(getattr(self, f.name), dtype=float)
            if shape == (3, 3) and value.shape in ((), (1,)):
                value = np.full((3, 3), float(value.reshape(-1)[0])) * (1.0 - np.eye(3) * (f.name == "misalignment"))
            try:
                value = np.broadcast_to(value, shape).copy()
            except ValueError:
                raise InvalidParameter(
                    f.name, f"shape {value.shape} does not fit {shape} (one value or one per axis)") from None
            if not np.all(np.isfinite(value)) or np.any(value < 0):
                raise InvalidParameter(f.name, f"must be finite and >= 0 (1-sigma magnitudes), got {value.tolist()}")
            if f.name == "gm_correlation_time_s" and np.any(value <= 0):
                raise InvalidParameter(f.name, f"must be > 0 s, got {value.tolist()}")
            if f.name == "misalignment":
                value[np.diag_indices(3)] = 0.0
            value.setflags(write=False)
            object.__setattr__(self, f.name, value)

    def scaled(self, factor: float) -> SensorErrors:
        """Every magnitude times ``factor`` (correlation times and tau range kept).

        Parameters
        ----------
        factor : float
            Scale of every error magnitude, plain number (0.5 halves them).

        Returns
        -------
        SensorErrors
            A copy with the scaled magnitudes.
        """
        keep = {"flicker_tau_range_s", "gm_correlation_time_s"}
        return replace(self, **{f.name: getattr(self, f.name) * factor for f in fields(self) if f.name not in keep})

    def allan_variance(self, tau, axis: int) -> np.ndarray:
        """The model's Allan variance on ``axis`` at averaging times ``tau`` (s): IEEE 952 terms + Gauss-Markov.

        The flicker term is represented by its Gauss-Markov sum (what the simulation produces).

        Parameters
        ----------
        tau : float or array_like
            Averaging times tau, s (> 0).
        axis : int
            Body axis index: 0 x forward, 1 y right, 2 z down.

        Returns
        -------
        ndarray
            sigma^2(tau), the shape of ``tau``: (rad/s)^2 for a gyro triad, (m/s^2)^2 for an accelerometer triad.
        """
        tau = np.asarray(tau, dtype=float)
        q, n, k = self.quantization[axis], self.random_walk[axis], self.rate_random_walk[axis]
        variance = 3 * q**2 / tau**2 + n**2 / tau + k**2 * tau / 3
        if self.gm_sigma[axis] > 0:
            variance = variance + gauss_markov_allan_variance(
                tau, self.gm_sigma[axis], self.gm_correlation_time_s[axis])
        if self.bias_instability[axis] > 0:
            for sigma, time in zip(*flicker_terms(self.bias_instability[axis], self.flicker_tau_range_s)):
                variance = variance + gauss_markov_allan_variance(tau, sigma, time)
        return variance


@dataclass(frozen=True)
class ErrorModel:
    """Errors of a six-axis IMU: gyro and accelerometer triads, with where the figures come from.

    Parameters
    ----------
    gyro, accel : SensorErrors
        SI (gyro: rad, rad/s ...; accelerometer: m/s, m/s^2 ...).
    name : str
        E.g. the grade or the part number.
    source : str
        Where the figures come from (data sheet, spec file, identification).
    notes : tuple of str
        Which figures are assumed rather than published, and why.
    """

    gyro: SensorErrors = field(default_factory=SensorErrors)
    accel: SensorErrors = field(default_factory=SensorErrors)
    name: str = "custom"
    source: str = ""
    notes: tuple[str, ...] = ()

    def __post_init__(self):
        if np.any(self.accel.g_sensitivity):
            raise InvalidParameter("accel.g_sensitivity",
                                   "g-sensitivity is a gyro error; leave it 0 for accelerometers")

    def scaled(self, factor: float) -> ErrorModel:
        """Every error magnitude times ``factor`` (a first-order check halves them and expects half the effect).

        Parameters
        ----------
        factor : float
            Scale of every error magnitude of both triads, plain number (correlation times and tau ranges kept).

        Returns
        -------
        ErrorModel
            A copy with both triads scaled, same name, source and notes.
        """
        return replace(self, gyro=self.gyro.scaled(factor), accel=self.accel.scaled(factor))
