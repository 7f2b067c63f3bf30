"""An IMU recording in the project's frame: :class:`ImuRecord`, axis conversions, what a record holds.

Conventions
-----------
* **Body frame**: x forward, y right, z down (FRD). A file in another frame is
  converted on reading by :func:`axes_matrix`: its three axes are named by the
  body directions they point to (``"RFU"``: X right, Y forward, Z up, the PSINS
  convention), and ``v_frd = P v_file`` with the signed permutation ``P``.
* **Samples**: either mean *rates* over each sample interval (rad/s, m/s^2) or
  *increments* over it (rad, m/s); ``kind`` says which. Sample k covers
  ``(t_k - dt, t_k]``: ``time_s`` is the **end** of each interval.
* **Accelerometers** measure specific force f = a - g: at rest and level, the
  z (down) accelerometer reads about -g; the gyros read the Earth rate,
  Omega [cos L, 0, -sin L] in NED, resolved in the body frame.

Examples
--------
>>> import numpy as np
>>> record = ImuRecord(time_s=np.arange(1, 5) * 0.01, gyro=np.zeros((4, 3)),
...                    accel=np.tile([0.0, 0.0, -9.8], (4, 1)), kind="rate", sample_interval_s=0.01)
>>> record.duration_s, record.samples
(0.04, 4)
>>> axes_matrix("RFU") @ np.array([1.0, 2.0, 3.0])  # X right, Y forward, Z up -> x fwd, y right, z down
array([ 2.,  1., -3.])
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.results import Result

KINDS = ("rate", "increment")
"""What the gyro and accelerometer columns hold."""

_DIRECTIONS = {
    "F": (0, 1.0), "B": (0, -1.0),
    "R": (1, 1.0), "L": (1, -1.0),
    "D": (2, 1.0), "U": (2, -1.0),
}


def axes_matrix(axes: str) -> np.ndarray:
    """The signed permutation P with ``v_frd = P v_file`` for a file whose axes are ``axes``.

    Parameters
    ----------
    axes : str
        Three letters naming where the file's X, Y, Z axes point: F(orward),
        B(ack), R(ight), L(eft), D(own), U(p). ``"FRD"`` is the identity.

    Returns
    -------
    ndarray, shape (3, 3)
        A proper rotation (determinant +1).

    Raises
    ------
    InvalidParameter
        Unknown letters, a repeated axis, or a left-handed triad.
    """
    spec = str(axes).upper()
    if len(spec) != 3 or any(letter not in _DIRECTIONS for letter in spec):
        raise InvalidParameter("axes", f"{axes!r} must be three letters from F, B, R, L, D, U (e.g. 'RFU')")
    matrix = np.zeros((3, 3))
    for column, letter in enumerate(spec):
        row, sign = _DIRECTIONS[letter]
        matrix[row, column] = sign
    if not np.allclose(np.abs(matrix).sum(axis=0), 1.0) or not np.allclose(np.abs(matrix).sum(axis=1), 1.0):
        raise InvalidParameter("axes", f"{axes!r} names the same body axis twice")
    if np.linalg.det(matrix) < 0:
        raise InvalidParameter("axes", f"{axes!r} is a left-handed triad; a sensor triad is right-handed")
    return matrix


def _vector3(values, name: str) -> tuple[float, float, float] | None:
    if values is None:
        return None
    array = np.asarray(values, dtype=float).reshape(-1)
    if array.size != 3 or not np.all(np.isfinite(array)):
        raise InvalidParameter(name, f"must be three finite numbers, got {values!r}")
    return (float(array[0]), float(array[1]), float(array[2]))


@dataclass
class ImuRecord:
    """Gyro and accelerometer samples of one IMU, body frame x forward, y right, z down.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        End time of each sample interval, s (uniform spacing).
    gyro, accel : ndarray, shape (n, 3)
        Rates (rad/s, m/s^2) or increments (rad, m/s), see ``kind``.
    kind : {"rate", "increment"}
        What ``gyro`` and ``accel`` hold.
    sample_interval_s : float
        dt, s.
    latitude_rad, longitude_rad, height_m : float, optional
        Site (geodetic), when known.
    initial_attitude_rad : tuple of float, optional
        (roll, pitch, heading) of the body in NED at the start, rad, when known.
    gravity_m_s2 : float, optional
        The gravity the file states (PSINS scales its accelerometer counts with it).
    source : str
        Where the record came from (file name or "simulated ...").
    """

    time_s: np.ndarray = field(repr=False)
    gyro: np.ndarray = field(repr=False)
    accel: np.ndarray = field(repr=False)
    kind: str
    sample_interval_s: float
    latitude_rad: float | None = None
    longitude_rad: float | None = None
    height_m: float | None = None
    initial_attitude_rad: tuple[float, float, float] | None = None
    gravity_m_s2: float | None = None
    source: str = ""

    def __post_init__(self):
        self.time_s = np.asarray(self.time_s, dtype=float).reshape(-1)
        self.gyro = np.asarray(self.gyro, dtype=float)
        self.accel = np.asarray(self.accel, dtype=float)
        n = self.time_s.size
        for name in ("gyro", "accel"):
            if getattr(self, name).shape != (n, 3):
                raise InvalidParameter(name, f"shape {getattr(self, name).shape} must be ({n}, 3) to match time_s")
        if self.kind not in KINDS:
            raise InvalidParameter("kind", f"{self.kind!r} must be one of {', '.join(KINDS)}")
        dt = float(self.sample_interval_s)
        if not (math.isfinite(dt) and dt > 0):
            raise InvalidParameter("sample_interval_s", f"must be finite and > 0, got {self.sample_interval_s!r}")
        self.sample_interval_s = dt
        if n < 2:
            raise InvalidParameter("samples", f"a record needs at least 2 samples, got {n}")
        self.initial_attitude_rad = _vector3(self.initial_attitude_rad, "initial_attitude_rad")
        if self.latitude_rad is not None and not abs(self.latitude_rad) <= math.pi / 2:
            raise InvalidParameter("latitude_rad", f"{self.latitude_rad!r} must be within [-pi/2, pi/2]")

    @property
    def samples(self) -> int:
        """Number of samples n."""
        return int(self.time_s.size)

    @property
    def duration_s(self) -> float:
        """n dt, s: the span the samples cover."""
        return round(self.samples * self.sample_interval_s, 12)

    @property
    def gyro_rate_rad_s(self) -> np.ndarray:
        """Mean angular rate over each interval, rad/s, shape (n, 3)."""
        return self.gyro if self.kind == "rate" else self.gyro / self.sample_interval_s

    @property
    def accel_m_s2(self) -> np.ndarray:
        """Mean specific force over each interval, m/s^2, shape (n, 3)."""
        return self.accel if self.kind == "rate" else self.accel / self.sample_interval_s

    @property
    def gyro_increment_rad(self) -> np.ndarray:
        """Angle increment over each interval, rad, shape (n, 3)."""
        return self.gyro if self.kind == "increment" else self.gyro * self.sample_interval_s

    @property
    def accel_increment_m_s(self) -> np.ndarray:
        """Velocity increment over each interval, m/s, shape (n, 3)."""
        return self.accel if self.kind == "increment" else self.accel * self.sample_interval_s

    def channels(self) -> dict[str, np.ndarray]:
        """The six channels as rates (gyro_x .. accel_z -> shape (n,)), for Allan analysis."""
        gyro, accel = self.gyro_rate_rad_s, self.accel_m_s2
        return {**{f"gyro_{a}": gyro[:, i] for i, a in enumerate("xyz")},
                **{f"accel_{a}": accel[:, i] for i, a in enumerate("xyz")}}

    def rotated(self, matrix) -> ImuRecord:
        """The record with both triads rotated: ``v_new = matrix v`` (e.g. :func:`axes_matrix`).

        Parameters
        ----------
        matrix : array_like
            Rotation from the record's axes to the new ones, array of shape (3, 3), plain numbers
            (direction cosines).

        Returns
        -------
        ImuRecord
            A copy with gyro and accelerometer samples rotated; times and metadata kept.
        """
        matrix = np.asarray(matrix, dtype=float)
        return dataclasses.replace(self, gyro=self.gyro @ matrix.T, accel=self.accel @ matrix.T)


@dataclass
class ImuInfo(Result):
    """What a record holds: size, rate, means, site, and the Earth rate and gravity it should show.

    Means are over the whole record, body frame x forward, y right, z down. At
    rest and level, ``mean_gyro_rad_s`` should be Omega cos L horizontally and
    -Omega sin L on z (down), and ``mean_accel_m_s2`` about (0, 0, -g).
    """

    source: str
    samples: int
    kind: str
    sample_interval_s: float
    sample_rate_hz: float
    duration_s: float
    mean_gyro_rad_s: tuple[float, float, float]
    mean_accel_m_s2: tuple[float, float, float]
    horizontal_gyro_rad_s: float
    specific_force_m_s2: float
    latitude_rad: float | None = None
    longitude_rad: float | None = None
    height_m: float | None = None
    gravity_m_s2: float | None = None
    earth_rate_horizontal_rad_s: float | None = None
    earth_rate_down_rad_s: float | None = None
    initial_attitude_rad: tuple[float, float, float] | None = None

    units = {"samples": "1", "mean_gyro_rad_s": "rad/s, body x forward, y right, z down",
             "mean_accel_m_s2": "m/s^2, specific force, body x forward, y right, z down",
             "earth_rate_horizontal_rad_s": "Omega cos(latitude)",
             "earth_rate_down_rad_s": "-Omega sin(latitude), the NED down component"}

    def render(self):
        """A table in display units: deg/h for rates, m/s^2 for specific force, deg for the site."""
        from rich.table import Table

        from schuler.units import to_unit

        table = Table(title=f"IMU record {self.source}", show_header=False)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        table.add_row("samples", f"{self.samples:,} ({self.kind}s)")
        table.add_row("sample rate", f"{self.sample_rate_hz:.6g} Hz (dt {self.sample_interval_s:.6g} s)")
        table.add_row("duration", f"{self.duration_s:.6g} s ({self.duration_s / 60:.4g} min)")
        gyro = ", ".join(f"{to_unit(v, 'deg/h'):+.4f}" for v in self.mean_gyro_rad_s)
        table.add_row("mean gyro (x, y, z)", f"{gyro} deg/h")
        accel = ", ".join(f"{v:+.5f}" for v in self.mean_accel_m_s2)
        table.add_row("mean specific force (x, y, z)", f"{accel} m/s^2")
        table.add_row("horizontal gyro magnitude", f"{to_unit(self.horizontal_gyro_rad_s, 'deg/h'):.4f} deg/h")
        table.add_row("|specific force|", f"{self.specific_force_m_s2:.5f} m/s^2")
        if self.latitude_rad is not None:
            table.add_row("site latitude", f"{math.degrees(self.latitude_rad):.6f} deg")
            horizontal = to_unit(self.earth_rate_horizontal_rad_s, "deg/h")
            table.add_row("Omega cos L (expected horizontal)", f"{horizontal:.4f} deg/h")
            table.add_row("-Omega sin L (expected down)", f"{to_unit(self.earth_rate_down_rad_s, 'deg/h'):+.4f} deg/h")
        if self.longitude_rad is not None:
            table.add_row("site longitude", f"{math.degrees(self.longitude_rad):.6f} deg")
        if self.height_m is not None:
            table.add_row("site height", f"{self.height_m:.1f} m")
        if self.gravity_m_s2 is not None:
            table.add_row("gravity stated by the file", f"{self.gravity_m_s2:.6f} m/s^2")
        if self.initial_attitude_rad is not None:
            roll, pitch, heading = (math.degrees(a) for a in self.initial_attitude_rad)
            table.add_row("initial roll, pitch, heading", f"{roll:.2f}, {pitch:.2f}, {heading:.2f} deg")
        return table


def record_info(record: ImuRecord) -> ImuInfo:
    """Summarise a record: sample count, rate, duration, mean rates, site.

    Parameters
    ----------
    record : ImuRecord

    Returns
    -------
    ImuInfo
        SI fields; the expected Earth-rate components when the latitude is known
        (Omega = 7.292115e-5 rad/s, WGS-84).
    """
    return info_from_means(record.source, record.samples, record.kind, record.sample_interval_s,
                           record.gyro_rate_rad_s.mean(axis=0), record.accel_m_s2.mean(axis=0),
                           latitude_rad=record.latitude_rad, longitude_rad=record.longitude_rad,
                           height_m=record.height_m, gravity_m_s2=record.gravity_m_s2,
                           initial_attitude_rad=record.initial_attitude_rad)


@renamed_keywords(sample_interval_s="sample_interval", mean_gyro_rad_s="mean_gyro", mean_accel_m_s2="mean_accel")
def info_from_means(source: str, samples: int, kind: str, sample_interval: float, mean_gyro,
                    mean_accel, **site) -> ImuInfo:
    """An :class:`ImuInfo` from a record's size and mean rates (what a streamed file gives).

    ``site``: ``latitude_rad``, ``longitude_rad``, ``height_m``, ``gravity_m_s2``,
    ``initial_attitude_rad`` where known.

    Parameters
    ----------
    source : str
        Name of the record (e.g. the file name).
    samples : int
        Samples in the record, number of.
    kind : {"rate", "increment"}
        What the file's sensor columns hold.
    sample_interval : float
        Sample interval dt, s.
    mean_gyro : array_like
        Mean angular rate, rad/s, shape (3,), body axes x forward, y right, z down.
    mean_accel : array_like
        Mean specific force, m/s^2, shape (3,), body axes.
    **site
        ``latitude_rad``, ``longitude_rad`` (rad), ``height_m`` (m), ``gravity_m_s2`` (m/s^2),
        ``initial_attitude_rad`` (roll, pitch, heading in NED, rad), each None or absent when unknown.

    Returns
    -------
    ImuInfo
        SI fields; the expected Earth-rate components when the latitude is known.
    """
    gyro = np.asarray(mean_gyro, dtype=float)
    accel = np.asarray(mean_accel, dtype=float)
    latitude = site.get("latitude_rad")
    return ImuInfo(
        source=source,
        samples=int(samples),
        kind=kind,
        sample_interval_s=float(sample_interval),
        sample_rate_hz=1.0 / sample_interval,
        duration_s=round(samples * sample_interval, 12),
        mean_gyro_rad_s=(float(gyro[0]), float(gyro[1]), float(gyro[2])),
        mean_accel_m_s2=(float(accel[0]), float(accel[1]), float(accel[2])),
        horizontal_gyro_rad_s=float(math.hypot(gyro[0], gyro[1])),
        specific_force_m_s2=float(np.linalg.norm(accel)),
        latitude_rad=latitude,
        longitude_rad=site.get("longitude_rad"),
        height_m=site.get("height_m"),
        gravity_m_s2=site.get("gravity_m_s2"),
        earth_rate_horizontal_rad_s=None if latitude is None else EARTH_RATE * math.cos(latitude),
        earth_rate_down_rad_s=None if latitude is None else -EARTH_RATE * math.sin(latitude),
        initial_attitude_rad=_vector3(site.get("initial_attitude_rad"), "initial_attitude_rad"),
    )
