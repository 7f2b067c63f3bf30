"""The gyrocompassing system as the CLI, scenario files, sweeps and the report see it.

``SYSTEM`` bundles the ``run`` parameters (one definition each), :func:`run`
(one case on the chosen model, optionally a Monte Carlo), :func:`reproduce`
(the source's design example with its errata), :func:`report` and the vectorised
:func:`sweep`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.gyrocompassing import models, study
from schuler.gyrocompassing.reproduction import ReproductionResult, reproduce, report
from schuler.params import Parameter, parse_parameters
from schuler.registry import System
from schuler.results import Result
from schuler.units import to_unit

_ERROR_RANGE = {"minimum": -600.0, "maximum": 600.0}

PARAMETERS = (
    Parameter("latitude", "deg", 50.0, "Latitude of the site.", minimum=-90, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("azimuth", "deg", 0.0, "Azimuth A of the platform's x_g axis.", minimum=-360, maximum=360),
    Parameter("drift_east", "deg/h", 0.0, "Residual drift about east, Delta omega_dxi (estimate - true)."),
    Parameter("drift_north", "deg/h", 0.0, "Residual drift about north, Delta omega_deta."),
    Parameter("drift_x", "deg/h", 0.0, "Residual drift about the platform x axis (adds to east/north)."),
    Parameter("drift_y", "deg/h", 0.0, "Residual drift about the platform y axis (adds to east/north)."),
    Parameter("drift_z", "deg/h", 0.0, "Residual drift about the vertical (platform z) axis."),
    Parameter("latitude_error", "arcmin", 0.0, "Error Delta phi of the latitude entered.", **_ERROR_RANGE),
    Parameter("accel_error_x", "g", 0.0, "Error Delta a_x of the x accelerometer.", minimum=-0.1, maximum=0.1),
    Parameter("accel_error_y", "g", 0.0, "Error Delta a_y of the y accelerometer.", minimum=-0.1, maximum=0.1),
    Parameter("time_constant", "s", study.DEFAULT_TIME_CONSTANT,
              "Time constant T of the azimuth loop (gains not given follow from T and zeta).",
              minimum=0, exclusive_minimum=True),
    Parameter("damping", "", study.DEFAULT_DAMPING, "Damping ratio zeta of the azimuth loop.",
              minimum=0, exclusive_minimum=True),
    Parameter("c_gamma", "1/s", None, "Level correction gain c_Gamma (default 2 zeta / T).",
              minimum=0, exclusive_minimum=True),
    Parameter("c_a", "1/s", None, "Azimuth correction gain c_a (default 1 / (T^2 U cos(latitude))).",
              minimum=0, exclusive_minimum=True),
    Parameter("initial_azimuth_error", "deg", math.degrees(study.DEFAULT_INITIAL_AZIMUTH_ERROR),
              "Initial azimuth misalignment delta0.", minimum=-90, maximum=90),
    Parameter("initial_beta", "arcmin", 0.0, "Initial level error beta0 (0: levelled).", **_ERROR_RANGE),
    Parameter("initial_alpha", "arcmin", 0.0, "Initial level error alpha0 (0: levelled).", **_ERROR_RANGE),
    Parameter("model", "", "full", "Model: full (mu, nu) (1.17), full-ab (beta, alpha) (1.18) or simplified (1.19).",
              choices=models.MODELS, kind="choice"),
    Parameter("duration", "s", None, "Simulated time (default 2 h, or 3 settling times if longer, at most 48 h).",
              minimum=0, exclusive_minimum=True),
    Parameter("time_step", "s", 1.0, "Output step (the simulation is exact between outputs).",
              minimum=0, exclusive_minimum=True),
    Parameter("max_latitude", "deg", math.degrees(study.DEFAULT_MAX_LATITUDE),
              "Latitude above which azimuth is reported not observable.", minimum=0, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("monte_carlo", "", 0, "Number of Monte Carlo members (0: none).", minimum=0, kind="integer"),
    Parameter("sigma_drift", "deg/h", 0.01, "Monte Carlo 1-sigma of the x and y residual drifts.", minimum=0),
    Parameter("sigma_drift_z", "deg/h", 0.01, "Monte Carlo 1-sigma of the vertical residual drift.", minimum=0),
    Parameter("sigma_accel", "g", 1e-4, "Monte Carlo 1-sigma of each accelerometer error.", minimum=0),
    Parameter("seed", "", 0, "Monte Carlo random seed.", minimum=0, kind="integer"),
)
"""Every option of ``schuler align run`` (and key of an ``align`` scenario)."""

CASE_FIELDS = (
    "latitude", "azimuth", "drift_east", "drift_north", "drift_x", "drift_y", "drift_z", "latitude_error",
    "accel_error_x", "accel_error_y", "time_constant", "damping", "c_gamma", "c_a", "initial_azimuth_error",
    "initial_beta", "initial_alpha", "max_latitude",
)
"""Parameters that describe a case (the others choose the model, the run and the Monte Carlo)."""

_ARCMIN = "arcmin"


def _arcmin(x) -> float:
    return float(to_unit(x, _ARCMIN))


def _regime(c_gamma: float, c_a: float, latitude: float) -> str:
    h_sq = (c_gamma / 2) ** 2
    omega0_sq = c_a * math.cos(latitude) * study.EARTH_RATE
    if math.isclose(h_sq, omega0_sq, rel_tol=1e-9):
        return "critical"
    return "oscillatory" if omega0_sq > h_sq else "aperiodic"


@dataclass
class MonteCarloSummary:
    """Distribution of the simulated azimuth error over the Monte Carlo members."""

    members: int
    azimuth_error_mean_arcmin: float
    azimuth_error_std_arcmin: float
    azimuth_error_sigma_analytic_arcmin: float
    azimuth_error_sigma_simplified_arcmin: float
    azimuth_error_percentiles_arcmin: dict
    constraints_ok_fraction: float
    samples_arcmin: np.ndarray = field(repr=False)


@dataclass
class AlignmentResult(Result):
    """One gyrocompassing run: accuracy, time, constraint check (and a Monte Carlo).

    Attributes
    ----------
    azimuth_error_arcmin : float
        Simulated steady state of the chosen model (the azimuth error at the end of the run).
    azimuth_error_analytic_arcmin, level_error_beta_analytic_arcmin : float
        (1.21) and (1.25).
    azimuth_error_closed_form_arcmin : float
        Closed-form steady state of the chosen model ((1.21) for the simplified one).
    full_minus_simplified_arcsec : float
        Full-model steady state minus (1.21): what alpha U_z adds from accelerometer
        errors (about eps_alpha tan(latitude)) and from the latitude error.
    settling_time_s, settling_time_simulated_s : float
        5/h (or the corrected aperiodic formula) and the simulated 1 % band time
        (inf, null in JSON, if the run ends before the band is reached).
    c_gamma, c_a : float
        Gains used, 1/s.
    constraints_ok : bool
        |delta| < 0.4 rad, |beta| < 0.01 rad and |delta'| < 0.2 rad/s over the whole run.
    """

    model: str
    azimuth_error_arcmin: float
    azimuth_error_analytic_arcmin: float
    azimuth_error_closed_form_arcmin: float
    full_minus_simplified_arcsec: float
    level_error_beta_arcmin: float
    level_error_beta_analytic_arcmin: float
    settling_time_s: float
    settling_time_simulated_s: float
    regime: str
    c_gamma: float
    c_a: float
    time_constant_s: float
    damping: float
    max_abs_delta_rad: float
    max_abs_beta_rad: float
    max_abs_delta_rate_rad_per_s: float
    constraints_ok: bool
    constraint_violations: list
    duration_s: float
    monte_carlo: MonteCarloSummary | None = None
    run: study.CaseRun | None = field(default=None, repr=False)
    simplified_run: study.CaseRun | None = field(default=None, repr=False)

    units = {"c_gamma": "1/s", "c_a": "1/s", "damping": "1"}

    def render(self):
        from rich.table import Table

        table = Table(title=f"Gyrocompassing, {self.model} model", show_header=True)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        rows = [
            ("azimuth error, simulated steady state", f"{self.azimuth_error_arcmin:.4f} arcmin"),
            ("azimuth error, analytic (1.21)", f"{self.azimuth_error_analytic_arcmin:.4f} arcmin"),
            ("full model minus (1.21)", f"{self.full_minus_simplified_arcsec:.3f} arcsec"),
            ("level error beta, simulated", f"{self.level_error_beta_arcmin:.4f} arcmin"),
            ("level error beta, analytic (1.25)", f"{self.level_error_beta_analytic_arcmin:.4f} arcmin"),
            ("settling time, analytic", f"{self.settling_time_s:.1f} s ({self.regime})"),
            ("settling time, simulated 1 % band", f"{self.settling_time_simulated_s:.1f} s"),
            ("c_Gamma, c_a", f"{self.c_gamma:.4g} 1/s, {self.c_a:.4g} 1/s"),
            ("T, zeta", f"{self.time_constant_s:.4g} s, {self.damping:.3g}"),
            ("max |delta|, |beta|, |delta'|",
             f"{self.max_abs_delta_rad:.3g} rad, {self.max_abs_beta_rad:.3g} rad, {self.max_abs_delta_rate_rad_per_s:.3g} rad/s"),
            ("constraints (0.4 rad, 0.01 rad, 0.2 rad/s)",
             "ok" if self.constraints_ok else "; ".join(self.constraint_violations)),
        ]
        if self.monte_carlo is not None:
            mc = self.monte_carlo
            rows += [
                (f"Monte Carlo ({mc.members} members): mean, std",
                 f"{mc.azimuth_error_mean_arcmin:.4f}, {mc.azimuth_error_std_arcmin:.4f} arcmin"),
                ("analytic 1-sigma: model, (1.21)",
                 f"{mc.azimuth_error_sigma_analytic_arcmin:.4f}, {mc.azimuth_error_sigma_simplified_arcmin:.4f} arcmin"),
            ]
        for name, value in rows:
            table.add_row(name, value)
        return table


def case_from_values(values: dict) -> study.AlignmentCase:
    """An :class:`~schuler.gyrocompassing.study.AlignmentCase` from SI parameter values (None: default)."""
    return study.AlignmentCase(**{name: values[name] for name in CASE_FIELDS if values.get(name) is not None})


def run(
    *, latitude=None, azimuth=None, drift_east=None, drift_north=None, drift_x=None, drift_y=None, drift_z=None,
    latitude_error=None, accel_error_x=None, accel_error_y=None, time_constant=None, damping=None, c_gamma=None,
    c_a=None, initial_azimuth_error=None, initial_beta=None, initial_alpha=None, model=None, duration=None,
    time_step=None, max_latitude=None, monte_carlo=None, sigma_drift=None, sigma_drift_z=None, sigma_accel=None,
    seed=None,
) -> AlignmentResult:
    """What ``schuler align run`` does: one case, from SI values as parsed from :data:`PARAMETERS`.

    Every argument is the SI value of the parameter of the same name (rad, rad/s,
    m/s^2, s, 1/s); None takes the parameter's default. The case is simulated on
    ``model`` with the constraint check; ``monte_carlo`` > 0 adds a Monte Carlo
    of that many members with the sigmas given.

    Examples
    --------
    >>> r = run(drift_east=np.radians(0.01) / 3600, model="simplified")
    >>> round(r.azimuth_error_arcmin, 3), r.constraints_ok
    (3.556, True)
    """
    given = {name: value for name, value in locals().items() if value is not None}  # only the arguments so far
    si = parse_parameters(PARAMETERS, {}) | given
    case = case_from_values(si)
    model = si["model"]
    case_run = study.run_case(case, model, duration=si["duration"], time_step=si["time_step"])
    closed = case_run.analytic
    full_closed = study.analytic_results(case, "full-ab")["azimuth_error_rad"]
    summary = None
    if si["monte_carlo"]:
        mc = study.monte_carlo(case, model, si["monte_carlo"], sigma_drift=si["sigma_drift"],
                               sigma_drift_z=si["sigma_drift_z"], sigma_accel=si["sigma_accel"], seed=si["seed"],
                               duration=case_run.duration, time_step=si["time_step"])
        samples = np.asarray(to_unit(mc.azimuth_errors, _ARCMIN))
        summary = MonteCarloSummary(
            members=int(mc.azimuth_errors.size),
            azimuth_error_mean_arcmin=float(np.mean(samples)),
            azimuth_error_std_arcmin=_arcmin(mc.std),
            azimuth_error_sigma_analytic_arcmin=_arcmin(mc.sigma_analytic),
            azimuth_error_sigma_simplified_arcmin=_arcmin(mc.sigma_simplified),
            azimuth_error_percentiles_arcmin={f"p{q}": float(np.percentile(samples, q)) for q in (5, 50, 95)},
            constraints_ok_fraction=mc.constraints_ok_fraction,
            samples_arcmin=samples,
        )
    simulated = case_run.simulated
    simplified_run = case_run
    if model != "simplified":
        with warnings.catch_warnings():
            # the same case on (1.19), for the comparison figures: run_case above has already warned about it
            warnings.simplefilter("ignore", study.DegradedAccuracyWarning)
            simplified_run = study.run_case(case, "simplified", duration=case_run.duration, time_step=si["time_step"])
    return AlignmentResult(
        model=model,
        azimuth_error_arcmin=_arcmin(simulated.azimuth_error[0]),
        azimuth_error_analytic_arcmin=_arcmin(closed["azimuth_error_analytic_rad"]),
        azimuth_error_closed_form_arcmin=_arcmin(closed["azimuth_error_rad"]),
        full_minus_simplified_arcsec=float(to_unit(full_closed - closed["azimuth_error_analytic_rad"], "arcsec")),
        level_error_beta_arcmin=_arcmin(simulated.level_error_beta[0]),
        level_error_beta_analytic_arcmin=_arcmin(closed["level_error_beta_analytic_rad"]),
        settling_time_s=closed["settling_time_s"],
        settling_time_simulated_s=float(simulated.settling_time[0]),
        regime=_regime(closed["c_gamma"], closed["c_a"], case.latitude),
        c_gamma=closed["c_gamma"],
        c_a=closed["c_a"],
        time_constant_s=closed["time_constant_s"],
        damping=closed["damping"],
        max_abs_delta_rad=float(simulated.max_abs_delta[0]),
        max_abs_beta_rad=float(simulated.max_abs_beta[0]),
        max_abs_delta_rate_rad_per_s=float(simulated.max_abs_delta_rate[0]),
        constraints_ok=case_run.constraints_ok,
        constraint_violations=list(case_run.violations),
        duration_s=case_run.duration,
        monte_carlo=summary,
        run=case_run,
        simplified_run=simplified_run,
    )


def sweep(values: dict, *, simulate_runs: bool = False) -> dict[str, np.ndarray]:
    """Vectorised evaluation of n cases: every given parameter an SI array of length n.

    Missing parameters take their defaults; NaN entries of ``c_gamma`` / ``c_a``
    mean "from T and zeta". ``model`` may be one name or an array of names. The
    closed forms are pure numpy (10^6 cases in well under a second); with
    ``simulate_runs`` the cases are also simulated in batches on the engine.

    Returns
    -------
    dict of ndarray (length n)
        ``azimuth_error_rad`` (steady state of the model), ``azimuth_error_analytic_rad``
        ((1.21)), ``level_error_beta_rad``, ``level_error_beta_analytic_rad`` ((1.25)),
        ``settling_time_s``, ``c_gamma``, ``c_a`` (1/s), ``time_constant_s``, ``damping``;
        with ``simulate_runs`` also the simulated values and ``constraints_ok``.

    Examples
    --------
    >>> out = sweep({"latitude": np.radians([0.0, 50.0]), "drift_east": np.full(2, np.radians(0.01) / 3600)})
    >>> np.round(np.degrees(out["azimuth_error_analytic_rad"]) * 60, 3)
    array([2.286, 3.556])
    """
    unknown = sorted(set(values) - {p.name for p in PARAMETERS})
    if unknown:
        raise InvalidParameter(unknown[0], "unknown parameter")
    lengths = {np.size(v) for k, v in values.items() if k != "model" and v is not None and np.ndim(v) > 0}
    if len(lengths) > 1:
        raise InvalidParameter("sweep", f"parameter arrays have different lengths: {sorted(lengths)}")
    n = lengths.pop() if lengths else 1
    defaults = parse_parameters(PARAMETERS, {})
    arrays = {}
    for name in CASE_FIELDS:
        value = values.get(name, defaults[name])
        if value is None:
            continue
        array = np.asarray(value, dtype=float)
        arrays[name] = float(array) if name == "max_latitude" and array.ndim == 0 else np.broadcast_to(array, (n,))
    if np.ndim(arrays.get("max_latitude", 0.0)) > 0:
        arrays["max_latitude"] = float(np.max(arrays["max_latitude"]))
    model_values = values.get("model", defaults["model"])
    duration = values.get("duration", defaults["duration"])
    time_step = values.get("time_step", defaults["time_step"])
    duration = None if duration is None or np.all(np.isnan(duration)) else float(np.max(duration))
    time_step = float(np.min(time_step))
    case = study.AlignmentCase(**arrays)
    if np.ndim(model_values) == 0:
        return study.evaluate_cases(case, str(model_values), simulate_runs=simulate_runs, duration=duration,
                                    time_step=time_step)
    names = np.broadcast_to(np.asarray(model_values, dtype=str), (n,))
    models_used = [str(names[0])] if np.all(names == names[0]) else [str(m) for m in np.unique(names)]
    if len(models_used) == 1:
        return study.evaluate_cases(case, models_used[0], simulate_runs=simulate_runs, duration=duration,
                                    time_step=time_step)
    output: dict[str, np.ndarray] = {}
    for model in models_used:
        chosen = names == model
        subset = study.AlignmentCase(**{k: (v[chosen] if isinstance(v, np.ndarray) else v) for k, v in arrays.items()})
        part = study.evaluate_cases(subset, model, simulate_runs=simulate_runs, duration=duration, time_step=time_step)
        for key, array in part.items():
            output.setdefault(key, np.empty(n, dtype=array.dtype))[chosen] = array
    return output


SYSTEM = System(
    name="align",
    title="Physical gyrocompassing of a semi-analytic platform INS",
    source="Meleshko V. V., KPI lab manual \"Physical gyrocompassing of a semi-analytic INS\" (source 003)",
    parameters=PARAMETERS,
    run=run,
    reproduce=reproduce,
    report=report,
    sweep=sweep,
)

__all__ = ["PARAMETERS", "SYSTEM", "AlignmentResult", "ReproductionResult", "run", "sweep", "reproduce"]
