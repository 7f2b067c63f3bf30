"""The two least-squares fits of the multi-static calibration and their 1-sigma by noise propagation.

Plain-array helpers of :mod:`~schuler.alignment.multi_static` (whose notes give the equations).
Every 1-sigma here is linear noise propagation through the Gauss-Newton solution,
cov(p) = H cov(r) H^T with H = (J^T J)^-1 J^T and cov(r) built from the measured
noise of the data the residuals are made of (a sandwich with the noise model as its meat):
nothing is scaled by the residual variance, which would both miss the correlations
(a static mean enters two gyro residuals and every accelerometer parameter) and
follow the threshold picked by the smallest residual.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from schuler.alignment import _kernels
from schuler.core.attitude import dcm_from_rotation_vector, skew
from schuler.exceptions import IdentificationError
from schuler.imu.error_model import flicker_terms


def slow_terms(errors) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per axis, the Gauss-Markov terms (sigmas, correlation times) of a triad's slow bias errors: its
    Gauss-Markov bias and its bias instability as the simulator's sum of terms (:func:`flicker_terms`)."""
    out = []
    for axis in range(3):
        sigmas, times = [errors.gm_sigma[axis]], [errors.gm_correlation_time_s[axis]]
        if errors.bias_instability[axis] > 0:
            flicker = flicker_terms(errors.bias_instability[axis], errors.flicker_tau_range_s)
            sigmas, times = sigmas + list(flicker[0]), times + list(flicker[1])
        keep = np.asarray(sigmas) > 0
        out.append((np.asarray(sigmas, dtype=float)[keep], np.asarray(times, dtype=float)[keep]))
    return out


def mean_covariance(first: np.ndarray, second: np.ndarray, terms) -> np.ndarray:
    """Covariance (n, m) of a slow process's means over spans ``first`` (n, 2) and ``second`` (m, 2), s.

    For a term sigma^2 exp(-|tau| / T): the double integral over [a, b) x [c, d) is
    K(b - c) - K(a - c) - K(b - d) + K(a - d), K(x) = T^2 (exp(-|x|/T) - 1 + |x|/T) (K'' the kernel),
    divided by the two lengths.
    """
    sigmas, times = terms
    (a, b), (c, d) = (first[:, 0, None], first[:, 1, None]), (second[None, :, 0], second[None, :, 1])
    total = np.zeros((len(first), len(second)))
    for sigma, T in zip(sigmas, times):
        def K(x, T=T):
            return T**2 * (np.expm1(-np.abs(x) / T) + np.abs(x) / T)

        total += sigma**2 * (K(b - c) - K(a - c) - K(b - d) + K(a - d))
    return total / ((b - a) * (d - c))


def least_squares_fit(residuals, start: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray, float]:
    """Levenberg-Marquardt: the solution, the residuals' Jacobian there, the residual rms."""
    solution = least_squares(residuals, start, method="lm", x_scale="jac")
    if not solution.success:
        raise IdentificationError(f"{what}: Levenberg-Marquardt did not converge ({solution.message})")
    return solution.x, solution.jac, float(np.sqrt(np.mean(solution.fun**2)))


def sensitivity(jacobian: np.ndarray) -> np.ndarray:
    """H = (J^T J)^-1 J^T: the change of the estimate per change of the residuals (Gauss-Newton)."""
    return np.linalg.pinv(jacobian.T @ jacobian) @ jacobian.T


def accel_matrix(params: np.ndarray) -> np.ndarray:
    """T K of eq. (8) from (a_yz, a_zy, a_zx, k_x, k_y, k_z, ...)."""
    a_yz, a_zy, a_zx, kx, ky, kz = params[:6]
    return np.array([[kx, -a_yz * ky, a_zy * kz], [0.0, ky, -a_zx * kz], [0.0, 0.0, kz]])


def accel_model(params: np.ndarray, means: np.ndarray) -> np.ndarray:
    """Calibrated specific forces v = T K (m - b), (j, 3)."""
    return (means - params[6:9]) @ accel_matrix(params).T


