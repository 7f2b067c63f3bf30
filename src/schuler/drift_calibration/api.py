"""System 3 for the CLI, scenarios, sweeps and the report: ``SYSTEM``.

Example
-------
>>> r = SYSTEM.run(**{p.name: p.parse(p.default) for p in PARAMETERS if p.default is not None}, drift_y=None)
>>> round(r.azimuth_deg, 6), round(r.drift_deg_h, 9)
(80.0, 0.1)
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from schuler.drift_calibration.error_budget import ErrorBudget
from schuler.drift_calibration.monte_carlo import monte_carlo
from schuler.drift_calibration.procedure import procedure_time, run_procedure
from schuler.drift_calibration.pulses import SHAPES
from schuler.drift_calibration.reproduction import (
    SOURCE_AZIMUTH_ERROR_ARCMIN, SOURCE_RELATIVE_DRIFT_ERROR_PERCENT, default_stabilizer, error_versus_positions,
    error_versus_tau, reproduce_source)
from schuler.drift_calibration.stabilizer import simulate_cycle
from schuler.params import Parameter
from schuler.registry import FigureRef, ReportSection, ReproductionRow, System
from schuler.results import Result

DEG_H = math.radians(1.0) / 3600.0
ARCMIN = math.radians(1.0) / 60.0

SITE = (
    Parameter("latitude", "deg", 70.0, "Site latitude phi.", minimum=-90, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("azimuth", "deg", 80.0, "True initial azimuth A0 of the platform Y axis, clockwise from north."),
    Parameter("drift", "deg/h", 0.1, "Own drift of the X gyro."),
    Parameter("drift_y", "deg/h", None, "Own drift of the second horizontal (Y) gyro (default: equal to --drift)."),
)
PROCEDURE = (
    Parameter("mode", "", "three-axis", "Both horizontal channels (atan2) or the X channel only (asin).",
              choices=("three-axis", "single-axis"), kind="choice"),
    Parameter("tau", "s", 5.0, "Pulse duration tau (a cycle is 2 tau).", minimum=0, exclusive_minimum=True),
    Parameter("k1", "V/deg", 1.0, "Command angle sensor gain K1.", minimum=0, exclusive_minimum=True),
    Parameter("pulse_shape", "", "rectangular", "Torque pulse shape.", choices=tuple(SHAPES), kind="choice"),
    Parameter("pulse_rate", "deg/s", 0.01, "Torquer precession rate (K_M/H) i at the pulse peak.",
              minimum=0, exclusive_minimum=True),
    Parameter("loop_time_constant", "s", 0.0, "Stabilization-loop time constant T_s (0 = ideal; typical 2 ms).",
              minimum=0),
    Parameter("positions", "", 2, "Equally spaced platform positions N (2 = the source's 0/180 deg).",
              minimum=2, kind="integer"),
    Parameter("cycles", "", 1, "Measurement cycles averaged at each position.", minimum=1, kind="integer"),
    Parameter("monte_carlo", "", 0, "Monte Carlo procedures over the error budget (0 = one error-free run).",
              minimum=0, kind="integer"),
    Parameter("seed", "", 0, "Random seed of the Monte Carlo.", minimum=0, kind="integer"),
)
BUDGET = (
    Parameter("sensor_noise", "arcsec/Hz^0.5", 0.01, "Command-sensor white noise density.", minimum=0),
    Parameter("sensor_scale_error", "", 1e-4, "Relative error of K1 (std).", minimum=0),
    Parameter("amplitude_mismatch", "", 1e-5, "Relative +/- pulse amplitude mismatch (std).", minimum=0),
    Parameter("duration_mismatch", "", 1e-6, "Relative +/- pulse duration mismatch (std).", minimum=0),
    Parameter("pulse_asymmetry", "", 1e-5, "Tilt of the pulse top (std).", minimum=0),
    Parameter("integrator_offset", "arcsec", 0.002, "Integrator input offset as a sensor angle (std).", minimum=0),
    Parameter("lag_compensation_error", "", 0.02, "Relative error of T_s used for lag compensation (std).",
              minimum=0),
    Parameter("sway_amplitude", "arcsec", 0.2, "Base sway angle (std).", minimum=0),
    Parameter("sway_frequency", "Hz", 0.7, "Base sway frequency.", minimum=0, exclusive_minimum=True),
    Parameter("angle_random_walk", "deg/h^0.5", 0.001, "Gyro angle random walk.", minimum=0),
    Parameter("turn_angle_error", "arcsec", 5.0, "Error of each platform turn (std).", minimum=0),
    Parameter("levelling_residual", "arcsec", 10.0, "Residual tilt of each horizontal axis (std).", minimum=0),
    Parameter("initial_angle", "arcsec", 10.0, "Command-sensor angle at the start of a cycle (std).", minimum=0),
    Parameter("latitude_error", "arcmin", 1.0, "Error of the site latitude (std).", minimum=0),
)
PARAMETERS = SITE + PROCEDURE + BUDGET
_BUDGET_NAMES = {"sensor_noise": "sensor_noise_density"}


def budget_from(values: dict) -> ErrorBudget:
    """The :class:`ErrorBudget` of SI parameter values (loop time constant included)."""
    items = {_BUDGET_NAMES.get(p.name, p.name): float(values[p.name]) for p in BUDGET}
    return ErrorBudget(loop_time_constant=float(values["loop_time_constant"]), **items)


def _stabilizer(values: dict):
    stabilizer = default_stabilizer(values["tau"], SHAPES[values["pulse_shape"]](),
                                    math.degrees(values["pulse_rate"]))
    return dataclasses.replace(stabilizer, k1=values["k1"], loop_time_constant=values["loop_time_constant"],
                               sway_frequency=values["sway_frequency"])


@dataclass
class CalibrationResult(Result):
    """One calibration procedure (and optionally its Monte Carlo)."""

    mode: str
    latitude_deg: float
    true_azimuth_deg: float
    drift_deg_h: float
    drift_y_deg_h: float | None
    earth_rate_component_deg_h: float
    azimuth_deg: float
    azimuth_alternative_deg: float
    azimuth_error_arcmin: float
    cycle_time_s: float
    procedure_time_s: float
    positions: int
    monte_carlo: dict | None = None
    cycle_history: dict = field(default=None, repr=False)
    errors: dict = field(default=None, repr=False)

    def render(self):
        from rich.table import Table

        table = Table(title=f"Drift calibration ({self.mode}, {self.positions} positions)", show_header=False)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        rows = [
            ("own drift X", f"{self.drift_deg_h:.6g} deg/h"),
            ("own drift Y", "not measured" if self.drift_y_deg_h is None else f"{self.drift_y_deg_h:.6g} deg/h"),
            ("omega_X0 = Omega cos(phi) sin(A0)", f"{self.earth_rate_component_deg_h:.6g} deg/h"),
            ("azimuth A0", f"{self.azimuth_deg:.6f} deg"),
            # one channel gives only sin(A0): two azimuths fit it; two channels or more positions give one by atan2
            *([("other asin branch (180 deg - A0)", f"{self.azimuth_alternative_deg:.6f} deg")]
              if self.mode == "single-axis" and self.positions == 2 else []),
            ("azimuth error", f"{self.azimuth_error_arcmin:.4g} arcmin"),
            ("cycle time", f"{self.cycle_time_s:.3g} s"),
            ("procedure time", f"{self.procedure_time_s:.3g} s"),
        ]
        for key, value in (self.monte_carlo or {}).items():
            rows.append((f"Monte Carlo {key}", f"{value:.4g}"))
        for row in rows:
            table.add_row(*row)
        return table


def run(**values) -> CalibrationResult:
    """One error-free procedure; with ``monte_carlo`` > 0 also its Monte Carlo over the budget."""
    stabilizer = _stabilizer(values)
    mode, positions, cycles = values["mode"], int(values["positions"]), int(values["cycles"])
    drift_y = values["drift"] if values.get("drift_y") is None else values["drift_y"]
    outcome = run_procedure(stabilizer, values["latitude"], values["azimuth"], values["drift"], drift_y,
                            mode=mode, positions=positions, cycles=cycles)
    history = simulate_cycle(stabilizer, outcome.drift_x[:1] + outcome.earth_rate_component[:1], keep_history=True)
    summary, errors = None, None
    if values["monte_carlo"] > 0:
        mc = monte_carlo(stabilizer, values["latitude"], values["azimuth"], values["drift"], drift_y,
                         budget=budget_from(values), trials=int(values["monte_carlo"]), mode=mode,
                         positions=positions, cycles=cycles, seed=int(values["seed"]))
        summary = {
            "trials": mc.trials,
            "mean_relative_drift_error_percent": 100 * mc.mean_relative_drift_error,
            "rms_relative_drift_error_percent": 100 * mc.rms_relative_drift_error,
            "rms_drift_error_deg_h": mc.rms_drift_error / DEG_H,
            "mean_azimuth_error_arcmin": mc.mean_azimuth_error / ARCMIN,
            "rms_azimuth_error_arcmin": mc.rms_azimuth_error / ARCMIN,
        }
        errors = {"drift": mc.drift_errors, "azimuth": mc.azimuth_errors}
    return CalibrationResult(
        mode=mode,
        latitude_deg=math.degrees(values["latitude"]),
        true_azimuth_deg=math.degrees(values["azimuth"]) % 360.0,
        drift_deg_h=float(outcome.drift_x[0] / DEG_H),
        drift_y_deg_h=None if mode == "single-axis" else float(outcome.drift_y[0] / DEG_H),
        earth_rate_component_deg_h=float(outcome.earth_rate_component[0] / DEG_H),
        azimuth_deg=float(math.degrees(outcome.azimuth[0])) % 360.0,
        azimuth_alternative_deg=float(math.degrees(outcome.azimuth_alternative[0])) % 360.0,
        azimuth_error_arcmin=float(outcome.azimuth_error[0] / ARCMIN),
        cycle_time_s=stabilizer.cycle_time,
        procedure_time_s=procedure_time(stabilizer.tau, mode, positions, cycles),
        positions=positions,
        monte_carlo=summary,
        cycle_history={"time": history.time, "angle": history.platform_angle[0],
                       "signal": history.sensor_signal[0], "integral": history.integrator_output[0]},
        errors=errors,
    )


def write_figures(result: CalibrationResult, out_dir: Path) -> list[Path]:
    """Cycle plot (and Monte Carlo histograms) as PNG and SVG into ``out_dir``."""
    from schuler.drift_calibration.plots import plot_cycle, plot_histograms
    from schuler.io import save_figure_formats

    out_dir.mkdir(parents=True, exist_ok=True)
    h = result.cycle_history
    files = save_figure_formats(plot_cycle(h["time"], h["angle"], h["signal"], h["integral"]),
                                out_dir / "calibrate_cycle")
    if result.errors is not None:
        files += save_figure_formats(plot_histograms(result.errors["drift"], result.errors["azimuth"]),
                                     out_dir / "calibrate_histograms")
    return files


@dataclass
class ReproductionResult(Result):
    """The source's case (latitude 70 deg, azimuth 80 deg) against its 0.34 % and 2 arcmin."""

    units: ClassVar[dict] = {"budget_scale": "times the typical budget"}
    latitude_deg: float
    azimuth_deg: float
    drift_deg_h: float
    source_mean_relative_drift_error_percent: float
    source_azimuth_error_arcmin: float
    budget_scale: float
    typical_budget: dict
    scaled_budget: dict

    def render(self):
        from rich.console import Group
        from rich.table import Table

        table = Table(title="Source 001: latitude 70 deg, azimuth 80 deg (Monte Carlo)")
        for column in ("budget", "mode", "mean rel. drift error %", "RMS azimuth error arcmin"):
            table.add_column(column)
        table.add_row("source", "three-axis", f"{self.source_mean_relative_drift_error_percent}",
                      f"{self.source_azimuth_error_arcmin}")
        for label, block in (("typical", self.typical_budget), (f"typical x {self.budget_scale:.3g}",
                                                                self.scaled_budget)):
            for mode, row in block.items():
                table.add_row(label, mode, f"{row['mean_relative_drift_error_percent']:.3g}",
                              f"{row['rms_azimuth_error_arcmin']:.3g}")
        scaled = self.scaled_budget["three-axis"]["mean_relative_drift_error_percent"]
        # the drift errors do not depend on the drift itself: the relative error scales as 1/drift
        implied_drift = self.drift_deg_h * scaled / self.source_mean_relative_drift_error_percent
        explanation = (
            f"The source states neither its error budget nor its drift. The typical budget x {self.budget_scale:.3g} "
            f"gives the source's {self.source_azimuth_error_arcmin:g} arcmin (three-axis, RMS; the scale is chosen "
            f"for it). With the assumed drift {self.drift_deg_h:g} deg/h that budget gives {scaled:.3g} % against "
            f"the source's {self.source_mean_relative_drift_error_percent:g} %; the relative error scales as "
            f"1/drift, so both of the source's numbers hold together for a drift of {implied_drift:.2g} deg/h."
        )
        return Group(table, explanation)


