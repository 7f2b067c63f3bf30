"""Shared numerical core: pure functions and types on SI floats and arrays.

Nothing here parses units, plots, prints or writes files. The shared geometry
(:mod:`schuler.core.geometry`: angle constants, the Earth rate in a level frame,
the time-grid rule) is re-exported here.
"""

from schuler.core.geometry import (
    ARCMIN,
    ARCSEC,
    DEG_PER_HOUR,
    DEGREE,
    earth_rate_north_up,
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
    "horizontal_earth_rate",
    "level_frame_earth_rate",
    "time_grid",
    "time_grids",
    "uniform_step",
]
