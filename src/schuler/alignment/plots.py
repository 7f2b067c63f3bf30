"""Figures of the alignment suite (at most 7 in wide at 100 dpi, default font sizes) and the files of its results.

Each ``*_figure`` builds one matplotlib figure; :func:`write_files` writes a
result's figures (PNG and SVG through :func:`schuler.io.save_figure_formats`)
and its data (CSV), and returns the paths.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from schuler.alignment.calibration_comparison import CalibrationComparison
from schuler.alignment.comparison import AlignmentComparison
from schuler.alignment.north import NORTH_METHODS
from schuler.alignment.north_comparison import NorthComparison
from schuler.core.attitude import wrap_angle
from schuler.io import save_figure_formats, write_dataframe_csv

ARCMIN = 180.0 * 60.0 / math.pi
WIDTH_IN = 7.0
DPI = 100
LABELS = {"coarse": "coarse (TRIAD)", "inertial_frame": "inertial frame (i0)", "kalman": "Kalman",
          "gyrocompass": "gyrocompass loop", "two_position": "two positions", "four_position": "four positions",
          "carousel": "carousel", "ground_gyrocompass": "ground gyrocompass (schuler north)"}


def _pyplot():
    import matplotlib.pyplot as plt

    return plt


def heading_figure(result: AlignmentComparison):
    """Heading of every method against time: error (arcmin) when the truth is known, else relative to Kalman.

    Parameters
    ----------
    result : AlignmentComparison
        The comparison with its histories (member 0 drawn).

    Returns
    -------
    matplotlib.figure.Figure
        One axes, heading in arcmin against time in s, the Kalman filter's 1-sigma band and limit.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(WIDTH_IN, 4.2), dpi=DPI)
    truth = result.true_attitude_rad
    reference = truth[2] if truth is not None else result.methods["kalman"]["heading_rad"]
    for index, (name, estimate) in enumerate(result.estimates.items()):
        values = wrap_angle(estimate.heading_history_rad[0] - reference) * ARCMIN
        ax.plot(estimate.time_s, values, lw=1.2, color=f"C{index}", label=LABELS[name])
        if estimate.sigma_history_rad is not None:
            sigma = estimate.sigma_history_rad[0, :, 2] * ARCMIN
            ax.fill_between(estimate.time_s, values - sigma, values + sigma, color=f"C{index}", alpha=0.15, lw=0)
    limit = result.methods["kalman"]["limit_heading_rad"] * ARCMIN
    ax.axhline(limit, color="k", ls=":", lw=0.8, label="1-sigma limit (Kalman)")
    ax.axhline(-limit, color="k", ls=":", lw=0.8)
    final = [wrap_angle(row["heading_rad"] - reference) * ARCMIN for row in result.methods.values()]
    span = max(4.0 * limit, 3.0 * max(abs(v) for v in final), 1e-3)
    ax.set_ylim(-span, span)
    ax.set_xlabel("time from the window's start, s")
    ax.set_ylabel("heading error, arcmin" if truth is not None else "heading - final Kalman heading, arcmin")
    ax.set_title(f"Heading of every method: {result.source}")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", ncol=2)
    fig.tight_layout()
    return fig


