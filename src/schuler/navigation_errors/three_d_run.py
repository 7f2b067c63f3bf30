"""``schuler errors three-d``: the linearised 3-D psi-angle error model on the rotating Earth, run once.

Beyond Bollay (1966), whose single channel is this model's non-rotating limit;
the model is :func:`~schuler.navigation_errors.three_d.psi_angle_model` (Benson
1975, psi-angle form): errors computed - true in the local-level North-East-Down
frame of the computed position, for a stationary vehicle or one flying at
constant north and east speeds (coefficients frozen at the latitude):

    delta_r' = -rho x delta_r + delta_v
    delta_v' = -(2 Omega_n + rho) x delta_v + f x psi + delta_g + nabla
    psi'     = -(Omega_n + rho) x psi + epsilon

Inputs and their signs (docs/conventions.md):

* ``drift_north|east|down`` = epsilon: the platform's drift rate about the level
  axes, the rate at which it turns away from the computer frame. It is
  -(gyro bias) resolved in the level frame (a gyro reading high makes the
  platform lag). A positive ``drift_east`` tilts the platform so that the north
  position error grows positive, as Bollay's drift Delta_theta_y makes a
  positive Delta_S_x.
* ``accel_bias_north|east|down`` = nabla: the accelerometer errors resolved in
  the level frame, measured - true (the down one acts on the vertical channel
  only, so it needs ``vertical_channel``).
* ``initial_velocity_error_north|east`` (m/s) and ``initial_attitude_error_north|east|down``
  = psi(0) (rad): errors at the start.

Outputs: the final errors, the largest horizontal position error, the Schuler
period, the Foucault rate Omega sin L that turns the Schuler swing, and the
model's eigenvalues (0, +/- i Omega, +/- i (sqrt(omega_s^2 + Omega_z^2) +/- Omega_z)
for a stationary vehicle).

References
----------
Benson, D. O., "A comparison of two approaches to pure-inertial and Doppler-inertial
error analysis", IEEE Transactions on Aerospace and Electronic Systems, vol. AES-11,
no. 4, pp. 447-455, 1975 (:data:`schuler.references.BENSON_1975`).
"""

from __future__ import annotations

import math
import sys
import warnings
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from schuler.core.earth import PRESETS
from schuler.core.geometry import grid_points, time_grid
from schuler.core.lti import simulate
from schuler.exceptions import InvalidParameter
from schuler.memory import require
from schuler.navigation_errors.inputs import (
    EARTH_PARAMETERS,
    GRID_NAMES,
    check_vertical_growth,
    earth_constants,
)
from schuler.navigation_errors.results import NOISE_FRACTION, lengths, sample_indices
from schuler.navigation_errors.three_d import psi_angle_model
from schuler.params import Parameter, ParameterSet
from schuler.results import Result
from schuler.units import to_unit

AXES = ("north", "east", "down")

MAX_DURATION = 30 * 86_400.0
"""Longest run, s (30 days)."""

LATITUDE_CHANGE_WARNING = math.radians(1.0)
"""A north speed that moves the vehicle by more than this in latitude over the run is warned about, rad."""

