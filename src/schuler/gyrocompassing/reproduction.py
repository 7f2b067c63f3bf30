"""The KPI manual's design example and statements, reproduced with their errata.

Source: Meleshko, "Physical gyrocompassing of a semi-analytic INS", KPI lab
manual (:data:`schuler.references.KPI_LAB_MANUAL`); equation numbers are the manual's.

Constants: Earth rate U = 7.292115e-5 rad/s (the source does not state one),
g = 9.80665 m/s^2, Kyiv (the source's university) at 50.45 deg for "the" latitude.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from schuler.contract import Cases, FigureRef, ReportSection, monte_carlo
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_design, loop_gains
from schuler.core.lti import simulate
from schuler.core.random import RandomStreams
from schuler.gyrocompassing import analytic, evaluation, models, plots
from schuler.gyrocompassing.case import AlignmentCase, GyrocompassingAccuracyWarning
from schuler.gyrocompassing.simulation import evaluate_cases, run_case
from schuler.references import KPI_LAB_MANUAL
from schuler.reproduction import Reproduction, Tolerance, compare
from schuler.units import from_unit, to_unit

KYIV_LATITUDE = math.radians(50.45)
"""Latitude of Kyiv, rad: the source's laboratory."""
PRINTED_C_GAMMA = 0.08
"""c_Gamma printed for T = 30 s, 1/s."""
PRINTED_C_A = 22.0
"""c_a printed for T = 30 s, 1/s."""
EXAMPLE_DRIFT = from_unit(0.01, "deg/h")
"""0.01 deg/h, rad/s: the residual drift of the worked cases."""
EXAMPLE_ACCEL_ERROR = 1e-4 * STANDARD_GRAVITY
"""100 micro-g, m/s^2."""
RUN_DURATION = 1500.0
"""Simulated time of the worked cases, s: 40 decay times 1/h at T = 30 s, zeta = 0.8 (transient < 1e-17)."""


def _printed_aperiodic_time(c_gamma: float, c_a: float, latitude: float) -> float:
    """The aperiodic settling time as printed: 5 / (-h + sqrt(h^2 - omega0^2)) (negative)."""
    h = c_gamma / 2
    omega0_sq = c_a * EARTH_RATE * math.cos(latitude)
    return 5.0 / (-h + math.sqrt(h**2 - omega0_sq))


