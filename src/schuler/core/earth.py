"""Earth constants, the Schuler frequency, and the source documents' constant sets.

All values SI. The defaults are WGS-84's rotation rate, the IUGG mean radius and
standard gravity; the WGS-84 functions give the ellipsoid's radii of curvature,
normal gravity with height, the gravity vector, the Earth and transport rates in
the local North-East-Down frame (Groves 2013, ch. 2 and eq. (5.44)). A
reproduction of a source uses that source's constants through one of the named
presets (:data:`BOLLAY`, :data:`DROZDOVICH`), never the defaults.

Examples
--------
>>> round(schuler_period(STANDARD_GRAVITY, MEAN_RADIUS) / 60, 2)
84.41
>>> BOLLAY.schuler_period
5060.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

EARTH_RATE = 7.292115e-5
"""WGS-84 Earth rotation rate Omega, rad/s."""

MEAN_RADIUS = 6_371_000.0
"""Mean Earth radius R, m."""

STANDARD_GRAVITY = 9.80665
"""Standard gravity g0, m/s^2."""

STATUTE_MILE = 1609.344
"""One statute mile, m (the exact international definition)."""

FOOT = 0.3048
"""One international foot, m."""

WGS84_SEMI_MAJOR_AXIS = 6_378_137.0
"""WGS-84 equatorial radius a, m."""

WGS84_FLATTENING = 1.0 / 298.257223563
"""WGS-84 flattening f."""

WGS84_ECCENTRICITY_SQUARED = WGS84_FLATTENING * (2.0 - WGS84_FLATTENING)
"""WGS-84 first eccentricity squared e^2."""

WGS84_M = 0.00344978650684
"""WGS-84 m = Omega^2 a^2 b / GM, the ratio of centrifugal to gravitational force at the equator."""

WGS84_GAMMA_EQUATOR = 9.7803253359
"""WGS-84 normal gravity on the equator gamma_e, m/s^2."""

WGS84_SOMIGLIANA_K = 0.00193185265241
"""Somigliana's constant k of WGS-84: (b gamma_p - a gamma_e) / (a gamma_e)."""

NORTH_GRAVITY_PER_HEIGHT = -8.08e-9
"""Coefficient of the north component of normal gravity above the ellipsoid, 1/s^2
(Groves 2013, eq. (2.140): g_N = -8.08e-9 h sin 2L m/s^2 with h in m)."""


def schuler_frequency(gravity: float, radius: float) -> float:
    """Schuler angular frequency omega_s = sqrt(g / R), rad/s.

    Parameters
    ----------
    gravity : float
        Gravity g, m/s^2 (> 0).
    radius : float
        Radius R of the sphere (or the path), m (> 0).
    """
    return math.sqrt(gravity / radius)


def schuler_period(gravity: float, radius: float) -> float:
    """Schuler period T = 2 pi sqrt(R / g), s.

    Parameters
    ----------
    gravity : float
        g, m/s^2.
    radius : float
        R, m.

    Examples
    --------
    >>> round(schuler_period(9.81, 6.4e6))
    5075
    """
    return 2.0 * math.pi / schuler_frequency(gravity, radius)


def normal_gravity(latitude):
    """WGS-84 normal gravity on the ellipsoid (Somigliana's formula), m/s^2.

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude, rad.

    Examples
    --------
    >>> round(float(normal_gravity(0.0)), 7), round(float(normal_gravity(np.pi / 2)), 7)
    (9.7803253, 9.8321849)
    """
    s2 = np.sin(latitude) ** 2
    return WGS84_GAMMA_EQUATOR * (1.0 + WGS84_SOMIGLIANA_K * s2) / np.sqrt(1.0 - WGS84_ECCENTRICITY_SQUARED * s2)


def radii_of_curvature(latitude):
    """WGS-84 meridian (R_M) and prime-vertical (R_N) radii of curvature, m.

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude, rad.

    Returns
    -------
    R_M, R_N : float or ndarray
        Meridian radius a(1 - e^2)/(1 - e^2 sin^2 phi)^(3/2) and prime-vertical
        radius a/(1 - e^2 sin^2 phi)^(1/2).
    """
    w2 = 1.0 - WGS84_ECCENTRICITY_SQUARED * np.sin(latitude) ** 2
    prime_vertical = WGS84_SEMI_MAJOR_AXIS / np.sqrt(w2)
    meridian = WGS84_SEMI_MAJOR_AXIS * (1.0 - WGS84_ECCENTRICITY_SQUARED) / w2**1.5
    return meridian, prime_vertical


