"""Public entry points of the gyro vertical: ``run``, ``reproduce``, ``report``, ``sweep``, ``SYSTEM``.

``run`` takes the SI values of :data:`PARAMETERS` (as the CLI, scenario files and
sweeps parse them), builds the model, simulates it and identifies the modes of
its velocity error. ``sweep`` evaluates the closed forms for many cases at once.

Examples
--------
>>> result = run(latitude=np.radians(60), speed=10.0, duration=6 * 3600.0, earth="drozdovich")
>>> round(result.steady_dv_y, 3), round(result.eigen_period_fast_min, 2)
(0.557, 82.45)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from schuler.core.earth import PRESETS
from schuler.exceptions import InvalidParameter
from schuler.gyro_vertical import friction as friction_model
from schuler.gyro_vertical import plots
from schuler.gyro_vertical.model import GyroVertical, forcing
from schuler.gyro_vertical.quasi_steady import Analysis, analyse, split_schuler_frequencies, steady_errors
from schuler.gyro_vertical.reproduction import SOURCE, reproduce
from schuler.gyro_vertical.trajectory import (
    GreatCircleTrajectory,
    SpeedProfile,
    start_kinematics,
    transport_coriolis_acceleration,
)
from schuler.io import save_figure_formats, write_dataframe_csv
from schuler.params import Parameter
from schuler.registry import FigureRef, ReportSection, ReproductionRow, System
from schuler.results import Result
from schuler.units import parse_quantity

ARCMIN = math.pi / 180 / 60
MAX_POINTS = 2_000_000

PARAMETERS = (
    Parameter("latitude", "deg", 60.0, "Latitude phi of the start.", minimum=-90, maximum=90),
    Parameter("azimuth", "deg", 0.0, "Azimuth theta of the x0 axis (outer gimbal axis) at the start, "
              "from north toward east."),
    Parameter("velocity_angle", "deg", 90.0, "Angle gamma from x0 to the velocity, positive toward y0 "
              "(with azimuth 0, 90 deg is due west: the source's example)."),
    Parameter("speed", "m/s", 10.0, "Constant speed along the great circle (below the orbital speed).", minimum=0),
    Parameter("speed_profile", "", None, "Piecewise-linear speed instead of --speed: 'TIME: SPEED, ...' "
              "(bare times in h, speeds in m/s), e.g. '0: 0, 1: 10, 24: 10, 25: 20'.", kind="text"),
    Parameter("duration", "h", 48.0, "Simulated time.", minimum=0, maximum=24 * 60, exclusive_minimum=True),
    Parameter("output_step", "s", 10.0, "Interval of the output samples.", minimum=0, exclusive_minimum=True),
    Parameter("earth", "", "default", "Earth constants (drozdovich: R = 6.4e6 m, g = 9.81, Omega = 7.3e-5).",
              choices=tuple(PRESETS), kind="choice"),
    Parameter("initial_alpha", "arcmin", 0.0, "Initial tilt alpha about x (from the start position)."),
    Parameter("initial_beta", "arcmin", 0.0, "Initial tilt beta about y (from the start position)."),
    Parameter("start", "", "levelled", "Start position: levelled on the accelerometers, or the geocentric "
              "vertical.", choices=("levelled", "geocentric"), kind="choice"),
    Parameter("preset_integrators", "", True, "Preset the integrators to the true initial velocity.", kind="flag"),
    Parameter("accelerometer_bias_x", "m/s^2", 0.0, "Bias b_x of the x accelerometer (e.g. '50 ug')."),
    Parameter("accelerometer_bias_y", "m/s^2", 0.0, "Bias b_y of the y accelerometer."),
    Parameter("gyro_drift_x", "deg/h", 0.0, "Drift rate eps_x of the housing about x."),
    Parameter("gyro_drift_y", "deg/h", 0.0, "Drift rate eps_y of the housing about y."),
    Parameter("compensation", "", "none", "Subtract the transport and Coriolis accelerations W* (21) computed "
              "from the known trajectory.", choices=("none", "trajectory"), kind="choice"),
    Parameter("earth_rate_compensation", "", True, "Apply the Earth-rate torques (8).", kind="flag"),
    Parameter("schuler_tuning", "", 1.0, "kappa = k R / H (1: the Schuler condition (11)).", minimum=0,
              exclusive_minimum=True),
    Parameter("trajectory", "", "great-circle", "Move along the great circle, or freeze latitude and azimuth "
              "(the source's slowly-varying assumption; exact matrix-exponential solution).",
              choices=("great-circle", "frozen"), kind="choice"),
)
"""The ``run`` command's inputs (SI after parsing)."""

