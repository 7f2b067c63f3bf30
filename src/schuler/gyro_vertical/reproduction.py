"""The source's worked example and friction estimate, recomputed, with its errata flagged.

Source: Drozdovich, "On an inertial method of measuring velocities" (1959)
(:data:`schuler.references.DROZDOVICH_1959`); equation numbers are the paper's.
The worked example after (29): v_y = 10 m/s, v_x = 0, phi = 60 deg,
R = 6.4e6 m, Omega = 7.3e-5 1/s, psi + gamma = 0 (here theta = 0, gamma = 90 deg:
x0 north, the velocity due west) and g = 9.81 m/s^2 (the source gives none): the
:data:`~schuler.core.earth.DROZDOVICH` constants. Every printed value below is
copied as the source prints it; the verdicts follow from the stated tolerances.

Examples
--------
>>> e = worked_example()
>>> round(e["W_star_x"], 4), round(e["beta_r"], 5), round(e["dv_y"], 3)
(0.0135, 0.00138, 0.557)
"""

from __future__ import annotations

import math
from pathlib import Path

from schuler.contract import FigureRef, ReportSection
from schuler.core.earth import DROZDOVICH, EarthModel
from schuler.gyro_vertical.actions import friction
from schuler.gyro_vertical.evaluation import PARAMETERS, simulated_run
from schuler.gyro_vertical.friction import friction_from_velocity_error
from schuler.gyro_vertical.quasi_steady import steady_errors
from schuler.gyro_vertical.results import data_files, figures
from schuler.gyro_vertical.trajectory import GreatCircleTrajectory, transport_coriolis_acceleration
from schuler.io import save_figure_formats
from schuler.references import DROZDOVICH_1959
from schuler.reproduction import Reproduction, Tolerance, compare
from schuler.units import from_unit, to_unit

LATITUDE = math.radians(60.0)
SPEED = 10.0
FRICTION_VELOCITY_ERROR = 0.01
"""|Delta v| = 0.01 m/s of the friction example after (32), m/s."""
LEVELLING_ERROR = from_unit(1.0, "arcsec")
"""A 1-arcsec levelling error about y in both compensation runs, rad: without any
error the compensated run is identically zero and a ratio of means says nothing."""
FRICTION_TILT = from_unit(0.2, "arcsec")
"""Initial tilt of the friction simulation, rad (small enough to start inside the dead zone)."""
SIMULATED_TIME = 48 * 3600.0
OUTPUT_STEP = 10.0
FRICTION_TIME = 12 * 3600.0
"""Simulated time of the friction example, s: the stick phase ends after about 1,050 s, and eight
Schuler periods show the growth of the slip."""
EXAMPLE = "worked example after (29)"


def worked_example(earth: EarthModel = DROZDOVICH, latitude: float = LATITUDE, speed: float = SPEED) -> dict:
    """The worked example by the slowly-varying form of (29): W*, tilts and velocity errors.

    Parameters
    ----------
    earth : EarthModel
        Constants (default: the source's).
    latitude : float
        rad.
    speed : float
        m/s, along +y0 with x0 north.

    Returns
    -------
    dict of float
        ``W_star_x``, ``W_star_y`` (m/s^2), ``alpha_r``, ``beta_r`` (rad), ``dv_x``,
        ``dv_y`` (m/s), and the source's own rounded arithmetic: ``source_chain_W_star_x``
        (sin 60 deg = 0.87, m/s^2) and ``source_chain_dv_y`` = 6.4e6 x 7.3e-5 x 0.87 x 1.4e-3 (m/s).
    """
    path = GreatCircleTrajectory.from_source(latitude, speed, radius=earth.radius, rate=earth.rate, frozen=True)
    kinematics = path.kinematics(0.0)
    W_x, W_y = (float(w) for w in transport_coriolis_acceleration(kinematics, earth.radius))
    steady = steady_errors(W_x, W_y, float(kinematics.omega_2), earth.gravity, earth.radius)
    values = {"W_star_x": W_x, "W_star_y": W_y}
    values.update({key: float(value) for key, value in steady.items()})
    values["source_chain_W_star_x"] = 6.4e6 * 7.3**2 * 0.87 * 0.5 * 1e-10 - 2 * 7.3 * 0.87 * 1e-5 * 10
    values["source_chain_dv_y"] = 6.4e6 * 7.3e-5 * 0.87 * 1.4e-3
    return values


