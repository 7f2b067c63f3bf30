"""The Rauch-Tung-Striebel fixed-interval smoother over a closed-loop filter run (spec 07, "Smoother").

The forward filter (:func:`schuler.aided.ekf.run_filter` with ``keep_for_smoother``) keeps, at each of its
stored times t_k (every covariance step and every measurement epoch; not every IMU sample), P_k^+, the prior
P_k^-, the transition Phi_{k-1} from t_{k-1} to t_k and the correction c_k it fed back there. The backward pass
(Rauch, Tung and Striebel 1965, eqs. as in spec 07) is

    A_k = P_k^+ Phi_k^T (P_{k+1}^-)^-1,
    x_k^s = x_k^+ + A_k (x_{k+1}^s - x_{k+1}^-),
    P_k^s = P_k^+ + A_k (P_{k+1}^s - P_{k+1}^-) A_k^T,

from x_K^s = x_K^+, P_K^s = P_K^+ at the last stored time, A_k^T solved from P_{k+1}^- A_k^T = Phi_k P_k^+ with
a Cholesky factorisation of P_{k+1}^- scaled to unit diagonal (scipy.linalg.cho_factor and cho_solve; the
states' variances span twenty decades), never an explicit inverse.

Closed-loop feedback. The error state (computed - true) is defined relative to the navigation solution in
force. After the update at t_k the estimate is fed back and reset, so x_k^+ = 0 relative to the corrected
solution s_k^+. The mechanization carries s_k^+ to s_{k+1}^-, and the prior is Phi_k 0 = 0 relative to it. The
update at t_{k+1} estimates c_{k+1} relative to s_{k+1}^- and feeds it back, s_{k+1}^+ = s_{k+1}^- (-) c_{k+1}
(r <- r - dr, v <- v - dv, C <- (I + [psi x]) C, b_hat <- b_hat + db): an error e relative to s_{k+1}^- is
e - c_{k+1} relative to s_{k+1}^+ to first order (with C_hat = (I - [psi x]) C, (I + [c x])(I - [psi x]) =
I - [(psi - c) x] to first order; the residual sensor errors b - b_hat likewise). So, relative to the stored
corrected solutions, x_k^+ = 0 and x_{k+1}^- = -c_{k+1}, and the backward step becomes

    x_k^s = A_k (x_{k+1}^s + c_{k+1}),

each x_k^s relative to s_k^+; x_{k+1}^s + c_{k+1} is the same smoothed error relative to s_{k+1}^-. The
smoothed solution is s_k^+ (-) x_k^s, with the same feedback formulas. Phi_k is the forward filter's own
(linearised about s_k^+): this is the smoother of the linearised model, not an iterated one.

Between stored times. An IMU epoch t in (t_k, t_{k+1}] carries the forward solution propagated from s_k^+
(the one at t_{k+1} itself is stored before that epoch's update). Its smoothed error is linearly interpolated
between x_k^s (at t_k, after the feedback) and x_{k+1}^s + c_{k+1} (at t_{k+1}, before it), and its smoothed
variances between P_k^s and P_{k+1}^s. The exact smoothed mean of the linear model is
Phi(t, t_k) x_k^s + Q(t, t_k) lambda(t) (the smoothed process noise; lambda = Phi(t_{k+1}, t)^T
(P_{k+1}^-)^-1 (x_{k+1}^s + c_{k+1})): the straight line differs from it by the error's curvature over the
interval Delta, at most Delta^2 / 8 times the largest d^2 e / dt^2 -- for position Delta^2 / 8 times
d(delta_v)/dt = -psi x f^n + C_b^n b_a + ..., where 1 mrad of tilt gives 9.8 mm/s^2 and so 1.2 mm at
Delta = 1 s -- and the interpolated variance misses the bridge term of the process noise over the interval,
at most Q_d / 4 (for velocity N_a^2 Delta / 4). After the last stored time the smoothed error is the filter's,
zero. (Measured on a straight drive, against the smoother kept at every IMU sample: 0.6 % of the 1-sigma at
most; tests/test_aided_smoother.py.)

References
----------
H. E. Rauch, F. Tung and C. T. Striebel, "Maximum likelihood estimates of linear dynamic systems", *AIAA
Journal* 3(8), 1965.
E.-H. Shin, *Estimation Techniques for Low-Cost Inertial Navigation*, PhD thesis, University of Calgary,
2005, ch. 4 (RTS smoothing of the INS error states).
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013, Sec. 3.4.6 (smoothing).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg

from schuler.aided.ekf import FilterRun
from schuler.aided.error_state import ATTITUDE, POSITION, VELOCITY
from schuler.core.attitude import quaternion_from_rotation_vector, quaternion_multiply
from schuler.core.earth import radii_of_curvature
from schuler.exceptions import InvalidParameter, SimulationError, renamed_keywords
from schuler.memory import require

NAVIGATION_STATES = 9
"""delta_r, delta_v and psi: the states the smoothed solution is corrected with."""


def rts(posterior: np.ndarray, prior: np.ndarray, transition: np.ndarray,
        correction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The backward pass over a closed-loop run: x_k^s = A_k (x_{k+1}^s + c_{k+1}) and P_k^s (module docstring).

    Parameters
    ----------
    posterior : ndarray, shape (N, K, n, n)
        P_k^+ at each stored time, (state units)^2.
    prior : ndarray, shape (N, K, n, n)
        P_k^- there (index 0 unused), (state units)^2.
    transition : ndarray, shape (N, K, n, n)
        Phi from time k - 1 to k, stored at k (index 0 unused), state unit per state unit.
    correction : ndarray, shape (N, K, n)
        The correction c_k fed back at time k, state units.

    Returns
    -------
    smoothed : ndarray, shape (N, K, n)
        x_k^s relative to the corrected solution at each time, state units.
    covariance : ndarray, shape (N, K, n, n)
        P_k^s, (state units)^2.
    """
    members, count, n = correction.shape
    smoothed = np.zeros((members, count, n))
    covariance = np.empty((members, count, n, n))
    covariance[:, -1] = posterior[:, -1]
    for k in range(count - 2, -1, -1):
        ahead = prior[:, k + 1]
        variance = np.diagonal(ahead, axis1=-2, axis2=-1)
        if not np.all(variance > 0):
            raise SimulationError("the smoother needs every state's prior variance > 0 (give each state a positive "
                                  "initial 1-sigma)")
        scale = 1.0 / np.sqrt(variance)
        try:
            factor = scipy.linalg.cho_factor(ahead * scale[:, :, None] * scale[:, None, :])
        except np.linalg.LinAlgError:
            raise SimulationError(f"the smoother's prior covariance at stored time {k + 1} is not positive "
                                  "definite") from None
        # P^- A^T = Phi P^+, solved as (S P^- S)(S^-1 A^T) = S Phi P^+ with S the unit-diagonal scaling
        gain_t = scale[:, :, None] * scipy.linalg.cho_solve(factor, scale[:, :, None]
                                                             * (transition[:, k + 1] @ posterior[:, k]))
        gain = np.swapaxes(gain_t, -1, -2)
        smoothed[:, k] = np.einsum("mij,mj->mi", gain, smoothed[:, k + 1] + correction[:, k + 1])
        P = posterior[:, k] + gain @ (covariance[:, k + 1] - ahead) @ gain_t
        covariance[:, k] = 0.5 * (P + np.swapaxes(P, -1, -2))
    return smoothed, covariance


