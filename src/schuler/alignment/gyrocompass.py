"""A strapdown gyrocompass: the KPI manual's physical gyrocompassing, with the platform computed.

A computed level frame (C_b^n) is carried by the gyros and torqued by its own
sensed specific force f = C f_b, as the KPI manual's platform is by its
accelerometers (control law (1.6) with c_Gamma = -c1 g, c_a = c2 g):

    omega_command = omega_ie + (c_gamma f_E / g, -c_gamma f_N / g, -c_a f_N / g)   (NED)

so a north tilt decays with c_Gamma and an east tilt, which a heading error
makes grow at Omega cos L per radian, turns the frame in azimuth until it
stops (the loop (1.19)/(1.20) of schuler align, the same equations under the mapping
of :func:`~schuler.alignment.limits.kpi_equivalent_inputs`). The gains come from
a time constant T and damping zeta by the manual's design (end of its Sec. 2,
:func:`schuler.core.gyrocompass_design.loop_gains`; T = 30 s, zeta = 0.8 by default):
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
>>> settling_time(DESIGN_TIME_CONSTANT, DESIGN_DAMPING)   # 5 T / zeta, s
187.5
"""

from __future__ import annotations

import numpy as np

from schuler.alignment import _kernels
from schuler.alignment.data import MethodEstimate, StaticBatch
from schuler.alignment.inertial import start_attitude
from schuler.alignment.limits import horizontal_rate
from schuler.core.attitude import euler_from_dcm
from schuler.core.earth import earth_rate_ned
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_gains
from schuler.exceptions import renamed_keywords

SETTLING_DECREMENTS = 5.0
"""Settling time = 5 / h (the manual's t = 5 / h)."""


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


@renamed_keywords(time_constant_s="time_constant", initial_window_s="initial_window", history_step_s="history_step")
def align_gyrocompass(batch: StaticBatch, *, time_constant: float = DESIGN_TIME_CONSTANT,
                      damping: float = DESIGN_DAMPING, initial_window: float = 30.0,
                      history_step: float = 1.0) -> MethodEstimate:
    """The strapdown gyrocompass over every record of ``batch``, started from inertial-frame alignment.

    Parameters
    ----------
    batch : StaticBatch
    time_constant, damping : float
        T (s) and zeta of the azimuth loop.
    initial_window : float
        Inertial-frame alignment over the first seconds gives the start.
    history_step : float
        Step of the histories, s.

    Returns
    -------
    MethodEstimate
        No 1-sigma of its own: its accuracy is the limit of its design
        (:func:`~schuler.alignment.limits.accuracy_limit` with the gains).
    """
    horizontal_rate(batch.latitude_rad)  # refuses beyond MAX_LATITUDE, where heading is not observable
    c_gamma, c_a = loop_gains(batch.latitude_rad, time_constant, damping)
    dt = batch.sample_interval_s
    attitude = start_attitude(batch.head(initial_window))
    ends = batch.history_indices(history_step)
    history = np.empty((batch.members, ends.size, 3, 3))
    _kernels.gyrocompass_loop(batch.gyro_increment, batch.accel_increment, dt, attitude,
                              earth_rate_ned(batch.latitude_rad), batch.gravity, c_gamma, c_a, ends,
                              history)
    roll, pitch, heading = euler_from_dcm(history)
    return MethodEstimate("gyrocompass", roll[:, -1], pitch[:, -1], heading[:, -1], None, ends * dt, roll, pitch,
                          heading)
