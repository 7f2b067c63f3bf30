"""Identification of north (and the run-down parameters) from the observed azimuth motion.

The observations are y_k at times t_k, either the coordinate the instrument sees,
alpha(t) - alpha0 (``reading="relative"``, source 004, eq. (10)), or absolute
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

The fit is nonlinear least squares by variable projection (Golub and Pereyra): for
given (lambda, B) the linear parameters are solved exactly by QR, and
Levenberg-Marquardt (MINPACK's lmder, through scipy ``leastsq``) minimises the
projected residual over ln(lambda) and ln(B), with the exact Golub-Pereyra Jacobian
built from the closed-form derivatives of the Bessel basis. The start needs no
grid: lambda and B come from a linear regression on the twice-integrated equation
of motion (:func:`initial_estimate`); the instrument's nominal values are a second
start, and the better of the two fits is kept.

Standard errors come from the full Jacobian J at the optimum and the residual:
cov = s^2 (J^T J)^-1 with s^2 = misfit / (n - p).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from scipy.linalg.lapack import dgeqrf, dorgqr, dtrtrs
from scipy.optimize import leastsq

from schuler.exceptions import IdentificationError, InvalidParameter
from schuler.ground_gyrocompass.motion import basis_columns, check_decay_rate, check_positive, directive_coefficient
from schuler.results import Result

UNKNOWN_SETS = {
    2: ("alpha0", "alpha0_dot"),
    3: ("alpha0", "alpha0_dot", "decay_rate"),
    4: ("alpha0", "alpha0_dot", "decay_rate", "coefficient"),
    5: ("alpha0", "alpha0_dot", "decay_rate", "coefficient", "specific_torque"),
}
"""Unknowns identified for each count (the source's 2, 3, 4; and 5 with the torque)."""

READINGS = ("relative", "absolute")


def check_record(time, observed, unknowns: int, reading: str = "relative"):
    """Validate an observation record and the requested fit; return float arrays.

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


def design(time, decay_rate, coefficient, unknowns: int, reading: str, derivatives: bool = True):
    """Columns of the linear parameters and their derivatives w.r.t. lambda and B.

    Returns ``(phi, d_decay_rate, d_coefficient, names)``, arrays (n, p) and the
    linear parameters' names in column order (zeros for the derivatives without
    ``derivatives``).
    """
    check_decay_rate(decay_rate)
    check_positive(coefficient, "B", "1/s^2")
    time = np.asarray(time, dtype=float)
    phi, d_lam, d_b, names = _design(time, float(decay_rate), float(coefficient), unknowns, reading, derivatives)
    if not derivatives:
        d_lam = d_b = np.zeros_like(phi)
    return phi, d_lam, d_b, names


def _design(time, decay_rate, coefficient, unknowns, reading, derivatives):
    """:func:`design` for validated float parameters (d_lam, d_b are None without ``derivatives``)."""
    torque = unknowns == 5
    angle, d_lam, d_b = basis_columns(time, decay_rate, coefficient, torque, derivatives)
    names = ["alpha0", "alpha0_dot"] + (["specific_torque"] if torque else [])
    angle[0] = angle[0] - 1.0 if reading == "relative" else angle[0]
    if reading == "absolute":
        # the offset's column is 1 and does not depend on lambda or B
        angle.append(np.ones(time.size))
        if derivatives:
            d_lam.append(np.zeros(time.size))
            d_b.append(np.zeros(time.size))
        names.append("offset")
    phi = np.column_stack(angle)
    if not derivatives:
        return phi, None, None, names
    return phi, np.column_stack(d_lam), np.column_stack(d_b), names


def _householder(matrix):
    """Thin QR factors (Q (n, p), R (p, p) in its upper triangle) of a tall matrix.

    LAPACK's Householder QR directly (what numpy.linalg.qr calls), without numpy's
    per-call overhead, which at a few columns costs more than the arithmetic; the
    triangular solves read only the upper triangle of R.
    """
    packed, tau, _, _ = dgeqrf(matrix)
    q, _, _ = dorgqr(packed, tau)
    return q, packed[: matrix.shape[1]]


def _solve_triangular(r, rhs, transpose=False):
    """Solve R x = rhs (or R^T x = rhs) with R the upper triangle of ``r`` (LAPACK dtrtrs)."""
    solution, info = dtrtrs(r, rhs, lower=0, trans=int(transpose))
    if info > 0:
        raise IdentificationError("the record does not depend on every linear unknown: not identifiable")
    return solution


def _cumulative_trapezoid(values, time_steps):
    """Running trapezoid integral from the first sample of each column of ``values`` (n, k)."""
    integral = np.empty_like(values)
    integral[0] = 0.0
    np.cumsum(0.5 * (values[1:] + values[:-1]) * time_steps[:, None], axis=0, out=integral[1:])
    return integral


def initial_estimate(time, observed):
    """Start values of (lambda, B) from a linear regression, no grid (1/s, 1/s^2).

    Integrating alpha'' = -B exp(-lambda t) alpha + m twice and writing
    -B exp(-lambda t) ~ a0 + a1 t + a2 t^2 + a3 t^3 gives an equation linear in the
    a_k, the initial rate and polynomial terms (which absorb alpha0, m and any
    offset): y(t) = c0 + c1 t + sum_k a_k int int s^k y + sum_j c_j t^j. Its least
    squares solution gives q(t) = -sum a_k t^k ~ B exp(-lambda t), and a straight
    line through ln q(t) gives lambda and B (about 0.3 % off on the source's case;
    the nonlinear fit then converges in a few iterations).

    Returns None when the regression gives no usable values (too short or too
    noisy a record).

    Examples
    --------
    >>> from schuler.ground_gyrocompass.motion import closed_form
    >>> t = np.arange(0.0, 201.0)
    >>> y = closed_form(t, 0.02, 4e-4, 2.15e-3, 0.0135849) - 0.02
    >>> lam, b = initial_estimate(t, y)
    >>> bool(abs(lam / 2.15e-3 - 1) < 0.01 and abs(b / 0.0135849 - 1) < 0.01)
    True
    """
    span = time[-1]
    if span <= 0.0 or time.size < 12:
        return None
    tau = time / span  # scaled time keeps the polynomial columns well conditioned
    powers = np.vander(tau, 6, increasing=True)
    steps = np.diff(time)
    twice = _cumulative_trapezoid(_cumulative_trapezoid(powers[:, :4] * observed[:, None], steps), steps)
    matrix = np.hstack([powers[:, :2], twice, powers[:, 2:]])
    norms = np.linalg.norm(matrix, axis=0)
    if np.any(norms == 0.0):
        return None
    matrix /= norms
    # QR is a third of the cost of lstsq's SVD; the two agree to round-off unless
    # the columns are nearly dependent, where lstsq's minimum-norm answer is kept
    q_factor, r_factor = _householder(matrix)
    diagonal = np.abs(np.diag(r_factor))
    if diagonal.min() > 1e-10 * diagonal.max():
        solution = _solve_triangular(r_factor, q_factor.T @ observed) / norms
    else:  # (nearly) dependent columns: the minimum-norm solution
        solution = np.linalg.lstsq(matrix, observed, rcond=None)[0] / norms
    q = -(powers[:, :4] @ solution[2:6])
    usable = q > 0.0
    if np.count_nonzero(usable) < 3:
        return None
    # straight line ln q = intercept + slope t, by the centred normal equation (two unknowns)
    line_time = time[usable] - time[usable].mean()
    log_q = np.log(q[usable])
    slope = (line_time @ log_q) / (line_time @ line_time)
    intercept = log_q.mean() - slope * time[usable].mean()
    decay_rate, coefficient = -slope, math.exp(intercept)
    if not (0.0 < decay_rate < 10.0 / span and math.isfinite(coefficient) and coefficient > 0.0):
        return None
    return decay_rate, coefficient


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
    """

    values: dict
    names: tuple
    covariance: np.ndarray | None
    misfit: float
    residuals: np.ndarray
    nfev: int
    converged: bool
    message: str