def corrected(solution: np.ndarray, error: np.ndarray) -> np.ndarray:
    """A solution with errors taken out as the filter's feedback does (r - dr, v - dv, q(psi) q), shape (..., 10).

    Parameters
    ----------
    solution : ndarray, shape (..., 10)
        Latitude, longitude (rad), height (m), v_N, v_E, v_D (m/s), q_bn (4).
    error : ndarray, shape (..., >= 9)
        Its errors (computed - true): delta_r (north, east, down, m), delta_v (NED, m/s), psi (NED, rad).
    """
    out = np.array(solution, dtype=float)
    lat, h = out[..., 0], out[..., 2]
    R_N, R_E = radii_of_curvature(lat)
    dr = error[..., POSITION]
    out[..., 1] -= dr[..., 1] / ((R_E + h) * np.cos(lat))
    out[..., 0] = lat - dr[..., 0] / (R_N + h)
    out[..., 2] = h + dr[..., 2]
    out[..., 3:6] -= error[..., VELOCITY]
    q = quaternion_multiply(quaternion_from_rotation_vector(error[..., ATTITUDE]), out[..., 6:10])
    out[..., 6:10] = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return out


def _between(stored_t: np.ndarray, t_s: np.ndarray):
    """Each output time's stored neighbours (previous, next) and its fraction of the way from one to the other."""
    count = stored_t.size
    following = np.searchsorted(stored_t, t_s - 1e-9)
    after = following >= count  # past the last stored time: that time's values
    following = np.minimum(following, count - 1)
    previous = np.where(after, count - 1, np.maximum(following - 1, 0))
    gap = stored_t[following] - stored_t[previous]
    fraction = np.where(gap > 0, (t_s - stored_t[previous]) / np.where(gap > 0, gap, 1.0), np.where(after, 0.0, 1.0))
    return previous, following, fraction


