"""North by variable-projection least squares: the estimator ``schuler north identify`` runs.

The fit is nonlinear least squares by variable projection (Golub and Pereyra):
for given (lambda, B) the linear parameters (:mod:`.problem`) are solved exactly
by QR, and Levenberg-Marquardt (MINPACK's lmder, through scipy ``leastsq``)
minimises the projected residual over ln(lambda) and ln(B), with the exact
Golub-Pereyra Jacobian built from the closed-form derivatives of the Bessel
basis. The start needs no grid: lambda and B come from a linear regression on the
twice-integrated equation of motion (:func:`initial_estimate`); the instrument's
nominal values are a second start, and the better of the two fits is kept. With
2 unknowns (lambda and B known) the problem is linear and one QR solves it.

:func:`fit_least_squares` fits one record; :func:`fit_records` fits many records
sampled at the same times with the same code (the Monte Carlo's entry), sharing
one factorisation across records where the problem is linear.

References
----------
G. H. Golub and V. Pereyra, "The differentiation of pseudo-inverses and nonlinear
least squares problems whose variables separate", SIAM Journal on Numerical
Analysis 10(2), 1973, pp. 413-432.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.linalg.lapack import dgeqrf, dorgqr, dtrtrs
from scipy.optimize import leastsq

from schuler.exceptions import IdentificationError, InvalidParameter
from schuler.ground_gyrocompass.motion import check_decay_rate, check_positive
from schuler.ground_gyrocompass.problem import (
    Fit,
    check_record,
    covariance,
    design_columns,
    jacobian_from_design,
    nonlinear_names,
    parameter_order,
    unscaled_covariance,
)


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

    Parameters
    ----------
    time : ndarray of shape (n,)
        Sample times since release, s (increasing, >= 0; validated by the caller).
    observed : ndarray of shape (n,)
        Observed coordinate, rad (relative or absolute: the polynomial terms absorb the offset).

    Returns
    -------
    (float, float) or None
        lambda (1/s) and B (1/s^2), or None (fewer than 12 samples, or no usable regression).

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
    with np.errstate(over="ignore"):  # an overflow is refused just below
        decay_rate, coefficient = -slope, float(np.exp(intercept))
    if not (0.0 < decay_rate < 10.0 / span and math.isfinite(coefficient) and coefficient > 0.0):
        return None
    return decay_rate, coefficient


class _Projected:
    """Projected residual r(x) and its Golub-Pereyra Jacobian, x = ln of the nonlinear parameters (3-5 unknowns).

    The caller validates the record and the parameters once; lambda = exp(x) and
    B = exp(x) stay positive, so the evaluations skip the checks (at a few hundred
    samples they would cost as much as the Bessel functions).
    """

    def __init__(self, time, observed, unknowns, reading, decay_rate, coefficient):
        self.time, self.observed, self.unknowns, self.reading = time, observed, unknowns, reading
        self.known = {"decay_rate": float(decay_rate), "coefficient": float(coefficient)}
        self.free = nonlinear_names(unknowns)
        # the last two points evaluated: MINPACK asks for the residual and then the
        # Jacobian at the same x, and the fit ends with the covariance at the best
        # point, usually the one before MINPACK's last (rejected or tiny) trial step
        self._recent = []
        self.evaluations = 0
        # longer than any projected residual (whose norm is at most |observed|): see residual()
        self._outside = np.full(observed.size, 2.0 * (float(np.linalg.norm(observed)) + 1.0))

    def parameters(self, x):
        values = dict(self.known)
        for name, value in zip(self.free, x):
            # numpy scalars: a trial step far out overflows to inf (a rejected step), not an OverflowError
            values[name] = np.exp(np.float64(value))
        return values

    def evaluate(self, x):
        """(residual, Jacobian in x, linear coefficients, their names, parameters, (phi, d_lam, d_b)) at x."""
        key = np.asarray(x, dtype=float).tobytes()
        for recent_key, recent in self._recent:
            if recent_key == key:
                return recent
        self.evaluations += 1
        # a trial step far out (lambda t >> 1 underflows z to 0, where Y0 is -inf) gives
        # a non-finite model: silently, since residual() turns it into a rejected step
        with np.errstate(all="ignore"):
            values = self.parameters(x)
            phi, d_lam, d_b, names = design_columns(
                self.time, values["decay_rate"], values["coefficient"], self.unknowns, self.reading, True
            )
            q, r = _householder(phi)
            coefficients = _solve_triangular(r, q.T @ self.observed)
            residual = self.observed - phi @ coefficients
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
        """The projected residual for MINPACK; one longer than any projected residual where there is none.

        Far out (lambda or B underflowing or overflowing) the model is not finite,
        or its columns vanish and the linear parameters are undetermined. MINPACK
        rejects a trial step whose residual grows and shrinks its trust region, so
        such a step is retried closer in and never accepted. The start, checked
        before the descent, and the accepted points are evaluated as they are.
        """
        try:
            residual = self.evaluate(x)[0]
        except IdentificationError:
            return self._outside
        return residual if np.all(np.isfinite(residual)) else self._outside

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
        See :data:`~.problem.UNKNOWN_SETS`.
    decay_rate, coefficient : float
        lambda (1/s) and B (1/s^2): the known values, and the nominal start of the
        unknown ones.
    reading : {"relative", "absolute"}
    start : (float, float), optional
        (lambda, B) start; by default :func:`initial_estimate` and the nominal values
        (both are descended from, and the better fit kept, unless they agree within 5 %).

    Returns
    -------
    Fit

    Raises
    ------
    IdentificationError
        When the record does not determine the unknowns (rank-deficient Jacobian)
        or the model is not finite at the start.

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
    if not nonlinear_names(unknowns):
        return _linear_fits(time, observed[None, :], unknowns, decay_rate, coefficient, reading)[0]
    if start is not None:
        check_decay_rate(start[0], "start lambda")
        check_positive(start[1], "start B", "1/s^2")
    return _nonlinear_fit(time, observed, unknowns, decay_rate, coefficient, reading, start)


def fit_records(time, records, unknowns, decay_rate, coefficient,
                reading="relative") -> Sequence[Fit | IdentificationError]:
    """:func:`fit_least_squares` from its default start for many records sampled at the same times.

    The same estimator, record by record, as ``schuler north identify`` runs it,
    so a Monte Carlo over these fits sees the users' failures. What the records
    share is done once: the checks of the time grid and, with 2 unknowns (a linear
    problem with the same design for every record), one QR factorisation and one
    covariance for all. MINPACK's descent is sequential, one record at a time.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    records : ndarray (N, n)
        Observed coordinates, rad, one record per row.
    unknowns : {2, 3, 4, 5}
        Number of unknowns, as in :func:`fit_least_squares` (no ``start``: the default one).
    decay_rate : float
        lambda, 1/s: known, or the nominal start.
    coefficient : float
        B, 1/s^2: known, or the nominal start.
    reading : {"relative", "absolute"}
        What the records hold: alpha - alpha0, or alpha + c.

    Returns
    -------
    list
        Per record, its :class:`~.problem.Fit`, or the
        :class:`~schuler.exceptions.IdentificationError` the estimator raised on it.

    Examples
    --------
    >>> from schuler.ground_gyrocompass.motion import closed_form
    >>> t = np.arange(0.0, 201.0)
    >>> y = closed_form(t, 0.0215, 4.08e-4, 2.15e-3, 0.0135849) - 0.0215
    >>> fits = fit_records(t, np.stack([y, 2 * y]), 2, 2.15e-3, 0.0135849)
    >>> [round(f.values["alpha0"], 10) for f in fits]
    [0.0215, 0.043]
    """
    records = np.asarray(records, dtype=float)
    if records.ndim != 2 or records.shape[0] < 1:
        raise InvalidParameter("records", f"expected an array (N, n) of records, got shape {records.shape}")
    time, _ = check_record(time, records[0], unknowns, reading)
    if not np.all(np.isfinite(records)):
        raise InvalidParameter("records", "observed angles must be finite numbers")
    check_decay_rate(decay_rate)
    check_positive(coefficient, "B", "1/s^2")
    if not nonlinear_names(unknowns):
        try:
            return _linear_fits(time, records, unknowns, decay_rate, coefficient, reading)
        except IdentificationError as error:  # the shared design: every record fails alike
            return [error] * records.shape[0]
    outcomes: list[Fit | IdentificationError] = []
    for observed in records:
        try:
            outcomes.append(_nonlinear_fit(time, observed, unknowns, decay_rate, coefficient, reading, None))
        except IdentificationError as error:
            outcomes.append(error)
    return outcomes


def _linear_fits(time, records, unknowns, decay_rate, coefficient, reading) -> list[Fit]:
    """Linear least squares of records (N, n) with lambda and B known: one QR for all of them."""
    phi, _, _, names = design_columns(time, float(decay_rate), float(coefficient), unknowns, reading, False)
    q, r = _householder(phi)
    coefficients = _solve_triangular(r, q.T @ records.T)  # (p, N): one solve, N right-hand sides
    residuals = records - (phi @ coefficients).T
    inverse = unscaled_covariance(phi, unknowns)  # the Jacobian is the design itself
    n, p = phi.shape
    known = {"decay_rate": float(decay_rate), "coefficient": float(coefficient), "specific_torque": 0.0,
             "offset": 0.0}
    order = parameter_order(unknowns, reading)
    message = "linear least squares (2x2 normal equations, eq. (10))"
    fits = []
    for k, residual in enumerate(residuals):
        misfit = float(residual @ residual)
        values = known | {name: float(value) for name, value in zip(names, coefficients[:, k])}
        cov = None if n == p else misfit / (n - p) * inverse
        fits.append(Fit(values, order, cov, misfit, residual, 1, True, message))
    return fits


def _nonlinear_fit(time, observed, unknowns, decay_rate, coefficient, reading, start) -> Fit:
    """The descent of :func:`fit_least_squares` over ln(lambda) [and ln(B)], on a validated record."""
    problem = _Projected(time, observed, unknowns, reading, decay_rate, coefficient)
    if start is not None:
        starts = [start]
    else:
        estimate = initial_estimate(time, observed)
        starts = [estimate, (decay_rate, coefficient)]
        if estimate is not None and _close(estimate, (decay_rate, coefficient), 0.05):
            starts = [estimate]  # both starts in one basin: a second descent adds nothing
    descents = []  # (cost, x, MINPACK status) from each start
    for guess in starts:
        if guess is None:
            continue
        x0 = np.log([guess[0] if name == "decay_rate" else guess[1] for name in problem.free])
        if not np.all(np.isfinite(problem.evaluate(x0)[0])):
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
        descents.append((float(info["fvec"] @ info["fvec"]), solution, status))
    _, x, status = min(descents, key=lambda descent: descent[0])  # the first of equal costs, as before
    converged, message = status in TERMINATION, TERMINATION.get(status, MAXIMUM_EVALUATIONS)
    residual, _, coefficients, names, values, (phi, d_lam, d_b) = problem.evaluate(np.asarray(x, dtype=float))
    values = {"specific_torque": 0.0, "offset": 0.0, **{name: float(value) for name, value in values.items()}}
    values.update({name: float(value) for name, value in zip(names, coefficients)})
    order = parameter_order(unknowns, reading)
    cov = covariance(jacobian_from_design(phi, d_lam, d_b, coefficients, unknowns), residual, unknowns)
    return Fit(values, order, cov, float(residual @ residual), residual, problem.evaluations, converged, message)
