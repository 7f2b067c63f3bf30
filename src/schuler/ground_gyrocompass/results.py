"""What ``schuler north`` returns and writes: the result types and :func:`write_files`.

* :class:`NorthRun` -- ``north run``: a simulated run-down record identified
  (every output of the system's ``evaluate``, and the estimate for figures);
* :class:`NorthIdentification` -- ``north identify RECORD``;
* :class:`ObservationRecord` -- ``north simulate -o FILE``.

Fields are SI with the unit in the name or in the class's ``units`` map; ``render()``
shows north in deg, arcmin, arcsec and deg-min-sec, errors in arcsec. North is the
azimuth of the meridian from the rotor axis at release, -alpha0 (Fedorov, Kikot and
Shtefan (2020), eq. (10)); errors are identified - true.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler.ground_gyrocompass import plots
from schuler.ground_gyrocompass.estimate import NorthEstimate
from schuler.ground_gyrocompass.grid import STEP_ALPHA0, run_stage
from schuler.ground_gyrocompass.monte_carlo import predicted_errors
from schuler.io import write_dataframe_csv
from schuler.reproduction import Reproduction
from schuler.results import Result, RunResult
from schuler.units import from_unit, to_unit

PARAMETER_KEYS = {"alpha0": "alpha0_rad", "alpha0_dot": "alpha0_dot_rad_s", "decay_rate": "decay_rate",
                  "coefficient": "directive_coefficient", "specific_torque": "torque", "offset": "offset_rad"}
"""The estimator's parameter names -> the result keys that hold them."""

_UNITS = {"decay_rate": "1/s", "directive_coefficient": "1/s^2", "hm": "N m s", "torque": "N m",
          "omega_h": "rad/s", "inertia": "kg m^2", "misfit_rad2": "rad^2", "samples": "1",
          "model_evaluations": "1", "unknowns": "1"}
_RUN_UNITS = {"identified_decay_rate": "1/s", "identified_directive_coefficient": "1/s^2", "identified_hm": "N m s",
              "identified_torque": "N m", "omega_h": "rad/s", "misfit_rad2": "rad^2", "samples": "1",
              "model_evaluations": "1", "unknowns": "1"}


def convergence(estimate: NorthEstimate) -> str:
    """How the estimator ended, in words (never the optimiser's own message).

    Parameters
    ----------
    estimate : NorthEstimate
        An estimate (its method, unknowns, evaluations and convergence).

    Returns
    -------
    str
        One line, e.g. "variable projection converged (12 model evaluations)".
    """
    if estimate.method == "grid":
        return f"3-stage grid refinement, {estimate.nfev} cells"
    if estimate.unknowns == 2:
        return "linear least squares (eq. (10))"
    if estimate.converged:
        return f"variable projection converged ({estimate.nfev} model evaluations)"
    return f"variable projection stopped after {estimate.nfev} model evaluations without converging"


def _angle(value: float | None, unit: str, digits: int) -> str:
    if value is None or not math.isfinite(value):
        return "-"
    text = f"{float(to_unit(value, unit)):.{digits}f}"
    if float(text) == 0:
        text = text.lstrip("-")  # no negative zero
    return f"{text} {unit}"


def _north_table(title: str, north_rad: float, std_rad: float | None, dms: str, std_heading: str = "standard error"):
    from rich.table import Table

    table = Table(title=title)
    table.add_column("north from the rotor axis at release", justify="right")
    table.add_column(std_heading, justify="right")
    for unit, digits, std_digits in (("deg", 6, 7), ("arcmin", 4, 4), ("arcsec", 2, 3)):
        table.add_row(_angle(north_rad, unit, digits), _angle(std_rad, unit, std_digits))
    table.add_row(dms, "")
    return table


