"""The figures and data files of ``schuler north``: :func:`figures`, the actions' hooks, :func:`data_files`.

A run, an identification and the reproduction draw the same things from a
:class:`RecordFit` (a record, the fit's residuals and the identified motion):
the fit and its residuals (``north_fit``), the misfit around the estimate on the
source's first-stage grid (``north_misfit_map``) and the standard error of north
predicted for windows around the record's (``north_error_vs_time``). A run with
a Monte Carlo adds the histogram of its members' errors (``north_monte_carlo``);
``north simulate`` draws its record (``north_record``). The CSV files are a
result's histories (``north_record_fit.csv``), written by the one writer, and the
reproduction's Table 1 (``north_table1.csv``, :func:`data_files`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from schuler.exceptions import renamed_keywords
from schuler.ground_gyrocompass import plots
from schuler.ground_gyrocompass.estimate import NorthEstimate, dms_text
from schuler.ground_gyrocompass.grid import STEP_ALPHA0, run_stage
from schuler.ground_gyrocompass.monte_carlo import predicted_errors
from schuler.ground_gyrocompass.problem import parameter_order
from schuler.ground_gyrocompass.results import RECORD_FIT, NorthIdentification, ObservationRecord
from schuler.io import write_dataframe_csv
from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult
from schuler.units import from_unit, to_unit


@dataclass(frozen=True)
class RecordFit:
    """A record and the fit to it: what the figures of a run, an identification and the reproduction show.

    ``motion`` holds the identified (or known) parameters by the estimator's names:
    ``alpha0`` rad, ``alpha0_dot`` rad/s, ``decay_rate`` 1/s, ``coefficient`` B 1/s^2,
    ``specific_torque`` rad/s^2, ``offset`` rad; ``misfit`` is the sum of squared residuals, rad^2.
    """

    time: np.ndarray
    observed: np.ndarray
    residuals: np.ndarray
    unknowns: int
    method: str
    reading: str
    motion: dict[str, float]
    misfit: float

    @property
    def north_dms(self) -> str:
        """North (-alpha0) in degrees, minutes and seconds."""
        return dms_text(math.degrees(-self.motion["alpha0"]))

    @classmethod
    def of_estimate(cls, estimate: NorthEstimate) -> RecordFit:
        """The record and fit of an estimate.

        Parameters
        ----------
        estimate : NorthEstimate
            What the estimator identified, with its record (SI).
        """
        motion = {"alpha0": estimate.alpha0_rad, "alpha0_dot": estimate.alpha0_dot,
                  "decay_rate": estimate.decay_rate, "coefficient": estimate.B,
                  "specific_torque": estimate.torque / estimate.inertia, "offset": estimate.offset_rad or 0.0}
        return cls(estimate.time, estimate.observed, estimate.residuals, estimate.unknowns, estimate.method,
                   estimate.reading, motion, estimate.misfit)

    @classmethod
    def of_run(cls, result: SystemResult) -> RecordFit:
        """The record and fit of a run: its histories ``north_record_fit`` and identified outputs.

        Parameters
        ----------
        result : SystemResult
            What ``north run`` returned (outputs SI, the case's ``inertia`` kg m^2 among its parameters).
        """
        history, out = result.histories[RECORD_FIT], result.outputs
        motion = {"alpha0": out["identified_alpha0_rad"], "alpha0_dot": out["identified_alpha0_dot_rad_s"],
                  "decay_rate": out["identified_decay_rate"], "coefficient": out["identified_directive_coefficient"],
                  "specific_torque": out["identified_torque"] / result.parameters["inertia"],
                  "offset": out["identified_offset_rad"]}
        return cls(history.time, history["observed_rad"], history["residual_rad"], result.extras["unknowns"],
                   result.extras["method"], result.extras["reading"], motion, out["misfit_rad2"])


def figures(result: Result) -> dict[str, Any]:
    """The figures of a run (with its Monte Carlo's histogram) or of the reproduction ({} for anything else).

    Parameters
    ----------
    result : Result
        What ``north run`` or ``north reproduce`` returned.
    """
    if isinstance(result, Reproduction):
        data = result.data
        return {"north_fit": plots.plot_fit(data.estimate),
                "north_misfit_map": plots.plot_misfit_map(
                    data.first_stage, title=f"The source's first grid stage ({data.first_stage.cells} cells): "
                                            "sum of squares")}
    if not isinstance(result, SystemResult):
        return {}
    drawn = fit_figures(RecordFit.of_run(result), result.extras["readout_noise_rad"])
    if result.monte_carlo is not None:
        errors = to_unit(result.monte_carlo.samples["north_error_rad"], "arcsec")
        drawn["north_monte_carlo"] = plots.plot_error_histogram(
            errors, float(to_unit(result.outputs["north_std_predicted_rad"], "arcsec")),
            f"North error over {result.monte_carlo.members} records ({result.extras['unknowns']} unknowns)")
    return drawn


def identification_figures(result: Result) -> dict[str, Any]:
    """The figures of ``north identify``: the fit, the misfit map, the predicted error against the window.

    Parameters
    ----------
    result : NorthIdentification
        What ``north identify`` returned ({} without its estimate).
    """
    assert isinstance(result, NorthIdentification)
    return {} if result.estimate is None else fit_figures(RecordFit.of_estimate(result.estimate))


def record_figures(result: Result) -> dict[str, Any]:
    """The figure of ``north simulate``: the record written (``north_record``).

    Parameters
    ----------
    result : ObservationRecord
        What ``north simulate`` returned.
    """
    assert isinstance(result, ObservationRecord)
    return {"north_record": plots.plot_record(result.time, result.observed,
                                              f"Simulated run-down record ({result.reading} reading)")}


@renamed_keywords(noise_rad="noise")
def fit_figures(fit: RecordFit, noise: float | None = None) -> dict[str, Any]:
    """The fit and residuals, the misfit map around the estimate, the predicted error against the window.

    Parameters
    ----------
    fit : RecordFit
        A record and its fit.
    noise : float, optional
        Read-out noise standard deviation, rad (default: the residuals' rms, or 1 arcsec for a noise-free record).
    """
    a0, rate = fit.motion["alpha0"], fit.motion["alpha0_dot"]
    box = {"alpha0": (a0 - 9 * STEP_ALPHA0, a0 + 9 * STEP_ALPHA0, STEP_ALPHA0),
           "alpha0_dot": (rate - 6e-4, rate + 6e-4, 1e-4)}
    stage = run_stage(fit.time, fit.observed, box, fit.motion["decay_rate"], fit.motion["coefficient"], fit.reading,
                      fit.unknowns == 5)
    return {"north_fit": plots.plot_fit(fit),
            "north_misfit_map": plots.plot_misfit_map(
                stage, title=f"Misfit around the estimate ({stage.cells} cells, the source's first-stage steps), "
                             "at the estimated lambda and B"),
            "north_error_vs_time": error_vs_time(fit, noise)}


@renamed_keywords(noise_rad="noise")
def error_vs_time(fit: RecordFit, noise: float | None = None):
    """The standard error of north predicted for windows around the record's, 2 and the fit's unknowns.

    Parameters
    ----------
    fit : RecordFit
        A record and its fit: its parameters are taken as the truth, its sampling step is kept.
    noise : float, optional
        Read-out noise standard deviation, rad (default: the residuals' rms, or 1 arcsec for a noise-free record).

    Returns
    -------
    matplotlib.figure.Figure
        The figure (arcsec against the window in s).
    """
    step = float(np.median(np.diff(fit.time))) if fit.time.size > 1 else 1.0
    arcsec = from_unit(1.0, "arcsec")
    noise = noise or math.sqrt(fit.misfit / fit.time.size)
    if noise < 0.01 * arcsec:  # a noise-free record: the error per arcsec of read-out noise
        noise = arcsec
    duration = float(fit.time[-1])
    parameters = len(parameter_order(fit.unknowns, fit.reading))
    shortest = max(min(60.0, duration / 2), (parameters + 1) * step)
    durations = np.linspace(shortest, max(600.0, 2 * duration, 2 * shortest), 19)
    series = []
    for count in sorted({2, fit.unknowns}):
        # one window at a time: the longest holds twice the record's samples, no more
        std = np.array([predicted_errors({k: np.array([v]) for k, v in fit.motion.items()}, np.array([window]),
                                         np.array([step]), np.array([noise]), unknowns=count,
                                         reading=fit.reading)["alpha0_std"][0] for window in durations])
        series.append((f"{count} unknowns", to_unit(std, "arcsec"), "-o"))
    return plots.plot_error_vs_time(durations, series,
                                    f"Predicted north error for read-out noise {to_unit(noise, 'arcsec'):.3g} arcsec")


def data_files(result: Result, out_dir: Path) -> list[Path]:
    """The reproduction's Table 1 beside the re-computed sums of squares (``north_table1.csv``); nothing else.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned (a run's and an identification's CSV are their histories).
    out_dir : Path
        Folder the file is written into.
    """
    import pandas as pd

    if not isinstance(result, Reproduction):
        return []
    return [write_dataframe_csv(pd.DataFrame(result.data.table1), Path(out_dir) / "north_table1.csv")]
