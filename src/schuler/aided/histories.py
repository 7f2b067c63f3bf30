"""What an aided run keeps of its first member: the error, navigation and innovation histories and the extras.

The histories are SI with their units (:class:`schuler.core.response.Histories`); ``aided_errors`` holds the
errors against the truth and the filter's 1-sigma at every output time (with ``--smooth`` the smoother's beside,
prefixed ``smoothed_``), ``navigation`` the solution and its 1-sigma, ``aided_innovations`` the GNSS innovations
over their predicted 1-sigma. :func:`run_extras` gives the JSON's structured keys (outages, NEES, NIS, rejected
measurements per source).
"""

from __future__ import annotations

import math

import numpy as np

from schuler.aided import analysis, smoother
from schuler.core.attitude import euler_from_quaternion
from schuler.core.response import Histories


def _variances(run, t_s: np.ndarray) -> np.ndarray:
    """Position, velocity and psi variances in force at each time (the last covariance stored), shape (n, 9)."""
    rows = np.maximum(np.searchsorted(run.covariance_t_s, t_s + 1e-9) - 1, 0)
    # the diagonal first: the full matrices at every IMU epoch would be 300,000 x 21 x 21 doubles
    return np.diagonal(run.covariance[0], axis1=1, axis2=2)[:, :9][rows]


def error_histories(run, errors, smoothed=None) -> Histories:
    """One member's errors and the filter's 1-sigma of each, at every output time (SI; no errors without a truth).

    With ``smoothed`` the smoother's errors and 1-sigma (interpolated between its stored times,
    :func:`schuler.aided.smoother.output_variances`) follow, the same channels prefixed ``smoothed_``.

    Parameters
    ----------
    run : FilterRun
        A filter run of one member.
    errors : analysis.Errors or None
        Its errors against the truth (None: the 1-sigma alone).
    smoothed : tuple of (FilterRun, analysis.Errors or None), optional
        The smoothed run of that member and its errors.
    """
    t_s = run.t_s if errors is None else errors.t_s
    channels = _error_channels(errors, _variances(run, t_s))
    if smoothed is not None:
        variance = smoother.output_variances(smoothed[0], t_s)[0]
        channels.update({f"smoothed_{name}": values for name, values in _error_channels(smoothed[1], variance).items()})
    units = {name: "rad" if name.endswith("_rad") else "m/s" if name.endswith("_m_s") else "m" for name in channels}
    return Histories(t_s, channels, units)


def _error_channels(errors, variance: np.ndarray) -> dict[str, np.ndarray]:
    """The error channels of member 0 (none without a truth) and the 1-sigma of the variances given, shape (n, 9)."""
    channels = {}
    if errors is not None:
        channels = {
            "north_error_m": errors.position[0, :, 0], "east_error_m": errors.position[0, :, 1],
            "down_error_m": errors.position[0, :, 2], "horizontal_error_m": errors.horizontal[0],
            "velocity_north_error_m_s": errors.velocity[0, :, 0], "velocity_east_error_m_s": errors.velocity[0, :, 1],
            "velocity_down_error_m_s": errors.velocity[0, :, 2], "heading_error_rad": errors.heading[0]}
    channels.update({
        "north_sigma_m": np.sqrt(variance[:, 0]), "east_sigma_m": np.sqrt(variance[:, 1]),
        "down_sigma_m": np.sqrt(variance[:, 2]), "horizontal_sigma_m": np.sqrt(variance[:, 0] + variance[:, 1]),
        "heading_sigma_rad": np.sqrt(variance[:, 8])})
    return channels


INNOVATION_COMPONENTS = ("position_north", "position_east", "position_down", "velocity_north", "velocity_east",
                         "velocity_down")
"""The GNSS residual's components in the order of the filter's measurement (velocities where they are used)."""


def innovation_histories(run) -> Histories:
    """One member's GNSS innovations at each epoch: each component over its predicted 1-sigma, the NIS, accepted.

    Parameters
    ----------
    run : FilterRun
        A filter run of one member.
    """
    residual, sigma = run.residual[0], run.residual_sigma[0]
    channels = {f"{name}_normalised": residual[:, k] / sigma[:, k]
                for k, name in enumerate(INNOVATION_COMPONENTS[:residual.shape[1]])}
    channels["nis"] = run.nis[0]
    channels["accepted"] = run.accepted[0].astype(float)
    return Histories(run.epoch_t_s, channels, {name: "1" for name in channels})


NAVIGATION_CHANNELS = {
    "latitude_rad": "rad", "longitude_rad": "rad", "height_m": "m", "velocity_north_m_s": "m/s",
    "velocity_east_m_s": "m/s", "velocity_down_m_s": "m/s", "roll_rad": "rad", "pitch_rad": "rad", "yaw_rad": "rad",
    "north_sigma_m": "m", "east_sigma_m": "m", "down_sigma_m": "m", "velocity_north_sigma_m_s": "m/s",
    "velocity_east_sigma_m_s": "m/s", "velocity_down_sigma_m_s": "m/s", "psi_north_sigma_rad": "rad",
    "psi_east_sigma_rad": "rad", "psi_down_sigma_rad": "rad"}
"""The ``navigation`` histories: the solution and the filter's 1-sigma of position, velocity and psi (NED)."""


def navigation_histories(run) -> Histories:
    """One member's navigation solution and the filter's 1-sigma at every output time (SI).

    Parameters
    ----------
    run : FilterRun
        A filter run of one member.
    """
    solution = run.solution[0]
    attitude = euler_from_quaternion(solution[:, 6:10])
    sigma = np.sqrt(_variances(run, run.t_s))
    values = np.column_stack([solution[:, :6], attitude, sigma])
    return Histories(run.t_s, {name: values[:, k] for k, name in enumerate(NAVIGATION_CHANNELS)},
                     dict(NAVIGATION_CHANNELS))


def run_extras(run, errors, outages) -> dict:
    """The JSON-safe results beside the outputs: each outage's drift, NEES and NIS consistency, rejected epochs.

    Without a truth (``errors`` None) the error keys are None and the filter's 1-sigma remain.

    Parameters
    ----------
    run : FilterRun
        A filter run of one member.
    errors : analysis.Errors or None
        Its errors against the truth.
    outages : sequence of (float, float)
        The outages, (start, duration), s.
    """
    import scipy.stats

    drifts = analysis.outage_drift(run, errors, outages)
    accepted = run.accepted[0]
    nis = run.nis[0][accepted]
    dof = run.residual.shape[-1]
    low, high = scipy.stats.chi2.ppf([0.005, 0.995], dof)
    if errors is not None:
        check = analysis.consistency(run, errors)
        nees = {name: {"inside": check.inside[name], "band": list(check.band)} for name in check.inside}
    else:
        band = list(scipy.stats.chi2.ppf([0.005, 0.995], 3))
        nees = {name: {"inside": None, "band": band} for name in analysis.GROUPS}

    def number(value):
        return None if math.isnan(value) else value

    return {
        "outages": [{"start_s": d.start_s, "duration_s": d.duration_s,
                     "horizontal_error_max_m": number(d.horizontal_error_max_m),
                     "vertical_error_max_m": number(d.vertical_error_max_m),
                     "heading_error_max_rad": number(d.heading_error_max_rad),
                     "horizontal_error_sigma_m": d.horizontal_error_sigma_m} for d in drifts],
        "nees": nees,
        "nis": {"inside": float(np.mean((nis >= low) & (nis <= high))) if nis.size else None,
                "band": [float(low), float(high)]},
        "rejected_by_source": {name: int(count[0]) for name, count in run.rejected_by_source().items()},  # epochs
    }