def north_figure(result: NorthComparison):
    """1-sigma of north against time (each method analytic, Monte Carlo at the chosen time; schuler north), per grade.

    Parameters
    ----------
    result : NorthComparison
        The north-finding comparison (its ``versus_time`` and ``versus_grade`` curves).

    Returns
    -------
    matplotlib.figure.Figure
        Two axes: 1-sigma in arcmin against observation time in s, and per grade.
    """
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(WIDTH_IN, 3.8), dpi=DPI, width_ratios=(3, 2))
    times = np.asarray(result.versus_time["duration_s"])
    styles = ("-", "--", ":")   # four positions and carousel share a closed form with one gyro: dashes keep both seen
    for index, method in enumerate(NORTH_METHODS):
        left.loglog(times, np.asarray(result.versus_time[method]) * ARCMIN, styles[index], color=f"C{index}",
                    label=LABELS[method])
        sigma = result.methods[method]["monte_carlo_sigma_rad"]
        if sigma is not None:
            left.loglog([result.duration_s], [sigma * ARCMIN], "o", color=f"C{index}")
    if "ground_gyrocompass" in result.versus_time:
        left.loglog(times, np.asarray(result.versus_time["ground_gyrocompass"]) * ARCMIN, "k-.",
                    label=LABELS["ground_gyrocompass"])
    left.set_xlabel("observation time, s")
    left.set_ylabel("north 1-sigma, arcmin")
    left.set_title(f"{result.grade} grade (dots: Monte Carlo)")
    left.grid(alpha=0.3, which="both")
    left.legend(loc="center left")
    grades = list(result.versus_grade)
    positions = np.arange(len(grades))
    for index, method in enumerate(NORTH_METHODS):
        values = [result.versus_grade[g][method] * ARCMIN for g in grades]
        right.semilogy(positions, values, "o-", color=f"C{index}")
    right.set_xticks(positions, grades, rotation=30, ha="right")
    right.set_ylabel("north 1-sigma, arcmin")
    right.set_title(f"per grade, {result.duration_s:g} s")
    right.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def calibration_figure(result: CalibrationComparison):
    """Normalised errors (estimate - true) / predicted 1-sigma of every estimated quantity, per procedure.

    Parameters
    ----------
    result : CalibrationComparison
        The calibration comparison (its six-position and multi-static entries).

    Returns
    -------
    matplotlib.figure.Figure
        One axes of the normalised errors z (plain numbers) with the +/-3 lines.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(WIDTH_IN, 4.0), dpi=DPI)
    labels, offset = [], 0
    for index, (name, block) in enumerate((("six positions", result.six_position),
                                           ("multi-static", result.multi_static))):
        for key, entry in block.items():
            if not isinstance(entry, dict):
                continue
            z = np.asarray(entry["z"])
            ax.plot(offset + np.arange(z.size), z, "o", color=f"C{index}", ms=4,
                    label=name if key == next(k for k, v in block.items() if isinstance(v, dict)) else None)
            labels.append((offset + (z.size - 1) / 2.0, key.replace("_", " ")))
            offset += z.size + 1
    for level in (-3, 3):
        ax.axhline(level, color="k", ls=":", lw=0.8)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks([p for p, _ in labels], [text for _, text in labels], rotation=60, ha="right")
    ax.set_ylabel("(estimate - true) / 1-sigma")
    ax.set_title(f"Calibration round trip, one {result.grade}-grade IMU")
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    return fig


def comparison_figures(result) -> dict:
    """The figure of an alignment, north-finding or calibration comparison, by file stem ({}: none of them).

    Parameters
    ----------
    result : Result
        An AlignmentComparison, NorthComparison or CalibrationComparison (anything else has no figure here).
    """
    if isinstance(result, AlignmentComparison):
        return {"align_compare_heading": heading_figure(result)}
    if isinstance(result, NorthComparison):
        return {"north_compare_accuracy": north_figure(result)}
    if isinstance(result, CalibrationComparison):
        return {"calibrate_compare_errors": calibration_figure(result)}
    return {}


def comparison_data_files(result, out_dir) -> list[Path]:
    """The CSV beside a comparison's figure: its table (:meth:`to_dataframe`) under the figure's stem.

    Parameters
    ----------
    result : Result
        An AlignmentComparison, NorthComparison or CalibrationComparison (anything else writes nothing).
    out_dir : str or Path
        Folder the file is written into.

    Returns
    -------
    list of Path
        The file written (empty for other results).
    """
    stems = {AlignmentComparison: "align_compare_heading", NorthComparison: "north_compare_accuracy",
             CalibrationComparison: "calibrate_compare_errors"}
    stem = stems.get(type(result))
    if stem is None:
        return []
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    return [write_dataframe_csv(result.to_dataframe(), out_dir / f"{stem}.csv")]


def write_files(result, out_dir) -> list[Path]:
    """Figure (PNG and SVG) and CSV of a comparison, for a system that writes through its own ``write_files``.

    Parameters
    ----------
    result : AlignmentComparison or NorthComparison or CalibrationComparison
        The comparison to write.
    out_dir : str or Path
        Folder the files are written into.

    Returns
    -------
    list of Path
        The files written.
    """
    files = []
    for stem, figure in comparison_figures(result).items():
        files += save_figure_formats(figure, Path(out_dir) / stem)
    return files + comparison_data_files(result, out_dir)