DEFAULTS = {p.name: p.parse(p.default) if p.default is not None else None for p in PARAMETERS}


def parse_speed_profile(text: str, label: str = "speed_profile") -> SpeedProfile:
    """Read 'TIME: SPEED, TIME: SPEED, ...' (bare times in h, speeds in m/s; units allowed).

    >>> parse_speed_profile("0: 0, 1 h: 36 km/h").speeds.tolist()
    [0.0, 10.0]
    """
    times, speeds = [], []
    for item in str(text).split(","):
        if ":" not in item:
            raise InvalidParameter(label, f"{item.strip()!r} is not 'TIME: SPEED'")
        time_text, speed_text = item.split(":", 1)
        times.append(parse_quantity(time_text.strip(), "h", name=label))
        speeds.append(parse_quantity(speed_text.strip(), "m/s", name=label))
    try:
        return SpeedProfile(times, speeds)
    except InvalidParameter as error:
        raise InvalidParameter(label, error.reason) from None


def build_model(values: dict) -> GyroVertical:
    """The :class:`GyroVertical` for SI parameter values (missing ones take their defaults)."""
    v = {**DEFAULTS, **values}
    earth = PRESETS[v["earth"]]
    profile = v["speed_profile"]
    speed = parse_speed_profile(profile) if profile else SpeedProfile.constant(v["speed"])
    try:
        path = GreatCircleTrajectory(v["latitude"], v["azimuth"], v["velocity_angle"], speed, earth.radius,
                                     earth.rate, frozen=v["trajectory"] == "frozen")
    except InvalidParameter as error:
        if profile and error.name == "speed":
            raise InvalidParameter("speed_profile", error.reason) from None
        raise
    return GyroVertical(
        path, earth.gravity, v["schuler_tuning"], bool(v["earth_rate_compensation"]),
        v["compensation"] == "trajectory", (v["accelerometer_bias_x"], v["accelerometer_bias_y"]),
        (v["gyro_drift_x"], v["gyro_drift_y"]), (v["initial_alpha"], v["initial_beta"]),
        v["start"] == "levelled", bool(v["preset_integrators"]),
    )


@dataclass
class VerticalRun(Result):
    """One simulated case: error statistics, steady values and the oscillation modes found."""

    duration_h: float
    final_latitude_deg: float
    W_star_x: float
    W_star_y: float
    steady_alpha_r: float
    steady_beta_r: float
    steady_dv_x: float
    steady_dv_y: float
    quasi_steady_mean_dv_x: float
    quasi_steady_mean_dv_y: float
    mean_dv_x: float
    mean_dv_y: float
    rms_dv_x: float
    rms_dv_y: float
    max_abs_dv_x: float
    max_abs_dv_y: float
    final_dv_x: float
    final_dv_y: float
    max_abs_alpha_arcmin: float
    max_abs_beta_arcmin: float
    eigen_period_fast_min: float
    eigen_period_slow_min: float
    beat_period_h: float | None
    fitted_period_fast_min: float | None
    fitted_period_slow_min: float | None
    fitted_amplitudes: list[float] | None
    tilt_oscillation_amplitude: float
    method: str
    nfev: int
    n_steps: int
    analysis: Analysis = field(repr=False)

    units: ClassVar[dict[str, str]] = {
        "W_star_x": "m/s^2", "W_star_y": "m/s^2", "steady_alpha_r": "rad", "steady_beta_r": "rad",
        **{name: "m/s" for name in ("steady_dv_x", "steady_dv_y", "quasi_steady_mean_dv_x", "quasi_steady_mean_dv_y",
                                    "mean_dv_x", "mean_dv_y", "rms_dv_x", "rms_dv_y", "max_abs_dv_x",
                                    "max_abs_dv_y", "final_dv_x", "final_dv_y", "fitted_amplitudes",
                                    "tilt_oscillation_amplitude")},
    }

    def render(self):
        from rich.table import Table

        table = Table(title="Gyro vertical with integral correction: simulated case")
        table.add_column("quantity")
        table.add_column("x", justify="right")
        table.add_column("y", justify="right")
        table.add_column("unit")
        rows = [
            ("W* (21) at the start", self.W_star_x, self.W_star_y, "m/s^2"),
            ("steady tilt alpha_r, beta_r", self.steady_alpha_r / ARCMIN, self.steady_beta_r / ARCMIN, "arcmin"),
            ("steady velocity error (slowly varying)", self.steady_dv_x, self.steady_dv_y, "m/s"),
            ("quasi-steady error (29), mean", self.quasi_steady_mean_dv_x, self.quasi_steady_mean_dv_y, "m/s"),
            ("velocity error: mean", self.mean_dv_x, self.mean_dv_y, "m/s"),
            ("velocity error: rms", self.rms_dv_x, self.rms_dv_y, "m/s"),
            ("velocity error: max |.|", self.max_abs_dv_x, self.max_abs_dv_y, "m/s"),
            ("velocity error: final", self.final_dv_x, self.final_dv_y, "m/s"),
            ("max |tilt| (alpha, beta)", self.max_abs_alpha_arcmin, self.max_abs_beta_arcmin, "arcmin"),
            ("split Schuler periods: eigenvalues", self.eigen_period_fast_min, self.eigen_period_slow_min, "min"),
        ]
        if self.fitted_period_fast_min is not None:
            rows.append(("split Schuler periods: fitted", self.fitted_period_fast_min,
                         self.fitted_period_slow_min, "min"))
        for name, x, y, unit in rows:
            table.add_row(name, f"{x:.5g}", f"{y:.5g}", unit)
        beat = "none (omega_2 = 0)" if self.beat_period_h is None else f"{self.beat_period_h:.4g} h"
        table.caption = (f"{self.duration_h:g} h, final latitude {self.final_latitude_deg:.3f} deg, beat period "
                         f"{beat}; solver {self.method}: {self.n_steps} steps, {self.nfev} evaluations")
        return table