def _parameter_table(rows, title="Parameters (known ones without standard error)"):
    from rich.table import Table

    table = Table(title=title)
    table.add_column("parameter")
    table.add_column("value", justify="right")
    table.add_column("standard error", justify="right")
    for name, value, error, unit in rows:
        table.add_row(name, f"{value:.10g} {unit}", "" if error is None else f"{error:.3g} {unit}")
    return table


@dataclass
class NorthRun(RunResult):
    """A simulated run-down record identified: every output of the system's ``evaluate``.

    ``north_std_predicted_rad`` is what the read-out noise and quantisation give by the
    linearised covariance; ``north_std_rad`` is the fit's own (residual-based)
    standard error, round-off for the nominal noise-free record (None without
    residual degrees of freedom). ``estimate`` holds the record and fit (not in ``to_dict``).
    """

    fidelity: str
    unknowns: int
    method: str
    reading: str
    readout_noise_rad: float
    true_north_rad: float
    north_rad: float
    north_error_rad: float
    north_std_predicted_rad: float
    north_std_rad: float | None
    identified_alpha0_rad: float
    identified_alpha0_dot_rad_s: float
    identified_decay_rate: float
    identified_directive_coefficient: float
    identified_hm: float
    identified_torque: float
    identified_offset_rad: float
    misfit_rad2: float
    residual_rms_rad: float
    omega_h: float
    samples: int
    model_evaluations: int
    converged: bool
    estimate: NorthEstimate | None = field(default=None, repr=False)

    units: ClassVar[dict[str, str]] = _RUN_UNITS

    def __post_init__(self):
        self.samples, self.model_evaluations = int(self.samples), int(self.model_evaluations)

    def render(self):
        from rich.console import Group
        from rich.table import Table

        dms = self.estimate.north_dms if self.estimate is not None else ""
        north = _north_table(f"North from a simulated run-down ({self.unknowns} unknowns, {self.method}, "
                             f"{self.fidelity} record)", self.north_rad, self.north_std_predicted_rad, dms,
                             "standard error predicted for the read-out noise")
        accuracy = Table(title="Accuracy", show_header=False)
        accuracy.add_column("quantity")
        accuracy.add_column("value", justify="right")
        accuracy.add_row("true north", _angle(self.true_north_rad, "deg", 6))
        accuracy.add_row("error of the estimate (identified - true)", _angle(self.north_error_rad, "arcsec", 3))
        accuracy.add_row("standard error from the fit's residuals", _angle(self.north_std_rad, "arcsec", 3))
        if self.monte_carlo is not None:
            stats = self.monte_carlo.statistics["north_error_rad"]
            rate = self.monte_carlo.statistics["converged"]["mean"]
            accuracy.add_row(f"Monte Carlo ({self.monte_carlo.members} records): mean, std of the error",
                             f"{_angle(stats['mean'], 'arcsec', 3)}, {_angle(stats['std'], 'arcsec', 3)}")
            accuracy.add_row("records identified and converged", "-" if rate is None else f"{100 * rate:.1f} %")
        rows = [
            ("alpha0", self.identified_alpha0_rad, None, "rad"),
            ("alpha0_dot", self.identified_alpha0_dot_rad_s, None, "rad/s"),
            ("lambda", self.identified_decay_rate, None, "1/s"),
            ("B = Hm Omega_h / J", self.identified_directive_coefficient, None, "1/s^2"),
            ("Hm", self.identified_hm, None, "N m s"),
            ("harmful torque", self.identified_torque, None, "N m"),
        ]
        if self.reading == "absolute":
            rows.append(("reading offset", self.identified_offset_rad, None, "rad"))
        summary = (f"misfit {self.misfit_rad2:.4g} rad^2 over {self.samples} samples "
                   f"(rms {_angle(self.residual_rms_rad, 'arcsec', 3)}); "
                   + (convergence(self.estimate) if self.estimate is not None else ""))
        return Group(north, accuracy, _parameter_table(rows, "Identified (or known) parameters"), summary)


