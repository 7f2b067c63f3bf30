"""The ground gyrocompass as the CLI, scenario files, sweeps and the report see it.

``SYSTEM`` (a :class:`~schuler.registry.System`) bundles the ``run`` parameters,
:func:`run` (simulate a run-down record, then identify north from it),
:func:`reproduce` (the source's machine experiment), :func:`report` and the
vectorised :func:`sweep` (predicted north standard error for many cases).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.core.geometry import ARCSEC, horizontal_earth_rate, time_grid
from schuler.exceptions import InvalidParameter
from schuler.ground_gyrocompass import motion
from schuler.ground_gyrocompass.estimate import NorthEstimate, identify
from schuler.ground_gyrocompass.grid import first_box, run_stage
from schuler.ground_gyrocompass.monte_carlo import monte_carlo, predicted_errors
from schuler.ground_gyrocompass.observations import observe
from schuler.ground_gyrocompass.reproduction import reproduce
from schuler.params import Parameter, parse_parameters
from schuler.registry import FigureRef, ReportSection, ReproductionRow, System
from schuler.results import Result

SOURCE = (
    "Fedorov, Kikot, Shtefan: meridian by a two-degree ground gyrocompass during natural rotor run-down"
    " (source 004)"
)

MOTION_PARAMETERS = (
    Parameter("alpha0", "rad", motion.SOURCE_ALPHA0,
              "True initial angle alpha0 of the rotor axis from north (source: 3.69 pi/540; small angles).",
              -0.5, 0.5),
    Parameter("alpha0_dot", "rad/s", motion.SOURCE_ALPHA0_DOT, "True initial azimuth rate.", -0.01, 0.01),
    Parameter("torque", "N*m", 0.0, "Constant harmful torque about the suspension axis (simulated)."),
)
INSTRUMENT_PARAMETERS = (
    Parameter("lambda", "1/s", motion.SOURCE_LAMBDA, "Decay rate of the rotor's angular momentum (known or nominal).",
              0.0, exclusive_minimum=True),
    Parameter("hm", "N*m*s", motion.SOURCE_HM, "Initial rotor angular momentum H_m (known or nominal).",
              0.0, exclusive_minimum=True),
    Parameter("inertia", "kg*m^2", motion.SOURCE_INERTIA, "Moment of inertia J about the suspension axis.",
              0.0, exclusive_minimum=True),
    Parameter("latitude", "deg", None, "Latitude of the site (sets omega_h = Omega cos(latitude)).", -90.0, 90.0),
    Parameter("omega_h", "rad/s", None, "Horizontal Earth rate (default: the source's 3.65e-5 1/s).",
              0.0, exclusive_minimum=True),
)
OBSERVATION_PARAMETERS = (
    Parameter("duration", "s", motion.SOURCE_DURATION, "Observation window from the release.", 0.0,
              exclusive_minimum=True),
    Parameter("step", "s", motion.SOURCE_STEP, "Sampling step.", 0.0, exclusive_minimum=True),
    Parameter("noise", "rad", 0.0, "Standard deviation of the read-out noise (e.g. '1 arcsec').", 0.0),
    Parameter("quantisation", "rad", 0.0, "Read-out resolution (0: none).", 0.0),
    Parameter("offset", "rad", 0.0, "Offset of absolute readings (absolute reading only)."),
    Parameter("seed", "", 0, "Seed of the noise generator.", kind="integer"),
)
READING_PARAMETER = Parameter(
    "reading", "", "relative", "Observed coordinate: alpha - alpha0 (relative) or alpha + offset (absolute).",
    choices=("relative", "absolute"), kind="choice",
)
FIT_PARAMETERS = (
    Parameter("unknowns", "", 4, "Unknowns: 2 (alpha0, rate), 3 (+lambda), 4 (+Hm), 5 (+harmful torque).", 2, 5,
              kind="integer"),
    Parameter("method", "", "lsq", "lsq: variable projection; grid: the source's 3-stage grid.",
              choices=("lsq", "grid"), kind="choice"),
)

SIMULATE_PARAMETERS = MOTION_PARAMETERS + INSTRUMENT_PARAMETERS + OBSERVATION_PARAMETERS + (READING_PARAMETER,)
IDENTIFY_PARAMETERS = INSTRUMENT_PARAMETERS + (READING_PARAMETER,) + FIT_PARAMETERS
PARAMETERS = SIMULATE_PARAMETERS + FIT_PARAMETERS


def resolve_omega_h(latitude=None, omega_h=None) -> float:
    """Omega_h from the latitude, or as given, or the source's 3.65e-5 rad/s."""
    if latitude is not None and omega_h is not None:
        raise InvalidParameter("latitude", "give either the latitude or omega_h, not both")
    if latitude is not None:
        return horizontal_earth_rate(latitude, EARTH_RATE)
    return motion.SOURCE_OMEGA_H if omega_h is None else float(omega_h)


