"""Typed results of the nonlinear INS, SI, with display rendering, and the system's one file writer.

* :class:`NavigationResult`: what :func:`~schuler.navigate.mechanization.navigate` returns, error
  histories of one run or of a batch of members;
* :class:`NavigateResult`: what ``schuler navigate run`` returns, one case's outputs (the final and
  largest errors, as ``evaluate`` gives them) with its histories, and its Monte Carlo if any;
* :func:`write_files`: the figures (PNG + SVG) and data (CSV) of a run or of the reproduction.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler.navigate.channels import (
    DISPLAY_UNITS,
    ERROR_CHANNELS,
    VERTICAL_CHANNELS_OUTPUT,
    shown_channels,
    suffix,
)
from schuler.reproduction import Reproduction
from schuler.results import Result, RunResult, json_safe
from schuler.units import to_unit


@dataclass
class TruthSamples:
    """The truth at the output times and, optionally, its means over each output interval.

    Attributes
    ----------
    t_s : ndarray, shape (n_out,)
    latitude_rad, longitude_rad, height_m : ndarray, shape (n_out,)
    velocity_ned_m_s : ndarray, shape (n_out, 3)
    quaternion : ndarray, shape (n_out, 4)
        q_bn.
    interval_means : dict of ndarray or None
        Over each of the n_out - 1 intervals: ``latitude_rad``, ``height_m``,
        ``velocity_ned_m_s`` (n, 3), ``specific_force_ned_m_s2`` (n, 3, the mean NED
        specific force) and ``body_to_ned`` (n, 3, 3, the mean C_b^n), sample means.
    """

    t_s: np.ndarray
    latitude_rad: np.ndarray
    longitude_rad: np.ndarray
    height_m: np.ndarray
    velocity_ned_m_s: np.ndarray
    quaternion: np.ndarray
    interval_means: dict | None = None


@dataclass
class NavigationResult(Result):
    """Error histories (computed - true) of a nonlinear INS run, at the output step.

    Single runs give arrays of shape (n_out,); a batch of N members gives
    (N, n_out). ``attitude_error_rad`` is the error rotation vector phi in NED
    (C_computed = (I - [phi x]) C_true to first order), shape (..., n_out, 3).
    ``warnings`` says where the run left its models' validity (:mod:`schuler.navigate.validity`).
    """

    mode: str
    vertical_channel: str
    imu_rate_hz: float
    output_step_s: float
    members: int | None
    t_s: np.ndarray
    position_error_north_m: np.ndarray
    position_error_east_m: np.ndarray
    height_error_m: np.ndarray
    velocity_error_north_m_s: np.ndarray
    velocity_error_east_m_s: np.ndarray
    velocity_error_down_m_s: np.ndarray
    roll_error_rad: np.ndarray
    pitch_error_rad: np.ndarray
    heading_error_rad: np.ndarray
    attitude_error_rad: np.ndarray = field(repr=False)
    truth: TruthSamples = field(repr=False)
    warnings: list[str] = field(default_factory=list)

    units: ClassVar[dict[str, str]] = {"imu_rate_hz": "Hz", "output_step_s": "s",
                                       "members": "batch size (null for a single run)"}

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe data; the height and vertical-velocity errors only when the vertical channel is on."""
        data = super().to_dict()
        if self.vertical_channel == "off":
            for name in VERTICAL_CHANNELS_OUTPUT:
                data.pop(name, None)
        return data

    def channel(self, name: str) -> np.ndarray:
        """An error history by name (one of :data:`ERROR_CHANNELS`).

        Parameters
        ----------
        name : str
            Channel name, e.g. ``"heading_error_rad"`` (SI unit in the name).

        Returns
        -------
        ndarray
            The history in the channel's SI unit (m, m/s or rad), shape (n_out,) or (N, n_out).

        Raises
        ------
        KeyError
            For a name that is not a channel.
        """
        if name not in ERROR_CHANNELS:
            raise KeyError(f"no channel {name!r}; channels are {ERROR_CHANNELS}")
        return getattr(self, name)

    def render(self):
        from rich.table import Table

        batch = self.members is not None
        title = (f"{self.mode} INS, vertical channel {self.vertical_channel}: errors at {self.t_s[-1]:,.0f} s"
                 + (f" ({self.members} members)" if batch else ""))
        table = Table(title=title)
        table.add_column("channel")
        for heading in (("mean final", "std final", "max |error|") if batch else ("final", "max |error|")):
            table.add_column(heading, justify="right")
        for name in ERROR_CHANNELS:
            if self.vertical_channel == "off" and name in VERTICAL_CHANNELS_OUTPUT:
                continue
            unit = DISPLAY_UNITS[suffix(name)]
            values = to_unit(np.asarray(self.channel(name)), unit)
            label = name.removesuffix("_" + suffix(name))
            if batch:
                final = values[:, -1]
                cells = (final.mean(), final.std(), np.abs(values).max())
            else:
                cells = (values[-1], np.abs(values).max())
            table.add_row(f"{label} ({unit})", *(f"{float(v):,.4g}" for v in cells))
        return table