def meridian_radius(latitude):
    """WGS-84 meridian radius of curvature R_N(L), m (Groves 2013, eq. (2.105)).

    R_N = a (1 - e^2) / (1 - e^2 sin^2 L)^(3/2): the radius of the north-south
    section of the ellipsoid (Groves's R_N; :func:`radii_of_curvature` calls it R_M).

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad.

    Returns
    -------
    float or ndarray
        R_N, m.

    Examples
    --------
    >>> round(float(meridian_radius(0.0)), 3), round(float(meridian_radius(np.pi / 2)), 3)
    (6335439.327, 6399593.626)
    """
    return radii_of_curvature(latitude)[0]


def transverse_radius(latitude):
    """WGS-84 transverse (prime-vertical) radius of curvature R_E(L), m (Groves 2013, eq. (2.106)).

    R_E = a / (1 - e^2 sin^2 L)^(1/2): the radius of the east-west section; a
    parallel at height h has radius (R_E + h) cos L.

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad.

    Returns
    -------
    float or ndarray
        R_E, m.

    Examples
    --------
    >>> round(float(transverse_radius(0.0)), 3)
    6378137.0
    """
    return radii_of_curvature(latitude)[1]


def gravity_height_coefficient(latitude):
    """k1(L) = (2 / a) (1 + f + m - 2 f sin^2 L), 1/m: the first-order fall of gravity with height.

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad.

    Returns
    -------
    float or ndarray
        k1, 1/m, so that g(L, h) ~ g0(L) (1 - k1 h + 3 h^2 / a^2) (Groves 2013, eq. (2.139)).
    """
    s2 = np.sin(latitude) ** 2
    f = WGS84_FLATTENING
    return 2.0 / WGS84_SEMI_MAJOR_AXIS * (1.0 + f + WGS84_M - 2.0 * f * s2)


def somigliana_gravity(latitude, height=0.0):
    """Magnitude of WGS-84 normal gravity at latitude L and height h, m/s^2.

    Notes
    -----
    Somigliana's formula on the ellipsoid (Groves 2013, eq. (2.134)),

        g0(L) = gamma_e (1 + k sin^2 L) / sqrt(1 - e^2 sin^2 L),

    continued upward to second order in h (Groves 2013, eq. (2.139)),

        g(L, h) = g0(L) [1 - (2/a)(1 + f + m - 2 f sin^2 L) h + 3 h^2 / a^2].

    Normal gravity includes the centrifugal acceleration of the Earth's
    rotation: it is what a plumb line and an accelerometer at rest feel.

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad.
    height : float or array_like
        Height above the ellipsoid h, m (the series is meant for |h| below some 20 km).

    Returns
    -------
    float or ndarray
        g, m/s^2.

    References
    ----------
    P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated
    Navigation Systems*, 2nd ed., Artech House, 2013, Sec. 2.4.7.

    Examples
    --------
    >>> round(float(somigliana_gravity(0.0)), 10)
    9.7803253359
    >>> round(float(somigliana_gravity(np.radians(45.0), 10_000.0)), 6)
    9.775415
    """
    h = np.asarray(height, dtype=float)
    a = WGS84_SEMI_MAJOR_AXIS
    return normal_gravity(latitude) * (1.0 - gravity_height_coefficient(latitude) * h + 3.0 * h**2 / a**2)


def gravity_ned(latitude, height=0.0):
    """WGS-84 normal gravity vector in the local North-East-Down frame, m/s^2.

    g^n = [-8.08e-9 h sin 2L, 0, g(L, h)] (Groves 2013, eqs. (2.139), (2.140)):
    down is :func:`somigliana_gravity`; above the ellipsoid the normal gravity
    vector leans slightly from the ellipsoid normal.

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad.
    height : float or array_like
        Height h, m.

    Returns
    -------
    ndarray, shape (..., 3)
        (g_N, g_E, g_D), m/s^2, broadcast over the arguments.

    Examples
    --------
    >>> gravity_ned(0.0, 0.0)
    array([0.        , 0.        , 9.78032534])
    """
    L, h = np.broadcast_arrays(np.asarray(latitude, dtype=float), np.asarray(height, dtype=float))
    north = NORTH_GRAVITY_PER_HEIGHT * h * np.sin(2.0 * L)
    return np.stack([north, np.zeros_like(north), somigliana_gravity(L, h)], axis=-1)


def earth_rate_ned(latitude, rate=EARTH_RATE):
    """Earth's rotation in NED axes, omega_ie^n = Omega (cos L, 0, -sin L), rad/s (Groves 2013, eq. (2.123)).

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad.
    rate : float
        Omega, rad/s.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> earth_rate_ned(np.pi / 2, 1.0).round(12)
    array([ 0.,  0., -1.])
    """
    L = np.asarray(latitude, dtype=float)
    return rate * np.stack([np.cos(L), np.zeros_like(L), -np.sin(L)], axis=-1)