def reproduce(trials: int = 2000) -> ReproductionResult:
    """The source's modelling case with the typical and the 2-arcmin budget."""
    r = reproduce_source(trials=trials)
    return ReproductionResult(r.latitude_deg, r.azimuth_deg, r.drift_deg_h, SOURCE_RELATIVE_DRIFT_ERROR_PERCENT,
                              SOURCE_AZIMUTH_ERROR_ARCMIN, r.budget_scale, r.typical, r.scaled)


def report(outdir: Path) -> ReportSection:
    """Figures and reproduction table for the report (about 10 s)."""
    from schuler.drift_calibration.plots import plot_trade_offs
    from schuler.io import save_figure_formats
    from schuler.params import parse_parameters

    outdir = Path(outdir)
    values = parse_parameters(PARAMETERS, {"monte_carlo": 1000})
    result = run(**values)
    files = write_figures(result, outdir)
    positions, az_positions, _ = error_versus_positions(trials=200)
    cycle_times, az_tau, _ = error_versus_tau(trials=200)
    files += save_figure_formats(plot_trade_offs(positions, az_positions, cycle_times, az_tau),
                                 outdir / "calibrate_trade_offs")
    repro = reproduce(trials=500)
    scaled = repro.scaled_budget["three-axis"]
    rows = [
        ReproductionRow("mean relative drift error (three-axis)", SOURCE_RELATIVE_DRIFT_ERROR_PERCENT,
                        scaled["mean_relative_drift_error_percent"], "%",
                        abs(scaled["mean_relative_drift_error_percent"] - 0.34) < 0.2,
                        f"typical budget x {repro.budget_scale:.3g} (the one giving 2 arcmin), drift 1 deg/h; "
                        f"the typical budget gives {repro.typical_budget['three-axis']['mean_relative_drift_error_percent']:.3g} %"),
        ReproductionRow("azimuth error (three-axis)", SOURCE_AZIMUTH_ERROR_ARCMIN,
                        scaled["rms_azimuth_error_arcmin"], "arcmin", True,
                        "RMS; the budget scale is chosen to give it: the source states no budget"),
        ReproductionRow("cycle time", "8-15", result.cycle_time_s, "s", 8.0 <= result.cycle_time_s <= 15.0,
                        "2 tau with tau = 5 s"),
    ]
    figures = [FigureRef(Path(f).name, caption) for f, caption in zip(
        [f for f in files if str(f).endswith(".png")],
        ["Platform angle, sensor signal and integrator output during one cycle (70 deg, 80 deg).",
         "Monte Carlo drift and azimuth errors, typical budget, 1000 procedures.",
         "RMS azimuth error versus number of positions and versus cycle time."])]
    return ReportSection(
        system="calibrate", title="Gyro drift calibration by alternating torque pulses",
        source="001 (Russian journal article; OCR-damaged)",
        summary="Two pulses of opposite sign, the sensor signal integrated with the pulse's sign: the reading "
                "-K1 (omega_d + omega_X0) tau^2 is free of K_M and H for any time-symmetric pulse; a 180 deg turn "
                "separates drift and Earth rate, two channels give the azimuth by atan2.",
        rows=rows, figures=figures,
        commands=["schuler calibrate run --latitude 70 --azimuth 80 --drift '0.1 deg/h' --monte-carlo 2000",
                  "schuler calibrate reproduce"],
        notes=["Sign reading: omega_X0 is the apparent drift -Omega.e_X, so (3), (5), (13)-(16) hold as printed.",
               "Scale up: --monte-carlo 100000 runs in chunks of 2000 members."],
    )