def covariance(jacobian, observed_residuals, unknowns):
    """cov = s^2 (J^T J)^-1 from the full Jacobian J (n, p) and the residuals (column-scaled SVD).

    Raises IdentificationError when J is (numerically) rank deficient: the unknowns
    are not identifiable from this record.
    """
    n, p = jacobian.shape
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
    if n == p:
        return None
    variance = float(observed_residuals @ observed_residuals) / (n - p)
    inverse = (vt.T / singular**2) @ vt
    return variance * inverse / np.outer(scale, scale)


def full_jacobian(time, values, unknowns, reading):
    """d model / d (identified parameters), shape (n, p), columns in ``names`` order."""
    phi, d_lam, d_b, linear = design(time, values["decay_rate"], values["coefficient"], unknowns, reading)
    return jacobian_from_design(phi, d_lam, d_b, np.array([values[name] for name in linear]), unknowns)


def jacobian_from_design(phi, d_lam, d_b, coefficients, unknowns):
    """Full Jacobian: the linear columns, then d model / d lambda and d model / d B if identified."""
    columns = [phi[:, k] for k in range(phi.shape[1])]
    nonlinear = [name for name in UNKNOWN_SETS[unknowns] if name in ("decay_rate", "coefficient")]
    for name in nonlinear:
        columns.append((d_lam if name == "decay_rate" else d_b) @ coefficients)
    return np.column_stack(columns)