@dataclass
class ObservationRecord(Result):
    """A simulated run-down record (``t_s``, ``alpha_rad``) and the truth behind it."""

    samples: int
    duration_s: float
    reading: str
    true_north_deg: float
    omega_h: float
    B: float
    noise_arcsec: float
    file: str | None = None
    time: np.ndarray = field(repr=False, default=None)
    observed: np.ndarray = field(repr=False, default=None)


def simulate_record(**values) -> ObservationRecord:
    """Simulate the observed coordinate of a run-down (closed form (9) with the torque).

    Keyword arguments are the SI values of :data:`SIMULATE_PARAMETERS`.
    """
    values = _with_defaults(SIMULATE_PARAMETERS, values)
    omega_h = resolve_omega_h(values["latitude"], values["omega_h"])
    b = float(motion.directive_coefficient(values["hm"], omega_h, values["inertia"]))
    time = time_grid(values["duration"], values["step"])
    angle = motion.closed_form(
        time, values["alpha0"], values["alpha0_dot"], values["lambda"], b, values["torque"] / values["inertia"]
    )
    observed = observe(
        angle, values["alpha0"], values["noise"], values["quantisation"], values["reading"], values["offset"],
        np.random.default_rng(values["seed"]),
    )
    return ObservationRecord(
        samples=time.size,
        duration_s=float(time[-1]),
        reading=values["reading"],
        true_north_deg=math.degrees(-values["alpha0"]),
        omega_h=omega_h,
        B=b,
        noise_arcsec=values["noise"] / ARCSEC,
        time=time,
        observed=observed,
    )


def identify_record(time, observed, **values) -> NorthEstimate:
    """Identify north from a record with the instrument's known/nominal values (SI keywords)."""
    values = _with_defaults(IDENTIFY_PARAMETERS, values)
    return identify(
        time,
        observed,
        values["unknowns"],
        decay_rate=values["lambda"],
        hm=values["hm"],
        inertia=values["inertia"],
        omega_h=resolve_omega_h(values["latitude"], values["omega_h"]),
        reading=values["reading"],
        method=values["method"],
    )


@dataclass
class NorthRun(Result):
    """A simulated run-down identified: the estimate (its keys at the top level) and its error."""

    true_north_deg: float
    north_error_arcsec: float
    north_error_in_std: float | None
    estimate: NorthEstimate = field(repr=False, default=None)
    record: ObservationRecord = field(repr=False, default=None)

    def to_dict(self):
        data = self.estimate.to_dict()
        data.update(super().to_dict())
        return data

    def render(self):
        from rich.console import Group

        line = f"true north {self.true_north_deg:.6f} deg; error of the estimate {self.north_error_arcsec:.3g} arcsec"
        if self.north_error_in_std is not None:
            line += f" ({self.north_error_in_std:.2f} standard errors)"
        return Group(self.estimate.render(), line)


