"""Typed results of the nonlinear INS, SI, with display rendering, and the system's figures and data files.

* :class:`NavigationResult`: what :func:`~schuler.navigate.mechanization.navigate` returns, error
  histories of one run or of a batch of members;
* :class:`NavigateResult`: what ``schuler navigate run`` returns (the contract's
  :class:`~schuler.results.SystemResult`): the final and largest errors, what it ran, its error
  histories ``histories["navigate_errors"]`` and its Monte Carlo if any;
* :func:`figures` and :func:`data_files`: the figures of a run or of the reproduction, and the
  reproduction's tables (the contract's one writer writes them with the histories' CSV).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler.core.response import Histories
from schuler.navigate.channels import (
    DISPLAY_UNITS,
    ERROR_CHANNELS,
    VERTICAL_CHANNELS_OUTPUT,
    shown_channels,
    suffix,
)
from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult, json_safe
from schuler.units import to_unit

HISTORIES = "navigate_errors"
"""Stem of a run's error histories: its CSV file and figure."""


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

    def histories(self, member: int | None = None) -> Histories:
        """The channels a run reports (the vertical ones only when the channel is on) as named histories.

        Parameters
        ----------
        member : int, optional
            Index of one member of a batch (its histories of shape (n_out,)); None: every member's.

        Returns
        -------
        Histories
            Time ``t_s`` (s) and each channel in its SI unit (m, m/s, rad).
        """
        names = shown_channels(self.vertical_channel)
        channels = {name: np.asarray(self.channel(name)) for name in names}
        if member is not None:
            channels = {name: values[member] for name, values in channels.items()}
        return Histories(np.asarray(self.t_s), channels, {name: suffix(name).replace("_", "/") for name in names})

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


@dataclass(kw_only=True)
class NavigateResult(SystemResult):
    """One case of ``schuler navigate run``: its final and largest errors, what it ran, its error histories.

    The outputs (``final_position_error_north_m``, ``max_abs_heading_error_rad`` ...) and the extras
    (``trajectory``, ``mode``, ``vertical_channel``, ``imu``, ``duration_s``, ``imu_rate_hz``,
    ``output_step_s``, ``warnings``: where the run left its models' validity) read as attributes;
    ``histories["navigate_errors"]`` (or :meth:`to_dataframe`) holds each channel's history, SI.
    :meth:`to_dict` also gives ``t_s`` and those histories at the top level (the vertical ones only
    when the channel is on), as scripts read them.
    """

    def to_dict(self) -> dict[str, Any]:
        data = super().to_dict()
        tail = {name: data.pop(name) for name in ("monte_carlo", "units")}
        data = {**{name: data.pop(name) for name in self.extras}, **data}  # what it ran first, as before
        histories = self.histories[HISTORIES]
        data["t_s"] = json_safe(histories.time)
        data.update({name: json_safe(values) for name, values in histories.channels.items()})
        return {**data, **tail, "units": {**tail["units"], "t_s": "s", **histories.units}}

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
            final = self.outputs[f"final_{name}"]
            largest = self.outputs[f"max_abs_{name}" if name in ERROR_CHANNELS else f"max_{name}"]
            table.add_row(f"{name.removesuffix('_' + suffix(name)).replace('_', ' ')} ({unit})",
                          *(f"{float(to_unit(v, unit)):,.4g}" for v in (final, largest)))
        return Group(table, self.monte_carlo.render()) if self.monte_carlo is not None else table


def figures(result: Result) -> dict[str, Any]:
    """The figures of a run or of the reproduction, file stem -> Figure ({} for any other result).

    A run: ``navigate_errors`` (the error histories) and, with a Monte Carlo, ``navigate_monte_carlo``
    (the final horizontal errors). The reproduction: ``navigate_gyrocompassing`` (steady state and
    settling time of the nonlinear platform against the KPI models, by initial azimuth error),
    ``navigate_bollay`` and ``navigate_drozdovich``.

    Parameters
    ----------
    result : Result
        What ``run`` (a :class:`NavigateResult`) or ``reproduce`` (a
        :class:`~schuler.reproduction.Reproduction`) returned.
    """
    from schuler.navigate import plots

    if isinstance(result, Reproduction):
        data = result.data
        return {"navigate_gyrocompassing": plots.plot_gyrocompassing(data["gyrocompassing"]),
                "navigate_bollay": plots.plot_bollay(data["bollay"]),
                "navigate_drozdovich": plots.plot_drozdovich(data["drozdovich"])}
    if not isinstance(result, NavigateResult) or HISTORIES not in result.histories:
        return {}
    drawn = {HISTORIES: plots.plot_errors(result.histories[HISTORIES], result.mode)}
    if result.monte_carlo is not None:
        drawn["navigate_monte_carlo"] = plots.plot_final_errors(
            result.monte_carlo.samples["final_horizontal_position_error_m"])
    return drawn


def data_files(result: Result, out_dir: Path) -> list[Path]:
    """The reproduction's tables, ``navigate_gyrocompassing.csv`` and ``navigate_bollay.csv`` (a run: none).

    Parameters
    ----------
    result : Result
        What ``run`` or ``reproduce`` returned (a run's histories are written as its CSV by the contract).
    out_dir : Path
        Folder for the CSV files.

    Returns
    -------
    list of Path
        The files written.
    """
    import pandas as pd

    from schuler.io import write_dataframe_csv

    if not isinstance(result, Reproduction):
        return []
    data, out_dir = result.data, Path(out_dir)
    return [write_dataframe_csv(pd.DataFrame(data["gyrocompassing_table"]), out_dir / "navigate_gyrocompassing.csv"),
            write_dataframe_csv(pd.DataFrame(data["bollay"].summary()), out_dir / "navigate_bollay.csv")]
