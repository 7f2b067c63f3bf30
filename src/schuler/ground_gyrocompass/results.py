"""What ``schuler north`` returns: how a run renders, and the results of its actions.

* :class:`NorthRun` -- ``north run``: the system's :class:`~schuler.results.SystemResult`
  (every output of ``evaluate``, the record and its fit as the histories
  ``north_record_fit``), shown in deg, arcmin, arcsec and deg-min-sec;
* :class:`NorthIdentification` -- ``north identify RECORD``;
* :class:`ObservationRecord` -- ``north simulate -o FILE``.

Fields are SI with the unit in the name or in the class's ``units`` map; errors
in arcsec. North is the azimuth of the meridian from the rotor axis at release,
-alpha0 (Fedorov, Kikot and Shtefan (2020), eq. (10)); errors are identified - true.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler.core.response import Histories
from schuler.ground_gyrocompass.estimate import NorthEstimate, dms_text
from schuler.results import Result, SystemResult
from schuler.units import to_unit

PARAMETER_KEYS = {"alpha0": "alpha0_rad", "alpha0_dot": "alpha0_dot_rad_s", "decay_rate": "decay_rate",
                  "coefficient": "directive_coefficient", "specific_torque": "torque", "offset": "offset_rad"}
"""The estimator's parameter names -> the result keys that hold them."""

RECORD_FIT = "north_record_fit"
"""Stem of the record and its fit: the histories of a run and an identification (``north_record_fit.csv``)."""

_UNITS = {"decay_rate": "1/s", "directive_coefficient": "1/s^2", "hm": "N m s", "torque": "N m",
          "omega_h": "rad/s", "inertia": "kg m^2", "misfit_rad2": "rad^2", "samples": "1",
          "model_evaluations": "1", "unknowns": "1"}


def convergence(method: str, unknowns: int, evaluations: int, converged: bool) -> str:
    """How the estimator ended, in words (never the optimiser's own message).

    Parameters
    ----------
    method : {"lsq", "grid"}
        The estimator.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified.
    evaluations : int
        Model evaluations of the estimator (grid cells for the grid), a count.
    converged : bool
        Whether it converged.

    Returns
    -------
    str
        One line, e.g. "variable projection converged (12 model evaluations)".
    """
    if method == "grid":
        return f"3-stage grid refinement, {evaluations} cells"
    if unknowns == 2:
        return "linear least squares (eq. (10))"
    if converged:
        return f"variable projection converged ({evaluations} model evaluations)"
    return f"variable projection stopped after {evaluations} model evaluations without converging"


def record_fit(time: np.ndarray, observed: np.ndarray, residuals: np.ndarray) -> Histories:
    """A record and the fit to it as histories: ``observed_rad``, ``fitted_rad``, ``residual_rad`` against ``t_s``.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since the release, s.
    observed : ndarray (n,)
        Observed coordinate, rad.
    residuals : ndarray (n,)
        Observed minus fitted, rad.
    """
    channels = {"observed_rad": observed, "fitted_rad": observed - residuals, "residual_rad": residuals}
    return Histories(np.asarray(time), channels, {name: "rad" for name in channels})


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


class NorthRun(SystemResult):
    """A simulated run-down record identified (``north run``); ``render()`` shows north in deg to arcsec.

    ``north_std_predicted_rad`` is what the read-out noise and quantisation give by the
    linearised covariance; ``north_std_rad`` is the fit's own (residual-based)
    standard error, round-off for the nominal noise-free record (NaN without
    residual degrees of freedom). ``histories["north_record_fit"]`` holds the record and its fit.
    """

    def render(self):
        from rich.console import Group
        from rich.table import Table

        out, extras = self.outputs, self.extras
        north = _north_table(f"North from a simulated run-down ({extras['unknowns']} unknowns, {extras['method']}, "
                             f"{self.fidelity} record)", out["north_rad"], out["north_std_predicted_rad"],
                             dms_text(math.degrees(out["north_rad"])),
                             "standard error predicted for the read-out noise")
        accuracy = Table(title="Accuracy", show_header=False)
        accuracy.add_column("quantity")
        accuracy.add_column("value", justify="right")
        accuracy.add_row("true north", _angle(extras["true_north_rad"], "deg", 6))
        accuracy.add_row("error of the estimate (identified - true)", _angle(out["north_error_rad"], "arcsec", 3))
        accuracy.add_row("standard error from the fit's residuals", _angle(out["north_std_rad"], "arcsec", 3))
        if self.monte_carlo is not None:
            stats = self.monte_carlo["north_error_rad"]
            rate = self.monte_carlo["converged"].mean
            accuracy.add_row(f"Monte Carlo ({self.monte_carlo.members} records): mean, std of the error",
                             f"{_angle(stats.mean, 'arcsec', 3)}, {_angle(stats.std, 'arcsec', 3)}")
            accuracy.add_row("records identified and converged", "-" if rate is None else f"{100 * rate:.1f} %")
        rows = [
            ("alpha0", out["identified_alpha0_rad"], None, "rad"),
            ("alpha0_dot", out["identified_alpha0_dot_rad_s"], None, "rad/s"),
            ("lambda", out["identified_decay_rate"], None, "1/s"),
            ("B = Hm Omega_h / J", out["identified_directive_coefficient"], None, "1/s^2"),
            ("Hm", out["identified_hm"], None, "N m s"),
            ("harmful torque", out["identified_torque"], None, "N m"),
        ]
        if extras["reading"] == "absolute":
            rows.append(("reading offset", out["identified_offset_rad"], None, "rad"))
        summary = (f"misfit {out['misfit_rad2']:.4g} rad^2 over {out['samples']} samples "
                   f"(rms {_angle(out['residual_rms_rad'], 'arcsec', 3)}); "
                   + convergence(extras["method"], extras["unknowns"], out["model_evaluations"], out["converged"]))
        return Group(north, accuracy, _parameter_table(rows, "Identified (or known) parameters"), summary)


@dataclass
class NorthIdentification(Result):
    """North identified from an observation record, with standard errors (SI; None where not identified).

    ``correlation`` holds the correlation matrix of the identified parameters, named
    by their keys in this result (``decay_rate``, ``directive_coefficient`` ...);
    ``histories["north_record_fit"]`` (and :meth:`to_dataframe`) the record and the fit, as a run's.
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
            convergence=convergence(estimate.method, estimate.unknowns, estimate.nfev, estimate.converged),
            inertia=estimate.inertia, omega_h=estimate.omega_h,
            correlation={"parameters": names, "matrix": estimate.correlation["matrix"]},
            estimate=estimate)

    @property
    def histories(self) -> dict[str, Histories]:
        """The record and the fit (``north_record_fit``: observed, fitted and residual, rad, against ``t_s``)."""
        if self.estimate is None:
            return {}
        return {RECORD_FIT: record_fit(self.estimate.time, self.estimate.observed, self.estimate.residuals)}

    def to_dataframe(self):
        """The record and the fit indexed by ``t_s`` (the CSV ``--out`` writes); one row of the values without it."""
        histories = self.histories
        return histories[RECORD_FIT].to_dataframe() if histories else super().to_dataframe()

    def render(self):
        from rich.console import Group

        dms = dms_text(math.degrees(self.north_rad))
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

    def to_dataframe(self):
        """The record written: ``alpha_rad`` indexed by ``t_s``."""
        import pandas as pd

        frame = pd.DataFrame({"alpha_rad": self.observed}, index=pd.Index(self.time, name="t_s"))
        frame.attrs["units"] = {"t_s": "s", "alpha_rad": "rad"}
        return frame

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
