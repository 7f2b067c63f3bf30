"""Accuracy against observation time: predicted standard errors and Monte Carlo, vectorised.

For a true motion and white read-out noise of standard deviation sigma (plus the
uniform quantisation error, variance q^2/12), the least-squares estimate of
alpha0 (hence of north, -alpha0) has the covariance sigma_eff^2 (J^T J)^-1, J being
the Jacobian of the model w.r.t. the identified parameters (see
:mod:`.identification`). :func:`predicted_errors` evaluates it for many cases at
once (each with its own window, sampling step, noise and parameters), and
:func:`monte_carlo` checks it by fitting many noisy records simultaneously
(a batched Gauss-Newton iteration of the same least-squares problem).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.ground_gyrocompass.identification import UNKNOWN_SETS
from schuler.ground_gyrocompass.motion import basis
from schuler.results import Result

ARCSEC = math.pi / (180.0 * 3600.0)


def _linear_names(unknowns, reading):
    names = ["alpha0", "alpha0_dot"] + (["specific_torque"] if unknowns == 5 else [])
    return names + (["offset"] if reading == "absolute" else [])


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
    for name, derivative in (("decay_rate", b.d_decay_rate), ("coefficient", b.d_coefficient)):
        if name in UNKNOWN_SETS[unknowns]:
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
        Observation window and sampling step, s.
    noise, quantisation : ndarray (n,)
        Read-out noise standard deviation and resolution, rad.
    unknowns : int
        2, 3, 4 or 5 (the same for all cases).

    Returns
    -------
    dict
        ``<parameter>_std`` (SI) for each identified parameter, arrays (n,).

    Examples
    --------
    >>> v = {"alpha0": np.array([0.0215]), "alpha0_dot": np.array([4.08e-4]),
    ...      "decay_rate": np.array([2.15e-3]), "coefficient": np.array([0.0135849])}
    >>> e = predicted_errors(v, np.array([200.0]), np.array([1.0]), np.array([5e-6]), unknowns=2)
    >>> bool(1e-7 < e["alpha0_std"][0] < 1e-6)
    True
    """
    duration, step, noise, quantisation = (
        np.atleast_1d(np.asarray(x, dtype=float)) for x in (duration, step, noise, quantisation)
    )
    n_max = int(np.max(np.floor(duration / step * (1.0 + 1e-12)))) + 1
    k = np.arange(n_max)
    time = step[:, None] * k[None, :]
    mask = time <= duration[:, None] * (1.0 + 1e-12)
    _, jacobian = batched_model(np.where(mask, time, 0.0), values, unknowns, reading)
    jacobian = jacobian * mask[..., None]
    if np.any(mask.sum(axis=1) < jacobian.shape[-1]):
        raise InvalidParameter("duration", "fewer samples than unknowns in some case")
    covariance = _scaled_inverse(np.swapaxes(jacobian, -1, -2) @ jacobian)
    variance = noise**2 + quantisation**2 / 12.0
    names = _linear_names(unknowns, reading) + [n for n in ("decay_rate", "coefficient") if n in UNKNOWN_SETS[unknowns]]
    diagonal = np.einsum("...ii->...i", covariance)
    return {f"{name}_std": np.sqrt(variance * diagonal[:, i]) for i, name in enumerate(names)}


def fit_batch(time, observed, start, unknowns, reading="relative", iterations=12):
    """Gauss-Newton fit of many records at once (same times), from ``start`` values.

    lambda and B are iterated as logarithms (they stay positive). Returns the
    final values (dict of arrays) and a boolean array of members that converged.
    """
    current = {k: np.array(v, dtype=float, copy=True) for k, v in start.items()}
    linear = _linear_names(unknowns, reading)
    nonlinear = [n for n in ("decay_rate", "coefficient") if n in UNKNOWN_SETS[unknowns]]
    converged = np.zeros(observed.shape[0], dtype=bool)
    for _ in range(iterations):
        model, jacobian = batched_model(time, current, unknowns, reading)
        for i, name in enumerate(nonlinear):
            jacobian[..., len(linear) + i] *= current[name][:, None]
        residual = observed - model
        normal = np.swapaxes(jacobian, -1, -2) @ jacobian
        delta = (_scaled_inverse(normal) @ (np.swapaxes(jacobian, -1, -2) @ residual[..., None]))[..., 0]
        for i, name in enumerate(linear):
            current[name] = current[name] + delta[:, i]
        for i, name in enumerate(nonlinear):
            current[name] = current[name] * np.exp(np.clip(delta[:, len(linear) + i], -0.5, 0.5))
        converged = np.abs(delta[:, len(linear):]).max(axis=1, initial=0.0) < 1e-10
        small = np.abs(delta[:, 0]) < 1e-13
        if np.all(converged & small):
            break
    return current, converged