@dataclass
class NorthIdentification(Result):
    """North identified from an observation record, with standard errors (SI; None where not identified).

    ``correlation`` holds the correlation matrix of the identified parameters, named
    by their keys in this result (``decay_rate``, ``directive_coefficient`` ...).
    """

    unknowns: int
    method: str
    reading: str
    identified: list[str]
    north_rad: float
    north_std_rad: float | None
    alpha0_rad: float
    alpha0_std_rad: float | None
    alpha0_dot_rad_s: float
    alpha0_dot_std_rad_s: float | None
    decay_rate: float
    decay_rate_std: float | None
    directive_coefficient: float
    directive_coefficient_std: float | None
    hm: float
    hm_std: float | None
    torque: float
    torque_std: float | None
    offset_rad: float | None
    offset_std_rad: float | None
    misfit_rad2: float
    residual_rms_rad: float
    samples: int
    model_evaluations: int
    converged: bool
    convergence: str
    inertia: float
    omega_h: float
    correlation: dict[str, Any]
    estimate: NorthEstimate | None = field(default=None, repr=False)

    units: ClassVar[dict[str, str]] = {**_UNITS, "decay_rate_std": "1/s", "directive_coefficient_std": "1/s^2",
                                       "hm_std": "N m s", "torque_std": "N m", "correlation": "1"}

    @classmethod
    def from_estimate(cls, estimate: NorthEstimate) -> NorthIdentification:
        """The result of ``north identify`` from an estimate: its values, standard errors and correlations.

        Parameters
        ----------
        estimate : NorthEstimate
            What the estimator identified (SI values; kept for the figures).

        Returns
        -------
        NorthIdentification
            North = -alpha0 and every parameter with its standard error, SI.
        """
        names = [PARAMETER_KEYS[name] for name in estimate.correlation["parameters"]]
        return cls(
            unknowns=estimate.unknowns, method=estimate.method, reading=estimate.reading, identified=names,
            north_rad=-estimate.alpha0_rad, north_std_rad=estimate.alpha0_rad_std,
            alpha0_rad=estimate.alpha0_rad, alpha0_std_rad=estimate.alpha0_rad_std,
            alpha0_dot_rad_s=estimate.alpha0_dot, alpha0_dot_std_rad_s=estimate.alpha0_dot_std,
            decay_rate=estimate.decay_rate, decay_rate_std=estimate.decay_rate_std,
            directive_coefficient=estimate.B, directive_coefficient_std=estimate.B_std,
            hm=estimate.Hm, hm_std=estimate.Hm_std, torque=estimate.torque, torque_std=estimate.torque_std,
            offset_rad=estimate.offset_rad, offset_std_rad=estimate.offset_rad_std,
            misfit_rad2=estimate.misfit, residual_rms_rad=math.sqrt(estimate.misfit / estimate.n_samples),
            samples=estimate.n_samples, model_evaluations=estimate.nfev, converged=estimate.converged,
            convergence=convergence(estimate), inertia=estimate.inertia, omega_h=estimate.omega_h,
            correlation={"parameters": names, "matrix": estimate.correlation["matrix"]},
            estimate=estimate)

    def render(self):
        from rich.console import Group

        dms = self.estimate.north_dms if self.estimate is not None else ""
        north = _north_table(f"North from the ground gyrocompass ({self.unknowns} unknowns, {self.method})",
                             self.north_rad, self.north_std_rad, dms)
        rows = [
            ("alpha0", self.alpha0_rad, self.alpha0_std_rad, "rad"),
            ("alpha0_dot", self.alpha0_dot_rad_s, self.alpha0_dot_std_rad_s, "rad/s"),
            ("lambda", self.decay_rate, self.decay_rate_std, "1/s"),
            ("B = Hm Omega_h / J", self.directive_coefficient, self.directive_coefficient_std, "1/s^2"),
            ("Hm", self.hm, self.hm_std, "N m s"),
            ("harmful torque", self.torque, self.torque_std, "N m"),
        ]
        if self.offset_rad is not None:
            rows.append(("reading offset", self.offset_rad, self.offset_std_rad, "rad"))
        summary = (f"misfit {self.misfit_rad2:.4g} rad^2 over {self.samples} samples "
                   f"(rms {_angle(self.residual_rms_rad, 'arcsec', 3)}); {self.convergence}")
        return Group(north, _parameter_table(rows), summary)


