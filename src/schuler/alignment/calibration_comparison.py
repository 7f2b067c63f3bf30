"""Multi-position calibration side by side: six positions with a rate test, the automatic multi-static
method, and the pulse method of schuler calibrate, on records of one grade whose errors are known.

:func:`compare_calibration` draws one IMU of the grade (its constant errors
addressed by seed and member 0), simulates both procedures with it, calibrates,
and sets every estimate beside the truth and its predicted 1-sigma (the
normalised error z = (estimate - true) / sigma should be of order 1). The
simulated IMU has the grade's constant errors and white noise -- what the
calibration models; the slow terms (bias instability, rate random walk) and
g-sensitivity are left out, as they are what no calibration removes. The pulse
method (schuler calibrate) is passed in by the caller (``pulse_method(angle_random_walk,
drift, latitude, members, seed)`` -> its drift and azimuth spread), since this
package does not import the seed systems.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from schuler.alignment.multi_static import MultiStaticPlan, calibrate_multi_static, identifiable_truth
from schuler.alignment.six_position import SixPositionPlan, calibrate_six_position
from schuler.core.earth import earth_rate_ned
from schuler.exceptions import renamed_keywords
from schuler.imu.error_model import ErrorModel
from schuler.imu.simulate import ImuSimulator
from schuler.imu.spec import preset
from schuler.memory import require
from schuler.results import Result

OFF_DIAGONAL = [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]

BYTES_PER_SAMPLE = 400
"""Held per sample of a simulated procedure: truth, samples, the simulator's and the fits' temporaries
(measured: about 160 bytes; the rest is margin)."""


def calibration_model(grade: str) -> ErrorModel:
    """The grade's constant errors and white noise (slow terms and g-sensitivity left out, see module notes).

    Parameters
    ----------
    grade : {"navigation", "tactical", "industrial", "consumer"}
        IMU preset (:func:`schuler.imu.spec.preset`).

    Returns
    -------
    ErrorModel
        The preset with bias instability, Gauss-Markov, rate random walk and g-sensitivity set to zero.
    """
    model = preset(grade)

    def constant(errors):
        zeros = np.zeros(3)
        return replace(errors, bias_instability=zeros, gm_sigma=zeros, rate_random_walk=zeros,
                       g_sensitivity=np.zeros((3, 3)))

    return replace(model, gyro=constant(model.gyro), accel=constant(model.accel),
                   name=f"{model.name}, constant errors and white noise")


def _entry(estimate, truth, sigma) -> dict[str, list[float]]:
    estimate, truth, sigma = (np.asarray(v, dtype=float).ravel() for v in (estimate, truth, sigma))
    z = (estimate - truth) / np.where(sigma > 0, sigma, np.inf)
    return {"estimate": estimate.tolist(), "true": truth.tolist(), "sigma": sigma.tolist(), "z": z.tolist()}


def _record(model: ErrorModel, gyro_truth, accel_truth, dt: float, seed: int):
    simulator = ImuSimulator(model, dt, true_gyro=gyro_truth, true_accel=accel_truth, seed=seed)
    gyro, accel = simulator.window([0], 0, gyro_truth.shape[0])
    return gyro[0], accel[0], simulator.constants([0])


@dataclass
class CalibrationComparison(Result):
    """Calibration procedures on simulated records of one IMU (module notes).

    ``six_position`` and ``multi_static`` map each estimated quantity to
    ``estimate``, ``true``, ``sigma`` (predicted 1-sigma) and ``z`` (normalised
    error), SI (rad/s, m/s^2, dimensionless matrices), plus ``duration_s`` and
    ``max_abs_z``. ``pulse`` is schuler calibrate's Monte Carlo spread for the x gyro
    (``drift_sigma_rad_s``, ``azimuth_sigma_rad``, ``procedure_time_s``).
    """

    grade: str
    latitude_rad: float
    seed: int
    six_position: dict
    multi_static: dict
    pulse: dict | None = None
    notes: list[str] = field(default_factory=list)

    units = {"latitude_rad": "rad", "seed": "1",
             "six_position": "gyro_* rad/s (biases) or 1 (matrix entries); accel_* m/s^2 or 1; z 1",
             "multi_static": "as six_position; accel_non_orthogonality rad", "pulse": "rad/s, rad, s"}

    def to_dataframe(self):
        """One row per estimated coefficient: procedure, quantity, index, estimate, true, sigma, z (SI)."""
        import pandas as pd

        return pd.DataFrame([
            {"procedure": procedure, "quantity": key, "index": i, "estimate": e, "true": t, "sigma": s, "z": z}
            for procedure, block in (("six_position", self.six_position), ("multi_static", self.multi_static))
            for key, entry in block.items() if isinstance(entry, dict)
            for i, (e, t, s, z) in enumerate(zip(entry["estimate"], entry["true"], entry["sigma"], entry["z"]))])

    def render(self):
        from rich.console import Group
        from rich.table import Table

        deg_h = math.degrees(1.0) * 3600.0
        table = Table(title=f"Calibration of one {self.grade}-grade IMU (latitude {math.degrees(self.latitude_rad):g} "
                            "deg)", caption="z = (estimate - true) / predicted 1-sigma")
        for column in ("procedure", "time (s)", "gyro bias 1-sigma (deg/h)", "accel bias 1-sigma (ug)",
                       "scale 1-sigma (ppm)", "max |z|"):
            table.add_column(column, justify="left" if column == "procedure" else "right")
        six, multi = self.six_position, self.multi_static
        table.add_row("six positions + rate test", f"{six['duration_s']:.0f}",
                      f"{max(six['gyro_bias']['sigma']) * deg_h:.3g}",
                      f"{max(six['accel_bias']['sigma']) / 9.80665e-6:.3g}",
                      f"{max(six['accel_scale']['sigma']) * 1e6:.3g}", f"{six['max_abs_z']:.2f}")
        table.add_row(f"multi-static ({multi['static_intervals']} static intervals)", f"{multi['duration_s']:.0f}",
                      f"{max(multi['gyro_bias']['sigma']) * deg_h:.3g}",
                      f"{max(multi['accel_bias']['sigma']) / 9.80665e-6:.3g}",
                      f"{max(multi['accel_scale']['sigma']) * 1e6:.3g}", f"{multi['max_abs_z']:.2f}")
        if self.pulse is not None:
            table.add_row(f"pulse method, schuler calibrate ({self.pulse['members']} members)",
                          f"{self.pulse['procedure_time_s']:.0f}", f"{self.pulse['drift_sigma_rad_s'] * deg_h:.3g}",
                          "-", "-", "-")
        return Group(table, *self.notes)


def _six_position(model: ErrorModel, latitude_rad: float, dwell_s: float, turn_s: float, dt: float, seed: int):
    plan = SixPositionPlan(latitude_rad=latitude_rad, dwell_s=dwell_s, turn_s=turn_s, sample_interval_s=dt)
    require(plan.samples * BYTES_PER_SAMPLE, f"the six-position record of {plan.samples:,} samples",
            "`dwell`, `turn` or `imu_rate`")
    gyro_truth, accel_truth = plan.truth()
    gyro, accel, constants = _record(model, gyro_truth, accel_truth, dt, seed)
    fit = calibrate_six_position(gyro, accel, plan, model.gyro.random_walk, model.accel.random_walk)
    rows, cols = zip(*OFF_DIAGONAL)
    out: dict[str, Any] = {}
    for sensor in ("gyro", "accel"):
        K, K_sigma = getattr(fit, f"{sensor}_matrix"), getattr(fit, f"{sensor}_matrix_sigma")
        true_K = constants[f"{sensor}_matrix"][0]
        out[f"{sensor}_bias"] = _entry(getattr(fit, f"{sensor}_bias"), constants[f"{sensor}_bias"][0],
                                       getattr(fit, f"{sensor}_bias_sigma"))
        out[f"{sensor}_scale"] = _entry(np.diag(K) - 1.0, np.diag(true_K) - 1.0, np.diag(K_sigma))
        out[f"{sensor}_misalignment"] = _entry(K[rows, cols], true_K[rows, cols], K_sigma[rows, cols])
    out["duration_s"] = plan.samples * dt
    out["max_abs_z"] = max(max(abs(z) for z in v["z"]) for v in out.values() if isinstance(v, dict))
    return out


def _multi_static(model: ErrorModel, latitude_rad: float, positions: int, static_s: float, dt: float, seed: int):
    plan = MultiStaticPlan(positions=positions, static_s=static_s, sample_interval_s=dt, latitude_rad=latitude_rad)
    samples = (plan.initial_s + positions * (static_s + plan.move_s)) / dt
    require(samples * BYTES_PER_SAMPLE, f"the multi-static record of {samples:,.0f} samples",
            "`positions`, `static` or `imu_rate`")
    gyro_truth, accel_truth = plan.truth(seed)
    gyro, accel, constants = _record(model, gyro_truth, accel_truth, dt, seed)
    fit = calibrate_multi_static(gyro, accel, dt, initial=plan.initial_s, gravity=plan.gravity,
                                 latitude=latitude_rad)
    truth = identifiable_truth(constants["accel_matrix"][0], constants["accel_bias"][0], constants["gyro_matrix"][0])
    # the initial period's mean holds the Earth rate seen in the first attitude: the bias it estimates
    start = plan.attitudes(seed)[0]
    apparent = constants["gyro_bias"][0] + constants["gyro_matrix"][0] @ (start.T @ earth_rate_ned(latitude_rad))
    out: dict[str, Any] = {name: _entry(getattr(fit, name), truth[name], getattr(fit, f"{name}_sigma"))
                           for name in ("accel_non_orthogonality", "accel_bias", "gyro_matrix")}
    out["gyro_bias"] = _entry(fit.gyro_bias, apparent, fit.gyro_bias_sigma)
    out["accel_scale"] = _entry(fit.accel_scale - 1.0, truth["accel_scale"] - 1.0, fit.accel_scale_sigma)
    out["max_abs_z"] = max(max(abs(z) for z in v["z"]) for v in out.values())
    out["duration_s"] = gyro_truth.shape[0] * dt
    out["static_intervals"] = fit.static_intervals
    out["threshold_factor"] = fit.threshold_factor
    return out


@renamed_keywords(latitude_rad="latitude", dwell_s="dwell", turn_s="turn", static_s="static",
                  sample_interval_s="sample_interval")
def compare_calibration(grade: str, *, latitude: float, seed: int = 0, dwell: float = 60.0,
                        turn: float = 36.0, positions: int = 36, static: float = 3.0,
                        sample_interval: float = 0.01, pulse_method: Callable | None = None,
                        pulse_members: int = 100) -> CalibrationComparison:
    """Both multi-position procedures on one simulated IMU of ``grade``, and the pulse method beside them.

    Parameters
    ----------
    grade : str
        An IMU preset.
    latitude : float
        L, rad.
    seed : int
        Address of the IMU's draws (member 0).
    dwell, turn : float
        Six-position dwell and rate-test turn, s.
    positions, static : float
        Multi-static orientations and their static time, s.
    sample_interval : float
        dt, s.
    pulse_method : callable, optional
        schuler calibrate's spread: ``f(angle_random_walk, drift, latitude, members, seed) -> dict``.
    pulse_members : int
        Its Monte Carlo members.
    """
    model = calibration_model(grade)
    six = _six_position(model, latitude, dwell, turn, sample_interval, seed)
    multi = _multi_static(model, latitude, positions, static, sample_interval, seed)
    pulse = None
    notes = ["multi-static gyro bias: the initial static period's mean, Earth rate included (compared with the "
             "bias plus the Earth rate seen there); its frame is the accelerometers' calibrated frame"]
    if pulse_method is not None:
        pulse = dict(pulse_method(float(model.gyro.random_walk[0]), float(preset(grade).gyro.bias[0]), latitude,
                                  pulse_members, seed))
        pulse["members"] = int(pulse_members)
        notes.append("pulse method (schuler calibrate): the x gyro's drift from alternating torque pulses at two "
                     "platform positions, with the grade's angle random walk and schuler calibrate's own default "
                     "error budget")
    return CalibrationComparison(grade=grade, latitude_rad=latitude, seed=seed, six_position=six,
                                 multi_static=multi, pulse=pulse, notes=notes)
