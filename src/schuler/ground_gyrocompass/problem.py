"""The identification problem every method solves: unknowns, records, model columns, covariance.

The observations are y_k at times t_k, either the coordinate the instrument sees,
alpha(t) - alpha0 (``reading="relative"``, Fedorov et al. (2020), eq. (10)), or absolute
readings alpha(t) + c with an unknown constant offset c (``reading="absolute"``).
The model (see :mod:`.motion`) is linear in alpha0, alpha0_dot, the specific harmful
torque m and c, and nonlinear only in lambda and B:

    y(t) = alpha0 (u1(t) - 1) + alpha0_dot u2(t) [+ m u3(t)]           (relative)
    y(t) = alpha0 u1(t) + alpha0_dot u2(t) [+ m u3(t)] + c             (absolute)

Sets of unknowns (the source's three plus one):

* 2: alpha0, alpha0_dot (lambda and B known: the source's 2x2 normal equations),
* 3: + lambda,
* 4: + B (reported as H_m = B J / Omega_h with J, Omega_h known: only B is
  identifiable, since H_m, Omega_h and J enter the motion only through B),
* 5: + a constant harmful torque M = J m about the suspension axis.

Standard errors come from the full Jacobian J at the optimum and the residual:
cov = s^2 (J^T J)^-1 with s^2 = misfit / (n - p). The methods that solve the
problem are :mod:`.varpro` (least squares) and :mod:`.grid` (the source's grid);
:mod:`.estimate` dispatches between them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.exceptions import IdentificationError, InvalidParameter
from schuler.ground_gyrocompass.motion import basis_columns, check_decay_rate, check_positive

UNKNOWN_SETS = {
    2: ("alpha0", "alpha0_dot"),
    3: ("alpha0", "alpha0_dot", "decay_rate"),
    4: ("alpha0", "alpha0_dot", "decay_rate", "coefficient"),
    5: ("alpha0", "alpha0_dot", "decay_rate", "coefficient", "specific_torque"),
}
"""Unknowns identified for each count (the source's 2, 3, 4; and 5 with the torque)."""

READINGS = ("relative", "absolute")

NONLINEAR = ("decay_rate", "coefficient")
"""The parameters the model is nonlinear in: lambda (1/s) and B (1/s^2)."""


def check_record(time, observed, unknowns: int, reading: str = "relative"):
    """Validate an observation record and the requested fit; return float arrays.

    Parameters
    ----------
    time : array_like of shape (n,)
        Times t_k since release, s (>= 0, strictly increasing).
    observed : array_like of shape (n,)
        Observed angles y_k, rad.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c with an unknown offset c.

    Returns
    -------
    time, observed : ndarray of shape (n,)
        The same, as float arrays (s, rad).

    Raises
    ------
    InvalidParameter
        Unknown count or reading, mismatched or non-finite arrays, time not
        strictly increasing or negative, or fewer samples than unknowns.
    """
    if unknowns not in UNKNOWN_SETS:
        raise InvalidParameter("unknowns", f"{unknowns!r} is not one of 2, 3, 4, 5")
    if reading not in READINGS:
        raise InvalidParameter("reading", f"{reading!r} is not one of {', '.join(READINGS)}")
    time = np.asarray(time, dtype=float)
    observed = np.asarray(observed, dtype=float)
    if time.ndim != 1 or time.shape != observed.shape:
        raise InvalidParameter("record", "time and angle must be 1-D arrays of the same length")
    if not (np.all(np.isfinite(time)) and np.all(np.isfinite(observed))):
        raise InvalidParameter("record", "time and angle must be finite numbers")
    if time.size and time[0] < 0.0:
        raise InvalidParameter("record", "time must start at or after the release, t >= 0 s")
    steps = np.diff(time)
    if np.any(steps <= 0.0):
        k = int(np.argmax(steps <= 0.0))
        raise InvalidParameter("record", f"time is not increasing at sample {k + 2} ({time[k + 1]:g} s)")
    needed = len(UNKNOWN_SETS[unknowns]) + (reading == "absolute")
    if time.size < needed:
        raise InvalidParameter(
            "unknowns", f"{unknowns} unknowns ({reading} reading) need at least {needed} samples; got {time.size}"
        )
    return time, observed


def linear_names(unknowns: int, reading: str) -> list[str]:
    """The linear parameters in column order: alpha0, alpha0_dot[, specific_torque][, offset].

    Parameters
    ----------
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c with an unknown offset c.

    Returns
    -------
    list of str
        Their names.
    """
    names = ["alpha0", "alpha0_dot"] + (["specific_torque"] if unknowns == 5 else [])
    return names + (["offset"] if reading == "absolute" else [])


def nonlinear_names(unknowns: int) -> list[str]:
    """The identified nonlinear parameters, in order: [decay_rate[, coefficient]].

    Parameters
    ----------
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).

    Returns
    -------
    list of str
        Their names (empty for 2 unknowns).
    """
    return [name for name in UNKNOWN_SETS[unknowns] if name in NONLINEAR]


def parameter_order(unknowns: int, reading: str) -> tuple:
    """Identified parameters in covariance order: linear ones first, then lambda, B.

    Parameters
    ----------
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c with an unknown offset c.

    Returns
    -------
    tuple of str
        Their names.
    """
    return tuple(linear_names(unknowns, reading) + nonlinear_names(unknowns))


def design(time, decay_rate, coefficient, unknowns: int, reading: str, derivatives: bool = True):
    """Columns of the linear parameters and their derivatives w.r.t. lambda and B.

    Returns ``(phi, d_lam, d_b, names)``, arrays (n, p) and the linear
    parameters' names in column order (zeros for the derivatives without
    ``derivatives``).

    Parameters
    ----------
    time : array_like of shape (n,)
        Times since release, s.
    decay_rate : float
        lambda, 1/s (> 0).
    coefficient : float
        B = H_m Omega_h / J, 1/s^2 (> 0).
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c with an unknown offset c.
    derivatives : bool
        Also compute the derivatives w.r.t. lambda and B.

    Returns
    -------
    phi : ndarray of shape (n, p)
        Model columns of the linear parameters, rad per unit of each: plain numbers for alpha0 and the
        offset, s for alpha0_dot, s^2 for the specific torque.
    d_lam, d_b : ndarray of shape (n, p)
        d phi / d lambda (phi's unit times s) and d phi / d B (times s^2).
    names : list of str
        The linear parameters' names, in column order (:func:`linear_names`).

    Raises
    ------
    InvalidParameter
        lambda or B not finite and positive.
    """
    check_decay_rate(decay_rate)
    check_positive(coefficient, "B", "1/s^2")
    time = np.asarray(time, dtype=float)
    phi, d_lam, d_b, names = design_columns(time, float(decay_rate), float(coefficient), unknowns, reading,
                                            derivatives)
    if not derivatives:
        d_lam = d_b = np.zeros_like(phi)
    return phi, d_lam, d_b, names


def design_columns(time, decay_rate: float, coefficient: float, unknowns: int, reading: str, derivatives: bool):
    """The arithmetic of :func:`design` for validated float parameters, without its checks.

    For the least-squares fit's inner loop, which validates once. Returns
    ``(phi, d_lam, d_b, names)``; ``d_lam`` and ``d_b`` are None without ``derivatives``.

    Parameters
    ----------
    time : ndarray of shape (n,)
        Times since release, s.
    decay_rate : float
        lambda, 1/s (> 0, not checked).
    coefficient : float
        B, 1/s^2 (> 0, not checked).
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c with an unknown offset c.
    derivatives : bool
        Also compute the derivatives w.r.t. lambda and B.

    Returns
    -------
    phi, d_lam, d_b, names
        As :func:`design`.
    """
    torque = unknowns == 5
    angle, d_lam, d_b = basis_columns(time, decay_rate, coefficient, torque, derivatives)
    names = linear_names(unknowns, reading)
    angle[0] = angle[0] - 1.0 if reading == "relative" else angle[0]
    if reading == "absolute":
        # the offset's column is 1 and does not depend on lambda or B
        angle.append(np.ones(time.size))
        if derivatives:
            d_lam.append(np.zeros(time.size))
            d_b.append(np.zeros(time.size))
    phi = np.column_stack(angle)
    if not derivatives:
        return phi, None, None, names
    return phi, np.column_stack(d_lam), np.column_stack(d_b), names


@dataclass(frozen=True)
class Fit:
    """A fitted model in SI: every parameter's value, the covariance of the identified ones.

    Attributes
    ----------
    values : dict
        alpha0 (rad), alpha0_dot (rad/s), decay_rate (1/s), coefficient (1/s^2),
        specific_torque (rad/s^2), offset (rad): identified or known.
    names : tuple of str
        The identified parameters, in the order of ``covariance``.
    covariance : ndarray (p, p) or None
        From the Jacobian and the residual; None when n == p (no residual dof).
    misfit : float
        Sum of squared residuals, rad^2.
    residuals : ndarray
        observed - model, rad.
    nfev : int
        Model evaluations (closed form; a grid counts one per cell).
    converged : bool
        The method reported success.
    message : str
        The method's termination message.
    """

    values: dict
    names: tuple
    covariance: np.ndarray | None
    misfit: float
    residuals: np.ndarray
    nfev: int
    converged: bool
    message: str


def unscaled_covariance(jacobian, unknowns: int) -> np.ndarray:
    """(J^T J)^-1 from the full Jacobian J (n, p) by a column-scaled SVD.

    Parameters
    ----------
    jacobian : ndarray of shape (n, p)
        d model / d parameters (:func:`full_jacobian`), rad per each parameter's SI unit.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).

    Returns
    -------
    ndarray of shape (p, p)
        (J^T J)^-1, in the products of the parameters' SI units per rad^2.

    Raises
    ------
    IdentificationError
        When J is (numerically) rank deficient: the unknowns are not
        identifiable from this record.
    """
    scale = np.linalg.norm(jacobian, axis=0)
    if np.any(scale == 0.0):
        raise IdentificationError("the record does not depend on every unknown: not identifiable")
    _, singular, vt = np.linalg.svd(jacobian / scale, full_matrices=False)
    # a column-scaled condition number above 1e6 amplifies the read-out noise a
    # million-fold: the unknowns are not separately identifiable (the source's
    # 200 s record gives about 15, a 60 s record with 5 unknowns about 150)
    if singular[-1] < 1e-6 * singular[0]:
        raise IdentificationError(
            f"the {unknowns} unknowns are not identifiable from this record (Jacobian rank deficient)"
        )
    return (vt.T / singular**2) @ vt / np.outer(scale, scale)


def covariance(jacobian, observed_residuals, unknowns):
    """cov = s^2 (J^T J)^-1 from the full Jacobian J (n, p) and the residuals.

    None when n == p (no residual degrees of freedom). Raises IdentificationError
    as :func:`unscaled_covariance`.

    Parameters
    ----------
    jacobian : ndarray of shape (n, p)
        d model / d parameters, rad per each parameter's SI unit.
    observed_residuals : ndarray of shape (n,)
        observed - model, rad.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).

    Returns
    -------
    ndarray of shape (p, p) or None
        Covariance of the identified parameters, SI (products of their units).
    """
    n, p = jacobian.shape
    inverse = unscaled_covariance(jacobian, unknowns)
    if n == p:
        return None
    return float(observed_residuals @ observed_residuals) / (n - p) * inverse


def full_jacobian(time, values, unknowns, reading):
    """d model / d (identified parameters), shape (n, p), columns in ``names`` order.

    Parameters
    ----------
    time : array_like of shape (n,)
        Times since release, s.
    values : dict of str to float
        Every parameter's value, SI (:class:`Fit`): ``decay_rate`` (1/s), ``coefficient`` (1/s^2) and the
        linear ones (rad, rad/s, rad/s^2).
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c with an unknown offset c.

    Returns
    -------
    ndarray of shape (n, p)
        Columns in :func:`parameter_order`, rad per each parameter's SI unit.
    """
    phi, d_lam, d_b, linear = design(time, values["decay_rate"], values["coefficient"], unknowns, reading)
    return jacobian_from_design(phi, d_lam, d_b, np.array([values[name] for name in linear]), unknowns)


def jacobian_from_design(phi, d_lam, d_b, coefficients, unknowns):
    """Full Jacobian: the linear columns, then d model / d lambda and d model / d B if identified.

    Parameters
    ----------
    phi : ndarray of shape (n, q)
        Columns of the linear parameters (:func:`design`), rad per unit of each.
    d_lam, d_b : ndarray of shape (n, q)
        Their derivatives w.r.t. lambda (times s) and B (times s^2).
    coefficients : ndarray of shape (q,)
        Values of the linear parameters, SI (rad, rad/s[, rad/s^2][, rad]).
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (:data:`UNKNOWN_SETS`).

    Returns
    -------
    ndarray of shape (n, p)
        Columns in :func:`parameter_order`: d model / d lambda in rad s, d model / d B in rad s^2.
    """
    columns = [phi[:, k] for k in range(phi.shape[1])]
    for name in nonlinear_names(unknowns):
        columns.append((d_lam if name == "decay_rate" else d_b) @ coefficients)
    return np.column_stack(columns)
