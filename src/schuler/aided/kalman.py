"""The Kalman filter's predict and update steps on a batch of members (pure numpy, SI).

Every member carries its own covariance P (shape (N, n, n)): an extended filter's gains
depend on its own estimate. With closed-loop feedback the error state is zero before
every update (the estimate is fed back and the state reset, spec 07), so the update
needs only the residual delta_z = h_hat - z_measured:

* S = H P H^T + R, K = P H^T S^-1 (Cholesky solves, no explicit inverse);
* the normalised innovation squared NIS = delta_z^T S^-1 delta_z is gated against the
  chi-square quantile of dim z at probability ``gate``: a member whose NIS exceeds it
  rejects the measurement (P and the solution unchanged, counted);
* delta_x = K delta_z and the Joseph form P = (I - K H) P (I - K H)^T + K R K^T, which keeps
  P symmetric positive definite in floating point (Bucy and Joseph 1968), symmetrised.

Measurements of several sources at one epoch (:func:`stacked_update`) are gated source by source,
each on its own NIS against its own S block (the marginal of its residual), and the accepted ones
applied in one update: a member's rejected block gets zero rows of H and of the residual, which
leaves its gain columns zero, the same as leaving the block out.

References
----------
R. S. Bucy and P. D. Joseph, *Filtering for Stochastic Processes with Applications to
Guidance*, Interscience, 1968 (the Joseph form).
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*,
2nd ed., Artech House, 2013, Sec. 3.2 and 3.4.3 (innovation gating).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import scipy.stats

DEFAULT_GATE = 0.9999
"""Probability of the chi-square gate: a measurement consistent with the filter is rejected once in 10,000."""


def predict(P: np.ndarray, Phi: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """P <- Phi P Phi^T + Q_d, symmetrised, shape (N, n, n).

    Parameters
    ----------
    P : ndarray, shape (N, n, n)
        Covariance of the error state, (state units)^2.
    Phi : ndarray, shape ([N,] n, n)
        Transition matrix over the step, in the state units (plain numbers for like states).
    Q : ndarray, shape ([N,] n, n)
        Discrete process noise over the step, (state units)^2.
    """
    P = Phi @ P @ np.swapaxes(Phi, -1, -2) + Q
    return 0.5 * (P + np.swapaxes(P, -1, -2))


@dataclass(frozen=True)
class Update:
    """What one measurement update did to each member.

    Attributes
    ----------
    correction : ndarray, shape (N, n)
        delta_x = K delta_z (zero where rejected), state units.
    covariance : ndarray, shape (N, n, n)
        P after the update (unchanged where rejected).
    nis : ndarray, shape (N,)
        Normalised innovation squared, dimensionless.
    accepted : ndarray of bool, shape (N,)
        Whether the member's NIS passed the gate.
    residual : ndarray, shape (N, m)
        delta_z = h_hat - z (measurement units).
    residual_sigma : ndarray, shape (N, m)
        sqrt(diag(S)): the predicted 1-sigma of each residual component.
    """

    correction: np.ndarray
    covariance: np.ndarray
    nis: np.ndarray
    accepted: np.ndarray
    residual: np.ndarray
    residual_sigma: np.ndarray


def _innovation(P, residual, H, R):
    """P H^T, S, its Cholesky factor and the NIS of every member."""
    PHt = P @ np.swapaxes(H, -1, -2)
    S = H @ PHt + R
    S = 0.5 * (S + np.swapaxes(S, -1, -2))
    L = np.linalg.cholesky(S)
    # K^T = S^-1 H P: two triangular solves per member
    whitened = np.linalg.solve(L, residual[..., None])[..., 0]
    return PHt, S, L, np.einsum("...i,...i->...", whitened, whitened)


@functools.lru_cache(maxsize=64)
def gate_threshold(dimension: int, probability: float = DEFAULT_GATE) -> float:
    """The chi-square quantile a NIS of ``dimension`` degrees of freedom is compared with.

    Parameters
    ----------
    dimension : int
        Number of components of the measurement.
    probability : float
        Gate probability, a plain number in (0, 1]; 1 accepts every measurement.

    Examples
    --------
    >>> round(gate_threshold(3, 0.99), 3)
    11.345
    """
    if probability >= 1.0:
        return np.inf
    return float(scipy.stats.chi2.ppf(probability, dimension))


def update(P: np.ndarray, residual: np.ndarray, H: np.ndarray, R: np.ndarray,
           gate: float = DEFAULT_GATE) -> Update:
    """The gated Joseph-form update of every member (module docstring).

    Parameters
    ----------
    P : ndarray, shape (N, n, n)
        Prior covariance, (state units)^2.
    residual : ndarray, shape (N, m)
        delta_z = h(x_hat) - z_measured = H delta_x + v, measurement units.
    H : ndarray, shape ([N,] m, n)
        Measurement matrix, measurement unit per state unit.
    R : ndarray, shape ([N,] m, m)
        Measurement noise covariance, (measurement units)^2.
    gate : float
        Chi-square gate probability, a plain number in (0, 1] (1: no gate).
    """
    H = np.broadcast_to(H, (P.shape[0],) + np.shape(H)[-2:])
    R = np.broadcast_to(R, (P.shape[0],) + np.shape(R)[-2:])
    PHt, S, L, nis = _innovation(P, residual, H, R)
    accepted = nis <= gate_threshold(int(residual.shape[-1]), float(gate))
    K = np.swapaxes(np.linalg.solve(np.swapaxes(L, -1, -2), np.linalg.solve(L, np.swapaxes(PHt, -1, -2))), -1, -2)
    correction = np.einsum("...ij,...j->...i", K, residual) * accepted[:, None]
    A = np.eye(P.shape[-1]) - K @ H
    posterior = A @ P @ np.swapaxes(A, -1, -2) + K @ R @ np.swapaxes(K, -1, -2)
    posterior = 0.5 * (posterior + np.swapaxes(posterior, -1, -2))
    covariance = np.where(accepted[:, None, None], posterior, P)
    sigma = np.sqrt(np.diagonal(S, axis1=-2, axis2=-1))
    return Update(correction, covariance, nis, accepted, residual, sigma)


def stacked_update(P: np.ndarray, blocks, gate: float = DEFAULT_GATE) -> tuple[Update, list[Update]]:
    """Several sources' measurements at one epoch: each gated on its own, the accepted applied at once.

    Parameters
    ----------
    P : ndarray, shape (N, n, n)
        Prior covariance, (state units)^2.
    blocks : sequence of (residual, H, R)
        Each source's residual (N, m_i), H ([N,] m_i, n) and R ([N,] m_i, m_i), measurement units.
    gate : float
        Chi-square gate probability, a plain number in (0, 1] (1: no gate).

    Returns
    -------
    update, per_block : Update, list of Update
        The joint update (its ``accepted``: every block accepted), and each block's NIS, acceptance, residual and
        predicted 1-sigma (their ``correction`` and ``covariance`` those of the joint update).
    """
    members = P.shape[0]
    stats, residuals, Hs, Rs = [], [], [], []
    for residual, H, R in blocks:
        H = np.broadcast_to(H, (members,) + np.shape(H)[-2:])
        R = np.broadcast_to(R, (members,) + np.shape(R)[-2:])
        _, S, _, nis = _innovation(P, residual, H, R)
        accepted = nis <= gate_threshold(int(residual.shape[-1]), float(gate))
        stats.append((nis, accepted, residual, np.sqrt(np.diagonal(S, axis1=-2, axis2=-1))))
        residuals.append(residual * accepted[:, None])
        Hs.append(H * accepted[:, None, None])
        Rs.append(R)
    m = sum(r.shape[-1] for r in residuals)
    R_all = np.zeros((members, m, m))
    start = 0
    for R in Rs:
        stop = start + R.shape[-1]
        R_all[:, start:stop, start:stop] = R
        start = stop
    joint = update(P, np.concatenate(residuals, axis=-1), np.concatenate(Hs, axis=-2), R_all, 1.0)
    every = np.logical_and.reduce([accepted for _, accepted, _, _ in stats])
    joint = Update(joint.correction, joint.covariance, joint.nis, every, joint.residual, joint.residual_sigma)
    return joint, [Update(joint.correction, joint.covariance, nis, accepted, residual, sigma)
                   for nis, accepted, residual, sigma in stats]