@dataclass
class ObservationRecord(Result):
    """A simulated run-down record (``t_s``, ``alpha_rad``) written to ``record_file``, and the truth behind it."""

    record_file: str
    samples: int
    duration_s: float
    output_step_s: float
    reading: str
    true_north_rad: float
    omega_h: float
    directive_coefficient: float
    readout_noise_rad: float
    seed: int
    time: np.ndarray | None = field(default=None, repr=False)
    observed: np.ndarray | None = field(default=None, repr=False)
    files: list[Path] = field(default_factory=list, repr=False)

    units: ClassVar[dict[str, str]] = {"samples": "1", "omega_h": "rad/s", "directive_coefficient": "1/s^2",
                                       "seed": "1"}

    def render(self):
        from rich.table import Table

        table = Table(title=f"Simulated run-down record: {self.record_file}", show_header=False)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        table.add_row("samples", f"{self.samples} ({self.duration_s:g} s every {self.output_step_s:g} s)")
        table.add_row("reading", self.reading)
        table.add_row("true north from the rotor axis", _angle(self.true_north_rad, "deg", 6))
        table.add_row("read-out noise (1 sigma)", _angle(self.readout_noise_rad, "arcsec", 3))
        table.add_row("seed", str(self.seed))
        return table


@dataclass(frozen=True)
class ReproductionFigures:
    """What the reproduction's figures need: the identification, the first grid stage, Table 1 side by side."""

    estimate: NorthEstimate
    first_stage: Any
    table1: dict[str, np.ndarray]


def write_files(result: Result, out_dir: Path) -> list[Path]:
    """Figures (PNG and SVG) and CSV data of a run, an identification, a record or the reproduction.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    out_dir : Path
        Folder for the figures (PNG, SVG) and data files (CSV); created if missing.
    """
    out_dir = Path(out_dir)
    if isinstance(result, Reproduction):
        return _reproduction_files(result.data, out_dir)
    if isinstance(result, ObservationRecord):
        return plots.plot_record(result.time, result.observed, out_dir / "north_record",
                                 f"Simulated run-down record ({result.reading} reading)")
    if isinstance(result, (NorthRun, NorthIdentification)) and result.estimate is not None:
        noise = result.readout_noise_rad if isinstance(result, NorthRun) else None
        files = estimate_files(result.estimate, out_dir, noise)
        if isinstance(result, NorthRun) and result.monte_carlo is not None:
            errors = to_unit(result.monte_carlo.samples["north_error_rad"], "arcsec")
            files += plots.plot_error_histogram(
                errors, float(to_unit(result.north_std_predicted_rad, "arcsec")), out_dir / "north_monte_carlo",
                f"North error over {result.monte_carlo.members} records ({result.unknowns} unknowns)")
        return files
    raise TypeError(f"north writes no files for {type(result).__name__}")


