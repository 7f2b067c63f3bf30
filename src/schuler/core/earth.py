"""Earth constants, the Schuler frequency, and the source documents' constant sets.

All values SI. The defaults are WGS-84's rotation rate, the IUGG mean radius and
standard gravity; :data:`WGS84` adds the ellipsoid for normal gravity and radii
of curvature. A reproduction of a source uses that source's constants through one
of the named presets (:data:`BOLLAY`, :data:`DROZDOVICH`), never the defaults.

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

_GAMMA_EQUATOR = 9.7803253359  # normal gravity at the equator, m/s^2 (WGS-84)
_SOMIGLIANA_K = 0.00193185265241  # Somigliana's constant k (WGS-84)


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

    >>> round(float(normal_gravity(0.0)), 7), round(float(normal_gravity(np.pi / 2)), 7)
    (9.7803253, 9.8321849)
    """
    s2 = np.sin(latitude) ** 2
    return _GAMMA_EQUATOR * (1.0 + _SOMIGLIANA_K * s2) / np.sqrt(1.0 - WGS84_ECCENTRICITY_SQUARED * s2)


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