@dataclass
class NavigateResult(RunResult):
    """One case of ``schuler navigate run``: its final and largest errors and its error histories.

    Attributes
    ----------
    trajectory, mode, vertical_channel : str
    imu : str or None
        The error model's name (None: ideal apart from the biases given).
    duration_s, imu_rate_hz, output_step_s : float
    errors : dict of float
        Every output of the system's ``evaluate``, SI (``final_position_error_north_m``,
        ``max_abs_heading_error_rad`` ...); :meth:`to_dict` puts them at the top level.
    navigation : NavigationResult
        The run (histories of shape (1, n_out)); :meth:`to_dict` gives ``t_s`` and
        each channel's history, the vertical ones only when the channel is on.
    warnings : list of str
        Where the run left its models' validity (also warned on stderr).
    """

    trajectory: str
    mode: str
    vertical_channel: str
    imu: str | None
    duration_s: float
    imu_rate_hz: float
    output_step_s: float
    errors: dict[str, float] = field(repr=False)
    navigation: NavigationResult = field(repr=False)
    warnings: list[str] = field(default_factory=list)

    units: ClassVar[dict[str, str]] = {"imu_rate_hz": "Hz"}

    def history(self, name: str) -> np.ndarray:
        """A channel's error history, SI, shape (n_out,).

        Parameters
        ----------
        name : str
            Channel name, one of :data:`~schuler.navigate.channels.ERROR_CHANNELS` (SI unit in the name).

        Returns
        -------
        ndarray
            The history in the channel's SI unit (m, m/s or rad), shape (n_out,).
        """
        return np.asarray(self.navigation.channel(name))[0]

    def to_dict(self) -> dict[str, Any]:
        data = super().to_dict()
        monte_carlo = data.pop("monte_carlo", None)
        data.pop("units", None)
        data.update(json_safe(self.errors))
        data["t_s"] = json_safe(self.navigation.t_s)
        for name in shown_channels(self.vertical_channel):
            data[name] = json_safe(self.history(name))
        data["monte_carlo"] = monte_carlo
        data["units"] = {**self.units, "t_s": "s",
                         **{name: suffix(name).replace("_", "/") for name in shown_channels(self.vertical_channel)}}
        return data

    def render(self):
        from rich.console import Group
        from rich.table import Table

        title = (f"{self.mode} INS on a {self.trajectory} trajectory, vertical channel {self.vertical_channel}, "
                 f"IMU {self.imu or 'ideal but for the biases given'}: errors at {self.duration_s:,.0f} s")
        table = Table(title=title)
        table.add_column("channel", justify="left")
        table.add_column("final", justify="right")
        table.add_column("largest |error|", justify="right")
        for name in (*shown_channels(self.vertical_channel), "horizontal_position_error_m"):
            unit = DISPLAY_UNITS[suffix(name)]
            final = self.errors[f"final_{name}"]
            largest = self.errors[f"max_abs_{name}" if name in ERROR_CHANNELS else f"max_{name}"]
            table.add_row(f"{name.removesuffix('_' + suffix(name)).replace('_', ' ')} ({unit})",
                          *(f"{float(to_unit(v, unit)):,.4g}" for v in (final, largest)))
        return Group(table, self.monte_carlo.render()) if self.monte_carlo is not None else table


def write_files(result: Result, out_dir: Path) -> list[Path]:
    """Figures (PNG + SVG) and data (CSV) of a run or of the reproduction, into ``out_dir``.

    A run: ``navigate_errors`` (the error histories), ``navigate_errors.csv`` and,
    with a Monte Carlo, ``navigate_monte_carlo`` (the final horizontal errors).
    The reproduction: ``navigate_gyrocompassing`` (steady state and settling
    time of the nonlinear platform against the KPI models, by initial azimuth
    error) with its table ``navigate_gyrocompassing.csv``, ``navigate_bollay``
    with ``navigate_bollay.csv``, and ``navigate_drozdovich``.

    Parameters
    ----------
    result : Result
        What ``run`` (a :class:`NavigateResult`) or ``reproduce`` (a
        :class:`~schuler.reproduction.Reproduction`) returned.
    out_dir : Path
        Folder for the figures (PNG, SVG) and data files (CSV).

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    TypeError
        For any other result type.
    """
    import pandas as pd

    from schuler.io import save_figure_formats, write_dataframe_csv
    from schuler.navigate import plots

    out_dir = Path(out_dir)
    files: list[Path] = []
    if isinstance(result, Reproduction):
        data = result.data
        figures = {"navigate_gyrocompassing": plots.plot_gyrocompassing(data["gyrocompassing"]),
                   "navigate_bollay": plots.plot_bollay(data["bollay"]),
                   "navigate_drozdovich": plots.plot_drozdovich(data["drozdovich"])}
        for stem, figure in figures.items():
            files += save_figure_formats(figure, out_dir / stem)
        files.append(write_dataframe_csv(pd.DataFrame(data["gyrocompassing_table"]),
                                         out_dir / "navigate_gyrocompassing.csv"))
        files.append(write_dataframe_csv(pd.DataFrame(data["bollay"].summary()), out_dir / "navigate_bollay.csv"))
        return files
    if not isinstance(result, NavigateResult):
        raise TypeError(f"navigate writes no files for {type(result).__name__}")
    files += save_figure_formats(plots.plot_errors(result.navigation), out_dir / "navigate_errors")
    columns = {"t_s": result.navigation.t_s, **{name: result.history(name)
                                                for name in shown_channels(result.vertical_channel)}}
    files.append(write_dataframe_csv(pd.DataFrame(columns), out_dir / "navigate_errors.csv"))
    if result.monte_carlo is not None:
        samples = result.monte_carlo.samples["final_horizontal_position_error_m"]
        files += save_figure_formats(plots.plot_final_errors(samples), out_dir / "navigate_monte_carlo")
    return files