def run(**values) -> NorthRun:
    """``schuler north run``: simulate a run-down record and identify north from it."""
    values = _with_defaults(PARAMETERS, values)
    record = simulate_record(**{p.name: values[p.name] for p in SIMULATE_PARAMETERS})
    estimate = identify_record(record.time, record.observed, **{p.name: values[p.name] for p in IDENTIFY_PARAMETERS})
    error = (estimate.north_deg - record.true_north_deg) * 3600.0
    std = estimate.north_std_arcsec
    return NorthRun(
        true_north_deg=record.true_north_deg,
        north_error_arcsec=error,
        north_error_in_std=None if not std else error / std,
        estimate=estimate,
        record=record,
    )


def _with_defaults(parameters, values):
    """Fill missing keys with the parameters' defaults (SI); reject unknown keys."""
    # parse_parameters names an unknown key and gives the defaults; the given values are SI already
    defaults = parse_parameters(parameters, dict.fromkeys(values))
    return defaults | {name: value for name, value in values.items() if value is not None}


def write_figures(estimate: NorthEstimate, outdir, prefix="north", decay_rate=None, coefficient=None) -> list[Path]:
    """Fit and residuals, the first grid stage's misfit map, and the predicted error vs window."""
    from schuler.ground_gyrocompass import plots

    outdir = Path(outdir)
    files = plots.plot_fit(estimate, outdir / f"{prefix}_fit")
    lam = estimate.decay_rate if decay_rate is None else decay_rate
    b = estimate.B if coefficient is None else coefficient
    unknowns = min(estimate.unknowns, 4)
    stage = run_stage(
        estimate.time, estimate.observed, first_box(unknowns, lam, b), lam, b, estimate.reading, estimate.unknowns == 5
    )
    files += plots.plot_misfit_map(stage, outdir / f"{prefix}_misfit_map")
    durations = np.arange(60.0, 601.0, 30.0)
    step = float(np.median(np.diff(estimate.time))) if estimate.time.size > 1 else 1.0
    noise = math.sqrt(estimate.misfit / estimate.n_samples)
    if noise < 0.01 * ARCSEC:  # a noise-free record: show the error per arcsec of read-out noise
        noise = ARCSEC
    cases = durations.size
    truth = {
        "alpha0": estimate.alpha0_rad,
        "alpha0_dot": estimate.alpha0_dot,
        "decay_rate": estimate.decay_rate,
        "coefficient": estimate.B,
        "specific_torque": estimate.torque / estimate.inertia,
        "offset": estimate.offset_rad or 0.0,
    }
    series = []
    for count in sorted({2, estimate.unknowns}):
        std = predicted_errors(
            {k: np.full(cases, v) for k, v in truth.items()}, durations, np.full(cases, step), np.full(cases, noise),
            unknowns=count, reading=estimate.reading,
        )["alpha0_std"]
        series.append((f"{count} unknowns", std / ARCSEC, "-o"))
    title = f"Predicted north error for read-out noise {noise / ARCSEC:.3g} arcsec"
    files += plots.plot_error_vs_time(durations, series, outdir / f"{prefix}_error_vs_time", title)
    return files