def parameter_order(unknowns: int, reading: str) -> tuple:
    """Identified parameters in covariance order: linear ones first, then lambda, B."""
    linear = ["alpha0", "alpha0_dot"] + (["specific_torque"] if unknowns == 5 else [])
    if reading == "absolute":
        linear.append("offset")
    nonlinear = [name for name in UNKNOWN_SETS[unknowns] if name in ("decay_rate", "coefficient")]
    return tuple(linear + nonlinear)


class _Projected:
    """Projected residual r(x) and its Golub-Pereyra Jacobian, x = ln of the nonlinear parameters.

    The caller validates the record and the parameters once; lambda = exp(x) and
    B = exp(x) stay positive, so the evaluations skip the checks (at a few hundred
    samples they would cost as much as the Bessel functions).
    """

    def __init__(self, time, observed, unknowns, reading, decay_rate, coefficient):
        self.time, self.observed, self.unknowns, self.reading = time, observed, unknowns, reading
        self.known = {"decay_rate": float(decay_rate), "coefficient": float(coefficient)}
        self.free = [n for n in UNKNOWN_SETS[unknowns] if n in ("decay_rate", "coefficient")]
        # the last two points evaluated: MINPACK asks for the residual and then the
        # Jacobian at the same x, and the fit ends with the covariance at the best
        # point, usually the one before MINPACK's last (rejected or tiny) trial step
        self._recent = []
        self.evaluations = 0

    def parameters(self, x):
        values = dict(self.known)
        for name, value in zip(self.free, x):
            values[name] = math.exp(value)
        return values

    def evaluate(self, x):
        """(residual, Jacobian in x, linear coefficients, their names, parameters, (phi, d_lam, d_b)) at x."""
        key = np.asarray(x, dtype=float).tobytes()
        for recent_key, recent in self._recent:
            if recent_key == key:
                return recent
        values = self.parameters(x)
        phi, d_lam, d_b, names = _design(
            self.time, values["decay_rate"], values["coefficient"], self.unknowns, self.reading, True
        )
        self.evaluations += 1
        q, r = _householder(phi)
        coefficients = _solve_triangular(r, q.T @ self.observed)
        residual = self.observed - phi @ coefficients
        jacobian = None
        if self.free:
            derivatives = [d_lam if name == "decay_rate" else d_b for name in self.free]
            # Golub-Pereyra: dr/dtheta = -(P_perp D c + Q R^-T D^T r), P_perp = I - Q Q^T;
            # all free parameters in one pass (one triangular solve with several right sides)
            a = np.column_stack([derivative @ coefficients for derivative in derivatives])
            rhs = np.column_stack([derivative.T @ residual for derivative in derivatives])
            scale = np.array([values[name] for name in self.free])  # chain rule for the ln parameters
            jacobian = -(a + q @ (_solve_triangular(r, rhs, transpose=True) - q.T @ a)) * scale
        result = (residual, jacobian, coefficients, names, values, (phi, d_lam, d_b))
        self._recent = [self._recent[-1], (key, result)] if self._recent else [(key, result)]
        return result

    def residual(self, x):
        return self.evaluate(x)[0]

    def jacobian(self, x):
        return self.evaluate(x)[1]


TERMINATION = {
    1: "`ftol` termination condition is satisfied.",
    2: "`xtol` termination condition is satisfied.",
    3: "Both `ftol` and `xtol` termination conditions are satisfied.",
    4: "`gtol` termination condition is satisfied.",
}
"""MINPACK lmder's successful exit codes. Its codes 6-8 (a tolerance below machine
precision) cannot occur with tolerances >= 2.2e-16; 5 is the evaluation limit."""

MAXIMUM_EVALUATIONS = "The maximum number of function evaluations is exceeded."