def reproduce() -> Reproduction:
    """Reproduce the design example (T = 30 s) and check the source's statements and equations.

    Every printed number is taken from Sec. 2 of the manual (after (1.25)) unless
    the row says otherwise.

    Examples
    --------
    >>> r = reproduce()
    >>> [row.quantity for row in r.rows][:2], r.failures
    (['c_Gamma for T = 30 s, zeta = 0.8', 'c_a for T = 30 s at Kyiv (50.45 deg)'], [])
    """
    where = "Sec. 2, after (1.25)"
    rows = []
    c_gamma, c_a_kyiv = loop_gains(KYIV_LATITUDE, DESIGN_TIME_CONSTANT, DESIGN_DAMPING)
    rows.append(compare(
        "c_Gamma for T = 30 s, zeta = 0.8", c_gamma, "1/s", printed="0.08", where=where,
        erratum="c_Gamma = 2 zeta / T; the printed 0.08 needs zeta = "
                f"{PRINTED_C_GAMMA * DESIGN_TIME_CONSTANT / 2:.2f}"))
    latitude_for_22 = math.acos(1.0 / (DESIGN_TIME_CONSTANT**2 * EARTH_RATE * PRINTED_C_A))
    rows.append(compare(
        "c_a for T = 30 s at Kyiv (50.45 deg)", c_a_kyiv, "1/s", printed="22", where=where,
        erratum=f"c_a = 1 / (T^2 U cos(latitude)); the printed 22 holds at {math.degrees(latitude_for_22):.2f} deg "
                f"(U = {EARTH_RATE} rad/s)"))
    _, zeta_printed = loop_design(latitude_for_22, PRINTED_C_GAMMA, PRINTED_C_A)
    rows.append(compare(
        "damping of the printed pair (0.08, 22)", float(zeta_printed), "1", printed="0.8", where=where,
        erratum="the printed gains give an aperiodic loop (zeta > 1), not the zeta = 0.8 they are meant for"))
    printed_time = _printed_aperiodic_time(PRINTED_C_GAMMA, PRINTED_C_A, latitude_for_22)
    rows.append(compare(
        "aperiodic settling time of the printed pair", float(analytic.settling_time(PRINTED_C_GAMMA, PRINTED_C_A,
                                                                                    latitude_for_22)), "s",
        printed="5 / (-h + sqrt(h^2 - omega0^2))", value=printed_time, where="Sec. 2, before the T, zeta design",
        erratum=f"the printed formula gives {printed_time:.4g} s (negative); corrected 5 / (h - sqrt(h^2 - omega0^2))"))
    design = AlignmentCase(latitude=KYIV_LATITUDE, drift_east=EXAMPLE_DRIFT, drift_z=EXAMPLE_DRIFT,
                                 latitude_error=from_unit(1.0, "arcmin"))
    run = run_case(design, "simplified", duration=RUN_DURATION)
    rows.append(compare(
        "settling time 5/h, T = 30 s, zeta = 0.8 (simulated 1 % band)", float(run.simulated.settling_time[0]), "s",
        printed="t = 5/h", value=run.analytic["settling_time_s"], where="Sec. 2, before the T, zeta design",
        tolerance=Tolerance(0.05),
        note="5/h against the last exit of the simulated azimuth error from a 1 % band"))
    rows.append(compare(
        "delta_y (1.21) vs simulated (1.19): 0.01 deg/h east and up, 1 arcmin latitude error",
        float(to_unit(run.simulated.azimuth_error[0], "arcmin")), "arcmin",
        printed="(1.21)", value=float(to_unit(run.analytic["azimuth_error_analytic_rad"], "arcmin")), where="(1.21)",
        tolerance=Tolerance(1e-9), note="the formula (1.21) evaluated, against the exact simulation of (1.19)"))
    east_only = analytic.steady_state(math.radians(50.0), c_gamma, c_a_kyiv, drift_east=EXAMPLE_DRIFT)[0]
    rows.append(compare(
        "delta_y for 0.01 deg/h east drift at 50 deg", float(to_unit(east_only, "arcmin")), "arcmin",
        note="dominant term of (1.21), Delta omega_dxi / (U cos(latitude)); a worked value of this toolkit"))
    rate = {}
    for label, builder in (("printed", models.printed_mu_nu_model), ("corrected", models.full_mu_nu_model)):
        rate[label] = float(np.max(builder(KYIV_LATITUDE, 0.0, c_gamma, c_a_kyiv).eigenvalues().real))
    rows.append(compare(
        "largest real part of the (1.17) eigenvalues at A = 0, as printed", rate["printed"], "1/s",
        note=f"as printed the azimuth loop diverges (e-folding {1 / rate['printed'] / 3600:.1f} h); "
             f"corrected: {rate['corrected']:.4f} 1/s"))
    accel = AlignmentCase(latitude=math.radians(50.0), accel_error_x=EXAMPLE_ACCEL_ERROR)
    shift = {m: run_case(accel, m, duration=RUN_DURATION).simulated.azimuth_error[0] for m in ("simplified", "full")}
    rows.append(compare(
        "azimuth shift from 100 micro-g on x at 50 deg, A = 0 (full model)", float(to_unit(shift["full"], "arcsec")),
        "arcsec", printed="does not depend on accelerometer errors", value=0.0, where=where,
        tolerance=Tolerance(0.0, 1e-3),
        erratum=f"holds for (1.19) ({float(to_unit(shift['simplified'], 'arcsec')):.2g} arcsec); in (1.17)/(1.18) "
                "alpha U_z adds about eps_alpha tan(latitude)"))
    tilt = AlignmentCase(latitude=math.radians(50.0), azimuth=math.pi / 2, accel_error_x=EXAMPLE_ACCEL_ERROR)
    beta_full = run_case(tilt, "full", duration=RUN_DURATION).simulated.level_error_beta[0]
    eps_beta_printed = EXAMPLE_ACCEL_ERROR * math.sin(math.pi / 2) / STANDARD_GRAVITY
    rows.append(compare(
        "beta_y for 100 micro-g on x at A = 90 deg", float(to_unit(beta_full, "arcsec")), "arcsec",
        printed="eps_beta = (Delta a_x sin A + Delta a_y cos A)/g", value=float(to_unit(-eps_beta_printed, "arcsec")),
        where=where,
        erratum="(1.8) gives eps_beta = (Delta a_y cos A - Delta a_x sin A)/g: the printed sign of Delta a_x is wrong"))
    return Reproduction(
        system="align",
        source=KPI_LAB_MANUAL.citation,
        constants=f"U = {EARTH_RATE} rad/s (not stated in the source), g = {STANDARD_GRAVITY} m/s^2, "
                  f"latitude {math.degrees(KYIV_LATITUDE)} deg (Kyiv)",
        rows=rows,
        notes=[
            "The third line of (1.17) pairs cos A with mu and sin A with nu; (1.10), (1.11) and (1.18) require "
            "(nu + eps_y) cos A + (mu - eps_x) sin A. The models use the corrected line.",
            "In (1.24) C1 has 'delta_2' for delta_y; the critical C2 is delta'0 + h (delta0 - delta_y).",
        ],
        data={"simplified model (1.19), design example": run},
    )


