"""A strapdown gyrocompass: the KPI manual's physical gyrocompassing, with the platform computed.

A computed level frame (C_b^n) is carried by the gyros and torqued by its own
sensed specific force f = C f_b, as the KPI manual's platform is by its
accelerometers (control law (1.6) with c_Gamma = -c1 g, c_a = c2 g):

    omega_command = omega_ie + (c_gamma f_E / g, -c_gamma f_N / g, -c_a f_N / g)   (NED)

so a north tilt decays with c_Gamma and an east tilt, which a heading error
makes grow at Omega cos L per radian, turns the frame in azimuth until it
stops (the loop (1.19)/(1.20) of schuler align, the same equations under the mapping
of :func:`~schuler.alignment.limits.kpi_equivalent_inputs`). The gains come from
a time constant T and damping zeta by the manual's design (end of its Sec. 2):
T^2 p^2 + 2 T zeta p + 1 = p^2 + c_Gamma p + U_eta c_a, so

    c_a = 1 / (T^2 Omega cos L),    c_Gamma = 2 zeta / T,

and the settling time is 5 / h = 5 T / zeta (h = c_Gamma / 2; the manual's
"t = 5 / h"). Steady state: :func:`~schuler.alignment.limits.gyrocompass_steady_state`;
noise: :func:`~schuler.alignment.limits.gyrocompass_noise`.

Reference: Meleshko, V. V. (compiler), "Physical gyrocompassing of a
semi-analytic INS", laboratory manual, NTUU "Kyiv Polytechnic Institute"
(:data:`schuler.references.KPI_LAB_MANUAL`), eqs. (1.6), (1.19)-(1.22).

Examples
--------
>>> import math
>>> c_gamma, c_a = loop_gains(math.radians(50.0), 30.0, 0.8)
>>> round(c_gamma, 4), round(c_a, 2)
(0.0533, 23.7)
"""

from __future__ import annotations

import math

import numpy as np

from schuler.alignment import _kernels
from schuler.alignment.data import MethodEstimate, StaticBatch
from schuler.alignment.inertial import start_attitude
from schuler.alignment.limits import horizontal_rate
from schuler.core.attitude import euler_from_dcm
from schuler.core.earth import earth_rate_ned
from schuler.exceptions import InvalidParameter

DEFAULT_TIME_CONSTANT = 30.0
"""T, s: the manual's "often T = 30 s"."""

DEFAULT_DAMPING = 0.8
"""zeta: the manual's "often zeta = 0.8"."""

SETTLING_DECREMENTS = 5.0
"""Settling time = 5 / h (the manual's t = 5 / h)."""


def loop_gains(latitude: float, time_constant: float, damping: float) -> tuple[float, float]:
    """(c_gamma, c_a), 1/s, from T (s) and zeta: c_a = 1 / (T^2 Omega cos L), c_gamma = 2 zeta / T.

    Parameters
    ----------
    latitude : float
        Latitude L, rad.
    time_constant : float
        Time constant T of the azimuth loop, s.
    damping : float
        Damping zeta of the azimuth loop, plain number.

    Returns
    -------
    c_gamma, c_a : float
        Gains of the levelling and azimuth channels (KPI manual (1.6)), 1/s.

    Raises
    ------
    InvalidParameter
        T or zeta not positive.
    NotObservable
        Beyond :data:`~schuler.alignment.limits.MAX_LATITUDE`.
    """
    if not (math.isfinite(time_constant) and time_constant > 0):
        raise InvalidParameter("time_constant", f"must be finite and > 0 s, got {time_constant!r}")
    if not (math.isfinite(damping) and damping > 0):
        raise InvalidParameter("damping", f"must be finite and > 0, got {damping!r}")
    rate = float(horizontal_rate(latitude))
    return 2.0 * damping / time_constant, 1.0 / (time_constant**2 * rate)


def settling_time(time_constant: float, damping: float) -> float:
    """5 / h = 5 T / zeta, s (the manual's settling time of the oscillatory loop; zeta <= 1).

    Parameters
    ----------
    time_constant : float
        Time constant T of the azimuth loop, s.
    damping : float
        Damping zeta of the azimuth loop, plain number.

    Returns
    -------
    float
        Settling time, s.
    """
    return SETTLING_DECREMENTS * time_constant / damping


def align_gyrocompass(batch: StaticBatch, *, time_constant_s: float = DEFAULT_TIME_CONSTANT,
                      damping: float = DEFAULT_DAMPING, initial_window_s: float = 30.0,
                      history_step_s: float = 1.0) -> MethodEstimate:
    """The strapdown gyrocompass over every record of ``batch``, started from inertial-frame alignment.

    Parameters
    ----------
    batch : StaticBatch
    time_constant_s, damping : float
        T (s) and zeta of the azimuth loop.
    initial_window_s : float
        Inertial-frame alignment over the first seconds gives the start.
    history_step_s : float
        Step of the histories, s.

    Returns
    -------
    MethodEstimate
        No 1-sigma of its own: its accuracy is the limit of its design
        (:func:`~schuler.alignment.limits.accuracy_limit` with the gains).
    """
    c_gamma, c_a = loop_gains(batch.latitude_rad, time_constant_s, damping)
    dt = batch.sample_interval_s
    attitude = start_attitude(batch.head(initial_window_s))
    ends = batch.history_indices(history_step_s)
    history = np.empty((batch.members, ends.size, 3, 3))
    _kernels.gyrocompass_loop(batch.gyro_increment, batch.accel_increment, dt, attitude,
                              earth_rate_ned(batch.latitude_rad), batch.gravity, c_gamma, c_a, ends,
                              history)
    roll, pitch, heading = euler_from_dcm(history)
    return MethodEstimate("gyrocompass", roll[:, -1], pitch[:, -1], heading[:, -1], None, ends * dt, roll, pitch,
                          heading)