def _stats(values: np.ndarray) -> tuple[float, float, float, float]:
    return float(np.mean(values)), float(np.sqrt(np.mean(values**2))), float(np.max(np.abs(values))), float(values[-1])


def run(**values) -> VerticalRun:
    """Simulate one case (keyword names and SI values as in :data:`PARAMETERS`)."""
    v = {**DEFAULTS, **values}
    duration, step = v["duration"], v["output_step"]
    if step > duration:
        raise InvalidParameter("output_step", f"{step:g} s is longer than the duration {duration:g} s")
    if duration / step > MAX_POINTS:
        raise InvalidParameter("output_step", f"{duration / step:.3g} output points; at most {MAX_POINTS:.0e}")
    model = build_model(v)
    time = np.arange(0.0, duration + step / 2, step)
    analysis = analyse(model, time)
    r = analysis.response
    k0 = model.trajectory.kinematics(0.0)
    W_x, W_y = (float(w) for w in transport_coriolis_acceleration(k0, model.radius))
    f_x, f_y, e_x, e_y = (float(x) for x in model.forcing(k0))
    steady = steady_errors(f_x, f_y, float(k0.omega_2), model.gravity, model.radius, gyro_drift=(e_x, e_y),
                           schuler_tuning=model.schuler_tuning)
    mean_x, rms_x, max_x, final_x = _stats(r.velocity_error_x)
    mean_y, rms_y, max_y, final_y = _stats(r.velocity_error_y)
    fit = analysis.fit
    fitted = np.sort(fit.periods) / 60 if fit is not None else (None, None)
    fast, slow = analysis.eigen_periods
    tilt = math.hypot(*model.initial_tilt)
    return VerticalRun(
        duration_h=duration / 3600, final_latitude_deg=math.degrees(float(r.latitude[-1])),
        W_star_x=W_x, W_star_y=W_y, steady_alpha_r=float(steady["alpha_r"]), steady_beta_r=float(steady["beta_r"]),
        steady_dv_x=float(steady["dv_x"]), steady_dv_y=float(steady["dv_y"]),
        quasi_steady_mean_dv_x=float(np.mean(analysis.quasi_steady.dv_x)),
        quasi_steady_mean_dv_y=float(np.mean(analysis.quasi_steady.dv_y)),
        mean_dv_x=mean_x, mean_dv_y=mean_y, rms_dv_x=rms_x, rms_dv_y=rms_y, max_abs_dv_x=max_x, max_abs_dv_y=max_y,
        final_dv_x=final_x, final_dv_y=final_y,
        max_abs_alpha_arcmin=float(np.max(np.abs(r.alpha))) / ARCMIN,
        max_abs_beta_arcmin=float(np.max(np.abs(r.beta))) / ARCMIN,
        eigen_period_fast_min=float(fast) / 60, eigen_period_slow_min=float(slow) / 60,
        beat_period_h=None if math.isclose(fast, slow) else 1 / (1 / fast - 1 / slow) / 3600,
        fitted_period_fast_min=None if fit is None else float(fitted[0]),
        fitted_period_slow_min=None if fit is None else float(fitted[1]),
        fitted_amplitudes=None if fit is None else [float(a) for a in fit.amplitudes],
        tilt_oscillation_amplitude=tilt * math.sqrt(model.gravity * model.radius),
        method=r.method, nfev=r.nfev, n_steps=r.n_steps, analysis=analysis,
    )


