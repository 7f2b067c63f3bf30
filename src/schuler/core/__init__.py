"""Shared numerical core: pure functions and types on SI floats and arrays.

Nothing here parses units, plots, prints or writes files. The shared geometry
(:mod:`schuler.core.geometry`: angle constants, the Earth rate in a level frame,
the time-grid rule and its point count) is re-exported here; the KPI manual's
gyrocompass loop design (T, zeta <-> c_Gamma, c_a) is
:mod:`schuler.core.gyrocompass_design`.
"""

from schuler.core.geometry import (
    ARCMIN,
    ARCSEC,
    DEG_PER_HOUR,
    DEGREE,
    earth_rate_north_up,
    grid_points,
    horizontal_earth_rate,
    level_frame_earth_rate,
    time_grid,
    time_grids,
    uniform_step,
)

__all__ = [
    "ARCMIN",
    "ARCSEC",
    "DEGREE",
    "DEG_PER_HOUR",
    "earth_rate_north_up",
    "grid_points",
    "horizontal_earth_rate",
    "level_frame_earth_rate",
    "time_grid",
    "time_grids",
    "uniform_step",
]