def _example_case(**changes):
    return PARAMETERS.case(latitude=LATITUDE, speed=SPEED, earth="drozdovich", duration=SIMULATED_TIME,
                           output_step=OUTPUT_STEP, **changes)


def _mean_error(result) -> float:
    """Magnitude of the mean velocity-error vector (the systematic error) of a run, m/s."""
    return math.hypot(result.velocity_error_x_mean_m_s, result.velocity_error_y_mean_m_s)


def reproduce() -> Reproduction:
    """Recompute the worked example, simulate it for 48 h along its great circle, and check the errata.

    The simulation starts levelled on the accelerometers with the integrators
    preset to the true velocity. The source's conclusion is checked by two more
    runs, with and without the transport and Coriolis terms compensated, both
    with a 1-arcsec levelling error (:data:`LEVELLING_ERROR`); the friction
    example by a simulation of (30) with the dead zone the source assumes.
    """
    earth = DROZDOVICH
    example = worked_example(earth)
    run = simulated_run(_example_case())
    tilted = simulated_run(_example_case(initial_beta=LEVELLING_ERROR))
    compensated = simulated_run(_example_case(initial_beta=LEVELLING_ERROR, compensation="trajectory"))
    stuck = friction(dead_zone=FRICTION_VELOCITY_ERROR, initial_beta=FRICTION_TILT, duration=FRICTION_TIME,
                     output_step=OUTPUT_STEP)
    q = float(friction_from_velocity_error(FRICTION_VELOCITY_ERROR, earth.radius))
    spectrum, fit = run.analysis.spectrum, run.analysis.fit
    line_24h = max(spectrum.amplitude_at(1 / 86400), spectrum.amplitude_at(-1 / 86400))
    mode_amplitude = float(fit.amplitudes.max())
    schuler = 2 * math.pi * math.sqrt(earth.radius / earth.gravity)
    schuler_mean_radius = 2 * math.pi * math.sqrt(6.371e6 / earth.gravity)
    fast, slow = run.split_period_fast_s, run.split_period_slow_s
    ratio = _mean_error(tilted) / _mean_error(compensated)
    minutes, hours = (lambda s: float(to_unit(s, "min"))), (lambda s: float(to_unit(s, "h")))
    splitting = (f"with the torques (8) the vertical Earth rate omega_2 splits the Schuler period into "
                 f"{minutes(fast):.2f} and {minutes(slow):.2f} min (eigenvalues of (27); fitted to the 48-h "
                 f"simulation: {minutes(run.fitted_period_fast_s):.2f} and {minutes(run.fitted_period_slow_s):.2f} "
                 f"min), sqrt(g/R + omega_2^2/4) +- omega_2/2")
    rows = [
        compare("W*_x (21), the source's arithmetic (sin 60 deg = 0.87)", example["source_chain_W_star_x"], "m/s^2",
                printed="0.0136", where=EXAMPLE, tolerance=Tolerance(0.0, 5e-5),
                note="the printed chain 6.4e6 x 7.3^2 x 0.87 x 0.5 x 1e-10 - 2 x 7.3 x 0.87 x 1e-5 x 10, "
                     "within the rounding of the last printed digit"),
        compare("W*_x (21)", example["W_star_x"], "m/s^2", printed="0.0136", where=EXAMPLE,
                tolerance=Tolerance(0.01), note="exact sin 60 deg; the source's 0.87 moves the third digit"),
        compare("W*_y (21)", example["W_star_y"], "m/s^2", printed="0", where=EXAMPLE,
                tolerance=Tolerance(0.0, 1e-12)),
        compare("alpha_r = -W*_y / g", example["alpha_r"], "rad", printed="0", where=EXAMPLE,
                tolerance=Tolerance(0.0, 1e-12)),
        compare("beta_r = W*_x / g", example["beta_r"], "rad", printed="0.0014", where=EXAMPLE,
                tolerance=Tolerance(0.0, 5e-5),
                note="g = 9.81 m/s^2 assumed (the source gives none); within the rounding of the printed digit"),
        compare("Delta v_y = R omega_2 beta_r (29)", example["dv_y"], "m/s", printed="0.67", where=EXAMPLE,
                tolerance=Tolerance(0.01),
                erratum=f"the source's own chain 6.4e6 x 7.3e-5 x 0.87 x 1.4e-3 gives "
                        f"{example['source_chain_dv_y']:.3f} m/s; 0.67 is a misprint of 0.57"),
        compare("Delta v_x (29)", example["dv_x"], "m/s", printed="0", where=EXAMPLE,
                tolerance=Tolerance(0.0, 1e-9)),
        compare("mean Delta v_y of the 48-h simulation along the great circle", run.velocity_error_y_mean_m_s, "m/s",
                note=f"oscillates about the quasi-steady error (29), whose mean is "
                     f"{run.quasi_steady_velocity_error_y_mean_m_s:.4f} m/s; the path turns, so it drifts from the "
                     f"slowly-varying {example['dv_y']:.3f} m/s"),
        compare("Schuler period 2 pi sqrt(R/g)", minutes(schuler), "min", printed="84.4 min", where="after (12)",
                tolerance=Tolerance(0.0, 0.05),
                erratum=f"84.4 min belongs to R = 6.371e6 m ({minutes(schuler_mean_radius):.2f} min); the "
                        f"example's R = 6.4e6 m gives {minutes(schuler):.2f} min"),
        compare("long period of the error oscillation about the forced motion", hours(run.beat_period_s), "h",
                printed="24 hours", where="after (27)",
                erratum=f"there is no 24-h mode: the split modes beat every 2 pi/(Omega sin phi) = "
                        f"{hours(run.beat_period_s):.1f} h (shown); the simulated spectrum's 24-h line is "
                        f"{line_24h:.1e} m/s against {mode_amplitude:.2f} m/s for the modes"),
        compare("short period of the error oscillation: fast split mode (simulated)",
                minutes(run.fitted_period_fast_s), "min", printed="84.4 min", where="after (27)", erratum=splitting),
        compare("short period of the error oscillation: slow split mode (simulated)",
                minutes(run.fitted_period_slow_s), "min", printed="84.4 min", where="after (27)", erratum=splitting),
        compare("M_fr / H for |Delta v| = 0.01 m/s (32)", q, "1/s", printed="1.6 · 10^-6", where="after (32)",
                erratum=f"0.01 / 6.4e6 = {q:.3g} 1/s ({float(to_unit(q, 'deg/h')):.1e} deg/h), not 1.6e-6; (32) "
                        "as printed drops the factor R: |Delta v_i| = R M_fr / H"),
        compare("largest static velocity error of the friction simulation (32)",
                stuck.max_static_velocity_error_x_m_s, "m/s", printed="0.01", where="after (32)",
                tolerance=Tolerance(1e-6),
                tuned="q = M_fr / H was set to 0.01 m/s / R from this value; the simulation of (30) confirms the "
                      "static errors stay within +-R q and reach its edge",
                note=f"{hours(FRICTION_TIME):g} h from a {to_unit(FRICTION_TILT, 'arcsec'):g}-arcsec tilt; stick "
                     f"intervals: {stuck.stick_intervals}"),
        compare("mean |Delta v| with W* compensated (conclusions)", _mean_error(compensated), "m/s",
                note=f"{ratio:.0f} times smaller than without compensation (both runs 48 h with a 1-arcsec "
                     "levelling error): the source's 'additional devices' remove the systematic error"),
    ]
    return Reproduction(
        system="vertical",
        source=DROZDOVICH_1959.citation,
        constants=f"R = {earth.radius:g} m, g = {earth.gravity:g} m/s^2 (assumed; the source gives none), "
                  f"Omega = {earth.rate:g} 1/s; phi = 60 deg, v = 10 m/s due west (theta = 0, gamma = 90 deg); "
                  f"simulation {hours(SIMULATED_TIME):g} h along the great circle, output every {OUTPUT_STEP:g} s",
        rows=rows,
        notes=[
            "The source's verbal angle definitions contradict its example; one azimuth theta = psi + gamma of the "
            "x0 axis is used in the torques (8) and the accelerations (19), (21) alike.",
            "The step from (13) to (24) needs the integrators preset to the true initial velocity; the simulations "
            "start so, levelled on the accelerometers.",
            "Friction: in (30) each bearing's friction precesses the other axis, so both gimbals stick together "
            "exactly when |Delta v_x| <= R q_1 and |Delta v_y| <= R q_2; in slip the friction drives the other "
            "Schuler loop in resonance and the velocity-error amplitudes grow by 2 q_i sqrt(g R)/pi per second "
            "(4 R q_i per Schuler period).",
        ],
        details_units={"compensation_ratio": "1"},
        details={
            "W_star_x_m_s2": example["W_star_x"], "beta_r_rad": example["beta_r"], "dv_y_m_s": example["dv_y"],
            "source_chain_dv_y_m_s": example["source_chain_dv_y"], "schuler_period_s": schuler,
            "split_period_fast_s": fast, "split_period_slow_s": slow, "beat_period_s": run.beat_period_s,
            "fitted_period_fast_s": run.fitted_period_fast_s, "fitted_period_slow_s": run.fitted_period_slow_s,
            "line_24h_amplitude_m_s": line_24h, "mode_amplitude_m_s": mode_amplitude,
            "simulated_mean_dv_y_m_s": run.velocity_error_y_mean_m_s,
            "quasi_steady_mean_dv_y_m_s": run.quasi_steady_velocity_error_y_mean_m_s,
            "compensated_mean_dv_m_s": _mean_error(compensated), "compensation_ratio": ratio,
            "friction_q_rad_s": q, "friction_max_static_dv_x_m_s": stuck.max_static_velocity_error_x_m_s,
        },
        data={"example": run.analysis, "compensated": compensated.analysis, "friction": stuck},
    )