@dataclass
class NorthErrorStudy(Result):
    """North error against observation time and noise (Monte Carlo and predicted).

    Arrays are indexed [duration, noise]; errors in arcsec.
    """

    unknowns: int
    members: int
    step_s: float
    quantisation_arcsec: float
    durations_s: np.ndarray
    noises_arcsec: np.ndarray
    rms_error_arcsec: np.ndarray
    std_error_arcsec: np.ndarray
    mean_error_arcsec: np.ndarray
    predicted_std_arcsec: np.ndarray
    converged_fraction: np.ndarray
    seed: int

    units: ClassVar[dict] = {}

    def render(self):
        from rich.table import Table

        table = Table(title=f"North error vs observation time ({self.unknowns} unknowns, {self.members} runs)")
        table.add_column("window, s")
        for noise in self.noises_arcsec:
            table.add_column(f"noise {noise:g}\": MC std / predicted, arcsec", justify="right")
        for i, duration in enumerate(self.durations_s):
            cells = [
                f"{self.std_error_arcsec[i, j]:.3g} / {self.predicted_std_arcsec[i, j]:.3g}"
                for j in range(len(self.noises_arcsec))
            ]
            table.add_row(f"{duration:g}", *cells)
        return table


def monte_carlo(
    truth, durations, noises, members=200, unknowns=4, step=1.0, quantisation=0.0, reading="relative", seed=0
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
        Noisy records per case (all fitted at once).
    unknowns, step, quantisation, reading, seed
        Fit set, sampling step (s), read-out resolution (rad), reading, random seed.

    Notes
    -----
    Each record is fitted by Gauss-Newton started at the true values: the study
    measures the scatter of the least-squares estimator itself, not the reach of a
    start procedure (which :func:`~.identification.fit_least_squares` handles).
    """
    if members < 2:
        raise InvalidParameter("members", "need at least 2 Monte Carlo runs")
    rng = np.random.default_rng(seed)
    durations = np.asarray(durations, dtype=float)
    noises = np.asarray(noises, dtype=float)
    shape = (durations.size, noises.size)
    rms, std, mean, predicted, ok = (np.zeros(shape) for _ in range(5))
    full = {"specific_torque": 0.0, "offset": 0.0, **truth}
    batch = members * noises.size
    start = {k: np.full(batch, float(v)) for k, v in full.items()}
    for i, duration in enumerate(durations):
        time = step * np.arange(int(math.floor(duration / step * (1.0 + 1e-12))) + 1)
        # the noise-free observed coordinate (the torque, if any, always included)
        clean, _ = batched_model(time, {k: v[:1] for k, v in start.items()}, 5, reading)
        sigma = np.repeat(noises, members)[:, None]
        noisy = clean + sigma * rng.standard_normal((batch, time.size))
        if quantisation > 0.0:
            noisy = quantisation * np.round(noisy / quantisation)
        values, converged = fit_batch(time, noisy, start, unknowns, reading)
        error = (values["alpha0"] - full["alpha0"]).reshape(noises.size, members) / ARCSEC
        good = converged.reshape(noises.size, members)
        for j in range(noises.size):
            e = error[j][good[j]]
            rms[i, j] = math.sqrt(float(np.mean(e**2))) if e.size else math.nan
            std[i, j] = float(np.std(e, ddof=1)) if e.size > 1 else math.nan
            mean[i, j] = float(np.mean(e)) if e.size else math.nan
            ok[i, j] = good[j].mean()
        cases = noises.size
        predicted[i] = (
            predicted_errors(
                {k: np.full(cases, float(v)) for k, v in full.items()},
                np.full(cases, duration),
                np.full(cases, step),
                noises,
                np.full(cases, quantisation),
                unknowns,
                reading,
            )["alpha0_std"]
            / ARCSEC
        )
    return NorthErrorStudy(
        unknowns=unknowns,
        members=members,
        step_s=step,
        quantisation_arcsec=quantisation / ARCSEC,
        durations_s=durations,
        noises_arcsec=noises / ARCSEC,
        rms_error_arcsec=rms,
        std_error_arcsec=std,
        mean_error_arcsec=mean,
        predicted_std_arcsec=predicted,
        converged_fraction=ok,
        seed=seed,
    )