def report(outdir) -> ReportSection:
    """The report section: Tables 1-3 reproduced, the identification, figures."""
    from schuler.ground_gyrocompass import plots

    outdir = Path(outdir)
    result = reproduce(4)
    figures = []
    files = write_figures(result.estimate, outdir, "north")
    captions = {
        "north_fit": "The source's simulated run-down (200 s) and the 4-unknown fit; residuals at round-off.",
        "north_misfit_map": "First grid stage (the source's box) at the best lambda, H_m: log10 misfit.",
        "north_error_vs_time": "Predicted north standard error against observation time.",
    }
    b = result.estimate.B
    study = monte_carlo(
        {"alpha0": motion.SOURCE_ALPHA0, "alpha0_dot": motion.SOURCE_ALPHA0_DOT, "decay_rate": motion.SOURCE_LAMBDA,
         "coefficient": b},
        np.arange(60.0, 601.0, 90.0), np.array([1.0, 10.0]) * ARCSEC, members=100, unknowns=4,
    )
    files += plots.plot_study(study, outdir / "north_monte_carlo")
    captions["north_monte_carlo"] = (
        "Monte Carlo (100 runs per point, 4 unknowns) against the Jacobian's prediction: "
        "north error against observation time for 1 and 10 arcsec read-out noise."
    )
    for path in files:
        if path.suffix == ".png":
            figures.append(FigureRef(path.name, captions[path.stem]))
    rows = []
    for stage in result.stages:
        label = f"{stage['unknowns']} unknowns, stage {stage['stage']}"
        rows.append(ReproductionRow(
            f"{label}: best cell", ", ".join(f"{v:g}" for v in stage["printed_best"]),
            float(stage["computed_best"][0]), "pi/540 (alpha0; full cell in note)", stage["best_agrees"],
            "computed " + ", ".join(f"{v:g}" for v in stage["computed_best"]),
        ))
        rows.append(ReproductionRow(
            f"{label}: misfit F", stage["printed_misfit"], stage["computed_misfit"], "rad^2", stage["misfit_agrees"],
            "F = sum (model - simulator)^2 of alpha - alpha0" if stage["misfit_agrees"]
            else "printed misfits behave like a norm, not a sum of squares (see Table 1 note)",
        ))
    rows.append(ReproductionRow(
        "4 unknowns: alpha0 by least squares", f"{motion.SOURCE_ALPHA0:.10g}", result.estimate.alpha0_rad, "rad",
        abs(result.alpha0_error_rad) < 1e-9, f"{result.estimate.nfev} model evaluations, no grid",
    ))
    table = result.table1
    relative, absolute = table["experiment_shape"]["relative"], table["experiment_shape"]["absolute"]
    notes = [
        "Table 1: the plain sum of squares of alpha - alpha0 finds the printed minimum cell (4 pi/540, 4e-4) with "
        f"F = {table['computed_sum_of_squares'][13, 10]:.4g} (printed 0.9751e-3), but grows quadratically away from "
        f"it (at k = m = 0: {table['computed_sum_of_squares'][9, 6]:.3g}, printed 12.4e-3). No reading of the misfit "
        "(sum of squares, its root, mean, rms, sum of |r|, max |r|; relative or absolute coordinate) matches the table "
        "within 5 % after one scale factor. Away from the minimum the squared table fits a quadratic form in "
        f"(alpha0, alpha0_dot) to {100 * table['quadratic_fit_max_deviation']:.1f} %, i.e. it is the norm of some "
        f"residual linear in the initial conditions, but of shape {table['table_shape'][0]:.2f}, "
        f"{table['table_shape'][1]:.0f} s^2 (cross / alpha0^2, alpha0_dot^2 / alpha0^2) where this experiment gives "
        f"{relative[0]:.2f}, {relative[1]:.0f} s^2 (relative) or {absolute[0]:.2f}, {absolute[1]:.0f} s^2 "
        "(absolute). Cells (k, m) = (-5, -1) and (1, -6) are misprints.",
        "4 unknowns, first stage: the printed best cell is not the grid's minimum; "
        f"F there is {result.four_unknowns_first_stage['printed_best_misfit']:.4g} while cell "
        f"{tuple(result.four_unknowns_first_stage['first_stage_best'])} has "
        f"{result.four_unknowns_first_stage['first_stage_misfit']:.4g}. The printed later boxes happen to contain "
        "the truth, which lies on the third-stage grid, so the source's final values follow.",
        f"lambda and B are correlated: {_correlation(result.estimate, 'decay_rate', 'coefficient'):.3f} in the "
        "4-unknown fit; only B = Hm Omega_h / J is identifiable.",
    ]
    return ReportSection(
        system="north",
        title="Ground gyrocompass during rotor run-down",
        source=SOURCE,
        summary=(
            "Bessel-function solution (9) of the run-down motion, checked against numerical integration; north from "
            "the observed motion by variable-projection least squares (2-5 unknowns) and by the source's grid."
        ),
        rows=rows,
        figures=figures,
        commands=["schuler north reproduce --unknowns 4", "schuler north run --noise '1 arcsec' --duration 300"],
        notes=notes + ["Monte Carlo: raise members in schuler.ground_gyrocompass.monte_carlo.monte_carlo to scale up."],
    )