def sweep(values: dict) -> dict:
    """Vectorised sweep: one procedure per case (random draws when the budget is nonzero).

    Cases sharing the instrument, procedure and budget settings are simulated
    together in one batch; site values (latitude, azimuth, drifts) vary within it.
    """
    n = len(np.atleast_1d(values["latitude"]))
    columns = {p.name: np.broadcast_to(np.asarray(values.get(p.name, p.parse(p.default) if p.default is not None
                                                          else np.nan), dtype=object), (n,)) for p in PARAMETERS}
    out = {key: np.full(n, np.nan) for key in ("drift_rad_s", "drift_error_rad_s", "relative_drift_error",
                                               "earth_rate_component_rad_s", "azimuth_rad", "azimuth_error_rad")}
    site = {"latitude", "azimuth", "drift", "drift_y"}
    keys = [tuple(columns[p.name][i] for p in PARAMETERS if p.name not in site) for i in range(n)]
    for key in dict.fromkeys(keys):
        index = np.array([i for i in range(n) if keys[i] == key])
        first = {p.name: columns[p.name][index[0]] for p in PARAMETERS}
        stabilizer = _stabilizer(first)
        budget = budget_from(first)
        random = any(getattr(budget, f.name) for f in dataclasses.fields(budget)
                     if f.name not in ("sway_frequency", "loop_time_constant"))
        drift = columns["drift"][index].astype(float)
        drift_y = np.array([d if (y is None or (isinstance(y, float) and np.isnan(y))) else y
                            for d, y in zip(drift, columns["drift_y"][index])], dtype=float)
        outcome = run_procedure(stabilizer, columns["latitude"][index].astype(float),
                                columns["azimuth"][index].astype(float), drift, drift_y, mode=first["mode"],
                                positions=int(first["positions"]), cycles=int(first["cycles"]),
                                budget=budget if random else None, members=index.size,
                                rng=np.random.default_rng(int(first["seed"])))
        out["drift_rad_s"][index] = outcome.drift_x
        out["drift_error_rad_s"][index] = outcome.drift_x - drift
        with np.errstate(divide="ignore", invalid="ignore"):
            out["relative_drift_error"][index] = (outcome.drift_x - drift) / np.abs(drift)
        out["earth_rate_component_rad_s"][index] = outcome.earth_rate_component
        out["azimuth_rad"][index] = outcome.azimuth
        out["azimuth_error_rad"][index] = outcome.azimuth_error
    return out


SYSTEM = System(
    name="calibrate",
    title="Gyro drift calibration by alternating-sign torque pulses, with autonomous azimuth",
    source="001_72a44050135b90a6 (Russian, OCR-damaged)",
    parameters=PARAMETERS,
    run=run,
    reproduce=reproduce,
    report=report,
    sweep=sweep,
)