THREE_D_PARAMETERS = ParameterSet((
    Parameter("latitude", "deg", 45.0, "Latitude L of the vehicle.", minimum=-90, maximum=90,
              exclusive_minimum=True, exclusive_maximum=True),
    Parameter("velocity_north", "m/s", 0.0, "Vehicle's constant north ground speed V_N (coefficients frozen at L).",
              minimum=-1e4, maximum=1e4),
    Parameter("velocity_east", "m/s", 0.0, "Vehicle's constant east ground speed V_E.", minimum=-1e4, maximum=1e4),
    Parameter("duration", "s", 86_400.0, "Length of the run (with the vertical channel: while its error grows "
              "less than exp(200)).",
              minimum=0.0, exclusive_minimum=True, maximum=MAX_DURATION),
    Parameter("output_step", "s", 60.0, "Output step (the simulation is exact between outputs).", minimum=0.0,
              exclusive_minimum=True),
    *(Parameter(f"drift_{axis}", "deg/h", 0.0, f"Platform drift rate about {axis}: -(gyro bias) resolved "
                f"{axis}.", minimum=-3600.0, maximum=3600.0) for axis in AXES),
    *(Parameter(f"accel_bias_{axis}", "g", 0.0, f"Accelerometer bias resolved {axis}, measured - true"
                + (" (vertical channel only)." if axis == "down" else "."), minimum=-0.1, maximum=0.1)
      for axis in AXES),
    *(Parameter(f"initial_velocity_error_{axis}", "m/s", 0.0, f"Velocity error {axis} at the start.",
                minimum=-1e3, maximum=1e3) for axis in AXES[:2]),
    *(Parameter(f"initial_attitude_error_{axis}", "arcmin", 0.0, f"Platform attitude error psi_{axis[0].upper()} "
                f"about {axis} at the start.", minimum=-600.0, maximum=600.0) for axis in AXES),
    Parameter("vertical_channel", "", False, "Include the pure-inertial vertical channel (unstable, "
              "eigenvalue near +sqrt(2) omega_s); without it the vertical errors are held at zero.", kind="flag"),
    *EARTH_PARAMETERS,
    Parameter("earth_rate", "deg/h", None, "Earth rate Omega (not set: the preset's; 0: a non-rotating Earth).",
              minimum=0.0, maximum=3600.0),
), owner="errors three-d")
"""Options of ``schuler errors three-d``."""


@dataclass
class ThreeDResult(Result):
    """A run of the 3-D psi-angle error model: final errors, modes, and histories for figures and CSV.

    Errors are computed - true in NED; attitude errors psi in rad. Down errors
    are None without the vertical channel. ``states`` (state name -> array
    over ``t_s``) and ``state_units`` feed the figures and :meth:`to_dataframe`
    (the CSV of ``--out``), not ``to_dict()``.
    """

    latitude_rad: float
    velocity_north_m_s: float
    velocity_east_m_s: float
    vertical_channel: bool
    radius_m: float
    gravity_m_s2: float
    earth_rate_rad_s: float
    duration_s: float
    final_position_error_north_m: float
    final_position_error_east_m: float
    final_position_error_down_m: float | None
    final_velocity_error_north_m_s: float
    final_velocity_error_east_m_s: float
    final_velocity_error_down_m_s: float | None
    final_attitude_error_north_rad: float
    final_attitude_error_east_rad: float
    final_attitude_error_down_rad: float
    max_horizontal_position_error_m: float
    schuler_period_s: float
    foucault_rate_rad_s: float
    eigenvalues_real_per_s: np.ndarray
    eigenvalues_imag_rad_s: np.ndarray
    t_s: np.ndarray = field(repr=False)
    states: dict[str, np.ndarray] = field(repr=False)
    state_units: dict[str, str] = field(repr=False)

    units: ClassVar[dict[str, str]] = {"eigenvalues_real_per_s": "1/s"}

    def to_dataframe(self):
        """The state histories, one row per time: ``t_s`` then each state, its SI unit in the column name."""
        import pandas as pd

        columns = {"t_s": self.t_s}
        for name, history in self.states.items():
            column = name.replace("psi_", "attitude_error_")
            columns[f"{column}_{self.state_units[name].replace('/', '_')}"] = history
        return pd.DataFrame(columns)

    def render(self):
        from rich.console import Group
        from rich.table import Table

        # each channel hides rounding noise against its own scale: one channel may be far smaller, yet real
        north_floor, east_floor = (NOISE_FRACTION * float(np.max(np.abs(self.states[f"position_error_{axis}"])))
                                   for axis in ("north", "east"))
        horizontal_floor = NOISE_FRACTION * self.max_horizontal_position_error_m
        title = (f"3-D psi-angle errors at {math.degrees(self.latitude_rad):.6g} deg, V_N = "
                 f"{self.velocity_north_m_s:g} m/s, V_E = {self.velocity_east_m_s:g} m/s, {self.duration_s:,.6g} s")
        summary = Table(title=title, show_header=False)
        summary.add_column("quantity")
        summary.add_column("value", justify="right")
        foucault = (f"{to_unit(self.foucault_rate_rad_s, 'deg/h'):.4g} deg/h" if self.foucault_rate_rad_s
                    else "0 (equator)")
        rows = [
            ("Schuler period, Foucault rate Omega sin L",
             f"{self.schuler_period_s / 60:.2f} min, {foucault}"),
            ("position error north, east at the end", (f"{lengths(self.final_position_error_north_m, north_floor)}, "
                                                      f"{lengths(self.final_position_error_east_m, east_floor)}")),
            ("largest horizontal position error", lengths(self.max_horizontal_position_error_m, horizontal_floor)),
            ("velocity error north, east at the end",
             f"{self.final_velocity_error_north_m_s:.4g} m/s, {self.final_velocity_error_east_m_s:.4g} m/s"),
            ("attitude error psi north, east, down at the end",
             ", ".join(f"{to_unit(v, 'arcsec'):.4g} arcsec" for v in (
                 self.final_attitude_error_north_rad, self.final_attitude_error_east_rad,
                 self.final_attitude_error_down_rad))),
        ]
        if self.vertical_channel:
            rows.append(("altitude error (down) at the end", lengths(self.final_position_error_down_m)))
        for row in rows:
            summary.add_row(*row)
        series = Table(title="position error versus time")
        for column in ("t (h)", "north (m)", "east (m)", "psi down (arcsec)"):
            series.add_column(column, justify="right")
        for k in sample_indices(self.t_s.size):
            series.add_row(f"{self.t_s[k] / 3600:.4g}", f"{self.states['position_error_north'][k]:,.6g}",
                           f"{self.states['position_error_east'][k]:,.6g}",
                           f"{to_unit(self.states['psi_down'][k], 'arcsec'):.4g}")
        return Group(summary, series)


