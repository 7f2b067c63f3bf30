"""Automatic multi-static calibration without equipment (after Tedaldi, Pretto and Menegatti, ICRA 2014).

The IMU is held still in many orientations (a few seconds each), turned by hand
in between, after an initial static period. Nothing about the orientations is
known; gravity's magnitude and the rotations the gyros measure are enough:

1. **Static intervals** (Tedaldi et al., sec. IV-A): the variance of each
   accelerometer over a sliding window of ``window_s``, summed over the axes,
   is compared with ``factor`` times its mean over the initial static period;
   runs below it that last ``min_static_s`` are static (their edges trimmed by
   half a window). The factor is chosen from :data:`THRESHOLD_FACTORS` by the
   smallest accelerometer residual, as the paper chooses its threshold.
2. **Accelerometers** (sec. IV-B, eqs. (8)-(10)): u = T K (y - b) with
   T = [[1, -a_yz, a_zy], [0, 1, -a_zx], [0, 0, 1]] (non-orthogonality),
   K = diag(k) (scale), b the bias (measured - true); Levenberg-Marquardt
   on the static means, residuals g^2 - |u|^2. T K is upper triangular: it
   fixes the sensor frame up to a rotation, which gravity alone cannot see.
3. **Gyros** (sec. IV-C, eqs. (11)-(14)): m_0 = mean over the initial static
   period (the bias plus the Earth rate there); omega = G (y - m_0) with G any
   3 x 3 matrix (the paper's T^g K^g, also aligning the gyros to the
   accelerometers' frame); Levenberg-Marquardt on the change of gravity's
   direction d_j = v_j / |v_j| between consecutive static intervals, residual
   d_{j+1} - Rc_j^T d_j, R_j = prod_k exp([G (y_k - m_0) dt x]) over the motion
   in between (exact per-sample exponentials; the paper integrates with
   Runge-Kutta).
   **Earth rate** (not in the paper, whose MEMS do not see it): Rc_j is the
   rotation relative to the local-level frame. G (y - m_0) = omega_ib - omega_0
   (omega_0 the Earth rate in the initial attitude's axes), the Earth rate in
   the body is P(t)^T omega_0 (P the rotation since the initial attitude), so
   omega_nb = G (y - m_0) + omega_0 - P(t)^T omega_0. To first order in the
   Earth rate, Rc_j = R_j exp([theta_j x]) with
   theta_j = R_j^T (S_j omega_0 - T_j P_j^T omega_0), S_j = integral of the
   partial rotation over the motion (trapezoid), T_j its length, P_j the product
   of the earlier Rc. omega_0 = Omega sin L d_0 + Omega (h_1 e_1 + h_2 e_2):
   the vertical part known from the latitude, the horizontal part (h, two more
   unknowns; e_1, e_2 normal to d_0) fitted with G, since the heading is unknown.
   Left out, the Earth rate puts up to Omega T_j (1.8e-4 rad over a 2.5 s motion)
   into each residual, 1e-4 of G in a noise-free record.

**Uncertainties** by noise propagation through the Gauss-Newton solution (a
sandwich whose middle is the measured noise, not the residual variance):
cov(p) = H cov(r) H^T, H = (J^T J)^-1 J^T. Accelerometers: dr_j/dm_j =
-2 v_j^T T K (v_j = T K (m_j - b), m_j the static means), cov(m_j) from the
scatter within interval j over its length.
Gyros: cov(r) gathers (a) the gyro white noise over each motion, rotation
error of covariance Q_j = sum_k R_j(t_k) G Sigma G^T R_j(t_k)^T dt^2 (Sigma the
per-sample variance pooled over the static intervals), moving r_j by
-[(Rc_j^T d_j) x] Rc_j^T dtheta; (b) the error of m_0 (Sigma over its sample
count), common to every motion: dtheta_j = -S_j G dm_0; (c) the static means'
noise through the directions, dd_j = (I - d_j d_j^T)/|v_j| (T K dm_j +
dv_j/dp_a dp_a), every mean entering twice (d_j is in two residuals) and
through the accelerometer parameters. Scaling (J^T J)^-1 by the residual
variance, as before, made the gyro matrix's rms z 1.46 (industrial grade,
200 IMUs; 1.58 consumer, 1.27 tactical over 100): it counts three residual
components per motion where only two carry noise (d is a unit vector), leaves
out (b) and (c) (an error of the accelerometer frame is an error of G's), and
the Earth rate was left out of the model. Now 0.97-1.02 per group over 200
industrial IMUs (tests/test_alignment_tools.py). The threshold picked by the
smallest residual does not enter the 1-sigma; fixing it at 4 or 32 changes no
accelerometer group's rms z by more than 0.03 (100 IMUs).

**Slow terms** (``error_model`` given): the Gauss-Markov bias and the bias
instability, as the simulator's sum of Gauss-Markov terms sigma_t^2
exp(-|tau|/T_t), are stationary, so the covariance of the means of one over
spans [a, b) and [c, d) is sum_t sigma_t^2 (K_t(b - c) - K_t(a - c) - K_t(b - d)
+ K_t(a - d)) / ((b - a)(d - c)), K_t(x) = T_t^2 (exp(-|x|/T_t) - 1 + |x|/T_t).
It fills cov(m) between the static means (not only its diagonal), and for the
gyros the covariance of the bias's change from the initial mean, averaged over
each motion (dtheta_j = -S_j G (mean over motion j - m_0)), and the gyro bias's
1-sigma. Without it, over 40 industrial IMUs with the preset's bias instability
the rms z (against the turn-on errors) was 1.46 for the accelerometer biases,
1.22 for the gyro matrix and 3.0 for the gyro bias; with it, over 200, 1.03,
0.99 and 0.99 (scale 1.00, non-orthogonality 1.01).

Limitations: rate random walk (not stationary) is not modelled; the slow gyro
bias is taken at its mean over each motion (the turn within one motion left
out of its weight); the fastest flicker terms are also in the scatter within the
intervals, so counted twice (the variance they add there is below 0.1 % of the
white noise's at the industrial grade). The Earth rate's correction is first
order over each motion: a noise-free record returns G to 5e-9.

References
----------
D. Tedaldi, A. Pretto, E. Menegatti, "A robust and easy to implement method for
IMU calibration without external equipments", IEEE International Conference on
Robotics and Automation (ICRA), 2014.

Examples
--------
>>> plan = MultiStaticPlan(positions=12, sample_interval_s=0.02)
>>> gyro, accel = plan.truth(seed=1)
>>> result = calibrate_multi_static(gyro, accel, plan.sample_interval_s, initial=plan.initial_s)
>>> result.static_intervals, bool(abs(result.accel_scale - 1).max() < 1e-9)
(13, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.alignment import _multi_static_fits as fits
from schuler.core.attitude import dcm_from_rotation_vector
from schuler.core.earth import EARTH_RATE, earth_rate_ned, normal_gravity
from schuler.core.random import RandomStreams
from schuler.exceptions import IdentificationError, InvalidParameter, renamed_keywords
from schuler.imu.error_model import ErrorModel

THRESHOLD_FACTORS = (2.0, 4.0, 8.0, 16.0, 32.0)
"""Static-detector thresholds tried, as multiples of the initial period's variance statistic."""

