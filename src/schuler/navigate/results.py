"""Typed results of the nonlinear INS: error histories at the output step, SI, with display rendering."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from schuler.results import Result
from schuler.units import to_unit

ERROR_CHANNELS: tuple[str, ...] = (
    "position_error_north_m",
    "position_error_east_m",
    "height_error_m",
    "velocity_error_north_m_s",
    "velocity_error_east_m_s",
    "velocity_error_down_m_s",
    "roll_error_rad",
    "pitch_error_rad",
    "heading_error_rad",
)
"""Every error history of :class:`NavigationResult`, in order (computed - true)."""

VERTICAL_CHANNELS_OUTPUT = ("height_error_m", "velocity_error_down_m_s")
"""Channels left out of :meth:`NavigationResult.to_dict` when the vertical channel is off."""

_DISPLAY = {"m": ("m", "{:,.4g}"), "m_s": ("m/s", "{:,.4g}"), "rad": ("arcsec", "{:,.4g}")}


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
        """An error history by name (one of :data:`ERROR_CHANNELS`)."""
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
            suffix = name.rsplit("_", 1)[-1] if not name.endswith("_m_s") else "m_s"
            unit, fmt = _DISPLAY[suffix]
            values = to_unit(np.asarray(self.channel(name)), unit)
            label = name.removesuffix("_" + suffix)
            if batch:
                final = values[:, -1]
                cells = (final.mean(), final.std(), np.abs(values).max())
            else:
                cells = (values[-1], np.abs(values).max())
            table.add_row(f"{label} ({unit})", *(fmt.format(float(v)) for v in cells))
        return table
