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
3. **Gyros** (sec. IV-C, eqs. (11)-(14)): bias = mean over the initial static
   period; omega = G (y - b) with G any 3 x 3 matrix (the paper's T^g K^g, also
   aligning the gyros to the accelerometers' frame); Levenberg-Marquardt on the
   change of gravity's direction between consecutive static intervals,
   residual u_{j+1} - R^T u_j, R the rotation integrated from the calibrated
   rates over the motion in between (exact per-sample exponentials, as
   :mod:`~schuler.alignment._kernels`; the paper integrates with Runge-Kutta).

Uncertainties: the residual variance times (J^T J)^-1 at the solution, the residual variance not below
what the sensor noise puts in a residual (from the scatter within the static intervals). The accelerometer
biases still come out 1.5-1.9 times their stated 1-sigma (rms over simulated IMUs), and the gyro matrix up to
1.9 times where the Earth rate left out of the turns matters: see tests/test_alignment_tools.py.
Limitations: the Earth rate is part of the initial period's gyro mean (so of
the gyro bias) and is not followed through the turns; for sensors whose bias
is far above the Earth rate (the MEMS the method is for) that is immaterial.

Examples
--------
>>> plan = MultiStaticPlan(positions=12, sample_interval_s=0.02)
>>> gyro, accel = plan.truth(seed=1)
>>> result = calibrate_multi_static(gyro, accel, plan.sample_interval_s, initial_s=plan.initial_s)
>>> result.static_intervals, bool(abs(result.accel_scale - 1).max() < 1e-9)
(13, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.alignment.attitude import earth_rate_ned, rotation_matrix
from schuler.core.earth import normal_gravity
from schuler.core.random import RandomStreams
from schuler.exceptions import IdentificationError, InvalidParameter

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
        """The positions + 1 attitudes C_b^n (uniform on the rotations, Shoemake's method), addressed by ``seed``."""
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
            C = C0 @ rotation_matrix(fractions[:, None] * turn)
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


def detect_static(accel, sample_interval_s: float, *, initial_s: float, factor: float, window_s: float = 1.0,
                  min_static_s: float = 1.0) -> list[tuple[int, int]]:
    """Static intervals [first, stop) of a record (module notes, step 1); the initial period is the first.

    Parameters
    ----------
    accel : ndarray (n, 3)
        Specific force samples, m/s^2.
    sample_interval_s : float
        dt, s.
    initial_s : float
        Length of the initial static period, s.
    factor : float
        Threshold as a multiple of the initial period's mean statistic.
    window_s, min_static_s : float
        Sliding window and shortest static interval, s.
    """
    dt = float(sample_interval_s)
    width = max(3, int(round(window_s / dt)))
    statistic = _moving_variance(np.asarray(accel, dtype=float), width).sum(axis=1)
    initial = int(round(initial_s / dt))
    if initial < width or initial > statistic.size:
        raise InvalidParameter("initial", f"the initial static period of {initial_s:g} s must cover the window "
                               f"({window_s:g} s) and fit in the record")
    threshold = factor * statistic[width // 2: initial - width // 2].mean() + VARIANCE_FLOOR
    still = statistic <= threshold
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    trim, shortest = width // 2, int(round(min_static_s / dt))
    intervals = []
    for first, stop in zip(edges[0::2], edges[1::2]):
        first, stop = (first if first == 0 else first + trim), stop - trim
        if stop - first >= shortest:
            intervals.append((int(first), int(stop)))
    return intervals


def _accel_model(params: np.ndarray, means: np.ndarray) -> np.ndarray:
    a_yz, a_zy, a_zx, kx, ky, kz, bx, by, bz = params
    TK = np.array([[kx, -a_yz * ky, a_zy * kz], [0.0, ky, -a_zx * kz], [0.0, 0.0, kz]])
    return (means - np.array([bx, by, bz])) @ TK.T


def _fit(residuals, start: np.ndarray, what: str, noise_variance: float = 0.0):
    """Levenberg-Marquardt; 1-sigma from (J^T J)^-1 times the residual variance, but not below the noise's.

    ``noise_variance`` is what the sensor noise alone puts in one residual: a residual variance below it
    (a lucky draw, or the threshold picked by the smallest residual) would state more than the data hold.
    """
    from scipy.optimize import least_squares

    solution = least_squares(residuals, start, method="lm", x_scale="jac")
    if not solution.success:
        raise IdentificationError(f"{what}: Levenberg-Marquardt did not converge ({solution.message})")
    J, r = solution.jac, solution.fun
    dof = max(1, r.size - start.size)
    covariance = np.linalg.pinv(J.T @ J) * max(float(r @ r) / dof, noise_variance)
    return solution.x, np.sqrt(np.maximum(np.diag(covariance), 0.0)), float(np.sqrt(r @ r / r.size))


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
        1-sigma of the same entries.
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


def _interval_statistics(accel: np.ndarray, intervals) -> tuple[np.ndarray, np.ndarray]:
    """Static means (j, 3) and the variances of those means (j, 3) from the scatter within each interval."""
    means = np.stack([accel[a:b].mean(axis=0) for a, b in intervals])
    variances = np.stack([accel[a:b].var(axis=0, ddof=1) / (b - a) for a, b in intervals])
    return means, variances


def _calibrate_accel(accel: np.ndarray, intervals, gravity: float):
    """Fit of eqs. (8)-(10); each residual g^2 - |u|^2 carries 4 g^2 sigma_mean^2 of noise (first order)."""
    means, variances = _interval_statistics(accel, intervals)
    start = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    unit = means / np.linalg.norm(means, axis=1, keepdims=True)
    noise = float(np.mean(4.0 * gravity**2 * (unit**2 * variances).sum(axis=1)))
    return _fit(lambda p: gravity**2 - (_accel_model(p, means) ** 2).sum(axis=1), start, "accelerometer fit", noise)


def _gravity_directions(accel: np.ndarray, intervals, params: np.ndarray) -> np.ndarray:
    means = np.stack([accel[a:b].mean(axis=0) for a, b in intervals])
    calibrated = _accel_model(params, means)
    return calibrated / np.linalg.norm(calibrated, axis=1, keepdims=True)


def _rotations(gyro_motion: np.ndarray, G: np.ndarray, dt: float) -> np.ndarray:
    """Products of exp([G y dt x]) over each motion (j, L, 3) padded with zeros: R_j (j, 3, 3)."""
    steps = rotation_matrix(gyro_motion @ G.T * dt)
    R = np.broadcast_to(np.eye(3), (gyro_motion.shape[0], 3, 3)).copy()
    for k in range(gyro_motion.shape[1]):
        R = R @ steps[:, k]
    return R


def calibrate_multi_static(gyro, accel, sample_interval_s: float, *, initial_s: float,
                           gravity_m_s2: float | None = None, latitude_rad: float = math.radians(45.0),
                           window_s: float = 1.0, min_static_s: float = 1.0) -> MultiStaticCalibration:
    """Calibrate both triads from a hand-held multi-static record (module notes).

    Parameters
    ----------
    gyro, accel : ndarray (n, 3)
        Mean rates (rad/s) and specific forces (m/s^2) of every sample, sensor axes.
    sample_interval_s : float
        dt, s.
    initial_s : float
        Length of the initial static period, s.
    gravity_m_s2 : float, optional
        Local g (default: normal gravity at ``latitude_rad``).
    latitude_rad : float
        Site latitude, for the default g.
    window_s, min_static_s : float
        Static detector settings, s.

    Raises
    ------
    IdentificationError
        Fewer than :data:`MIN_INTERVALS` static intervals at every threshold, or a fit that does not converge.
    """
    gyro, accel = np.asarray(gyro, dtype=float), np.asarray(accel, dtype=float)
    if gyro.shape != accel.shape or gyro.ndim != 2 or gyro.shape[1] != 3:
        raise InvalidParameter("samples", f"gyro {gyro.shape} and accel {accel.shape} must both be (n, 3)")
    dt = float(sample_interval_s)
    gravity = float(normal_gravity(latitude_rad)) if gravity_m_s2 is None else float(gravity_m_s2)
    best = None
    for factor in THRESHOLD_FACTORS:
        intervals = detect_static(accel, dt, initial_s=initial_s, factor=factor, window_s=window_s,
                                  min_static_s=min_static_s)
        if len(intervals) < MIN_INTERVALS:
            continue
        params, sigma, rms = _calibrate_accel(accel, intervals, gravity)
        if best is None or rms < best[3]:
            best = (factor, intervals, (params, sigma), rms)
    if best is None:
        raise IdentificationError(f"fewer than {MIN_INTERVALS} static intervals found at every threshold; hold the "
                                  "sensor still longer or more often")
    factor, intervals, (accel_params, accel_sigma), accel_rms = best
    first, stop = intervals[0]
    gyro_bias = gyro[first:stop].mean(axis=0)
    gyro_bias_sigma = gyro[first:stop].std(axis=0, ddof=1) / math.sqrt(stop - first)
    directions = _gravity_directions(accel, intervals, accel_params)
    gaps = [(a_stop, b_first) for (_, a_stop), (b_first, _) in zip(intervals[:-1], intervals[1:])]
    longest = max(b - a for a, b in gaps)
    motion = np.zeros((len(gaps), longest, 3))
    for j, (a, b) in enumerate(gaps):
        motion[j, :b - a] = gyro[a:b] - gyro_bias

    def gyro_residuals(p):
        R = _rotations(motion, p.reshape(3, 3), dt)
        return (directions[1:] - np.einsum("jki,jk->ji", R, directions[:-1])).ravel()

    # each residual holds two gravity directions' noise, sigma_mean / g per component of each
    _, variances = _interval_statistics(accel, intervals)
    direction_noise = 2.0 * float(np.mean(variances)) / gravity**2
    gyro_params, gyro_sigma, gyro_rms = _fit(gyro_residuals, np.eye(3).ravel(), "gyro fit", direction_noise)
    a_yz, a_zy, a_zx, kx, ky, kz = accel_params[:6]
    accel_matrix = np.array([[kx, -a_yz * ky, a_zy * kz], [0.0, ky, -a_zx * kz], [0.0, 0.0, kz]])
    return MultiStaticCalibration(
        accel_non_orthogonality=accel_params[0:3], accel_scale=accel_params[3:6], accel_bias=accel_params[6:9],
        accel_matrix=accel_matrix, gyro_matrix=gyro_params.reshape(3, 3), gyro_bias=gyro_bias,
        accel_non_orthogonality_sigma=accel_sigma[0:3], accel_scale_sigma=accel_sigma[3:6],
        accel_bias_sigma=accel_sigma[6:9], gyro_matrix_sigma=gyro_sigma.reshape(3, 3),
        gyro_bias_sigma=gyro_bias_sigma, static_intervals=len(intervals), threshold_factor=factor,
        accel_residual_rms=accel_rms, gyro_residual_rms=gyro_rms)


def identifiable_truth(accel_matrix, accel_bias, gyro_matrix):
    """What a multi-static calibration can recover from a sensor y = K u + b (imu's model, measured - true).

    K_a^-1 = Q U (Q a rotation, U upper triangular with a positive diagonal): the accelerometers
    give T K = U (so k = diag U, a_yz = -U_01 / U_11, a_zy = U_02 / U_22, a_zx = -U_12 / U_22), the
    calibrated frame is Q^T of the sensor's, and the gyros' G = Q^T K_g^-1.

    Returns
    -------
    dict
        ``accel_non_orthogonality``, ``accel_scale``, ``accel_bias``, ``accel_matrix`` (U), ``gyro_matrix``.
    """
    Q, U = np.linalg.qr(np.linalg.inv(np.asarray(accel_matrix, dtype=float)))
    signs = np.sign(np.diag(U))
    Q, U = Q * signs, signs[:, None] * U
    return {"accel_non_orthogonality": np.array([-U[0, 1] / U[1, 1], U[0, 2] / U[2, 2], -U[1, 2] / U[2, 2]]),
            "accel_scale": np.diag(U).copy(), "accel_bias": np.asarray(accel_bias, dtype=float),
            "accel_matrix": U, "gyro_matrix": Q.T @ np.linalg.inv(np.asarray(gyro_matrix, dtype=float))}
