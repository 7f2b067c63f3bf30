"""A swaying base: the exact gyro and accelerometer increments of a level IMU that rocks and shakes in place.

A vehicle at rest with people, wind or an engine moves about its rest attitude and
position. Here each member's roll, pitch and heading and its north, east and down
displacement are each a sum of sinusoids with random amplitude, frequency and phase
(addressed draws: the same member always sways the same way). The increments are
what an ideal IMU measures, integrated over each sample interval (3-point
Gauss-Legendre quadrature of the body rate and of the specific force in body axes),
so the strapdown algorithms see the sway's coning and sculling as they would on a
real base:

    omega_ib^b = omega_nb^b(Euler rates) + C_n^b omega_ie^n,   f^b = C_n^b (a^n - g^n)

with C_b^n = R_z(psi) R_y(theta) R_x(phi) (NED, body x forward / y right / z down) and
the Coriolis term 2 Omega x v of the sway velocity left out (about 1e-6 m/s^2 for
millimetres at a few hertz, and of zero mean). :func:`sway_batch` adds the sway to a
batch simulated at rest: the sensor errors act on the rest inputs only, and leave out
their scale-factor and misalignment share of the sway itself (parts per million of it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.alignment.data import StaticBatch
from schuler.core.attitude import dcm_from_euler
from schuler.core.earth import earth_rate_ned
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter, renamed_keywords

_NODES = np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0


@dataclass(frozen=True)
class Sway:
    """How the base moves (SI): per channel, ``components`` sinusoids of amplitude drawn in [amplitude / 2, amplitude].

    Attributes
    ----------
    angle_rad : float
        Largest amplitude of each sinusoid of roll, pitch and heading, rad.
    displacement_m : float
        Largest amplitude of each sinusoid of the north, east and down displacement, m.
    frequency_hz : (float, float)
        Range of the sinusoids' frequencies, Hz.
    components : int
        Sinusoids per channel.
    """

    angle_rad: float = math.radians(0.02)
    displacement_m: float = 0.002
    frequency_hz: tuple[float, float] = (0.3, 3.0)
    components: int = 3

    def __post_init__(self):
        low, high = self.frequency_hz
        if not (self.angle_rad >= 0 and self.displacement_m >= 0 and 0 < low <= high and self.components >= 1):
            raise InvalidParameter("sway", f"{self!r}: amplitudes >= 0, 0 < lowest <= highest frequency, >= 1 "
                                   "component")


def _draws(sway: Sway, members, seed: int):
    streams = RandomStreams(seed)
    shape = (len(members), 6, sway.components)
    size = 6 * sway.components
    amplitude = (0.5 + 0.5 * streams.uniform("sway amplitude", members, size)).reshape(shape)
    amplitude[:, :3] *= sway.angle_rad
    amplitude[:, 3:] *= sway.displacement_m
    low, high = sway.frequency_hz
    frequency = 2.0 * math.pi * (low + (high - low) * streams.uniform("sway frequency", members, size)).reshape(shape)
    phase = 2.0 * math.pi * streams.uniform("sway phase", members, size).reshape(shape)
    return amplitude, frequency, phase


def _motion(t: np.ndarray, amplitude, frequency, phase):
    """(value, rate, second derivative) of the six channels at times t: each (6, len(t))."""
    arg = frequency[:, :, None] * t[None, None, :] + phase[:, :, None]
    value = (amplitude[:, :, None] * np.sin(arg)).sum(axis=1)
    rate = (amplitude[:, :, None] * frequency[:, :, None] * np.cos(arg)).sum(axis=1)
    second = -(amplitude[:, :, None] * frequency[:, :, None] ** 2 * np.sin(arg)).sum(axis=1)
    return value, rate, second


def _inputs(t: np.ndarray, heading: float, latitude: float, gravity: float, amplitude, frequency, phase):
    """Body rate (rad/s) and specific force (m/s^2) in body axes at times t, each (len(t), 3), and C_b^n."""
    angle, angle_rate, _ = _motion(t, amplitude[:3], frequency[:3], phase[:3])
    _, _, accel = _motion(t, amplitude[3:], frequency[3:], phase[3:])
    roll, pitch, yaw = angle[0], angle[1], heading + angle[2]
    d_roll, d_pitch, d_yaw = angle_rate
    sr, cr, sp, cp = np.sin(roll), np.cos(roll), np.sin(pitch), np.cos(pitch)
    body_rate = np.stack([d_roll - d_yaw * sp, d_pitch * cr + d_yaw * sr * cp, -d_pitch * sr + d_yaw * cr * cp],
                         axis=1)
    C = dcm_from_euler(roll, pitch, yaw)
    specific_force = accel.T - np.array([0.0, 0.0, gravity])
    body_rate += np.einsum("kji,j->ki", C, earth_rate_ned(latitude))
    return body_rate, np.einsum("kji,kj->ki", C, specific_force), C


@renamed_keywords(heading_rad="heading")
def sway_batch(batch: StaticBatch, sway: Sway, *, heading: float, members, seed: int = 0):
    """``batch`` (simulated at rest, level, at ``heading``) with the base's sway added: (batch, final attitudes).

    Parameters
    ----------
    batch : StaticBatch
        Records of a level IMU at rest (true heading ``heading``), with their sensor errors.
    sway : Sway
        How the base moves.
    heading : float
        The records' rest heading, rad, clockwise from north.
    members : array_like of int
        The member numbers of the batch's records (the addresses of the sway's draws).
    seed : int
        Seed of the sway's draws.

    Returns
    -------
    batch : StaticBatch
        The swaying records.
    attitude : ndarray (m, 3)
        Each member's true roll, pitch and heading at the window's end, rad.
    """
    members = np.atleast_1d(np.asarray(members, dtype=np.int64))
    if members.size != batch.members:
        raise InvalidParameter("members", f"{members.size} member numbers for {batch.members} records")
    dt, n = batch.sample_interval_s, batch.samples
    starts = dt * np.arange(n)
    rest_gyro = np.einsum("ji,j->i", dcm_from_euler(0.0, 0.0, heading), earth_rate_ned(batch.latitude_rad))
    rest_accel = np.array([0.0, 0.0, -batch.gravity])
    gyro, accel = batch.gyro_increment.copy(), batch.accel_increment.copy()
    final = np.empty((members.size, 3))
    amplitude, frequency, phase = _draws(sway, members, seed)
    for row in range(members.size):
        for node, weight in zip(_NODES, _WEIGHTS, strict=True):
            rate, force, _ = _inputs(starts + dt * (1.0 + node) / 2.0, heading, batch.latitude_rad,
                                     batch.gravity, amplitude[row], frequency[row], phase[row])
            gyro[row] += weight * dt * (rate - rest_gyro)
            accel[row] += weight * dt * (force - rest_accel)
        angle, _, _ = _motion(np.array([n * dt]), amplitude[row, :3], frequency[row, :3], phase[row, :3])
        final[row] = angle[0, 0], angle[1, 0], heading + angle[2, 0]
    return StaticBatch(gyro, accel, dt, batch.latitude_rad, batch.gravity_m_s2), final
