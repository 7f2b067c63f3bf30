"""Names of the nonlinear INS's error channels (computed - true), SI unit in each name, and their display units.

Shared by the result types (:mod:`schuler.navigate.results`) and the figures
(:mod:`schuler.navigate.plots`), which must not import each other.
"""

from __future__ import annotations

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
"""Every error history of a run, in order."""

VERTICAL_CHANNELS_OUTPUT: tuple[str, ...] = ("height_error_m", "velocity_error_down_m_s")
"""Channels left out of a result's ``to_dict`` when the vertical channel is off (height held to the truth)."""

DISPLAY_UNITS = {"m": "m", "m_s": "m/s", "rad": "arcsec"}
"""Display unit of each SI suffix: errors of position in m, velocity in m/s, attitude in arcsec."""


def suffix(name: str) -> str:
    """The SI suffix of a channel name: ``m``, ``m_s`` or ``rad``.

    Parameters
    ----------
    name : str
        Channel name, one of :data:`ERROR_CHANNELS` (or another name ending in its SI unit).

    Returns
    -------
    str
        The suffix, a key of :data:`DISPLAY_UNITS`.

    Examples
    --------
    >>> suffix("velocity_error_down_m_s"), suffix("roll_error_rad")
    ('m_s', 'rad')
    """
    return "m_s" if name.endswith("_m_s") else name.rsplit("_", 1)[-1]


def shown_channels(vertical_channel: str) -> tuple[str, ...]:
    """The channels a run reports: all nine, or seven when the vertical channel is off.

    Parameters
    ----------
    vertical_channel : {"free", "off", "baro"}
        The run's vertical channel; ``"off"`` (height held to the truth) drops
        the height and down-velocity errors.

    Returns
    -------
    tuple of str
        Channel names, in the order of :data:`ERROR_CHANNELS`.
    """
    return tuple(c for c in ERROR_CHANNELS if vertical_channel != "off" or c not in VERTICAL_CHANNELS_OUTPUT)
