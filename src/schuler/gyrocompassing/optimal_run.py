"""``schuler align optimal``: the KPI design (T = 30 s, zeta = 0.8) against the Kalman filter of the same IMU.

The model and its equations are :mod:`schuler.gyrocompassing.optimal`; this module resolves ``--imu``
through the IMU layer (:func:`schuler.imu.instrument.resolve_model`), lets explicit noise options win over
the IMU's, and returns :class:`OptimalAlignment` with its figures (accuracy versus T with the optimum
marked; the time-varying Kalman gain converging to the steady one).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler.contract import Action
from schuler.core.earth import STANDARD_GRAVITY
from schuler.core.geometry import horizontal_earth_rate
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT
from schuler.exceptions import InvalidParameter
from schuler.gyrocompassing import optimal as model
from schuler.params import Parameter, ParameterSet
from schuler.results import Result, json_safe, write_result
from schuler.units import to_unit

OPTIMAL_PARAMETERS = ParameterSet((
    Parameter("imu", "", "tactical", "IMU: a grade (navigation, tactical, industrial, consumer), a TOML spec file "
              "or a recording whose identified noise terms are used.", kind="text"),
    Parameter("latitude", "deg", 50.0, "Latitude of the site.", minimum=-85, maximum=85),
    Parameter("time_constant", "s", DESIGN_TIME_CONSTANT, "T of the seed's design.", minimum=1, maximum=1e5),
    Parameter("damping", "", DESIGN_DAMPING, "zeta of the seed's design.", minimum=0.05, maximum=10),
    Parameter("imu_window", "s", 600.0, "Time between the gyro calibration and the alignment (the constant "
              "residual drift).", minimum=1e-3, maximum=1e7),
    Parameter("gyro_noise", "deg/sqrt(h)", None, "Gyro angle random walk N (not set: the IMU's).", minimum=0,
              maximum=1e4),
    Parameter("accel_noise", "ug/sqrt(Hz)", None, "Accelerometer white noise N_a (not set: the IMU's).", minimum=0,
              exclusive_minimum=True, maximum=1e7),
    Parameter("correlation_time", "s", None, "tau of the Gauss-Markov drift (not set: from the IMU).", minimum=0,
              exclusive_minimum=True, maximum=1e8),
    Parameter("duration", "s", "2 h", "Alignment over which the time-varying gain is drawn.", minimum=10,
              maximum=1e6),
    Parameter("initial_azimuth_sigma", "deg", 5.0, "1-sigma azimuth error at the start of the time-varying "
              "filter.", minimum=0, exclusive_minimum=True, maximum=30),
    Parameter("initial_tilt_sigma", "arcmin", 3.0, "1-sigma level error at its start.", minimum=0,
              exclusive_minimum=True, maximum=600),
), owner="align optimal")
"""Options of ``schuler align optimal``."""

LOOP_KEYS = ("time_constant_s", "damping", "c_gamma", "c_a", "azimuth_error_sigma_rad", "azimuth_error_bias_rad",
             "settling_time_s")
"""The keys of ``seed`` and ``optimal`` in the JSON."""


def _loop(accuracy: model.LoopAccuracy) -> dict[str, Any]:
    data = dataclasses.asdict(accuracy)
    return {key: data[key] for key in LOOP_KEYS} | {"bias_gains": list(accuracy.bias_gains)}


@dataclass
class OptimalAlignment(Result):
    """The seed's loop and the steady-state Kalman filter on one IMU (``seed``, ``optimal``: :data:`LOOP_KEYS`).

    ``seed_optimal_for`` holds the noise ratios q_beta / r, q_delta / r (1/s^2) for which the seed's gains are
    the white-noise loop's optimum and the gyro noises (rad/sqrt(s)) that give them with this IMU's
    accelerometer, or None when zeta < 1/sqrt(2).
    """

    imu: str
    latitude_rad: float
    noise: dict[str, float]
    seed: dict[str, Any]
    optimal: dict[str, Any]
    seed_optimal_for: dict[str, float] | None
    best_time_constant_s: float
    sweep: dict[str, Any] = field(default_factory=dict, repr=False)
    gains: dict[str, Any] = field(default_factory=dict, repr=False)

    units: ClassVar[dict[str, str]] = {"time_constant_s": "s", "damping": "1", "c_gamma": "1/s", "c_a": "1/s",
                                       "bias_gains": "1/s", "settling_time_s": "s"}

    def render(self):
        from rich.table import Table

        table = Table(title=f"Gyrocompassing loop on the {self.imu} IMU, latitude "
                            f"{math.degrees(self.latitude_rad):g} deg: the KPI design and the Kalman filter")
        for column in ("quantity", "seed (KPI)", "optimal (Kalman)"):
            table.add_column(column, justify="left" if column == "quantity" else "right")
        shown = {"time_constant_s": ("T", "s", "{:.5g}"), "damping": ("zeta", "", "{:.4g}"),
                 "c_gamma": ("c_Gamma", "1/s", "{:.4g}"), "c_a": ("c_a", "1/s", "{:.4g}"),
                 "azimuth_error_sigma_rad": ("azimuth error, noise 1-sigma", "arcmin", "{:.4g}"),
                 "azimuth_error_bias_rad": ("azimuth error, constant drifts (RSS)", "arcmin", "{:.4g}"),
                 "settling_time_s": ("settling time", "s", "{:.5g}")}
        for key, (label, unit, form) in shown.items():
            values = [self.seed[key], self.optimal[key]]
            if unit == "arcmin":
                values = [float(to_unit(v, "arcmin")) for v in values]
            table.add_row(f"{label} {unit}".strip(), *(form.format(v) for v in values))
        table.add_row("best T of the KPI loop (same zeta) s", f"{self.best_time_constant_s:.5g}", "")
        ratio = self.seed_optimal_for
        table.add_row("seed optimal for q_beta/r, q_delta/r 1/s^2",
                      "none (zeta < 1/sqrt 2)" if ratio is None
                      else f"{ratio['q_beta_over_r']:.4g}, {ratio['q_delta_over_r']:.4g}", "")
        return table

    def to_dict(self) -> dict[str, Any]:
        data = super().to_dict()
        data["sweep"] = json_safe(self.sweep)
        return data


def _noise(imu: str, window: float, gyro_noise, accel_noise, correlation_time) -> model.LoopNoise:
    from schuler.imu.instrument import resolve_model

    noise = model.noise_from_imu(resolve_model(imu), window, correlation_time)
    given = {"gyro_noise": gyro_noise, "gyro_noise_z": gyro_noise, "accel_noise": accel_noise}
    return dataclasses.replace(noise, **{k: v for k, v in given.items() if v is not None})


def optimal(imu: str = "tactical", latitude: float = math.radians(50.0), time_constant: float = DESIGN_TIME_CONSTANT,
            damping: float = DESIGN_DAMPING, imu_window: float = 600.0, gyro_noise: float | None = None,
            accel_noise: float | None = None, correlation_time: float | None = None, duration: float = 7200.0,
            initial_azimuth_sigma: float = math.radians(5.0),
            initial_tilt_sigma: float = math.radians(3.0 / 60.0)) -> OptimalAlignment:
    """The KPI loop's accuracy (Lyapunov, (1.21)) beside the steady-state Kalman filter's (ARE) on one IMU.

    Equations: :mod:`schuler.gyrocompassing.optimal` (the KPI manual's (1.19), (1.21), c_Gamma = 2 zeta / T,
    c_a = 1 / (T^2 U_eta); Kalman and Bucy 1961).

    Parameters
    ----------
    imu : str
        A grade, a TOML spec file or a recording (:func:`schuler.imu.instrument.resolve_model`).
    latitude : float
        phi, rad.
    time_constant : float
        T of the seed's design, s.
    damping : float
        zeta of the seed's design, dimensionless.
    imu_window : float
        Time between gyro calibration and alignment, s.
    gyro_noise : float, optional
        Gyro angle random walk, rad/sqrt(s) (not set: the IMU's).
    accel_noise : float, optional
        Accelerometer white noise, m/s/sqrt(s) (not set: the IMU's).
    correlation_time : float, optional
        tau of the Gauss-Markov drift, s (not set: from the IMU).
    duration : float
        Span of the time-varying gain, s.
    initial_azimuth_sigma, initial_tilt_sigma : float
        Initial 1-sigma azimuth and level errors of the time-varying filter, rad.

    Returns
    -------
    OptimalAlignment

    Examples
    --------
    >>> r = optimal("navigation")
    >>> r.optimal["azimuth_error_sigma_rad"] <= r.seed["azimuth_error_sigma_rad"]
    True
    """
    noise = _noise(imu, imu_window, gyro_noise, accel_noise, correlation_time)
    seed = model.seed_accuracy(noise, latitude, time_constant, damping)
    best = model.optimal_accuracy(noise, latitude)
    try:
        q_beta, q_delta = model.noise_for_gains(seed.c_gamma, seed.c_a, latitude)
        r = (noise.accel_noise / STANDARD_GRAVITY) ** 2
        optimal_for = {"q_beta_over_r": q_beta, "q_delta_over_r": q_delta,
                       "gyro_noise_rad_sqrt_s": math.sqrt(q_beta * r),
                       "gyro_noise_z_rad_sqrt_s": math.sqrt(q_delta * r)}
    except InvalidParameter:
        optimal_for = None
    best_T = model.best_time_constant(noise, latitude, damping, bounds=(1.0, 1e5))
    T = np.geomspace(3.0, 3e4, 81)
    errors = model.accuracy_versus_time_constant(noise, latitude, T, damping)
    t = np.linspace(0.0, duration, 721)
    U_eta = horizontal_earth_rate(latitude)
    P0 = np.diag([initial_tilt_sigma**2, initial_azimuth_sigma**2,
                  (noise.bias_sigma**2 + noise.drift_east**2) / U_eta**2,
                  (noise.bias_sigma_z**2 + noise.drift_z**2) / U_eta**2])
    gains = model.gain_history(noise, latitude, P0, t)
    result = OptimalAlignment(
        imu=str(imu), latitude_rad=latitude, noise=dataclasses.asdict(noise), seed=_loop(seed), optimal=_loop(best),
        seed_optimal_for=optimal_for, best_time_constant_s=best_T,
        sweep={"time_constant_s": T, "azimuth_error_sigma_rad": errors[:, 0], "azimuth_error_bias_rad": errors[:, 1]},
        gains={"t_s": t, "gain": gains})
    return result.attach_figures(figures)  # type: ignore[return-value]


def figures(result: Result) -> dict[str, Any]:
    """Accuracy versus T of the KPI loop with the optimum marked; the time-varying gain against the steady one.

    Parameters
    ----------
    result : OptimalAlignment
        What :func:`optimal` returned (SI).
    """
    import matplotlib.pyplot as plt

    assert isinstance(result, OptimalAlignment)
    sweep = result.sweep
    T = np.asarray(sweep["time_constant_s"])
    sigma = np.asarray(to_unit(np.asarray(sweep["azimuth_error_sigma_rad"]), "arcmin"))
    bias = np.asarray(to_unit(np.asarray(sweep["azimuth_error_bias_rad"]), "arcmin"))
    fig, ax = plt.subplots(figsize=(8, 4.2))
    ax.loglog(T, sigma, label="noise 1-sigma (Lyapunov)")
    ax.loglog(T, bias, "--", label="constant drifts (1.21), RSS")
    ax.loglog(T, np.hypot(sigma, bias), "k", label="total")
    best = result.best_time_constant_s
    best_row = model.seed_accuracy(model.LoopNoise(**result.noise), result.latitude_rad, best,
                                   result.seed["damping"])
    ax.plot(best, float(to_unit(math.hypot(best_row.azimuth_error_sigma_rad, best_row.azimuth_error_bias_rad),
                                "arcmin")), "o", color="C3", label=f"least total, T = {best:.4g} s")
    ax.axvline(result.seed["time_constant_s"], color="0.5", lw=0.8, label="the seed's T")
    ax.axhline(float(to_unit(result.optimal["azimuth_error_sigma_rad"], "arcmin")), color="C2", ls=":",
               label="Kalman filter, noise 1-sigma")
    ax.set(xlabel="time constant T, s", ylabel="azimuth error, arcmin",
           title=f"KPI loop (zeta = {result.seed['damping']:.3g}) on the {result.imu} IMU")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig2, ax2 = plt.subplots(figsize=(8, 4.2))
    t, gain = np.asarray(result.gains["t_s"]), np.asarray(result.gains["gain"])
    steady = np.array([result.optimal["c_gamma"], result.optimal["c_a"], *list(result.optimal["bias_gains"])])
    labels = ("c_Gamma", "c_a", "drift gain, east", "drift gain, z")
    for k, label in enumerate(labels):
        if steady[k] != 0:
            ax2.plot(t[1:], np.abs(gain[1:, k] / steady[k]), label=label)
    ax2.axhline(1.0, color="k", lw=0.8)
    ax2.set_xscale("log")
    ax2.set_yscale("log")
    ax2.set(xlabel="time, s", ylabel="|K(t) / K steady|", title="Time-varying Kalman gain over the alignment")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    fig2.tight_layout()
    return {"align_optimal_accuracy": fig, "align_optimal_gain": fig2}


def write_files(result: Result, out_dir: Path) -> list[Path]:
    """The figures of ``align optimal`` (PNG, SVG).

    Parameters
    ----------
    result : OptimalAlignment
        What :func:`optimal` returned.
    out_dir : Path
        Folder to write into.
    """
    return write_result(result, Path(out_dir))


OPTIMAL = Action(
    name="optimal",
    help="The KPI loop (T, zeta) beside the steady-state Kalman filter of the same IMU: gains, accuracy, time.\n\n"
         "Example: schuler align optimal --imu tactical --latitude 50 --json",
    function=optimal,
    parameters=OPTIMAL_PARAMETERS,
    write_files=write_files,
    figures=figures,
)
"""The ``optimal`` command of ``schuler align``."""