def write_run_figures(analysis: Analysis, out_dir, prefix: str = "vertical", compensated=None) -> list[Path]:
    """Tilts, velocity errors and (for long enough runs) the spectrum as PNG and SVG; the histories as CSV."""
    import pandas as pd

    out_dir = Path(out_dir)
    r, q = analysis.response, analysis.quasi_steady
    table = pd.DataFrame({
        "time_s": r.time, "alpha_rad": r.alpha, "beta_rad": r.beta, "latitude_deg": np.degrees(r.latitude),
        "measured_velocity_x": r.measured_velocity_x, "measured_velocity_y": r.measured_velocity_y,
        "true_velocity_x": r.true_velocity_x, "true_velocity_y": r.true_velocity_y,
        "velocity_error_x": r.velocity_error_x, "velocity_error_y": r.velocity_error_y,
        "quasi_steady_dv_x": q.dv_x, "quasi_steady_dv_y": q.dv_y,
    })
    files = [write_dataframe_csv(table, out_dir / f"{prefix}_timeseries.csv")]
    files += save_figure_formats(plots.plot_tilts(analysis), out_dir / f"{prefix}_tilts")
    files += save_figure_formats(plots.plot_velocity_errors(analysis, compensated),
                                 out_dir / f"{prefix}_velocity_errors")
    if analysis.spectrum is not None:
        files += save_figure_formats(plots.plot_spectrum(analysis), out_dir / f"{prefix}_spectrum")
    return files


FRICTION_PARAMETERS = (
    Parameter("dead_zone", "m/s", 0.01, "Half-width R q of the velocity dead zone (the source's 0.01 m/s); "
              "q = M_fr / H follows.", minimum=0, exclusive_minimum=True),
    Parameter("inner_ratio", "", 1.0, "q_2 / q_1: friction of the inner (y) bearing relative to the outer.",
              minimum=0),
    Parameter("initial_beta", "arcsec", 0.2, "Initial tilt beta about y."),
    Parameter("ramp", "m/s^2", 0.0, "Final value of a ramp of W_x on the accelerometer (0: no input)."),
    Parameter("ramp_time", "h", 24.0, "Duration of the ramp.", minimum=0, exclusive_minimum=True),
    Parameter("duration", "h", 48.0, "Simulated time.", minimum=0, maximum=24 * 30, exclusive_minimum=True),
    Parameter("output_step", "s", 10.0, "Interval of the output samples.", minimum=0, exclusive_minimum=True),
)


@dataclass
class FrictionRun(Result):
    """Coulomb-friction case: stick phases, the static errors and the growth of the slip."""

    q_1: float
    q_2: float
    dead_zone_x: float
    dead_zone_y: float
    stick_intervals: int
    switches: int
    max_static_dv_x: float
    max_static_dv_y: float
    max_abs_dv_x: float
    max_abs_dv_y: float
    growth_rate_x: float
    growth_rate_y: float
    nfev: int
    response: friction_model.FrictionResponse = field(repr=False)

    units: ClassVar[dict[str, str]] = {
        "q_1": "1/s", "q_2": "1/s", "dead_zone_x": "m/s", "dead_zone_y": "m/s", "max_static_dv_x": "m/s",
        "max_static_dv_y": "m/s", "max_abs_dv_x": "m/s", "max_abs_dv_y": "m/s", "growth_rate_x": "m/s^2",
        "growth_rate_y": "m/s^2",
    }


