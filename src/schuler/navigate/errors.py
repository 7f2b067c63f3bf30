"""What goes wrong: initial navigation errors, constant sensor errors per member, and additive sensor noise.

Conventions (spec 06): errors are computed - true; a sensor bias is measured -
true, in body axes (x forward, y right, z down; for the platform mechanization
the sensor axes are the platform's, nominally north, east, down). A sensor with
scale-factor errors S (diagonal) and misalignment M (off-diagonal, small angles)
measures

    measured = (I + S + M) true + b  (+ noise),

applied to each interval's increment (b dt for the bias). Every field is a
scalar (or a 3-vector, 3x3 matrix) shared by all members, or carries a leading
member axis of length N: the batch size is what the fields broadcast to.

Position errors follow the issue's definitions: north = Delta latitude (R_N + h),
east = Delta longitude (R_E + h) cos L, both at the mean of the computed and the
true latitude and height. Attitude errors are differences of the roll, pitch and
heading angles.

Noise plugs in through :class:`SensorNoise`: anything with a method
``increments(members, start, stop, dt)`` returning the additive errors of the
angle and velocity increments of IMU intervals ``start .. stop - 1`` for the
given global member numbers. :class:`WhiteNoise` is the simplest such source
(angle and velocity random walk through :class:`schuler.core.random.RandomStreams`);
the IMU layer's error models provide the same method.

Examples
--------
>>> errors = ConstantSensorErrors(gyro_bias=[[1e-7, 0, 0], [2e-7, 0, 0]])
>>> errors.members
2
>>> noise = WhiteNoise(angle_random_walk=1e-5, velocity_random_walk=1e-4, seed=3)
>>> gyro, accel = noise.increments(np.arange(2), 0, 5, 0.01)
>>> gyro.shape, accel.shape
((2, 5, 3), (2, 5, 3))
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import ClassVar, Protocol

import numpy as np
from numpy.typing import ArrayLike

from schuler.core.earth import radii_of_curvature
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter


def _member_array(name: str, value, tail: tuple[int, ...]) -> np.ndarray:
    """A finite float array of shape tail or (N, *tail)."""
    array = np.asarray(value, dtype=float)
    if array.shape != tail and array.shape[1:] != tail:
        expected = f"{tail}" if tail else "a scalar"
        raise InvalidParameter(name, f"expected {expected} or one per member (N, *{tail}), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InvalidParameter(name, "contains NaN or infinite values")
    return array


def _batch_size(arrays: dict[str, np.ndarray], tails: dict[str, tuple]) -> int | None:
    sizes = {name: a.shape[0] for name, a in arrays.items() if a.ndim == len(tails[name]) + 1}
    if len(set(sizes.values())) > 1:
        raise InvalidParameter(next(iter(sizes)), f"member counts disagree: {sizes}")
    return next(iter(sizes.values())) if sizes else None


@dataclass(frozen=True)
class InitialErrors:
    """Errors of the navigation state at t = 0 (computed - true), SI, scalar or one per member.

    Parameters
    ----------
    position_error_north, position_error_east : float or array
        m (definitions in the module docstring).
    height_error : float or array
        m, up.
    velocity_error_north, velocity_error_east, velocity_error_down : float or array
        m/s.
    roll_error, pitch_error, heading_error : float or array
        rad, differences of the Euler angles.
    """

    position_error_north: ArrayLike = 0.0
    position_error_east: ArrayLike = 0.0
    height_error: ArrayLike = 0.0
    velocity_error_north: ArrayLike = 0.0
    velocity_error_east: ArrayLike = 0.0
    velocity_error_down: ArrayLike = 0.0
    roll_error: ArrayLike = 0.0
    pitch_error: ArrayLike = 0.0
    heading_error: ArrayLike = 0.0

    def __post_init__(self):
        for f in fields(self):
            object.__setattr__(self, f.name, _member_array(f.name, getattr(self, f.name), ()))
        for name in ("roll_error", "pitch_error", "heading_error"):
            if np.any(np.abs(getattr(self, name)) > np.pi):
                raise InvalidParameter(name, "must lie within +/-180 deg")
        if np.any(np.abs(self.position_error_north) > 1e6) or np.any(np.abs(self.position_error_east) > 1e6):
            raise InvalidParameter("position_error_north", "position errors must stay within 1000 km")

    @property
    def members(self) -> int | None:
        """Batch size N, or None when every field is a scalar."""
        arrays = {f.name: getattr(self, f.name) for f in fields(self)}
        return _batch_size(arrays, {name: () for name in arrays})

    def column(self, name: str, members: int) -> np.ndarray:
        """A field broadcast to (members,).

        Parameters
        ----------
        name : str
            Field name, e.g. ``"roll_error"``.
        members : int
            Batch size N, number of members.

        Returns
        -------
        ndarray
            The field's values, shape (members,), in the field's SI unit (m, m/s or rad).
        """
        return np.broadcast_to(getattr(self, name), (members,))

    def apply_position(self, latitude, longitude, height, members: int):
        """Computed latitude, longitude (rad) and height (m) of each member, shape (members,).

        Inverts north = dL (R_N(L_m) + h_m), east = dlambda (R_E(L_m) + h_m) cos L_m at
        the mean latitude L_m = L + dL/2 and height h_m = h + dh/2 by fixed-point
        iteration (each pass gains a factor ~ e^2 dL; four passes reach rounding).

        Parameters
        ----------
        latitude : float
            True geodetic latitude L, rad.
        longitude : float
            True longitude, rad.
        height : float
            True height h above the ellipsoid, m, up.
        members : int
            Batch size N, number of members.

        Returns
        -------
        latitude, longitude, height : ndarray
            Computed latitude (rad), longitude (rad) and height (m), each of shape (members,).
        """
        north = self.column("position_error_north", members)
        east = self.column("position_error_east", members)
        dh = self.column("height_error", members)
        h_mean = height + 0.5 * dh
        d_lat = np.zeros(members)
        for _ in range(4):
            R_N, _R_E = radii_of_curvature(latitude + 0.5 * d_lat)
            d_lat = north / (R_N + h_mean)
        lat_mean = latitude + 0.5 * d_lat
        _R_N, R_E = radii_of_curvature(lat_mean)
        d_lon = east / ((R_E + h_mean) * np.cos(lat_mean))
        return latitude + d_lat, longitude + d_lon, height + dh


MAX_SCALE_FACTOR = 0.5
"""Largest |scale-factor error| of :class:`ConstantSensorErrors` (dimensionless)."""

MAX_MISALIGNMENT = 0.2
"""Largest |misalignment| of :class:`ConstantSensorErrors`, rad."""


@dataclass(frozen=True)
class ConstantSensorErrors:
    """Constant sensor errors, body axes, SI (bias = measured - true), shared or one per member.

    Parameters
    ----------
    gyro_bias : array, shape (3,) or (N, 3)
        rad/s.
    accel_bias : array, shape (3,) or (N, 3)
        m/s^2.
    gyro_scale_factor, accel_scale_factor : array, shape (3,) or (N, 3)
        Dimensionless scale-factor errors S (1e-6 = 1 ppm).
    gyro_misalignment, accel_misalignment : array, shape (3, 3) or (N, 3, 3)
        Off-diagonal misalignment M, rad (the diagonal must be zero: that is S).

    Notes
    -----
    Scale factors within +/-0.5 and misalignments within +/-0.2 rad keep I + S + M
    diagonally dominant (0.5 > 2 x 0.2), hence invertible as the platform needs;
    they leave room for the draws of a consumer-grade model (3 % and 20 mrad at
    1 sigma, :mod:`schuler.imu.spec`).
    """

    gyro_bias: ArrayLike = (0.0, 0.0, 0.0)
    accel_bias: ArrayLike = (0.0, 0.0, 0.0)
    gyro_scale_factor: ArrayLike = (0.0, 0.0, 0.0)
    accel_scale_factor: ArrayLike = (0.0, 0.0, 0.0)
    gyro_misalignment: ArrayLike = ((0.0,) * 3,) * 3
    accel_misalignment: ArrayLike = ((0.0,) * 3,) * 3

    _TAILS: ClassVar[dict[str, tuple[int, ...]]] = {
        "gyro_bias": (3,), "accel_bias": (3,), "gyro_scale_factor": (3,), "accel_scale_factor": (3,),
        "gyro_misalignment": (3, 3), "accel_misalignment": (3, 3)}

    def __post_init__(self):
        for f in fields(self):
            object.__setattr__(self, f.name, _member_array(f.name, getattr(self, f.name), self._TAILS[f.name]))
        for name in ("gyro_misalignment", "accel_misalignment"):
            if np.any(np.diagonal(getattr(self, name), axis1=-2, axis2=-1) != 0.0):
                raise InvalidParameter(name, "the diagonal must be zero (scale-factor errors go in *_scale_factor)")
            if np.any(np.abs(getattr(self, name)) > MAX_MISALIGNMENT):
                raise InvalidParameter(name, f"misalignments must stay within {MAX_MISALIGNMENT:g} rad")
        for name in ("gyro_scale_factor", "accel_scale_factor"):
            if np.any(np.abs(getattr(self, name)) > MAX_SCALE_FACTOR):
                raise InvalidParameter(name, f"scale-factor errors must stay within {MAX_SCALE_FACTOR:g} "
                                             f"({MAX_SCALE_FACTOR * 1e6:,.0f} ppm)")

    @property
    def members(self) -> int | None:
        """Batch size N, or None when every field is shared."""
        return _batch_size({f.name: getattr(self, f.name) for f in fields(self)}, self._TAILS)

    def rows(self, sensor: str, members: int, invert: bool = False) -> np.ndarray:
        """Kernel rows (members, 12): the matrix I + S + M (or its inverse), row-major, then the bias.

        Parameters
        ----------
        sensor : {"gyro", "accel"}
            Which sensor triad.
        members : int
            Batch size N, number of members.
        invert : bool
            Give (I + S + M)^-1 instead of I + S + M (the platform mechanization's gyros).

        Returns
        -------
        ndarray
            Shape (members, 12): the 3x3 matrix row-major (dimensionless), then the
            bias in body axes (rad/s for the gyros, m/s^2 for the accelerometers).
        """
        scale = np.broadcast_to(getattr(self, f"{sensor}_scale_factor"), (members, 3))
        forward = np.broadcast_to(getattr(self, f"{sensor}_misalignment"), (members, 3, 3)) + \
            np.eye(3) * (1.0 + scale)[:, None, :]
        matrix = np.linalg.inv(forward) if invert else forward
        bias = np.broadcast_to(getattr(self, f"{sensor}_bias"), (members, 3))
        return np.ascontiguousarray(np.concatenate([matrix.reshape(members, 9), bias], axis=1))


class SensorNoise(Protocol):
    """Additive sensor noise: the interface the IMU layer's error models implement.

    ``increments(members, start, stop, dt)`` returns two arrays of shape
    (len(members), stop - start, 3): the errors added to the angle increments
    (rad) and velocity increments (m/s), body axes, of the IMU intervals
    ``start .. stop - 1`` (global indices; interval k ends at t = (k + 1) dt).
    ``members`` are global member numbers. The same (member, interval) must
    always give the same numbers, however the run is chunked.
    """

    def increments(self, members: np.ndarray, start: int, stop: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Noise of the angle and velocity increments of IMU intervals ``start .. stop - 1``.

        Parameters
        ----------
        members : ndarray of int
            Global member numbers, shape (M,).
        start : int
            Index of the first IMU interval (global).
        stop : int
            Index one past the last IMU interval (global).
        dt : float
            IMU sample interval, s.

        Returns
        -------
        gyro, accel : ndarray
            Errors added to the angle increments (rad) and the velocity
            increments (m/s), body axes x, y, z, each of shape (M, stop - start, 3).
        """
        ...


@dataclass(frozen=True)
class WhiteNoise:
    """White rate noise: angle random walk (gyros) and velocity random walk (accelerometers), per body axis.

    Each interval's increment error is normal with standard deviation N sqrt(dt)
    per axis (the integral of white rate noise of PSD N^2 over dt). Interval k of
    member m on axis x takes the normal of :class:`~schuler.core.random.RandomStreams`
    at (``"gyro_x/white"``, m, k), the stream the IMU layer's white noise draws
    (:class:`~schuler.imu.simulate.ImuSimulator`), in compiled code: the same numbers
    however a run is cut.

    Parameters
    ----------
    angle_random_walk : float or array_like (3,)
        N_g, rad/sqrt(s), one for all axes or one per body axis (1 deg/sqrt(h) = 2.9089e-4 rad/sqrt(s)).
    velocity_random_walk : float or array_like (3,)
        N_a, m/s/sqrt(s), likewise (1 ug/sqrt(Hz) = 9.80665e-6 m/s/sqrt(s)).
    seed : int
        Study seed of the :class:`~schuler.core.random.RandomStreams`.
    """

    angle_random_walk: float | np.ndarray = 0.0
    velocity_random_walk: float | np.ndarray = 0.0
    seed: int = 0

    def __post_init__(self):
        for name in ("angle_random_walk", "velocity_random_walk"):
            value = np.asarray(getattr(self, name), dtype=float)
            if value.shape not in ((), (3,)):
                raise InvalidParameter(name, f"one density or one per body axis (3,), got shape {value.shape}")
            if not np.all(np.isfinite(value) & (value >= 0)):
                raise InvalidParameter(name, f"must be finite and >= 0, got {getattr(self, name)!r}")
            object.__setattr__(self, name, np.broadcast_to(value, (3,)).copy())

    def increments(self, members, start: int, stop: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Normal increment errors of standard deviation N sqrt(dt), the :class:`SensorNoise` method.

        Parameters
        ----------
        members : array_like of int
            Global member numbers, shape (M,): a member's noise depends only on its number and the interval.
        start : int
            Index of the first IMU interval (global).
        stop : int
            Index one past the last IMU interval (global).
        dt : float
            IMU sample interval, s.

        Returns
        -------
        gyro, accel : ndarray
            Errors added to the angle increments (rad) and the velocity
            increments (m/s), body axes x, y, z, each of shape (M, stop - start, 3).
        """
        streams = RandomStreams(self.seed)
        members = np.asarray(members, dtype=np.int64)
        out = []
        for sensor, densities in (("gyro", self.angle_random_walk), ("accel", self.velocity_random_walk)):
            values = np.zeros((members.size, stop - start, 3))
            for index, density in enumerate(np.atleast_1d(densities)):
                if density > 0.0:
                    series = streams.normal_series(f"{sensor}_{'xyz'[index]}/white", members, start, stop)
                    values[:, :, index] = series * (density * np.sqrt(dt))
            out.append(values)
        return out[0], out[1]