def _correlation(estimate: NorthEstimate, first: str, second: str) -> float:
    names = estimate.correlation["parameters"]
    matrix = estimate.correlation["matrix"]
    return float(matrix[names.index(first)][names.index(second)])


def sweep(values: dict) -> dict:
    """Predicted north standard error for n cases at once (vectorised, from the Jacobian).

    ``values`` holds each run parameter as an SI array of length n (``latitude`` and
    ``omega_h`` may be NaN for "not set"). Returns arrays of length n:
    ``north_std_arcsec``, ``alpha0_std_rad``, ``true_north_deg``, ``B``.
    """
    arrays = {p.name: np.atleast_1d(np.asarray(values[p.name])) if p.name in values else None for p in PARAMETERS}
    n = max(a.size for a in arrays.values() if a is not None)
    filled = {}
    for spec in PARAMETERS:
        given = arrays[spec.name]
        if given is None:
            default = None if spec.default is None else spec.parse(spec.default, spec.name)
            given = np.full(n, np.nan if default is None else default, dtype=object if spec.kind == "choice" else float)
        filled[spec.name] = np.broadcast_to(given, (n,))
    latitude = filled["latitude"].astype(float)
    omega_given = filled["omega_h"].astype(float)
    omega_h = np.where(np.isfinite(omega_given), omega_given, motion.SOURCE_OMEGA_H)
    has_latitude = np.isfinite(latitude)
    if np.any(has_latitude):
        omega_h = np.where(has_latitude, horizontal_earth_rate(np.where(has_latitude, latitude, 0.0)), omega_h)
    hm, inertia, lam = (filled[k].astype(float) for k in ("hm", "inertia", "lambda"))
    b = motion.directive_coefficient(hm, omega_h, inertia)
    motion.check_decay_rate(lam)
    std = np.full(n, np.nan)
    unknowns = filled["unknowns"].astype(int)
    readings = filled["reading"].astype(str)
    for count in np.unique(unknowns):
        for reading in np.unique(readings):
            pick = (unknowns == count) & (readings == reading)
            if not pick.any():
                continue
            truth = {
                "alpha0": filled["alpha0"].astype(float)[pick],
                "alpha0_dot": filled["alpha0_dot"].astype(float)[pick],
                "decay_rate": lam[pick],
                "coefficient": b[pick],
                "specific_torque": (filled["torque"].astype(float) / inertia)[pick],
                "offset": filled["offset"].astype(float)[pick],
            }
            std[pick] = predicted_errors(
                truth, filled["duration"].astype(float)[pick], filled["step"].astype(float)[pick],
                filled["noise"].astype(float)[pick], filled["quantisation"].astype(float)[pick], int(count), reading,
            )["alpha0_std"]
    return {
        "north_std_arcsec": std / ARCSEC,
        "alpha0_std_rad": std,
        "true_north_deg": np.degrees(-filled["alpha0"].astype(float)),
        "B": np.asarray(b, dtype=float) * np.ones(n),
    }


SYSTEM = System(
    name="north",
    title="Ground gyrocompass during natural rotor run-down",
    source=SOURCE,
    parameters=PARAMETERS,
    run=run,
    reproduce=reproduce,
    report=report,
    sweep=sweep,
)