CAPTIONS = {
    "vertical_example_tilts": "Tilts of the worked example (60 deg, 10 m/s due west, 48 h on the great circle) "
                              "about the forced motion (26).",
    "vertical_example_velocity_errors": "Velocity errors: simulation, the quasi-steady error (29), its slowly-varying "
                                        "form, and the run with W* compensated (with a 1-arcsec levelling error, "
                                        "hence its small oscillation).",
    "vertical_example_spectrum": "Spectrum of the oscillation about (29): the split Schuler lines at 82.5 and "
                                 "86.8 min on either side of zero; nothing at 24 h.",
    "vertical_friction": "Coulomb friction (30), q = 0.01 m/s / R on both axes, initial tilt 0.2 arcsec: stick while "
                         "the integrator crosses the dead zone, then slip whose amplitude grows by 4 R q per Schuler "
                         "period.",
}


def report(figures_dir: Path) -> ReportSection:
    """The reproduction, its figures (worked example, spectrum, friction) and the commands (a few seconds).

    Parameters
    ----------
    figures_dir : Path
        The report's figure folder.
    """
    reproduction = reproduce()
    figures_dir = Path(figures_dir)
    refs = []
    for stem, figure in figures(reproduction).items():
        save_figure_formats(figure, figures_dir / stem)
        refs.append(FigureRef(f"{stem}.png", CAPTIONS[stem]))
    data_files(reproduction, figures_dir)
    return ReportSection(
        system="vertical",
        title="Gyro vertical with integral correction measuring velocity",
        source=reproduction.source,
        summary=("A gyro vertical whose accelerometer integrators drive its torquers (integral correction, "
                 "Schuler-tuned) measures velocity. Moving along a great circle on the rotating Earth, the "
                 "transport and Coriolis accelerations leave a systematic velocity error (0.557 m/s in the "
                 "source's example, printed as 0.67) and split Schuler oscillations that beat every "
                 "2 pi/(Omega sin phi); compensating them from the trajectory removes the systematic error. "
                 "Coulomb friction leaves static errors within +-R q, but its coupled slip is self-exciting."),
        rows=reproduction.rows,
        figures=refs,
        commands=[
            "schuler vertical reproduce --out DIR",
            "schuler vertical run --latitude 60 --speed 10 --earth drozdovich --duration '48 h' --out DIR",
            "schuler vertical run --latitude 60 --earth drozdovich --fidelity closed",
            "schuler vertical friction --initial-beta '0.2 arcsec' --duration '48 h' --out DIR",
            "schuler sweep examples/vertical_gyro_vertical.toml --param latitude=0:80:20 --out DIR",
        ],
        notes=reproduction.notes + [
            "Scale up: 'schuler vertical run --duration \"720 h\" --output-step 10' simulates 30 days.",
        ],
    )