def _close(first, second, tolerance):
    return all(abs(a / b - 1.0) <= tolerance for a, b in zip(first, second))


def fit_least_squares(time, observed, unknowns, decay_rate, coefficient, reading="relative", start=None) -> Fit:
    """Variable-projection least squares fit of 2, 3, 4 or 5 unknowns.

    Parameters
    ----------
    time : ndarray
        Sample times since release, s (increasing, >= 0).
    observed : ndarray
        Observed coordinate, rad: alpha - alpha0 (relative) or alpha + c (absolute).
    unknowns : {2, 3, 4, 5}
        See :data:`UNKNOWN_SETS`.
    decay_rate, coefficient : float
        lambda (1/s) and B (1/s^2): the known values, and the nominal start of the
        unknown ones.
    reading : {"relative", "absolute"}
    start : (float, float), optional
        (lambda, B) start; by default :func:`initial_estimate` and the nominal values
        (both are descended from, and the better fit kept, unless they agree within 5 %).

    Examples
    --------
    >>> from schuler.ground_gyrocompass.motion import closed_form
    >>> t = np.arange(0.0, 201.0)
    >>> y = closed_form(t, 0.0215, 4.08e-4, 2.15e-3, 0.0135849) - 0.0215
    >>> fit = fit_least_squares(t, y, 4, 2.0e-3, 0.013)
    >>> round(fit.values["alpha0"], 10), round(fit.values["decay_rate"], 12)
    (0.0215, 0.00215)
    """
    time, observed = check_record(time, observed, unknowns, reading)
    check_decay_rate(decay_rate)
    check_positive(coefficient, "B", "1/s^2")
    problem = _Projected(time, observed, unknowns, reading, decay_rate, coefficient)
    best = None
    if problem.free:
        if start is not None:
            check_decay_rate(start[0], "start lambda")
            check_positive(start[1], "start B", "1/s^2")
            starts = [start]
        else:
            estimate = initial_estimate(time, observed)
            starts = [estimate, (decay_rate, coefficient)]
            if estimate is not None and _close(estimate, (decay_rate, coefficient), 0.05):
                starts = [estimate]  # both starts in one basin: a second descent adds nothing
        for guess in starts:
            if guess is None:
                continue
            x0 = np.log([guess[0] if name == "decay_rate" else guess[1] for name in problem.free])
            if not np.all(np.isfinite(problem.residual(x0))):
                raise IdentificationError("the model is not finite at the start values (lambda t too large?)")
            # tight tolerances: a noise-free record is fitted to round-off (1e-9 relative
            # is required); Levenberg-Marquardt converges quadratically near a zero residual.
            # leastsq runs the same MINPACK lmder with the same defaults (diag from the
            # Jacobian's column norms, factor 100) as least_squares(method="lm"), so the
            # iterates are identical, at a fraction of least_squares' per-call overhead
            solution, _, info, _, status = leastsq(
                problem.residual, x0, Dfun=problem.jacobian, full_output=True, xtol=1e-15, ftol=1e-15,
                gtol=1e-15, maxfev=200,
            )
            cost = float(info["fvec"] @ info["fvec"])
            if best is None or cost < best[0]:
                best = (cost, solution, status)
        x, status = best[1], best[2]
        converged, message = status in TERMINATION, TERMINATION.get(status, MAXIMUM_EVALUATIONS)
    else:
        x, converged, message = [], True, "linear least squares (2x2 normal equations, eq. (10))"
    residual, _, coefficients, names, values, columns = problem.evaluate(np.asarray(x, dtype=float))
    values = {"specific_torque": 0.0, "offset": 0.0, **values}
    values.update({name: float(value) for name, value in zip(names, coefficients)})
    order = parameter_order(unknowns, reading)
    cov = covariance(jacobian_from_design(*columns, coefficients, unknowns), residual, unknowns)
    return Fit(values, order, cov, float(residual @ residual), residual, problem.evaluations, converged, message)


# ---------------------------------------------------------------- the result people see


def _dms(angle_deg: float) -> str:
    sign = "-" if angle_deg < 0 else "+"
    seconds = round(abs(angle_deg) * 3600.0, 2)
    degrees, rest = divmod(seconds, 3600.0)
    minutes, seconds = divmod(rest, 60.0)
    return f"{sign}{int(degrees)}°{int(minutes):02d}′{seconds:05.2f}″"