def report(outdir: Path) -> ReportSection:
    """Write this system's figures into ``outdir`` and describe them (a few seconds).

    The Monte Carlo uses 400 members and the latitude sweep 9 simulated cases;
    ``schuler align run --monte-carlo 10000`` and ``schuler sweep`` scale them up.

    Parameters
    ----------
    outdir : Path
        The report's figure folder.
    """
    outdir = Path(outdir)
    reproduction = reproduce()
    base = AlignmentCase(drift_east=EXAMPLE_DRIFT)
    runs = {f"{name} model": run_case(base, name, duration=1200) for name in ("full", "simplified")}
    slow = AlignmentCase(drift_east=EXAMPLE_DRIFT, damping=0.4)
    phase_runs = {"zeta = 0.8": runs["full model"], "zeta = 0.4": run_case(slow, "full", duration=1200)}
    latitudes = np.radians(np.arange(0.0, 81.0, 10.0))
    # gains fixed at their T = 30 s, zeta = 0.8 values for 50 deg: the loop slows and turns aperiodic poleward
    fixed_gains = AlignmentCase().gains()
    sweep_case = AlignmentCase(latitude=latitudes, drift_east=EXAMPLE_DRIFT, c_gamma=float(fixed_gains[0]),
                                     c_a=float(fixed_gains[1]))
    with warnings.catch_warnings():
        # the sweep reaches 80 deg on purpose, to show the degradation the warning is about
        warnings.simplefilter("ignore", GyrocompassingAccuracyWarning)
        swept = evaluate_cases(sweep_case, "full", simulate_runs=True)
    mc_case = evaluation.PARAMETERS.case(drift_east=EXAMPLE_DRIFT, sigma_drift=EXAMPLE_DRIFT,
                                         sigma_drift_z=EXAMPLE_DRIFT, sigma_accel=EXAMPLE_ACCEL_ERROR, duration=1200.0)
    mc = monte_carlo(evaluation.evaluate, evaluation.OUTPUTS, mc_case, 400, RandomStreams(0))
    mc_sigma = float(evaluation.evaluate(Cases.from_case(mc_case))["azimuth_error_sigma_rad"][0])
    corrected = AlignmentCase(latitude=KYIV_LATITUDE)
    gains = corrected.gains()
    time = np.arange(0.0, 48 * 3600.0 + 1, 600.0)
    x0 = models.initial_state("full", corrected.initial_azimuth_error)
    printed = simulate(models.printed_mu_nu_model(KYIV_LATITUDE, 0.0, *gains), time, x0)["delta"]
    fixed = simulate(models.full_mu_nu_model(KYIV_LATITUDE, 0.0, *gains), time, x0)["delta"]
    figures = {
        "align_time_history": plots.time_history(runs),
        "align_phase_trajectory": plots.phase_trajectory(phase_runs),
        "align_latitude_sweep": plots.sweep_curves(
            np.degrees(latitudes), "latitude [deg]",
            {"azimuth_error_analytic_arcmin": to_unit(swept["azimuth_error_analytic_rad"], "arcmin"),
             "azimuth_error_arcmin": to_unit(swept["azimuth_error_simulated_rad"], "arcmin"),
             "settling_time_s": swept["settling_time_s"],
             "settling_time_simulated_s": swept["settling_time_simulated_s"]}),
        "align_monte_carlo": plots.monte_carlo_histogram(
            to_unit(mc.samples["azimuth_error_rad"], "arcmin"), float(to_unit(mc_sigma, "arcmin")),
            float(to_unit(mc.statistics["azimuth_error_rad"]["mean"], "arcmin")), "full"),
        "align_printed_1_17": plots.printed_versus_corrected(time, printed, fixed),
    }
    plots.write_figures(figures, outdir, formats=("png",))
    captions = {
        "align_time_history": "Azimuth error delta and level error beta against time, full and simplified "
                              "models (0.01 deg/h east drift, 50 deg, T = 30 s, zeta = 0.8): the source's Fig. 1.4.",
        "align_phase_trajectory": "Phase trajectory in the (delta, beta) plane (task 5) for zeta = 0.8 and 0.4.",
        "align_latitude_sweep": "Accuracy and time against latitude with the gains of T = 30 s, zeta = 0.8 at "
                                "50 deg held fixed: (1.21) and the analytic settling time (lines), simulated full "
                                "model (circles). The error grows as 1/cos(latitude); poleward of 66 deg the loop "
                                "is aperiodic and slows down. Where the loop oscillates, the simulated time is "
                                "shorter than 5/h: 5/h is the time the envelope exp(-h t) takes to fall to "
                                "exp(-5) = 0.67 %, while the simulation reports the last exit from a 1 % band, "
                                "which happens at the last oscillation peak above 1 %, before the envelope "
                                "ln(100 sqrt(1 + h^2/omega^2))/h; near the equator omega is largest and the two "
                                "differ most (150-170 s against 187.5 s).",
        "align_monte_carlo": "Monte Carlo (400 members; 0.01 deg/h drifts, 100 micro-g accelerometers, "
                             "1-sigma): simulated azimuth errors and the analytic 1-sigma.",
        "align_printed_1_17": "The printed third line of (1.17) diverges at A = 0; the corrected one converges.",
    }
    return ReportSection(
        system="align",
        title="Physical gyrocompassing of a semi-analytic platform INS",
        source=reproduction.source,
        summary=(
            "The platform is driven to north by its accelerometers: three linear models (full in (mu, nu), "
            "full in (beta, alpha), simplified (1.19)) are simulated exactly and compared with the closed forms "
            "(1.21), (1.22), (1.25). The source's design example and several printed equations are corrected."
        ),
        rows=reproduction.rows,
        figures=[FigureRef(f"{stem}.png", captions[stem]) for stem in figures],
        commands=[
            "schuler align reproduce",
            "schuler align run --latitude 50 --azimuth 30 --drift-east '0.01 deg/h' --out align",
            "schuler sweep examples/align_gyrocompassing.toml --param latitude=0:80:10 --out align-sweep",
            "schuler align run --drift-east '0.01 deg/h' --monte-carlo 10000 --out align",
        ],
        notes=reproduction.notes,
    )
