"""``schuler vertical friction``: Coulomb friction in the gimbal bearings, Drozdovich (1959), eqs. (30)-(32).

The simplest base motion of the source's friction study (no Earth rotation,
Schuler-tuned) with q_1 = M_fr,x / H = dead_zone / R on the outer axis x and
q_2 = inner_ratio q_1 on the inner axis y; an optional ramp of W_x on the
x accelerometer tests how the static error follows an input. Frames, signs and
the stick/slip rule are those of :mod:`schuler.gyro_vertical.friction`.

Formerly: ``ramp`` -> ``ramp_acceleration``; ``ramp_time`` -> ``ramp_duration``;
bare durations (``duration``, ``ramp_duration``) were hours and are seconds now.
"""

from __future__ import annotations

import sys

import numpy as np

from schuler.contract import Action
from schuler.core.earth import PRESETS
from schuler.core.geometry import grid_points, time_grid
from schuler.gyro_vertical import friction as friction_model
from schuler.gyro_vertical.evaluation import GRID_NAMES
from schuler.gyro_vertical.results import FrictionResult
from schuler.memory import require
from schuler.params import Parameter, ParameterSet

MAX_DURATION = 30 * 86400.0
"""Longest simulated time of the friction action, s (30 days)."""

POINT_BYTES = 240
"""Memory one output point holds at the friction simulation's peak, bytes: the time grid,
the (T, 4) history, and the masks and interpolated values of one solver segment
(167 bytes measured with tracemalloc for 720 s at 1 ms)."""

FRICTION_PARAMETERS = ParameterSet((
    Parameter("dead_zone", "m/s", 0.01, "Half-width R q_1 of the velocity dead zone of the outer axis (the source's "
              "0.01 m/s); q_1 = M_fr / H follows.", minimum=0, exclusive_minimum=True, maximum=100),
    Parameter("inner_ratio", "", 1.0, "q_2 / q_1: friction of the inner (y) bearing relative to the outer.",
              minimum=0, maximum=100),
    Parameter("initial_beta", "arcsec", 0.2, "Initial tilt beta about y.", minimum=-36000, maximum=36000),
    Parameter("ramp_acceleration", "m/s^2", 0.0, "Final value of a ramp of W_x on the x accelerometer "
              "(0: no input).", minimum=-1, maximum=1),
    Parameter("ramp_duration", "s", "24 h", "Duration of the ramp.", minimum=0, exclusive_minimum=True),
    Parameter("duration", "s", "48 h", "Simulated time.", minimum=0, maximum=MAX_DURATION, exclusive_minimum=True),
    Parameter("output_step", "s", 10.0, "Interval of the output samples.", minimum=0, exclusive_minimum=True),
    Parameter("earth", "", "drozdovich", "Earth constants R and g (the source's by default).",
              choices=tuple(PRESETS), kind="choice"),
), owner="vertical friction")
"""Options of ``schuler vertical friction``."""


def friction(dead_zone: float = 0.01, inner_ratio: float = 1.0, initial_beta: float = 0.0,
             ramp_acceleration: float = 0.0, ramp_duration: float = 86400.0, duration: float = 172800.0,
             output_step: float = 10.0, earth: str = "drozdovich") -> FrictionResult:
    """Simulate (30) with q_1 = dead_zone / R and q_2 = inner_ratio q_1 (SI values).

    Parameters
    ----------
    dead_zone : float
        R q_1, m/s: half-width of the velocity dead zone of the outer axis x (> 0).
    inner_ratio : float
        q_2 / q_1: friction of the inner (y) bearing relative to the outer, plain number (>= 0).
    initial_beta : float
        Initial tilt about y, rad.
    ramp_acceleration : float
        Final W_x of the ramp, m/s^2 (0: none).
    ramp_duration, duration, output_step : float
        s.
    earth : str
        Name of the Earth constants (:data:`schuler.core.earth.PRESETS`).

    Returns
    -------
    FrictionResult
        Friction rates q_1, q_2 (rad/s) and dead zones (m/s), the stick intervals and switches (number of),
        the largest static and overall velocity errors (m/s), the slip growth rates (m/s^2) and the response
        with its histories (SI).

    Raises
    ------
    InvalidParameter
        ``output_step`` longer than ``duration``.
    MemoryBudgetExceeded
        When the histories would not fit the memory budget (before allocating).

    Examples
    --------
    >>> r = friction(initial_beta=np.radians(0.2 / 3600), duration=6 * 3600.0)
    >>> r.dead_zone_x_m_s, r.friction_x_rad_s, round(r.max_static_velocity_error_x_m_s, 9)
    (0.01, 1.5625e-09, 0.01)
    """
    constants = PRESETS[earth]
    R, g = constants.radius, constants.gravity
    require(POINT_BYTES * grid_points(duration, output_step, names=GRID_NAMES), "this friction run",
            "`duration` or `output_step`")
    time = time_grid(duration, output_step, names=GRID_NAMES, max_points=sys.maxsize)  # sized by require above
    q = (dead_zone / R, inner_ratio * dead_zone / R)
    acceleration = friction_model.AccelerationInput.ramp(ramp_acceleration, 0.0, ramp_duration) \
        if ramp_acceleration else None
    response = friction_model.simulate_friction(q, time, initial_tilt=(0.0, initial_beta), acceleration=acceleration,
                                                gravity=g, radius=R)
    static = np.abs(response.stick_velocity_errors)
    rate_x, rate_y = friction_model.friction_growth_rate(q, g, R)
    return FrictionResult(
        friction_x_rad_s=q[0], friction_y_rad_s=q[1], dead_zone_x_m_s=R * q[0], dead_zone_y_m_s=R * q[1],
        stick_intervals=len(response.stick_intervals), switches=len(response.switch_times) - 1,
        max_static_velocity_error_x_m_s=float(static[:, [0, 2]].max()) if static.size else 0.0,
        max_static_velocity_error_y_m_s=float(static[:, [1, 3]].max()) if static.size else 0.0,
        velocity_error_x_max_abs_m_s=float(np.abs(response.velocity_error_x).max()),
        velocity_error_y_max_abs_m_s=float(np.abs(response.velocity_error_y).max()),
        growth_rate_x_m_s2=float(rate_x), growth_rate_y_m_s2=float(rate_y), end_time_s=float(time[-1]),
        nfev=response.nfev, response=response,
    )


FRICTION = Action(
    name="friction",
    help="Coulomb friction in the gimbal bearings (30)-(32): stick/slip, the dead zone +-R q, the slip growth.\n\n"
         "Example: schuler vertical friction --dead-zone 0.01 --initial-beta '0.2 arcsec' --duration '48 h' "
         "--out results",
    function=friction,
    parameters=FRICTION_PARAMETERS,
)
"""The ``friction`` command of ``schuler vertical``."""
