"""What a record at rest says about where it is and how it stands: latitude and attitude from its mean rates.

At rest the gyros measure the Earth rate and the accelerometers the specific
force, whatever the attitude: in NED, omega_ie = Omega [cos L, 0, -sin L] and
f = [0, 0, -g]. The double-vector (TRIAD) solution builds the NED axes in body
coordinates from the two measured means (spec 06, "Alignment at rest: coarse
(double vector)")::

    d_b = -f / |f|,   e_b = (d_b x omega) / |d_b x omega|,   n_b = e_b x d_b,
    C_b^n = [n_b; e_b; d_b]   (rows),

and the latitude from the angle between the two vectors, which no attitude
changes: sin L = (omega . f) / (|omega| |f|). Heading psi = atan2(C21, C11),
pitch theta = -asin(C31), roll phi = atan2(C32, C33) (aerospace Euler angles,
heading-pitch-roll order). A gyro bias b_E east of the true north tilts the solution by
-b_E / (Omega cos L) in heading (the static limit of spec 06), so this is a
check of a record, not an alignment.

References
----------
P. D. Groves, "Principles of GNSS, Inertial, and Multisensor Integrated
Navigation Systems", 2nd ed., Artech House, 2013, ch. 5 (initialisation and alignment).
D. H. Titterton, J. L. Weston, "Strapdown Inertial Navigation Technology", 2nd ed.,
IET, 2004, ch. 10 (alignment).

Examples
--------
>>> import math
>>> from schuler.imu.simulate import static_truth
>>> gyro, accel = static_truth(math.radians(34.0), math.radians(90.0))
>>> attitude = static_attitude(gyro, accel)
>>> round(math.degrees(attitude.latitude_rad), 9), round(math.degrees(attitude.heading_rad), 9)
(34.0, 90.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.exceptions import InvalidParameter, renamed_keywords


@dataclass(frozen=True)
class StaticAttitude:
    """Latitude and attitude of a resting IMU from its mean rates, rad (heading in [0, 2 pi))."""

    latitude_rad: float
    roll_rad: float
    pitch_rad: float
    heading_rad: float


@renamed_keywords(mean_gyro_rad_s="mean_gyro", mean_accel_m_s2="mean_accel")
def static_attitude(mean_gyro, mean_accel) -> StaticAttitude:
    """Latitude, roll, pitch and heading of a resting IMU from its mean gyro and accelerometer rates.

    Parameters
    ----------
    mean_gyro : array_like (3,)
        Mean angular rate, body x forward, y right, z down, rad/s.
    mean_accel : array_like (3,)
        Mean specific force, same axes, m/s^2.

    Returns
    -------
    StaticAttitude

    Raises
    ------
    InvalidParameter
        A zero vector, or parallel rates (at a pole, or a record in motion).
    """
    omega = np.asarray(mean_gyro, dtype=float).reshape(3)
    force = np.asarray(mean_accel, dtype=float).reshape(3)
    if not (np.all(np.isfinite(omega)) and np.all(np.isfinite(force))):
        raise InvalidParameter("mean rates", "must be finite")
    size_omega, size_force = float(np.linalg.norm(omega)), float(np.linalg.norm(force))
    if size_omega == 0.0 or size_force == 0.0:
        raise InvalidParameter("mean rates", "a zero mean rate or specific force gives no direction")
    down = -force / size_force
    east = np.cross(down, omega)
    if np.linalg.norm(east) < 1e-6 * size_omega:
        raise InvalidParameter("mean rates", "the Earth rate is parallel to gravity (a pole): no north")
    east /= np.linalg.norm(east)
    north = np.cross(east, down)
    c = np.vstack([north, east, down])  # C_b^n
    sin_latitude = float(np.clip(omega @ force / (size_omega * size_force), -1.0, 1.0))
    return StaticAttitude(latitude_rad=math.asin(sin_latitude), roll_rad=math.atan2(c[2, 1], c[2, 2]),
                          pitch_rad=-math.asin(float(np.clip(c[2, 0], -1.0, 1.0))),
                          heading_rad=math.atan2(c[1, 0], c[0, 0]) % (2.0 * math.pi))