def _model_inputs(model, values: dict[str, float]) -> list[float]:
    """The model's input vector from the options, by channel name (accelerometer errors, then drifts)."""
    by_channel = {f"accelerometer_error_{axis}": values[f"accel_bias_{axis}"] for axis in AXES}
    by_channel.update({f"drift_{axis}": values[f"drift_{axis}"] for axis in AXES})
    return [by_channel[name] for name in model.inputs]


def _initial_state(model, values: dict[str, float]) -> list[float]:
    """The model's initial state from the options, by state name (other states start at zero)."""
    by_state = {f"velocity_error_{axis}": values[f"initial_velocity_error_{axis}"] for axis in AXES[:2]}
    by_state.update({f"psi_{axis}": values[f"initial_attitude_error_{axis}"] for axis in AXES})
    return [by_state.get(name, 0.0) for name in model.states]


def three_d(*, latitude: float, velocity_north: float, velocity_east: float, duration: float, output_step: float,
            drift_north: float, drift_east: float, drift_down: float, accel_bias_north: float,
            accel_bias_east: float, accel_bias_down: float, initial_velocity_error_north: float,
            initial_velocity_error_east: float, initial_attitude_error_north: float,
            initial_attitude_error_east: float, initial_attitude_error_down: float, vertical_channel: bool,
            earth: str, radius: float | None, gravity: float | None, earth_rate: float | None) -> ThreeDResult:
    """Simulate the 3-D psi-angle error model exactly on an output grid (SI in and out).

    Takes every option of :data:`THREE_D_PARAMETERS` (build them with its
    ``case()``, which fills the defaults and refuses unknown names); signs in the
    module notes.

    Parameters
    ----------
    latitude : float
        Latitude L of the vehicle, rad, in (-pi/2, pi/2).
    velocity_north, velocity_east : float
        Vehicle's constant ground speeds V_N, V_E, m/s (coefficients frozen at L).
    duration : float
        Length of the run, s (> 0, at most :data:`MAX_DURATION`).
    output_step : float
        Output step, s (> 0; the simulation is exact between outputs).
    drift_north, drift_east, drift_down : float
        Platform drift rate epsilon about north, east, down, rad/s: -(gyro bias) resolved in the level frame.
    accel_bias_north, accel_bias_east, accel_bias_down : float
        Accelerometer bias nabla resolved north, east, down, m/s^2, measured - true (down: vertical channel
        only).
    initial_velocity_error_north, initial_velocity_error_east : float
        Velocity errors at the start, m/s (computed - true).
    initial_attitude_error_north, initial_attitude_error_east, initial_attitude_error_down : float
        Platform attitude errors psi(0) about north, east, down, rad.
    vertical_channel : bool
        Whether to include the pure-inertial vertical channel (unstable); without it the down errors are held
        at zero.
    earth : str
        Preset of the Earth constants (:func:`~schuler.navigation_errors.inputs.earth_constants`).
    radius : float, optional
        R overriding the preset's, m.
    gravity : float, optional
        g0 overriding the preset's, m/s^2.
    earth_rate : float, optional
        Earth rate Omega, rad/s (None: the preset's; 0: a non-rotating Earth).

    Returns
    -------
    ThreeDResult
        Final errors (m, m/s, rad; computed - true in NED), the largest horizontal position error (m), the
        Schuler period (s), the Foucault rate (rad/s), the eigenvalues (real part 1/s, imaginary rad/s) and
        the histories over ``t_s`` (s).

    Raises
    ------
    InvalidParameter
        ``accel_bias_down`` without ``vertical_channel``; a grid longer than the
        duration; options out of range.

    Examples
    --------
    >>> r = three_d(**THREE_D_PARAMETERS.case(initial_velocity_error_north=0.3048, duration=5060.0,
    ...                                       output_step=10.0, earth_rate=0.0, earth="bollay"))
    >>> round(r.max_horizontal_position_error_m / 0.3048)   # Bollay: Delta_V / omega = 805 ft
    805
    """
    values = dict(locals())
    if not vertical_channel and accel_bias_down != 0.0:
        raise InvalidParameter("accel_bias_down", "acts on the vertical channel only: set vertical_channel too")
    R, g = earth_constants(earth, radius, gravity)
    if vertical_channel:
        check_vertical_growth(duration, R, g)
    rate = PRESETS[earth].rate if earth_rate is None else earth_rate
    model = psi_angle_model(latitude=latitude, radius=R, gravity=g, rate=rate, velocity_north=velocity_north,
                            velocity_east=velocity_east, vertical_channel=vertical_channel)
    width = model.n_states + model.n_inputs
    require(grid_points(duration, output_step, names=GRID_NAMES) * 8 * (width * width + 3 * model.n_states + 2),
            "this run", "`duration` or `output_step`")
    latitude_change = abs(velocity_north) * duration / R
    if latitude_change > LATITUDE_CHANGE_WARNING:
        warnings.warn(f"the vehicle moves {math.degrees(latitude_change):.3g} deg in latitude over the run; the "
                      f"model's coefficients stay those of {math.degrees(latitude):.6g} deg", UserWarning,
                      stacklevel=2)
    t = time_grid(duration, output_step, names=GRID_NAMES, max_points=sys.maxsize)  # sized by require above
    response = simulate(model, t, initial_state=_initial_state(model, values), inputs=_model_inputs(model, values))
    histories = {name: response[name] for name in model.states}
    final = {name: float(history[-1]) for name, history in histories.items()}
    eigenvalues = model.eigenvalues()
    return ThreeDResult(
        latitude_rad=latitude, velocity_north_m_s=velocity_north, velocity_east_m_s=velocity_east,
        vertical_channel=vertical_channel, radius_m=R, gravity_m_s2=g, earth_rate_rad_s=rate, duration_s=float(t[-1]),
        final_position_error_north_m=final["position_error_north"],
        final_position_error_east_m=final["position_error_east"],
        final_position_error_down_m=final.get("position_error_down"),
        final_velocity_error_north_m_s=final["velocity_error_north"],
        final_velocity_error_east_m_s=final["velocity_error_east"],
        final_velocity_error_down_m_s=final.get("velocity_error_down"),
        final_attitude_error_north_rad=final["psi_north"], final_attitude_error_east_rad=final["psi_east"],
        final_attitude_error_down_rad=final["psi_down"],
        max_horizontal_position_error_m=float(np.max(np.hypot(histories["position_error_north"],
                                                              histories["position_error_east"]))),
        schuler_period_s=2.0 * math.pi * math.sqrt(R / g), foucault_rate_rad_s=rate * math.sin(latitude),
        eigenvalues_real_per_s=eigenvalues.real, eigenvalues_imag_rad_s=eigenvalues.imag,
        t_s=t, states=histories, state_units=dict(zip(model.states, model.state_units)),
    )
