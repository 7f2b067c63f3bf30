"""The ground gyrocompass's section of the HTML report: Tables 1-3 reproduced, figures, commands.

The Monte Carlo figure runs exactly what ``schuler north run --readout-noise ...
--monte-carlo N`` runs (the system's ``evaluate`` through
:func:`schuler.contract.monte_carlo`: the production estimator on records with
counter-based read-out noise), for a few observation windows and two noise levels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.contract import Cases, FigureRef, ReportSection, monte_carlo
from schuler.core.random import RandomStreams
from schuler.ground_gyrocompass import files as north_files
from schuler.ground_gyrocompass import plots
from schuler.ground_gyrocompass.evaluation import OUTPUTS, PARAMETERS, evaluate
from schuler.ground_gyrocompass.reproduction import reproduce
from schuler.io import save_figure_formats
from schuler.results import write_result
from schuler.units import from_unit, to_unit

REPORT_MEMBERS = 50
"""Records per point of the report's Monte Carlo (``north run --monte-carlo N`` scales it up)."""
REPORT_WINDOWS = np.array([60.0, 150.0, 300.0, 600.0])
"""Observation windows of the report's Monte Carlo, s."""
REPORT_NOISES = (1.0, 10.0)
"""Read-out noise levels of the report's Monte Carlo, arcsec."""


def accuracy_against_window(windows, noises_arcsec, members: int, unknowns: int = 4):
    """Monte Carlo and predicted standard error of north (arcsec) per window and noise level.

    Noise level ``j`` uses seed ``j``, so the levels are independent samples (the
    windows of one level share their members' noise series, as records cut short would).
    Returns ``(monte_carlo_std, predicted_std)``, arrays indexed [window, noise].

    Parameters
    ----------
    windows : array_like (k,)
        Observation windows, s.
    noises_arcsec : sequence of float
        Read-out noise levels, arcsec (display unit: the report's).
    members : int
        Number of Monte Carlo records per window and noise level.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified.

    Returns
    -------
    monte_carlo_std, predicted_std : ndarray (k, len(noises_arcsec))
        Standard deviation of the north error over the members and the one the Jacobian predicts, arcsec.
    """
    std = np.empty((len(windows), len(noises_arcsec)))
    predicted = np.empty_like(std)
    for i, window in enumerate(windows):
        for j, noise in enumerate(noises_arcsec):
            case = PARAMETERS.case(duration=float(window), readout_noise=from_unit(noise, "arcsec"), unknowns=unknowns)
            summary = monte_carlo(evaluate, OUTPUTS, case, members, RandomStreams(j))
            std[i, j] = to_unit(summary.statistics["north_error_rad"]["std"], "arcsec")
            predicted[i, j] = to_unit(evaluate(Cases.from_case(case))["north_std_predicted_rad"][0], "arcsec")
    return std, predicted


def report(outdir: Path) -> ReportSection:
    """Write this system's figures into ``outdir`` and describe them (a few seconds).

    Parameters
    ----------
    outdir : Path
        Folder the figures are written into.

    Returns
    -------
    ReportSection
        The section: the reproduction's rows, the figures with captions, the commands to try.
    """
    outdir = Path(outdir)
    reproduction = reproduce(4)
    reproduction.attach_figures(north_files.figures)
    files = write_result(reproduction, outdir, north_files.data_files)
    fit = north_files.RecordFit.of_estimate(reproduction.data.estimate)
    files += save_figure_formats(north_files.error_vs_time(fit, from_unit(1.0, "arcsec")),
                                 outdir / "north_error_vs_time")
    std, predicted = accuracy_against_window(REPORT_WINDOWS, REPORT_NOISES, REPORT_MEMBERS)
    series = []
    for j, noise in enumerate(REPORT_NOISES):
        series.append((f'Monte Carlo, noise {noise:g}"', std[:, j], f"C{j}o"))
        series.append((f'predicted (Jacobian), noise {noise:g}"', predicted[:, j], f"C{j}-"))
    files += save_figure_formats(plots.plot_error_vs_time(
        REPORT_WINDOWS, series, f"Accuracy against time: 4 unknowns, {REPORT_MEMBERS} records per point"),
        outdir / "north_monte_carlo")
    captions = {
        "north_fit": "The source's simulated run-down (200 s) and the 4-unknown fit; residuals at round-off.",
        "north_misfit_map": "The source's first grid stage for 2 unknowns (Table 1's cells) as a sum of squares: "
                            "its minimum is the printed cell, its values are not the printed ones.",
        "north_error_vs_time": "Predicted north standard error against observation time, 1 arcsec read-out noise.",
        "north_monte_carlo": f"Monte Carlo ({REPORT_MEMBERS} records per point, 4 unknowns, the estimator of "
                             "'north identify') against the Jacobian's prediction: north error against observation "
                             "time for 1 and 10 arcsec read-out noise.",
    }
    figures = [FigureRef(path.name, captions[path.stem]) for path in files
               if path.suffix == ".png" and path.stem in captions]
    return ReportSection(
        system="north",
        title="Ground gyrocompass during rotor run-down",
        source=reproduction.source,
        summary=(
            "Bessel-function solution (9) of the run-down motion, checked against numerical integration; north from "
            "the observed motion by variable-projection least squares (2-5 unknowns) and by the source's grid. "
            "Every optimum and misfit of the source's Tables 1-3 is printed beside the re-computed one."
        ),
        rows=reproduction.rows,
        figures=figures,
        commands=[
            "schuler north reproduce --unknowns 4",
            "schuler north run --readout-noise '1 arcsec' --duration 300 --monte-carlo 1000 --out north",
            "schuler north simulate --readout-noise '2 arcsec' --seed 4 -o record.csv",
            "schuler north identify record.csv --unknowns 4 --out north",
            "schuler sweep examples/north_ground_gyrocompass.toml --param duration=60:600:60 --monte-carlo 200",
        ],
        notes=reproduction.notes,
    )