@renamed_keywords(t_s="t")
def output_variances(smoothed: FilterRun, t: np.ndarray) -> np.ndarray:
    """The smoothed variances of position, velocity and psi at output times, interpolated, shape (N, n_t, 9).

    Parameters
    ----------
    smoothed : FilterRun
        What :func:`smooth` returned (its ``covariance`` is P^s at the stored times).
    t : ndarray, shape (n_t,)
        Times, s.
    """
    previous, following, fraction = _between(smoothed.covariance_t_s, np.asarray(t, dtype=float))
    variance = np.diagonal(smoothed.covariance[..., :NAVIGATION_STATES, :NAVIGATION_STATES], axis1=-2, axis2=-1)
    return (1.0 - fraction)[:, None] * variance[:, previous] + fraction[:, None] * variance[:, following]


def smoothed_bytes(members: int, stored: int, outputs: int, n: int) -> float:
    """Memory the smoother holds at once, bytes: P^s and x^s per stored time, the solution and error per output.

    Parameters
    ----------
    members : int
        N, the members.
    stored : int
        Stored times of the forward run (a count).
    outputs : int
        Output times (a count).
    n : int
        Number of states.
    """
    return 8.0 * members * (stored * (2 * n * n + n) + outputs * (3 * 10 + 2 * NAVIGATION_STATES))


def smooth(run: FilterRun) -> FilterRun:
    """The forward run smoothed: solution, P^s and sensor estimates from every measurement (module docstring).

    The memory is estimated and checked against the budget (:func:`schuler.memory.require`) before anything is
    allocated. The innovations, NIS and gate decisions are the forward run's: the smoother reprocesses no
    measurement.

    Parameters
    ----------
    run : FilterRun
        A forward run kept for the smoother (``run_filter(..., keep_for_smoother=True)``), SI.

    Returns
    -------
    FilterRun
        The same times; ``solution`` the smoothed one at the output times, ``covariance`` P^s at the stored
        times, ``sensor_estimates`` the smoothed b_g, b_a, s_g, s_a, and no smoother inputs.
    """
    if run.prior_covariance is None or run.transition is None or run.correction is None:
        raise InvalidParameter("run", "was not kept for the smoother: run the filter with keep_for_smoother=True")
    members, stored, n = run.correction.shape
    require(smoothed_bytes(members, stored, run.t_s.size, n), "the smoother's covariances and solution",
            "the duration, the members, the covariance interval or the output step")
    errors, covariance = rts(run.covariance, run.prior_covariance, run.transition, run.correction)
    previous, following, fraction = _between(run.covariance_t_s, run.t_s)
    nav = slice(0, NAVIGATION_STATES)
    # before the update at the following time: x^s + c there, relative to the solution the outputs carry
    ahead = errors[:, following, nav] + run.correction[:, following, nav]
    at_outputs = (1.0 - fraction)[:, None] * errors[:, previous, nav] + fraction[:, None] * ahead
    # the sensor states, then the aiding states (odometer scale, barometer bias) after them
    aiding = run.aiding_estimates
    sensor_end = n - (0 if aiding is None else aiding.shape[-1])
    sensors = run.sensor_estimates.copy()
    sensors[..., :sensor_end - NAVIGATION_STATES] += errors[..., NAVIGATION_STATES:sensor_end]
    if aiding is not None and aiding.shape[-1]:
        aiding = aiding + errors[..., sensor_end:]
    return dataclasses.replace(run, solution=corrected(run.solution, at_outputs), covariance=covariance,
                               sensor_estimates=sensors, aiding_estimates=aiding, prior_covariance=None,
                               transition=None, correction=None)