def transport_rate_ned(latitude, height, velocity_north, velocity_east):
    """Transport rate omega_en^n: the NED frame's turn over the ellipsoid, rad/s (Groves 2013, eq. (5.44)).

    omega_en^n = (v_E / (R_E + h), -v_N / (R_N + h), -v_E tan L / (R_E + h)).

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad (|L| < pi/2).
    height : float or array_like
        h, m.
    velocity_north, velocity_east : float or array_like
        Ground velocity v_N, v_E, m/s.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> transport_rate_ned(0.0, 0.0, 0.0, 6378137.0)
    array([ 1., -0., -0.])
    """
    L = np.asarray(latitude, dtype=float)
    h = np.asarray(height, dtype=float)
    R_N, R_E = radii_of_curvature(L)
    v_N = np.asarray(velocity_north, dtype=float)
    v_E = np.asarray(velocity_east, dtype=float)
    east = v_E / (R_E + h)
    return np.stack(np.broadcast_arrays(east, -v_N / (R_N + h), -east * np.tan(L)), axis=-1)


def centripetal_acceleration_ned(latitude, height=0.0, rate=EARTH_RATE):
    """Centripetal acceleration of a point fixed to the Earth, omega_ie x (omega_ie x r), in NED, m/s^2.

    A point at latitude L and height h turns on a circle of radius
    (R_E + h) cos L about the polar axis; its acceleration points at the axis:
    Omega^2 (R_E + h) cos L (sin L, 0, cos L). Gravitation (mass attraction)
    is normal gravity plus this: a computer that models gravitation only
    leaves the horizontal part, Omega^2 (R_E + h) sin L cos L north (source
    000's R omega_1 omega_2), uncompensated.

    Parameters
    ----------
    latitude : float or array_like
        Geodetic latitude L, rad.
    height : float or array_like
        h, m.
    rate : float
        Omega, rad/s.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> a = centripetal_acceleration_ned(np.radians(45.0))
    >>> bool(np.isclose(a[0], a[2]))
    True
    """
    L, h = np.broadcast_arrays(np.asarray(latitude, dtype=float), np.asarray(height, dtype=float))
    radius = (transverse_radius(L) + h) * np.cos(L) * rate**2
    return np.stack([radius * np.sin(L), np.zeros_like(radius), radius * np.cos(L)], axis=-1)


@dataclass(frozen=True)
class EarthModel:
    """A spherical Earth: radius, gravity, rotation rate and the Schuler period.

    Parameters
    ----------
    name : str
        Preset name.
    radius : float
        R, m.
    gravity : float
        g, m/s^2.
    rate : float
        Omega, rad/s.
    stated_period : float or None
        A Schuler period the source states and uses (s). When given it defines
        omega_s = 2 pi / stated_period, and the loop's effective gravity becomes
        omega_s^2 R; otherwise omega_s = sqrt(g / R).
    note : str
        Where the constants come from.
    """

    name: str
    radius: float
    gravity: float
    rate: float = EARTH_RATE
    stated_period: float | None = None
    note: str = ""

    @property
    def schuler_frequency(self) -> float:
        """omega_s, rad/s."""
        if self.stated_period is not None:
            return 2.0 * math.pi / self.stated_period
        return schuler_frequency(self.gravity, self.radius)

    @property
    def schuler_period(self) -> float:
        """T = 2 pi / omega_s, s."""
        return 2.0 * math.pi / self.schuler_frequency

    @property
    def effective_gravity(self) -> float:
        """omega_s^2 R, m/s^2: the gravity that makes the loop's period the stated one."""
        return self.schuler_frequency**2 * self.radius


DEFAULT = EarthModel(
    "default",
    MEAN_RADIUS,
    STANDARD_GRAVITY,
    EARTH_RATE,
    note="mean radius 6,371 km, standard gravity, WGS-84 rate",
)
BOLLAY = EarthModel(
    "bollay",
    3960.0 * STATUTE_MILE,
    32.2 * FOOT,
    EARTH_RATE,
    stated_period=5060.0,
    note="Bollay, 'The Story of 84 Minutes': R = 3960 statute mi, g = 32.2 ft/s^2, T = 5060 s "
    "(2 pi sqrt(R/g) would be 5063.1 s; the source's omega t = 4 pi at 10,120 s needs T = 5060 s)",
)
DROZDOVICH = EarthModel(
    "drozdovich",
    6.4e6,
    9.81,
    7.3e-5,
    note="Drozdovich (1959) worked example: R = 6.4e6 m, Omega = 7.3e-5 1/s, g = 9.81 m/s^2 (g assumed)",
)

PRESETS: dict[str, EarthModel] = {m.name: m for m in (DEFAULT, BOLLAY, DROZDOVICH)}
"""Named constant sets, selectable by name from the CLI and scenario files."""