def estimate_files(estimate: NorthEstimate, out_dir: Path, noise_rad: float | None = None) -> list[Path]:
    """The fit and residuals, the misfit map around the estimate, the predicted error against the window, the CSV.

    Parameters
    ----------
    estimate : NorthEstimate
        An estimate with its record.
    out_dir : Path
        Folder the files are written into.
    noise_rad : float, optional
        Read-out noise standard deviation, rad (default: the residuals' rms, or 1 arcsec for a noise-free
        record).

    Returns
    -------
    list of Path
        The figures (PNG, SVG) and ``north_record_fit.csv``.
    """
    import pandas as pd


    out_dir = Path(out_dir)
    files = plots.plot_fit(estimate, out_dir / "north_fit")
    a0, rate = estimate.alpha0_rad, estimate.alpha0_dot
    box = {"alpha0": (a0 - 9 * STEP_ALPHA0, a0 + 9 * STEP_ALPHA0, STEP_ALPHA0),
           "alpha0_dot": (rate - 6e-4, rate + 6e-4, 1e-4)}
    stage = run_stage(estimate.time, estimate.observed, box, estimate.decay_rate, estimate.B, estimate.reading,
                      estimate.unknowns == 5)
    files += plots.plot_misfit_map(stage, out_dir / "north_misfit_map",
                                   title=f"Misfit around the estimate ({stage.cells} cells, the source's first-stage "
                                         "steps), at the estimated lambda and B")
    files += error_vs_time_files(estimate, out_dir, noise_rad)
    fitted = estimate.observed - estimate.residuals
    frame = pd.DataFrame({"t_s": estimate.time, "observed_rad": estimate.observed, "fitted_rad": fitted,
                          "residual_rad": estimate.residuals})
    files.append(write_dataframe_csv(frame, out_dir / "north_record_fit.csv"))
    return files


def error_vs_time_files(estimate: NorthEstimate, out_dir: Path, noise_rad: float | None = None) -> list[Path]:
    """The standard error of north predicted for windows around the record's, 2 and the estimate's unknowns.

    ``noise_rad`` is the read-out noise (default: the residuals' rms, or 1 arcsec
    for a noise-free record).

    Parameters
    ----------
    estimate : NorthEstimate
        An estimate with its record: its parameters are taken as the truth, its sampling step is kept.
    out_dir : Path
        Folder the figure is written into.
    noise_rad : float, optional
        Read-out noise standard deviation, rad (default: the residuals' rms, or 1 arcsec for a noise-free
        record).

    Returns
    -------
    list of Path
        The figure's files (PNG, SVG).
    """

    step = float(np.median(np.diff(estimate.time))) if estimate.time.size > 1 else 1.0
    arcsec = from_unit(1.0, "arcsec")
    noise = noise_rad or math.sqrt(estimate.misfit / estimate.n_samples)
    if noise < 0.01 * arcsec:  # a noise-free record: the error per arcsec of read-out noise
        noise = arcsec
    duration = float(estimate.time[-1])
    parameters = len(estimate.correlation["parameters"])
    shortest = max(min(60.0, duration / 2), (parameters + 1) * step)
    durations = np.linspace(shortest, max(600.0, 2 * duration, 2 * shortest), 19)
    truth = {"alpha0": estimate.alpha0_rad, "alpha0_dot": estimate.alpha0_dot, "decay_rate": estimate.decay_rate,
             "coefficient": estimate.B, "specific_torque": estimate.torque / estimate.inertia,
             "offset": estimate.offset_rad or 0.0}
    series = []
    for count in sorted({2, estimate.unknowns}):
        # one window at a time: the longest holds twice the record's samples, no more
        std = np.array([predicted_errors({k: np.array([v]) for k, v in truth.items()}, np.array([window]),
                                         np.array([step]), np.array([noise]), unknowns=count,
                                         reading=estimate.reading)["alpha0_std"][0] for window in durations])
        series.append((f"{count} unknowns", to_unit(std, "arcsec"), "-o"))
    return plots.plot_error_vs_time(durations, series, out_dir / "north_error_vs_time",
                                    f"Predicted north error for read-out noise {to_unit(noise, 'arcsec'):.3g} arcsec")


def _reproduction_files(data: ReproductionFigures, out_dir: Path) -> list[Path]:
    import pandas as pd


    files = plots.plot_fit(data.estimate, out_dir / "north_fit")
    files += plots.plot_misfit_map(data.first_stage, out_dir / "north_misfit_map",
                                   title=f"The source's first grid stage ({data.first_stage.cells} cells): "
                                         "sum of squares")
    files.append(write_dataframe_csv(pd.DataFrame(data.table1), out_dir / "north_table1.csv"))
    return files
