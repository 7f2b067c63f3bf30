"""Accuracy against observation time: predicted standard errors, and a Monte Carlo of the estimator.

For a true motion and white read-out noise of standard deviation sigma (plus the
uniform quantisation error, variance q^2/12), the least-squares estimate of
alpha0 (hence of north, -alpha0) has the covariance sigma_eff^2 (J^T J)^-1, J being
the Jacobian of the model w.r.t. the identified parameters (see :mod:`.problem`).
:func:`predicted_errors` evaluates it for many cases at once (each with its own
window, sampling step, noise and parameters). :func:`monte_carlo` checks it with
the estimator users run, ``schuler north identify``'s variable-projection least
squares from its default start (:func:`~.varpro.fit_records`), on records made by
the same observation model as ``schuler north run`` (:func:`~.observations.observe`):
its failures are the users' failures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from schuler.core.geometry import ARCSEC, time_grid, time_grids
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.ground_gyrocompass.motion import basis, closed_form
from schuler.ground_gyrocompass.observations import observe
from schuler.ground_gyrocompass.problem import Fit, linear_names, nonlinear_names
from schuler.ground_gyrocompass.varpro import fit_records
from schuler.results import Result

GROSS_ERROR = 5.0
"""A converged fit whose north error exceeds this many predicted standard errors
counts as a gross error (a wrong minimum): Gaussian scatter exceeds 5 sigma once
in 1.7 million fits."""


def batched_model(time, values, unknowns, reading="relative"):
    """Model and Jacobian for many members at once.

    Parameters
    ----------
    time : ndarray (N, n) or (n,)
        Sample times, s.
    values : dict of ndarray (N,)
        alpha0 (rad), alpha0_dot (rad/s), decay_rate (1/s), coefficient (1/s^2),
        specific_torque (rad/s^2), offset (rad).
    unknowns : {2, 3, 4, 5}
    reading : {"relative", "absolute"}

    Returns
    -------
    model : ndarray (N, n)
        rad.
    jacobian : ndarray (N, n, p)
        Columns: linear parameters, then lambda and B (natural units).
    """
    lam = np.asarray(values["decay_rate"], dtype=float)[:, None]
    b_coef = np.asarray(values["coefficient"], dtype=float)[:, None]
    torque = unknowns == 5
    b = basis(np.asarray(time, dtype=float), lam, b_coef, torque=torque, derivatives=unknowns >= 3)
    first = b.angle[0] - 1.0 if reading == "relative" else b.angle[0]
    a0 = np.asarray(values["alpha0"], dtype=float)[:, None]
    a0d = np.asarray(values["alpha0_dot"], dtype=float)[:, None]
    m = np.asarray(values.get("specific_torque", 0.0 * a0[:, 0]), dtype=float)[:, None]
    model = a0 * first + a0d * b.angle[1] + m * b.angle[2]
    columns = [first, b.angle[1]] + ([b.angle[2]] if torque else [])
    if reading == "absolute":
        model = model + np.asarray(values["offset"], dtype=float)[:, None]
        columns.append(np.ones_like(first))
    for name in nonlinear_names(unknowns):
        derivative = b.d_decay_rate if name == "decay_rate" else b.d_coefficient
        columns.append(a0 * derivative[0] + a0d * derivative[1] + m * derivative[2])
    return model, np.stack(columns, axis=-1)


def _scaled_inverse(normal):
    scale = np.sqrt(np.einsum("...ii->...i", normal))
    inverse = np.linalg.inv(normal / (scale[..., :, None] * scale[..., None, :]))
    return inverse / (scale[..., :, None] * scale[..., None, :])


def predicted_errors(values, duration, step, noise, quantisation=0.0, unknowns=4, reading="relative"):
    """Standard errors of the identified parameters from the Jacobian, for n cases at once.

    Parameters
    ----------
    values : dict of ndarray (n,)
        True alpha0 (rad), alpha0_dot (rad/s), decay_rate (1/s), coefficient (1/s^2),
        specific_torque (rad/s^2), offset (rad).
    duration, step : ndarray (n,)
        Observation window and sampling step, s; each case is sampled on the core's
        time grid (:func:`~schuler.core.geometry.time_grid`, as the records are).
    noise, quantisation : ndarray (n,)
        Read-out noise standard deviation and resolution, rad.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified (the same for all cases).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c with an unknown offset c.

    Returns
    -------
    dict
        ``<parameter>_std`` (SI) for each identified parameter, arrays (n,).

    Raises
    ------
    InvalidParameter
        A case with fewer samples than unknowns.

    Examples
    --------
    >>> v = {"alpha0": np.array([0.0215]), "alpha0_dot": np.array([4.08e-4]),
    ...      "decay_rate": np.array([2.15e-3]), "coefficient": np.array([0.0135849])}
    >>> e = predicted_errors(v, np.array([200.0]), np.array([1.0]), np.array([5e-6]), unknowns=2)
    >>> bool(1e-7 < e["alpha0_std"][0] < 1e-6)
    True
    """
    noise, quantisation = (np.atleast_1d(np.asarray(x, dtype=float)) for x in (noise, quantisation))
    time, valid = time_grids(duration, step)
    _, jacobian = batched_model(time, values, unknowns, reading)
    jacobian = jacobian * valid[..., None]
    if np.any(valid.sum(axis=1) < jacobian.shape[-1]):
        raise InvalidParameter("duration", "fewer samples than unknowns in some case")
    covariance = _scaled_inverse(np.swapaxes(jacobian, -1, -2) @ jacobian)
    variance = noise**2 + quantisation**2 / 12.0
    names = linear_names(unknowns, reading) + nonlinear_names(unknowns)
    diagonal = np.einsum("...ii->...i", covariance)
    return {f"{name}_std": np.sqrt(variance * diagonal[:, i]) for i, name in enumerate(names)}


@dataclass
class NorthErrorStudy(Result):
    """North error against observation time and noise (Monte Carlo and predicted).

    Arrays are indexed [duration, noise]; errors in rad, over the records whose
    fit converged. ``converged_fraction`` is the share of records the estimator
    fitted (it raised on, or did not converge for, the rest);
    ``gross_error_fraction`` the share of converged fits off by more than
    :data:`GROSS_ERROR` predicted standard errors.
    """

    unknowns: int
    members: int
    step_s: float
    quantisation_rad: float
    durations_s: np.ndarray
    noises_rad: np.ndarray
    rms_error_rad: np.ndarray
    std_error_rad: np.ndarray
    mean_error_rad: np.ndarray
    predicted_std_rad: np.ndarray
    converged_fraction: np.ndarray
    gross_error_fraction: np.ndarray
    seed: int

    units: ClassVar[dict] = {}

    def render(self):
        from rich.table import Table

        table = Table(title=f"North error vs observation time ({self.unknowns} unknowns, {self.members} runs)")
        table.add_column("window, s")
        for noise in self.noises_rad / ARCSEC:
            table.add_column(f"noise {noise:g}\": MC std / predicted, arcsec", justify="right")
        for i, duration in enumerate(self.durations_s):
            cells = [
                f"{self.std_error_rad[i, j] / ARCSEC:.3g} / {self.predicted_std_rad[i, j] / ARCSEC:.3g}"
                for j in range(len(self.noises_rad))
            ]
            table.add_row(f"{duration:g}", *cells)
        return table


def _north_errors(fits, alpha0):
    """alpha0 errors (rad) of the fits that converged, and the mask of those fits."""
    ok = np.array([isinstance(fit, Fit) and fit.converged for fit in fits])
    estimates = np.array([fit.values["alpha0"] for fit, good in zip(fits, ok) if good])
    return estimates - alpha0, ok


def monte_carlo(
    truth, durations, noises, members=200, unknowns=4, step=1.0, quantisation=0.0, reading="relative", seed=0,
    nominal=None,
) -> NorthErrorStudy:
    """Monte Carlo of the north error (arcsec) versus observation time and read-out noise.

    Parameters
    ----------
    truth : dict
        alpha0 (rad), alpha0_dot (rad/s), decay_rate (1/s), coefficient (1/s^2),
        specific_torque (rad/s^2), offset (rad): the true motion.
    durations : sequence of float
        Observation windows, s (e.g. 60 ... 600).
    noises : sequence of float
        Read-out noise standard deviations, rad.
    members : int
        Number of noisy records per case (at least 2).
    unknowns : {2, 3, 4, 5}
        Number of unknowns the estimator identifies.
    step : float
        Sampling step, s.
    quantisation : float
        Read-out resolution, rad (0: none).
    reading : {"relative", "absolute"}
        The observations: alpha(t) - alpha0, or alpha(t) + c (``truth["offset"]``).
    seed : int
        Seed of the read-out noise: record k of window i and noise level j is member
        ``(i * len(noises) + j) * members + k`` of the stream ``"readout_noise"``
        (:class:`~schuler.core.random.RandomStreams`, as ``north run --monte-carlo`` draws).
    nominal : dict, optional
        The instrument's nominal ``decay_rate`` (1/s) and ``coefficient`` (1/s^2)
        handed to the estimator, as ``--lambda`` and ``--hm`` are: the known values
        for fewer unknowns, and its second start. Default: the true ones.

    Returns
    -------
    NorthErrorStudy

    Notes
    -----
    Each record is fitted by the estimator users run, from its default start
    (:func:`~.varpro.fit_records`): the study measures the scatter and the
    failures of the estimator as used, not of an idealised one started at the
    truth. Records are sampled on the core's time grid and read out by
    :func:`~.observations.observe` (noise, then quantisation).
    """
    if members < 2:
        raise InvalidParameter("members", "need at least 2 Monte Carlo runs")
    streams = RandomStreams(seed)
    durations = np.asarray(durations, dtype=float)
    noises = np.asarray(noises, dtype=float)
    full = {"specific_torque": 0.0, "offset": 0.0, **truth}
    nominal = {"decay_rate": full["decay_rate"], "coefficient": full["coefficient"], **(nominal or {})}
    cases = noises.size
    predicted = np.stack([
        predicted_errors({k: np.full(cases, float(v)) for k, v in full.items()}, np.full(cases, duration),
                         np.full(cases, step), noises, np.full(cases, quantisation), unknowns, reading)["alpha0_std"]
        for duration in durations
    ]) / ARCSEC
    shape = (durations.size, cases)
    rms, std, mean, converged, gross = (np.full(shape, math.nan) for _ in range(5))
    for i, duration in enumerate(durations):
        time = time_grid(duration, step)
        angle = closed_form(time, full["alpha0"], full["alpha0_dot"], full["decay_rate"], full["coefficient"],
                            full["specific_torque"])
        for j, noise in enumerate(noises):
            first = (i * cases + j) * members
            draws = streams.normal_series("readout_noise", np.arange(first, first + members), 0, time.size)
            records = observe(angle + noise * draws, full["alpha0"], 0.0, quantisation, reading, full["offset"])
            fits = fit_records(time, records, unknowns, nominal["decay_rate"], nominal["coefficient"], reading)
            error, ok = _north_errors(fits, full["alpha0"])
            error /= ARCSEC
            converged[i, j] = ok.mean()
            if error.size:
                rms[i, j] = math.sqrt(float(np.mean(error**2)))
                mean[i, j] = float(np.mean(error))
                # a micro-arcsecond floor: the rounding of a noise-free fit
                gross[i, j] = float(np.mean(np.abs(error) > GROSS_ERROR * predicted[i, j] + 1e-6))
            if error.size > 1:
                std[i, j] = float(np.std(error, ddof=1))
    return NorthErrorStudy(
        unknowns=unknowns,
        members=members,
        step_s=step,
        quantisation_rad=quantisation,
        durations_s=durations,
        noises_rad=noises,
        rms_error_rad=rms * ARCSEC,
        std_error_rad=std * ARCSEC,
        mean_error_rad=mean * ARCSEC,
        predicted_std_rad=predicted * ARCSEC,
        converged_fraction=converged,
        gross_error_fraction=gross,
        seed=seed,
    )