def run_friction(dead_zone=0.01, inner_ratio=1.0, initial_beta=0.0, ramp=0.0, ramp_time=86400.0,
                 duration=172800.0, output_step=10.0, earth="drozdovich") -> FrictionRun:
    """Simulate (30) with q_1 = dead_zone / R, q_2 = inner_ratio q_1 (SI values)."""
    constants = PRESETS[earth]
    R, g = constants.radius, constants.gravity
    if output_step > duration:
        raise InvalidParameter("output_step", f"{output_step:g} s is longer than the duration {duration:g} s")
    q = (dead_zone / R, inner_ratio * dead_zone / R)
    time = np.arange(0.0, duration + output_step / 2, output_step)
    acceleration = friction_model.AccelerationInput.ramp(ramp, 0.0, ramp_time) if ramp else None
    response = friction_model.simulate_friction(q, time, initial_tilt=(0.0, initial_beta), acceleration=acceleration,
                                                gravity=g, radius=R)
    static = np.abs(response.stick_velocity_errors)
    rate_x, rate_y = friction_model.friction_growth_rate(q, g, R)
    return FrictionRun(
        q_1=q[0], q_2=q[1], dead_zone_x=R * q[0], dead_zone_y=R * q[1],
        stick_intervals=len(response.stick_intervals), switches=len(response.switch_times) - 1,
        max_static_dv_x=float(static[:, [0, 2]].max()) if static.size else 0.0,
        max_static_dv_y=float(static[:, [1, 3]].max()) if static.size else 0.0,
        max_abs_dv_x=float(np.abs(response.velocity_error_x).max()),
        max_abs_dv_y=float(np.abs(response.velocity_error_y).max()),
        growth_rate_x=float(rate_x), growth_rate_y=float(rate_y), nfev=response.nfev, response=response,
    )


def report(outdir: Path) -> ReportSection:
    """Figures of the worked example, its spectrum and friction; the reproduction table (a few seconds)."""
    outdir = Path(outdir)
    result = reproduce()
    figures = []
    files = write_run_figures(result.analysis, outdir, "vertical_example", compensated=result.compensated)
    captions = {
        "vertical_example_tilts": "Tilts of the worked example (60 deg, 10 m/s due west, 48 h on the great "
                                  "circle) about the forced motion (26).",
        "vertical_example_velocity_errors": "Velocity errors: simulation, the quasi-steady error (29), its "
                                            "slowly-varying form, and the run with W* compensated (with a "
                                            "1-arcsec levelling error, hence its small oscillation).",
        "vertical_example_spectrum": "Spectrum of the oscillation about (29): the split Schuler lines at "
                                     "82.5 and 86.8 min on either side of zero; nothing at 24 h.",
    }
    for path in files:
        if path.suffix == ".png":
            figures.append(FigureRef(path.name, captions[path.stem]))
    friction = run_friction(initial_beta=math.radians(0.2 / 3600), duration=48 * 3600.0)
    files = save_figure_formats(plots.plot_friction(friction.response, (friction.q_1, friction.q_2),
                                                    PRESETS["drozdovich"].radius), outdir / "vertical_friction")
    figures.append(FigureRef(files[0].name, "Coulomb friction (30), q = 0.01 m/s / R on both axes, initial tilt "
                                            "0.2 arcsec: stick while the integrator crosses the dead zone, then "
                                            "slip whose amplitude grows by 4 R q per Schuler period."))
    rows = result.rows()
    rows.append(ReproductionRow("static velocity error limit (32)", "M_fr / H", friction.max_static_dv_x, "m/s",
                                friction.max_static_dv_x <= friction.dead_zone_x * (1 + 1e-9),
                                "static errors stay inside +-R q; the source's (32) lacks the factor R"))
    return ReportSection(
        system="vertical",
        title="Gyro vertical with integral correction measuring velocity",
        source=SOURCE,
        summary=("A gyro vertical whose accelerometer integrators drive its torquers (integral correction, "
                 "Schuler-tuned) measures velocity. Moving along a great circle on the rotating Earth, the "
                 "transport and Coriolis accelerations leave a systematic velocity error (0.557 m/s in the "
                 "source's example, printed as 0.67) and split Schuler oscillations that beat every "
                 "2 pi/(Omega sin phi); compensating them from the trajectory removes the systematic error. "
                 "Coulomb friction leaves static errors within +-R q, but its coupled slip is self-exciting."),
        rows=rows,
        figures=figures,
        commands=["schuler vertical reproduce --out DIR", "schuler vertical run --latitude 60 --speed 10 "
                  "--earth drozdovich --duration 48 --out DIR", "schuler vertical friction --out DIR"],
        notes=result.errata + [
            "Friction: in (30) each bearing's friction precesses the other axis, so both gimbals stick together "
            "exactly when |Delta v_x| <= R q_1 and |Delta v_y| <= R q_2; in slip the friction drives the other "
            "Schuler loop in resonance and the velocity-error amplitudes grow by 2 q_i sqrt(g R)/pi per second "
            "(4 R q_i per Schuler period), confirmed by the simulation to 1e-4.",
            "Scale up: 'schuler vertical run --duration 720 --output-step 1' simulates 30 days at 1-s output.",
        ],
    )