VARIANCE_FLOOR = 1e-10
"""Added to the detector threshold, (m/s^2)^2: noise-free records (variance at rounding level) still have a floor."""

MIN_INTERVALS = 9
"""Fewest static intervals the accelerometer fit accepts (nine unknowns)."""


@dataclass(frozen=True)
class MultiStaticPlan:
    """A simulated hand calibration: an initial static period, then random orientations held still.

    Parameters
    ----------
    positions : int
        Static orientations after the initial one.
    initial_s, static_s, move_s : float
        Initial static period, each later static interval, each motion between them, s.
    sample_interval_s : float
        dt, s.
    latitude_rad : float
        L (the Earth rate in the truth), rad.
    gravity_m_s2 : float, optional
        g (default: WGS-84 normal gravity at L).
    """

    positions: int = 36
    initial_s: float = 30.0
    static_s: float = 3.0
    move_s: float = 1.5
    sample_interval_s: float = 0.01
    latitude_rad: float = math.radians(45.0)
    gravity_m_s2: float | None = None

    def __post_init__(self):
        if self.positions < MIN_INTERVALS:
            raise InvalidParameter("positions", f"{self.positions} must be >= {MIN_INTERVALS}")
        for name in ("initial_s", "static_s", "move_s", "sample_interval_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise InvalidParameter(name.removesuffix("_s"), f"must be finite and > 0 s, got {value!r}")

    @property
    def gravity(self) -> float:
        return float(normal_gravity(self.latitude_rad)) if self.gravity_m_s2 is None else float(self.gravity_m_s2)

    def attitudes(self, seed: int) -> np.ndarray:
        """The positions + 1 attitudes C_b^n (uniform on the rotations, Shoemake's method), addressed by ``seed``.

        Parameters
        ----------
        seed : int
            Seed of the orientation draws (stream ``calibration/orientation``, one draw per attitude index).

        Returns
        -------
        ndarray (positions + 1, 3, 3)
            C_b^n of the initial attitude, then of each later static orientation (NED, body x fwd/y right/z down).
        """
        u = RandomStreams(seed).uniform("calibration/orientation", np.arange(self.positions + 1), 3)
        a, b = np.sqrt(1.0 - u[:, 0]), np.sqrt(u[:, 0])
        quaternion = np.stack([a * np.sin(2 * np.pi * u[:, 1]), a * np.cos(2 * np.pi * u[:, 1]),
                               b * np.sin(2 * np.pi * u[:, 2]), b * np.cos(2 * np.pi * u[:, 2])], axis=1)
        from scipy.spatial.transform import Rotation

        return Rotation.from_quat(quaternion).as_matrix()

    def truth(self, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """True mean angular rates (n, 3) and specific forces (n, 3) of the whole record.

        Each motion turns the body at a constant body rate from one attitude to the next
        (rotation vector log(C_j^T C_{j+1}) over ``move_s``); rotation is about the
        sensor, so the specific force stays C^T (0, 0, -g).

        Parameters
        ----------
        seed : int
            Seed of the attitudes (:meth:`attitudes`).

        Returns
        -------
        gyro : ndarray (n, 3)
            omega_ib in body axes (Earth rate included), rad/s, one row per sample of ``sample_interval_s``.
        accel : ndarray (n, 3)
            Specific force in body axes, m/s^2.
        """
        from scipy.spatial.transform import Rotation

        dt = self.sample_interval_s
        attitudes = self.attitudes(seed)
        omega, down = earth_rate_ned(self.latitude_rad), np.array([0.0, 0.0, -self.gravity])
        initial, still, move = (int(round(v / dt)) for v in (self.initial_s, self.static_s, self.move_s))
        gyro_parts, accel_parts = [], []

        def hold(C, count):
            gyro_parts.append(np.tile(C.T @ omega, (count, 1)))
            accel_parts.append(np.tile(C.T @ down, (count, 1)))

        hold(attitudes[0], initial)
        for C0, C1 in zip(attitudes[:-1], attitudes[1:]):
            turn = Rotation.from_matrix(C0.T @ C1).as_rotvec()
            fractions = (np.arange(move) + 0.5) / move
            C = C0 @ dcm_from_rotation_vector(fractions[:, None] * turn)
            gyro_parts.append(turn / (move * dt) + np.einsum("kji,j->ki", C, omega))
            accel_parts.append(np.einsum("kji,j->ki", C, down))
            hold(C1, still)
        return np.concatenate(gyro_parts), np.concatenate(accel_parts)


def _moving_variance(values: np.ndarray, width: int) -> np.ndarray:
    """Variance over a centred window of ``width`` samples (shrunk at the ends), per column."""
    n = values.shape[0]
    values = values - values.mean(axis=0)   # smaller sums, smaller rounding
    padded = np.vstack([np.zeros((1, values.shape[1])), values])
    sums, squares = padded.cumsum(axis=0), (padded**2).cumsum(axis=0)
    half = width // 2
    lo = np.clip(np.arange(n) - half, 0, n)
    hi = np.clip(np.arange(n) + width - half, 0, n)
    count = (hi - lo)[:, None]
    mean = (sums[hi] - sums[lo]) / count
    return np.maximum((squares[hi] - squares[lo]) / count - mean**2, 0.0)


@renamed_keywords(sample_interval_s="sample_interval", initial_s="initial", window_s="window",
                  min_static_s="min_static")
def detect_static(accel, sample_interval: float, *, initial: float, factor: float, window: float = 1.0,
                  min_static: float = 1.0) -> list[tuple[int, int]]:
    """Static intervals [first, stop) of a record (module notes, step 1); the initial period is the first.

    Parameters
    ----------
    accel : ndarray (n, 3)
        Specific force samples, m/s^2.
    sample_interval : float
        dt, s.
    initial : float
        Length of the initial static period, s.
    factor : float
        Threshold as a multiple of the initial period's mean statistic (a ratio).
    window, min_static : float
        Sliding window and shortest static interval, s.
    """
    dt = float(sample_interval)
    width = max(3, int(round(window / dt)))
    statistic = _moving_variance(np.asarray(accel, dtype=float), width).sum(axis=1)
    initial_samples = int(round(initial / dt))
    if initial_samples < width or initial_samples > statistic.size:
        raise InvalidParameter("initial", f"the initial static period of {initial:g} s must cover the window "
                               f"({window:g} s) and fit in the record")
    threshold = factor * statistic[width // 2: initial_samples - width // 2].mean() + VARIANCE_FLOOR
    still = statistic <= threshold
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    trim, shortest = width // 2, int(round(min_static / dt))
    intervals = []
    for first, stop in zip(edges[0::2], edges[1::2]):
        first, stop = (first if first == 0 else first + trim), stop - trim
        if stop - first >= shortest:
            intervals.append((int(first), int(stop)))
    return intervals


@dataclass
class MultiStaticCalibration:
    """The calibration, its 1-sigma and what it was found from.

    Attributes
    ----------
    accel_non_orthogonality : ndarray (3,)
        (a_yz, a_zy, a_zx), rad.
    accel_scale : ndarray (3,)
        k, the diagonal of K (1 + scale correction).
    accel_bias : ndarray (3,)
        m/s^2.
    accel_matrix : ndarray (3, 3)
        T K: u = T K (y - b).
    gyro_matrix : ndarray (3, 3)
        G: omega = G (y - b_g), in the accelerometers' calibrated frame.
    gyro_bias : ndarray (3,)
        Mean of the initial static period, rad/s (includes the Earth rate there).
    *_sigma : ndarray
        1-sigma of the same entries, by noise propagation (module notes, uncertainties).
    static_intervals : int
    threshold_factor : float
    accel_residual_rms : float
        RMS of g^2 - |u|^2 at the solution, m^2/s^4.
    gyro_residual_rms : float
        RMS of the gravity-direction residuals, 1 (unit vectors).
    """

    accel_non_orthogonality: np.ndarray
    accel_scale: np.ndarray
    accel_bias: np.ndarray
    accel_matrix: np.ndarray
    gyro_matrix: np.ndarray
    gyro_bias: np.ndarray
    accel_non_orthogonality_sigma: np.ndarray
    accel_scale_sigma: np.ndarray
    accel_bias_sigma: np.ndarray
    gyro_matrix_sigma: np.ndarray
    gyro_bias_sigma: np.ndarray
    static_intervals: int
    threshold_factor: float
    accel_residual_rms: float
    gyro_residual_rms: float


def _interval_statistics(samples: np.ndarray, intervals) -> tuple[np.ndarray, np.ndarray]:
    """Static means (j, 3) and the variances of those means (j, 3) from the scatter within each interval."""
    means = np.stack([samples[a:b].mean(axis=0) for a, b in intervals])
    variances = np.stack([samples[a:b].var(axis=0, ddof=1) / (b - a) for a, b in intervals])
    return means, variances


def _noise(gyro: np.ndarray, intervals, gaps, mean_variances: np.ndarray, dt: float, error_model) -> dict:
    """The data's noise for :meth:`~schuler.alignment._multi_static_fits.GyroProblem.covariance` (module notes).

    White: the gyros' per-sample variance pooled over the static intervals (each about its own mean), the
    static means' from the scatter within each. Slow (``error_model`` given): its Gauss-Markov and flicker terms
    between the static means (accelerometers) and between the motions and the initial period (gyros).
    """
    squares = sum(((gyro[a:b] - gyro[a:b].mean(axis=0)) ** 2).sum(axis=0) for a, b in intervals)
    rate = np.diag(squares / sum(b - a - 1 for a, b in intervals))
    first, stop = intervals[0]
    means = np.stack([np.diag(mean_variances[:, axis]) for axis in range(3)])
    gap_bias = np.zeros((3, len(gaps), len(gaps)))
    bias_slow = np.zeros(3)
    if error_model is not None:
        spans, motions = np.asarray(intervals, dtype=float) * dt, np.asarray(gaps, dtype=float) * dt
        for axis, terms in enumerate(fits.slow_terms(error_model.accel)):
            means[axis] += fits.mean_covariance(spans, spans, terms)
        for axis, terms in enumerate(fits.slow_terms(error_model.gyro)):
            with_initial = fits.mean_covariance(motions, spans[:1], terms)
            bias_slow[axis] = fits.mean_covariance(spans[:1], spans[:1], terms)[0, 0]
            gap_bias[axis] = (fits.mean_covariance(motions, motions, terms) - with_initial - with_initial.T
                              + bias_slow[axis])
    return {"rate": rate, "bias": rate / (stop - first), "bias_slow": bias_slow, "means": means,
            "gap_bias": gap_bias}


@renamed_keywords(sample_interval_s="sample_interval", initial_s="initial", latitude_rad="latitude", window_s="window",
                  min_static_s="min_static", gravity_m_s2="gravity")
def calibrate_multi_static(gyro, accel, sample_interval: float, *, initial: float,
                           gravity: float | None = None, latitude: float = math.radians(45.0),
                           window: float = 1.0, min_static: float = 1.0,
                           error_model: ErrorModel | None = None) -> MultiStaticCalibration:
    """Calibrate both triads from a hand-held multi-static record (module notes).

    Parameters
    ----------
    gyro, accel : ndarray (n, 3)
        Mean rates (rad/s) and specific forces (m/s^2) of every sample, sensor axes.
    sample_interval : float
        dt, s.
    initial : float
        Length of the initial static period, s.
    gravity : float, optional
        Local g, m/s^2 (default: normal gravity at ``latitude``).
    latitude : float
        Site latitude L, rad: the default g and the Earth rate's vertical part, Omega sin L (module notes, step 3).
    window, min_static : float
        Static detector settings, s.
    error_model : ErrorModel, optional
        The IMU's error model: its slow bias terms (Gauss-Markov bias, bias instability as the simulator's sum of
        Gauss-Markov terms; rate random walk is not modelled) enter the 1-sigma (module notes). None: white
        noise only.

    Raises
    ------
    IdentificationError
        Fewer than :data:`MIN_INTERVALS` static intervals at every threshold, or a fit that does not converge.
    """
    gyro, accel = np.asarray(gyro, dtype=float), np.asarray(accel, dtype=float)
    if gyro.shape != accel.shape or gyro.ndim != 2 or gyro.shape[1] != 3:
        raise InvalidParameter("samples", f"gyro {gyro.shape} and accel {accel.shape} must both be (n, 3)")
    dt = float(sample_interval)
    gravity = float(normal_gravity(latitude)) if gravity is None else float(gravity)
    best = None
    for factor in THRESHOLD_FACTORS:
        intervals = detect_static(accel, dt, initial=initial, factor=factor, window=window,
                                  min_static=min_static)
        if len(intervals) < MIN_INTERVALS:
            continue
        means = _interval_statistics(accel, intervals)[0]
        params, jacobian, rms = fits.fit_accel(means, gravity)
        if best is None or rms < best[4]:
            best = (factor, intervals, params, jacobian, rms)
    if best is None:
        raise IdentificationError(f"fewer than {MIN_INTERVALS} static intervals found at every threshold; hold the "
                                  "sensor still longer or more often")
    factor, intervals, accel_params, accel_jacobian, accel_rms = best
    means, mean_variances = _interval_statistics(accel, intervals)
    first, stop = intervals[0]
    gaps = [(a_stop, b_first) for (_, a_stop), (b_first, _) in zip(intervals[:-1], intervals[1:])]
    noise = _noise(gyro, intervals, gaps, mean_variances, dt, error_model)
    accel_gain = fits.accel_gain(accel_params, accel_jacobian, means)
    accel_covariance = np.einsum("pja,ajk,qka->pq", accel_gain, noise["means"], accel_gain)

    gyro_bias = gyro[first:stop].mean(axis=0)
    lengths = np.array([b - a for a, b in gaps])
    motion = np.zeros((len(gaps), lengths.max(), 3))
    for j, (a, b) in enumerate(gaps):
        motion[j, :b - a] = gyro[a:b] - gyro_bias
    problem = fits.GyroProblem(motion, lengths, dt, fits.directions(accel_params, means), EARTH_RATE,
                               EARTH_RATE * math.sin(latitude))
    gyro_params, gyro_jacobian, gyro_rms = fits.least_squares_fit(problem.residuals, np.r_[np.eye(3).ravel(), 0, 0],
                                                                  "gyro fit")
    gyro_covariance = problem.covariance(gyro_params, gyro_jacobian, noise,
                                         fits.direction_gain(accel_params, accel_jacobian, means))
    accel_sigma, gyro_sigma = (np.sqrt(np.diag(c)) for c in (accel_covariance, gyro_covariance))
    return MultiStaticCalibration(
        accel_non_orthogonality=accel_params[0:3], accel_scale=accel_params[3:6], accel_bias=accel_params[6:9],
        accel_matrix=fits.accel_matrix(accel_params), gyro_matrix=gyro_params[:9].reshape(3, 3), gyro_bias=gyro_bias,
        accel_non_orthogonality_sigma=accel_sigma[0:3], accel_scale_sigma=accel_sigma[3:6],
        accel_bias_sigma=accel_sigma[6:9], gyro_matrix_sigma=gyro_sigma[:9].reshape(3, 3),
        gyro_bias_sigma=np.sqrt(np.diag(noise["bias"]) + noise["bias_slow"]), static_intervals=len(intervals),
        threshold_factor=factor,
        accel_residual_rms=accel_rms, gyro_residual_rms=gyro_rms)


def identifiable_truth(accel_matrix, accel_bias, gyro_matrix):
    """What a multi-static calibration can recover from a sensor y = K u + b (imu's model, measured - true).

    K_a^-1 = Q U (Q a rotation, U upper triangular with a positive diagonal): the accelerometers
    give T K = U (so k = diag U, a_yz = -U_01 / U_11, a_zy = U_02 / U_22, a_zx = -U_12 / U_22), the
    calibrated frame is Q^T of the sensor's, and the gyros' G = Q^T K_g^-1.

    Parameters
    ----------
    accel_matrix : array_like (3, 3)
        K_a = I + S + M of the accelerometers (output per input), dimensionless.
    accel_bias : array_like (3,)
        Accelerometer bias b (measured - true), m/s^2, sensor axes.
    gyro_matrix : array_like (3, 3)
        K_g = I + S + M of the gyros, dimensionless.

    Returns
    -------
    dict
        ``accel_non_orthogonality`` (rad), ``accel_scale`` (dimensionless), ``accel_bias`` (m/s^2),
        ``accel_matrix`` (U, dimensionless), ``gyro_matrix`` (dimensionless).
    """
    Q, U = np.linalg.qr(np.linalg.inv(np.asarray(accel_matrix, dtype=float)))
    signs = np.sign(np.diag(U))
    Q, U = Q * signs, signs[:, None] * U
    return {"accel_non_orthogonality": np.array([-U[0, 1] / U[1, 1], U[0, 2] / U[2, 2], -U[1, 2] / U[2, 2]]),
            "accel_scale": np.diag(U).copy(), "accel_bias": np.asarray(accel_bias, dtype=float),
            "accel_matrix": U, "gyro_matrix": Q.T @ np.linalg.inv(np.asarray(gyro_matrix, dtype=float))}