@dataclass
class NorthEstimate(Result):
    """Identified north and run-down parameters, with standard errors (SI unless named).

    ``north_deg`` is the azimuth of north measured from the rotor axis at release,
    = -alpha0. JSON keys ``lambda``/``lambda_std`` hold ``decay_rate``.
    """

    unknowns: int
    method: str
    reading: str
    identified: list
    north_deg: float
    north_std_arcsec: float | None
    north_dms: str
    alpha0_rad: float
    alpha0_rad_std: float | None
    alpha0_dot: float
    alpha0_dot_std: float | None
    decay_rate: float
    decay_rate_std: float | None
    B: float
    B_std: float | None
    Hm: float
    Hm_std: float | None
    torque: float
    torque_std: float | None
    offset_rad: float | None
    offset_rad_std: float | None
    misfit: float
    residual_rms_arcsec: float
    n_samples: int
    nfev: int
    converged: bool
    message: str
    inertia: float
    omega_h: float
    correlation: dict
    time: np.ndarray = field(repr=False, default=None)
    observed: np.ndarray = field(repr=False, default=None)
    residuals: np.ndarray = field(repr=False, default=None)

    units: ClassVar[dict] = {
        "alpha0_dot": "rad/s",
        "alpha0_dot_std": "rad/s",
        "lambda": "1/s",
        "lambda_std": "1/s",
        "B": "1/s^2",
        "B_std": "1/s^2",
        "Hm": "N m s",
        "Hm_std": "N m s",
        "torque": "N m",
        "torque_std": "N m",
        "misfit": "rad^2",
        "inertia": "kg m^2",
        "omega_h": "rad/s",
    }
    json_names: ClassVar[dict] = {"decay_rate": "lambda", "decay_rate_std": "lambda_std"}

    def to_dict(self):
        data = super().to_dict()
        return {self.json_names.get(key, key): value for key, value in data.items()}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        std = self.north_std_arcsec
        north = Table(title=f"North from the ground gyrocompass ({self.unknowns} unknowns, {self.method})")
        north.add_column("quantity")
        north.add_column("value", justify="right")
        north.add_column("standard error", justify="right")
        north.add_row("north from the rotor axis", f"{self.north_deg:.6f} deg", _std(std, 1 / 3600, "deg", ".2g"))
        north.add_row("", f"{self.north_deg * 60:.4f} arcmin", _std(std, 1 / 60, "arcmin", ".2g"))
        north.add_row("", f"{self.north_deg * 3600:.2f} arcsec", _std(std, 1.0, "arcsec", ".2g"))
        north.add_row("", self.north_dms, "")
        rows = [
            ("alpha0", self.alpha0_rad, self.alpha0_rad_std, "rad"),
            ("alpha0_dot", self.alpha0_dot, self.alpha0_dot_std, "rad/s"),
            ("lambda", self.decay_rate, self.decay_rate_std, "1/s"),
            ("B = Hm Omega_h / J", self.B, self.B_std, "1/s^2"),
            ("Hm", self.Hm, self.Hm_std, "N m s"),
            ("harmful torque", self.torque, self.torque_std, "N m"),
        ]
        if self.offset_rad is not None:
            rows.append(("reading offset", self.offset_rad, self.offset_rad_std, "rad"))
        params = Table(title="Parameters (known ones without standard error)")
        params.add_column("parameter")
        params.add_column("value", justify="right")
        params.add_column("standard error", justify="right")
        for name, value, error, unit in rows:
            params.add_row(name, f"{value:.10g} {unit}", "" if error is None else f"{error:.3g} {unit}")
        summary = (
            f"misfit {self.misfit:.4g} rad^2 over {self.n_samples} samples "
            f"(rms {self.residual_rms_arcsec:.3g} arcsec), {self.nfev} model evaluations; {self.message}"
        )
        return Group(north, params, summary)


def _std(std_arcsec, factor, unit, fmt):
    return "" if std_arcsec is None else f"{std_arcsec * factor:{fmt}} {unit}"