def sweep(values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Closed forms for many cases at once: W*, the steady tilts and velocity errors, the split periods.

    Every parameter of :data:`PARAMETERS` may be given as an SI array of length n
    (missing ones take their defaults). The results are evaluated at the start of
    each path by the slowly-varying form of (29) and the mode formulas of (27); no
    simulation is run.

    Examples
    --------
    >>> out = sweep({"latitude": np.radians([30.0, 60.0]), "earth": np.array(["drozdovich"] * 2)})
    >>> out["dv_y"].round(3).tolist(), (out["split_period_fast_s"] / 60).round(2).tolist()
    ([0.334, 0.557], [83.35, 82.45])
    """
    n = max((np.size(v) for v in values.values()), default=1)
    v = {name: np.broadcast_to(np.asarray(values.get(name, DEFAULTS[name])), (n,)) for name in DEFAULTS}
    earth = [PRESETS[str(name)] for name in v["earth"]]
    radius = np.array([e.radius for e in earth])
    gravity = np.array([e.gravity for e in earth])
    rate = np.array([e.rate for e in earth])
    speed = np.array([parse_speed_profile(p).speeds[0] if p else s for p, s in zip(v["speed_profile"], v["speed"])],
                     dtype=float)
    orbital = np.sqrt(gravity * radius)
    if np.any(speed >= orbital):
        raise InvalidParameter("speed", "every case's speed must be below the orbital speed sqrt(g R)")
    kinematics = start_kinematics(v["latitude"].astype(float), v["azimuth"].astype(float),
                                  v["velocity_angle"].astype(float), speed, rate)
    kappa = v["schuler_tuning"].astype(float)
    f_x, f_y, e_x, e_y = forcing(kinematics, radius, kappa, v["earth_rate_compensation"].astype(bool),
                                 v["compensation"] == "trajectory",
                                 (v["accelerometer_bias_x"].astype(float), v["accelerometer_bias_y"].astype(float)),
                                 (v["gyro_drift_x"].astype(float), v["gyro_drift_y"].astype(float)))
    steady = steady_errors(f_x, f_y, kinematics.omega_2, gravity, radius, gyro_drift=(e_x, e_y),
                           schuler_tuning=kappa)
    W_x, W_y = transport_coriolis_acceleration(kinematics, radius)
    fast, slow = split_schuler_frequencies(gravity, radius, kinematics.omega_2, kappa)
    with np.errstate(divide="ignore"):
        beat = np.where(fast > slow, 2 * np.pi / (fast - slow), np.inf)
    tilt = np.hypot(v["initial_alpha"].astype(float), v["initial_beta"].astype(float))
    return {
        "W_star_x": W_x, "W_star_y": W_y,
        "alpha_r_rad": steady["alpha_r"], "beta_r_rad": steady["beta_r"],
        "dv_x": steady["dv_x"], "dv_y": steady["dv_y"],
        "schuler_period_s": 2 * np.pi * np.sqrt(radius / (kappa * gravity)),
        "split_period_fast_s": 2 * np.pi / fast, "split_period_slow_s": 2 * np.pi / slow,
        "beat_period_s": beat,
        "tilt_oscillation_amplitude": tilt * np.sqrt(gravity * radius),
    }


SYSTEM = System(
    name="vertical",
    title="Gyro vertical with integral correction measuring velocity",
    source=SOURCE,
    parameters=PARAMETERS,
    run=run,
    reproduce=reproduce,
    report=report,
    sweep=sweep,
)