def accel_model_jacobian(params: np.ndarray, means: np.ndarray) -> np.ndarray:
    """dv/dp of :func:`accel_model`, (j, 3, 9)."""
    a_yz, a_zy, a_zx, kx, ky, kz = params[:6]
    w = means - params[6:9]
    zero = np.zeros(len(w))
    columns = [(-ky * w[:, 1], zero, zero), (kz * w[:, 2], zero, zero), (zero, -kz * w[:, 2], zero),
               (w[:, 0], zero, zero), (-a_yz * w[:, 1], w[:, 1], zero), (a_zy * w[:, 2], -a_zx * w[:, 2], w[:, 2])]
    out = np.empty((len(w), 3, 9))
    out[:, :, :6] = np.stack([np.stack(c, axis=1) for c in columns], axis=2)
    out[:, :, 6:] = -accel_matrix(params)
    return out


def fit_accel(means: np.ndarray, gravity: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Eqs. (8)-(10): residuals g^2 - |v_j|^2 over the static means."""
    start = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    return least_squares_fit(lambda p: gravity**2 - (accel_model(p, means) ** 2).sum(axis=1), start,
                             "accelerometer fit")


def accel_gain(params: np.ndarray, jacobian: np.ndarray, means: np.ndarray) -> np.ndarray:
    """dp/dm, (9, j, 3): the parameters' change per change of each static mean.

    dr_j/dm_j = -2 v_j^T T K, so dp/dm_j = 2 H[:, j] v_j^T T K.
    """
    gain = (accel_model(params, means) @ accel_matrix(params))[None]
    return 2.0 * sensitivity(jacobian)[:, :, None] * gain


def directions(params: np.ndarray, means: np.ndarray) -> np.ndarray:
    """Gravity's directions d_j = v_j / |v_j|, (j, 3)."""
    v = accel_model(params, means)
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def direction_gain(params: np.ndarray, jacobian: np.ndarray, means: np.ndarray):
    """dd/dm: (I - d_j d_j^T) / |v_j| times T K (own mean, (j, 3, 3)), times dv_j/dp (j, 3, 9) and the
    accelerometer gain dp/dm (9, j, 3) (every mean, through the parameters)."""
    v = accel_model(params, means)
    norm = np.linalg.norm(v, axis=1)
    d = v / norm[:, None]
    projector = (np.eye(3) - d[:, :, None] * d[:, None, :]) / norm[:, None, None]
    return (projector @ accel_matrix(params), projector @ accel_model_jacobian(params, means),
            accel_gain(params, jacobian, means))


def partial_rotations(rates: np.ndarray, lengths: np.ndarray, dt: float, noise: np.ndarray | None = None):
    """Per motion j (rates (j, L, 3) rad/s, zero-padded past ``lengths``): R_j = prod_k exp([w_k dt x]),
    S_j = integral of the partial product R_j(t) dt (trapezoid), and, given the rates' per-sample noise
    covariance ``noise`` (3, 3), Q_j = sum_k R_j(t_k) noise R_j(t_k)^T dt^2 (the rotation's noise, start frame).
    The time loop is compiled (:func:`~schuler.alignment._kernels.partial_rotations`).
    """
    gaps = rates.shape[0]
    R, S, Q = (np.empty((gaps, 3, 3)) for _ in range(3))
    _kernels.partial_rotations(np.ascontiguousarray(rates, dtype=float), np.asarray(lengths, dtype=np.int64),
                               float(dt), np.zeros((3, 3)) if noise is None else np.ascontiguousarray(noise),
                               noise is not None, R, S, Q)
    return R, S, Q


def earth_corrected(R: np.ndarray, S: np.ndarray, durations: np.ndarray, omega0: np.ndarray) -> np.ndarray:
    """The motions' rotations relative to the local-level frame, the Earth rate taken out (module notes of
    :mod:`~schuler.alignment.multi_static`, step 3): R_j exp([theta_j x]) with
    theta_j = R_j^T (S_j omega_0 - T_j P_j^T omega_0), P_j the product of the earlier corrected rotations.
    """
    out, P = np.empty_like(R), np.eye(3)
    for j in range(len(R)):
        theta = R[j].T @ (S[j] @ omega0 - durations[j] * (P.T @ omega0))
        out[j] = R[j] @ dcm_from_rotation_vector(theta)
        P = P @ out[j]
    return out


class GyroProblem:
    """The gyro fit (eqs. (11)-(14) with the Earth rate): parameters G (9, row by row) and the initial
    attitude's horizontal Earth rate (2, in units of the Earth rate, on a basis normal to gravity)."""

    def __init__(self, motion, lengths, dt: float, d: np.ndarray, earth_rate: float, vertical_rate: float):
        self.motion, self.lengths, self.dt, self.d = motion, lengths, dt, d
        self.durations = lengths * dt
        self.earth_rate, self.vertical = earth_rate, vertical_rate * d[0]
        self.basis = np.linalg.svd(d[0][None, :])[2][1:]   # two unit vectors normal to the first direction

    def omega0(self, p: np.ndarray) -> np.ndarray:
        """The Earth rate in the calibrated frame at the initial attitude, rad/s."""
        return self.vertical + self.earth_rate * (p[9:11] @ self.basis)

    def rotations(self, p: np.ndarray, noise=None):
        G = p[:9].reshape(3, 3)
        R, S, Q = partial_rotations(self.motion @ G.T, self.lengths, self.dt, noise)
        return earth_corrected(R, S, self.durations, self.omega0(p)), S, Q

    def residuals(self, p: np.ndarray) -> np.ndarray:
        Rc = self.rotations(p)[0]
        return (self.d[1:] - np.einsum("jki,jk->ji", Rc, self.d[:-1])).ravel()

    def covariance(self, p, jacobian, noise: dict, direction_gain) -> np.ndarray:
        """cov(p) from the noise of the data (``noise``):

        ``rate`` (3, 3) the gyros' per-sample white-noise covariance, raw axes; ``bias`` (3, 3) the white part of
        the initial mean's error (common to every motion); ``gap_bias`` (3, gaps, gaps) per raw axis, the slow
        bias's change from the initial mean, averaged over each motion; ``means`` (3, j, j) per axis, the
        covariance of the static means, taken through the directions: dd_j/dm = ``blocks`` (j, 3, 3) for its own
        mean plus ``via_params`` (j, 3, 9) times ``gain`` (9, j, 3) through the accelerometer parameters
        (``direction_gain``, :func:`direction_gain`).

        The residual r_j = d_{j+1} - Rc_j^T d_j moves by -[(Rc_j^T d_j) x] Rc_j^T dtheta for a rotation
        error dtheta (start frame); the gyro noise gives dtheta cov Q_j, a bias error db gives -S_j G db.
        """
        G = p[:9].reshape(3, 3)
        Rc, S, Q = self.rotations(p, G @ noise["rate"] @ G.T)
        H = sensitivity(jacobian).reshape(p.size, -1, 3)
        cross = -skew(np.einsum("jki,jk->ji", Rc, self.d[:-1]))
        Y = np.einsum("pja,jab,jcb->pjc", H, cross, Rc)                # dp per rotation error, start frame
        covariance = np.einsum("pja,jab,qjb->pq", Y, Q, Y)
        per_bias = -np.einsum("pja,jab,bc->pjc", Y, S, G)               # dp per bias error in motion j
        bias = per_bias.sum(axis=1)
        covariance += bias @ noise["bias"] @ bias.T
        covariance += np.einsum("pja,ajk,qka->pq", per_bias, noise["gap_bias"], per_bias)
        # residual j holds +d_{j+1} and -Rc_j^T d_j
        per_direction = np.zeros((p.size, len(self.d), 3))
        per_direction[:, 1:] += H
        per_direction[:, :-1] -= np.einsum("pjk,jik->pji", H, Rc)
        blocks, via_params, gain = direction_gain
        per_mean = (np.einsum("pja,jab->pjb", per_direction, blocks)
                    + np.einsum("pja,jaq,qkb->pkb", per_direction, via_params, gain))
        return covariance + np.einsum("pja,ajk,qka->pq", per_mean, noise["means"], per_mean)