def make_estimate(fit: Fit, time, observed, unknowns, reading, method, inertia, omega_h) -> NorthEstimate:
    """Turn a :class:`Fit` into the user-facing :class:`NorthEstimate`."""
    values = fit.values
    errors = {}
    correlation = {"parameters": list(fit.names), "matrix": None}
    if fit.covariance is not None:
        errors = dict(zip(fit.names, np.sqrt(np.diag(fit.covariance))))
        scale = np.sqrt(np.diag(fit.covariance))
        with np.errstate(invalid="ignore", divide="ignore"):
            matrix = fit.covariance / np.outer(scale, scale)
        correlation["matrix"] = np.where(np.isfinite(matrix), matrix, 0.0)

    def err(name, factor=1.0):
        if name not in fit.names or fit.covariance is None:
            return None
        return float(errors[name] * factor)

    hm_per_b = inertia / omega_h
    alpha0_std = err("alpha0")
    return NorthEstimate(
        unknowns=unknowns,
        method=method,
        reading=reading,
        identified=list(fit.names),
        north_deg=math.degrees(-values["alpha0"]),
        north_std_arcsec=None if alpha0_std is None else math.degrees(alpha0_std) * 3600.0,
        north_dms=_dms(math.degrees(-values["alpha0"])),
        alpha0_rad=values["alpha0"],
        alpha0_rad_std=alpha0_std,
        alpha0_dot=values["alpha0_dot"],
        alpha0_dot_std=err("alpha0_dot"),
        decay_rate=values["decay_rate"],
        decay_rate_std=err("decay_rate"),
        B=values["coefficient"],
        B_std=err("coefficient"),
        Hm=values["coefficient"] * hm_per_b,
        Hm_std=err("coefficient", hm_per_b),
        torque=values["specific_torque"] * inertia,
        torque_std=err("specific_torque", inertia),
        offset_rad=values["offset"] if reading == "absolute" else None,
        offset_rad_std=err("offset"),
        misfit=fit.misfit,
        residual_rms_arcsec=math.degrees(math.sqrt(fit.misfit / len(time))) * 3600.0,
        n_samples=len(time),
        nfev=fit.nfev,
        converged=fit.converged,
        message=fit.message,
        inertia=inertia,
        omega_h=omega_h,
        correlation=correlation,
        time=np.asarray(time),
        observed=np.asarray(observed),
        residuals=fit.residuals,
    )


def identify(
    time, observed, unknowns: int = 4, *, decay_rate, hm, inertia, omega_h, reading="relative", method="lsq"
) -> NorthEstimate:
    """Identify north from an observed run-down record (source 004, eqs. (9)-(10)).

    Parameters
    ----------
    time : ndarray
        Sample times since release, s.
    observed : ndarray
        Observed coordinate, rad (alpha - alpha0 for ``reading="relative"``).
    unknowns : {2, 3, 4, 5}
        Parameters to identify (:data:`UNKNOWN_SETS`).
    decay_rate : float
        lambda, 1/s: known (2 unknowns) or nominal start / grid centre.
    hm : float
        H_m, N m s: known (2, 3 unknowns) or nominal.
    inertia : float
        J, kg m^2 (known: only B = H_m Omega_h / J is identifiable).
    omega_h : float
        Omega_h, rad/s (known; e.g. from the latitude).
    reading : {"relative", "absolute"}
    method : {"lsq", "grid"}
        Variable-projection least squares, or the source's three-stage grid
        refinement (:func:`schuler.ground_gyrocompass.grid.identify_grid`).

    Returns
    -------
    NorthEstimate

    Examples
    --------
    >>> from schuler.ground_gyrocompass.motion import closed_form
    >>> t = np.arange(0.0, 201.0)
    >>> b = 0.432 * 3.65e-5 / 1.1607e-3  # B = Hm Omega_h / J
    >>> y = closed_form(t, 0.0215, 4.08e-4, 2.15e-3, b) - 0.0215
    >>> est = identify(t, y, 2, decay_rate=2.15e-3, hm=0.432, inertia=1.1607e-3, omega_h=3.65e-5)
    >>> round(est.north_deg, 6), round(math.degrees(-0.0215), 6)
    (-1.231859, -1.231859)
    """
    coefficient = float(directive_coefficient(hm, omega_h, inertia))
    check_decay_rate(decay_rate)
    if method == "lsq":
        fit = fit_least_squares(time, observed, unknowns, decay_rate, coefficient, reading)
    elif method == "grid":
        from schuler.ground_gyrocompass.grid import identify_grid

        fit = identify_grid(time, observed, unknowns, decay_rate, coefficient, reading)
    else:
        raise InvalidParameter("method", f"{method!r} is not one of lsq, grid")
    return make_estimate(fit, time, observed, unknowns, reading, method, inertia, omega_h)
