"""Errors of a filter run against a truth, drift through GNSS outages, and consistency (NEES).

Errors are computed - true: position in NED metres (north, east, down), velocity in m/s, and the
attitude error as psi, the rotation vector of C_hat C^T (C_hat = (I - [psi x]) C to first order,
so psi = -(rotation vector of C_hat C^T)); the heading error (computed - true) is -psi_D to
first order (spec 07).

NEES of a group of states at one epoch: epsilon = e^T P^-1 e over the group; over M members its
mean lies in the chi-square(M n) / M band with the stated probability when the filter is
consistent (Bar-Shalom, Li and Kirubarajan 2001, Sec. 5.4). Epochs are correlated: each epoch's
mean is compared with its band, never a pool of epochs.

References
----------
Y. Bar-Shalom, X. R. Li and T. Kirubarajan, *Estimation with Applications to Tracking and
Navigation*, Wiley, 2001, Sec. 5.4.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.stats

from schuler.aided.ekf import FilterRun
from schuler.aided.error_state import ATTITUDE, POSITION, VELOCITY
from schuler.aided.initialisation import LARGEST_SIGMA
from schuler.core.attitude import (
    conjugate,
    euler_from_quaternion,
    quaternion_multiply,
    rotation_vector_from_quaternion,
    wrap_angle,
)
from schuler.core.earth import radii_of_curvature

GROUPS = {"position": POSITION, "velocity": VELOCITY, "attitude": ATTITUDE}


@dataclass(frozen=True)
class Truth:
    """The true solution at the run's output times (SI), shared by every member.

    Parameters
    ----------
    latitude, longitude : ndarray, shape (n,)
        rad.
    height : ndarray, shape (n,)
        m.
    velocity : ndarray, shape (n, 3)
        NED, m/s.
    quaternion : ndarray, shape (n, 4)
        q_bn, scalar first.
    """

    latitude: np.ndarray
    longitude: np.ndarray
    height: np.ndarray
    velocity: np.ndarray
    quaternion: np.ndarray


@dataclass(frozen=True)
class Errors:
    """Errors (computed - true) of every member at the run's output times.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        s.
    position : ndarray, shape (N, n, 3)
        North, east, down, m.
    velocity : ndarray, shape (N, n, 3)
        NED, m/s.
    psi : ndarray, shape (N, n, 3)
        Attitude error psi, NED, rad.
    heading : ndarray, shape (N, n)
        Heading error, rad in (-pi, pi].
    """

    t_s: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    psi: np.ndarray
    heading: np.ndarray

    @property
    def horizontal(self) -> np.ndarray:
        """Horizontal position error, m, shape (N, n)."""
        return np.hypot(self.position[..., 0], self.position[..., 1])


def errors(run: FilterRun, truth: Truth) -> Errors:
    """The run's errors against the truth at its output times.

    Parameters
    ----------
    run : FilterRun
        A filter run (N members).
    truth : Truth
        The true solution at ``run.t_s``.
    """
    sol = run.solution
    R_N, R_E = radii_of_curvature(truth.latitude)
    h = truth.height
    position = np.stack([(sol[..., 0] - truth.latitude) * (R_N + h),
                         wrap_angle(sol[..., 1] - truth.longitude) * (R_E + h) * np.cos(truth.latitude),
                         -(sol[..., 2] - h)], axis=-1)
    q = sol[..., 6:10]
    true_q = np.broadcast_to(truth.quaternion, q.shape)
    psi = -rotation_vector_from_quaternion(quaternion_multiply(q, conjugate(true_q)))
    heading = wrap_angle(euler_from_quaternion(q)[..., 2] - euler_from_quaternion(truth.quaternion)[..., 2])
    return Errors(run.t_s, position, sol[..., 3:6] - truth.velocity, psi, heading)


@dataclass(frozen=True)
class OutageDrift:
    """The errors through one GNSS outage (per member, or their RMS over members).

    Attributes
    ----------
    start_s, duration_s : float
        The outage, s (times as in the data).
    horizontal_error_max_m : float
        Largest horizontal position error inside it, m (RMS over members of each member's largest).
    vertical_error_max_m : float
        Largest |down error| inside it, m (likewise).
    heading_error_max_rad : float
        Largest |heading error| inside it, rad (likewise).
    horizontal_error_end_m : float
        Horizontal error at its end, m (RMS over members): at the last covariance time before the epoch that ends
        it (the covariance stored at that epoch is already updated).
    horizontal_error_sigma_m : float
        The filter's predicted sqrt(P_NN + P_EE) at that time, m (RMS over members).
    """

    start_s: float
    duration_s: float
    horizontal_error_max_m: float
    vertical_error_max_m: float
    heading_error_max_rad: float
    horizontal_error_end_m: float
    horizontal_error_sigma_m: float


def _rms(values) -> float:
    return float(np.sqrt(np.mean(np.square(values))))


def member(value, m: int):
    """Member ``m`` alone of a filter run or of its errors (leading axis kept, length 1).

    Parameters
    ----------
    value : FilterRun or Errors
        Runs or errors of several members, batched on the leading axis.
    m : int
        The member's index in the batch.
    """
    fields = {}
    for f in dataclasses.fields(value):
        item = getattr(value, f.name)
        per_member = isinstance(item, np.ndarray) and item.ndim >= 2 and f.name not in ("t_s", "covariance_t_s",
                                                                                         "epoch_t_s")
        if isinstance(item, dict):  # a run's other sources: each log alone
            fields[f.name] = {name: member(log, m) for name, log in item.items()}
            continue
        fields[f.name] = item[m:m + 1] if per_member else item
    return dataclasses.replace(value, **fields)


def outage_drift(run: FilterRun, run_errors: Errors | None, outages) -> list[OutageDrift]:
    """How far the solution drifted in each outage, beside the filter's own 1-sigma at its end.

    Parameters
    ----------
    run : FilterRun
        The run (its covariances give the predicted 1-sigma).
    run_errors : Errors or None
        Its errors against the truth; None without a truth (the error fields are then NaN).
    outages : sequence of (start, duration)
        The outages, s.
    """
    drifts = []
    t_s = run.t_s if run_errors is None else run_errors.t_s
    for start, duration in outages:
        end = start + duration
        inside = (t_s > start) & (t_s <= end + 1e-9)
        if not inside.any():
            continue
        # the outage's end, as stored: the last covariance strictly before the epoch that ends it (the covariance
        # stored at that epoch is already updated), and the errors at that same time
        index = max(int(np.searchsorted(run.covariance_t_s, end - 1e-9)) - 1, 0)
        P = run.covariance[:, index]
        sigma = _rms(np.sqrt(P[:, 0, 0] + P[:, 1, 1]))
        if run_errors is None:
            drifts.append(OutageDrift(float(start), float(duration), math.nan, math.nan, math.nan, math.nan, sigma))
            continue
        last = min(int(np.searchsorted(run_errors.t_s, run.covariance_t_s[index] - 1e-9)), run_errors.t_s.size - 1)
        drifts.append(OutageDrift(
            float(start), float(duration),
            _rms(run_errors.horizontal[:, inside].max(axis=1)),
            _rms(np.abs(run_errors.position[:, inside, 2]).max(axis=1)),
            _rms(np.abs(run_errors.heading[:, inside]).max(axis=1)),
            _rms(run_errors.horizontal[:, last]), sigma))
    return drifts


@dataclass(frozen=True)
class Consistency:
    """Mean NEES over the members per group at the covariance epochs, with its band.

    Attributes
    ----------
    t_s : ndarray, shape (k,)
        Epochs (covariance times that fall on an output time), s.
    nees : dict of str to ndarray, shape (k,)
        Mean NEES over members per group (``position``, ``velocity``, ``attitude``).
    band : tuple of float
        The chi-square(M n) / M interval of the stated probability (n = 3 per group).
    inside : dict of str to float
        Fraction of epochs inside the band per group.
    """

    t_s: np.ndarray
    nees: dict[str, np.ndarray]
    band: tuple[float, float]
    inside: dict[str, float]


def consistency(run: FilterRun, run_errors: Errors, probability: float = 0.99) -> Consistency:
    """The members' mean NEES per group at every stored covariance that falls on an output time.

    Parameters
    ----------
    run : FilterRun
        A run of M members.
    run_errors : Errors
        Their errors against the truth.
    probability : float
        Probability of the band, a plain number in (0, 1).
    """
    members = run.solution.shape[0]
    rows = np.searchsorted(run_errors.t_s, run.covariance_t_s)
    on_output = (rows < run_errors.t_s.size) & (np.abs(run_errors.t_s[np.minimum(rows, run_errors.t_s.size - 1)]
                                                       - run.covariance_t_s) < 1e-9)
    covariances, rows = run.covariance[:, on_output], rows[on_output]
    stacked = {"position": run_errors.position, "velocity": run_errors.velocity, "attitude": run_errors.psi}
    nees, inside = {}, {}
    dof = 3 * members
    low, high = scipy.stats.chi2.ppf([(1 - probability) / 2, (1 + probability) / 2], dof) / members
    for name, states in GROUPS.items():
        e = stacked[name][:, rows]
        P = covariances[..., states, states]
        solved = np.linalg.solve(P, e[..., None])[..., 0]
        nees[name] = np.einsum("mki,mki->mk", e, solved).mean(axis=0)
        inside[name] = float(np.mean((nees[name] >= low) & (nees[name] <= high)))
    return Consistency(run_errors.t_s[rows], nees, (float(low), float(high)), inside)


class FilterLinearityWarning(UserWarning):
    """The filter's attitude uncertainty grew past its small-angle model: its solution is not to be trusted."""


def warn_if_nonlinear(run: FilterRun) -> None:
    """Warn (:class:`FilterLinearityWarning`) when any member's psi 1-sigma passes
    :data:`~schuler.aided.initialisation.LARGEST_SIGMA`, the limit of its small-angle model.

    A gyro bias no measurement sees, such as a consumer IMU's 20 deg/s at a stop with GNSS alone, turns the
    heading by hundreds of degrees while the filter's model stays linear; its covariance says so first.

    Parameters
    ----------
    run : FilterRun
        A filter run (its stored covariances).
    """
    variance = np.diagonal(run.covariance[..., ATTITUDE, ATTITUDE], axis1=-2, axis2=-1)
    past = np.any(variance > LARGEST_SIGMA**2, axis=(0, 2))
    if not past.any():
        return
    k = int(np.argmax(past))
    sigma = math.degrees(math.sqrt(float(variance[:, k].max())))
    t = float(run.covariance_t_s[k])
    warnings.warn(f"the filter's attitude 1-sigma reached {sigma:.3g} deg at t = {t:g} s, past the "
                  f"{math.degrees(LARGEST_SIGMA):g} deg of its small-angle model: its solution is not to be "
                  "trusted (a gyro bias unseen at a stop needs zero-rate updates there, --aiding ...,zupt,zaru, or "
                  "an in-motion start, which takes it from the rest before: --initialisation in-motion)",
                  FilterLinearityWarning, stacklevel=2)
