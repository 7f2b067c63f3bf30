"""One gyrocompassing case or N cases (the KPI manual, Sec. 3): parameters, validation, gains, closed forms.

A :class:`AlignmentCase` holds one case or N cases (every field a float or an
array of length N, SI); it checks that azimuth is observable at its latitude,
derives the gains c_gamma, c_a from the time constant T and damping zeta by the
manual's design (:mod:`schuler.core.gyrocompass_design`, T = 30 s and zeta = 0.8 by
default), and builds the state-space models of :mod:`schuler.gyrocompassing.models`.
:func:`analytic_results` evaluates the closed forms of :mod:`~schuler.gyrocompassing.analytic`
for many cases at once (pure numpy); :func:`automatic_duration` fixes how long a
case is simulated (its output times: :func:`schuler.core.geometry.time_grid`).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass

import numpy as np

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_design, loop_gains
from schuler.core.lti import StateSpace
from schuler.exceptions import InvalidParameter, NotObservable
from schuler.gyrocompassing import analytic, models

DEFAULT_LATITUDE = math.radians(50.0)
DEFAULT_INITIAL_AZIMUTH_ERROR = math.radians(1.0)
DEFAULT_MAX_LATITUDE = math.radians(85.0)
"""Above this latitude gyrocompassing is refused as not observable (user-overridable)."""
DEGRADED_LATITUDE = math.radians(70.0)
"""Above this latitude a warning says that accuracy degrades as 1 / cos(latitude)."""
DEFAULT_DURATION = 7200.0
"""Simulated time, s, unless 3 settling times are longer."""
MAX_DURATION = 48 * 3600.0
"""Longest automatic run, s: a case that settles slower is reported as not settled."""


class GyrocompassingAccuracyWarning(UserWarning):
    """Gyrocompassing works but its accuracy or time is poor (high latitude, slow settling)."""


@dataclass(frozen=True)
class AlignmentCase:
    """One gyrocompassing case, or N cases when any field is an array of length N (all SI).

    Parameters
    ----------
    latitude : float or ndarray
        phi, rad.
    azimuth : float or ndarray
        A, rad: azimuth of the platform's x_g axis.
    drift_x, drift_y, drift_z : float or ndarray
        Residual drifts Delta omega_d = estimate - true, platform axes, rad/s (z up).
    drift_east, drift_north : float or ndarray
        Residual drifts about east (Delta omega_dxi) and north (Delta omega_deta),
        rad/s; added to the platform-axis ones.
    latitude_error : float or ndarray
        Delta phi, rad.
    accel_error_x, accel_error_y : float or ndarray
        Delta a_x, Delta a_y, m/s^2.
    time_constant, damping : float or ndarray
        T (s) and zeta, used for the gains not given.
    c_gamma, c_a : float, ndarray or None
        Gains, 1/s; None (or NaN entries of an array) means "from T and zeta".
    initial_azimuth_error, initial_beta, initial_alpha : float or ndarray
        delta0, beta0, alpha0, rad (levelled platform: beta0 = alpha0 = 0).
    max_latitude : float
        Latitude limit, rad, above which azimuth is reported not observable.
    earth_rate, gravity : float
        U (rad/s) and g (m/s^2).

    Examples
    --------
    >>> case = AlignmentCase(latitude=np.radians([30.0, 60.0]))
    >>> case.size, case.inputs().shape, case.model("full").A.shape
    (2, (2, 6), (2, 3, 3))
    """

    latitude: float | np.ndarray = DEFAULT_LATITUDE
    azimuth: float | np.ndarray = 0.0
    drift_x: float | np.ndarray = 0.0
    drift_y: float | np.ndarray = 0.0
    drift_z: float | np.ndarray = 0.0
    drift_east: float | np.ndarray = 0.0
    drift_north: float | np.ndarray = 0.0
    latitude_error: float | np.ndarray = 0.0
    accel_error_x: float | np.ndarray = 0.0
    accel_error_y: float | np.ndarray = 0.0
    time_constant: float | np.ndarray = DESIGN_TIME_CONSTANT
    damping: float | np.ndarray = DESIGN_DAMPING
    c_gamma: float | np.ndarray | None = None
    c_a: float | np.ndarray | None = None
    initial_azimuth_error: float | np.ndarray = DEFAULT_INITIAL_AZIMUTH_ERROR
    initial_beta: float | np.ndarray = 0.0
    initial_alpha: float | np.ndarray = 0.0
    max_latitude: float = DEFAULT_MAX_LATITUDE
    earth_rate: float = EARTH_RATE
    gravity: float = STANDARD_GRAVITY

    def __post_init__(self):
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None:
                continue
            array = np.asarray(value, dtype=float)
            if array.ndim > 1:
                raise InvalidParameter(f.name, "must be a number or a 1-D array of cases")
            allow_unset = f.name in ("c_gamma", "c_a")
            if np.any(np.isinf(array)) or (np.any(np.isnan(array)) and not allow_unset):
                raise InvalidParameter(f.name, "must be a finite number")
            object.__setattr__(self, f.name, array if array.ndim else float(array))
        for name in ("c_gamma", "c_a"):
            value = getattr(self, name)
            if value is not None and np.any(np.asarray(value) <= 0):
                raise InvalidParameter(name, "must be positive (a negative gain makes the loop unstable)")
        if not 0 < self.max_latitude < math.pi / 2:
            raise InvalidParameter("max_latitude", "must be between 0 and 90 deg")

    @property
    def size(self) -> int | None:
        """N for a batch of cases, None for a single case."""
        sizes = {np.size(getattr(self, f.name)) for f in dataclasses.fields(self)
                 if isinstance(getattr(self, f.name), np.ndarray)}
        if len(sizes) > 1:
            raise InvalidParameter("cases", f"arrays of different lengths: {sorted(sizes)}")
        return sizes.pop() if sizes else None

    def check_observable(self) -> None:
        """Raise NotObservable above the latitude limit; warn when accuracy degrades."""
        phi = np.abs(np.asarray(self.latitude, dtype=float))
        analytic.horizontal_earth_rate(phi, self.earth_rate)  # raises at the poles
        worst = float(np.max(phi))
        if worst > self.max_latitude:
            raise NotObservable(
                f"latitude: {math.degrees(worst):g} deg is beyond the gyrocompassing limit "
                f"{math.degrees(self.max_latitude):g} deg (`max_latitude`): the horizontal Earth rate "
                f"U cos(latitude) = {self.earth_rate * math.cos(worst):.3g} rad/s is too small to find north"
            )
        if worst > DEGRADED_LATITUDE:
            warnings.warn(
                f"latitude {math.degrees(worst):g} deg: azimuth accuracy degrades as 1/cos(latitude), "
                f"{1 / math.cos(worst):.1f} times the equator's error for the same drifts",
                GyrocompassingAccuracyWarning, stacklevel=3,
            )

    def gains(self) -> tuple[np.ndarray, np.ndarray]:
        """(c_gamma, c_a), 1/s: the given ones, else from T and zeta (c_a = 1/(T^2 U_eta), c_gamma = 2 zeta/T)."""
        from_design = loop_gains(self.latitude, self.time_constant, self.damping, self.earth_rate)
        gains = []
        for given, designed in zip((self.c_gamma, self.c_a), from_design):
            if given is None:
                gains.append(designed)
            else:
                gains.append(np.where(np.isnan(given), designed, given))
        return gains[0], gains[1]

    def platform_drifts(self) -> tuple[np.ndarray, np.ndarray]:
        """Residual drifts about the platform's x and y axes, rad/s."""
        return models.platform_drifts(self.azimuth, self.drift_x, self.drift_y, self.drift_east, self.drift_north)

    def inputs(self) -> np.ndarray:
        """The six model inputs (:data:`models.INPUTS`), shape (6,) or (N, 6), SI."""
        drift_x, drift_y = self.platform_drifts()
        columns = np.stack(np.broadcast_arrays(
            drift_x, drift_y, self.drift_z, self.latitude_error, self.accel_error_x, self.accel_error_y
        ), axis=-1).astype(float)
        return columns if self.size is None else np.broadcast_to(columns, (self.size, 6)).copy()

    def model(self, name: str) -> StateSpace:
        """The state-space model ``name`` (one of :data:`models.MODELS`) of this case (batched for N cases).

        Parameters
        ----------
        name : str
            One of :data:`models.MODELS`.
        """
        c_gamma, c_a = self.gains()
        return models.build_model(name, self.latitude, self.azimuth, c_gamma, c_a,
                                  earth_rate=self.earth_rate, gravity=self.gravity)

    def initial_state(self, name: str) -> np.ndarray:
        """Initial state of the model ``name``: (delta0, beta0, alpha0) in its coordinates, rad.

        Parameters
        ----------
        name : str
            One of :data:`models.MODELS`.
        """
        return models.initial_state(name, self.initial_azimuth_error, self.initial_beta, self.initial_alpha,
                                    self.azimuth)


def check_model(model: str) -> None:
    """Raise InvalidParameter unless ``model`` is one of :data:`models.MODELS`.

    Parameters
    ----------
    model : str
        The model name to check.
    """
    if model not in models.MODELS:
        raise InvalidParameter("model", f"{model!r} is not one of {', '.join(models.MODELS)}")


def analytic_results(case: AlignmentCase, model: str = "full") -> dict[str, np.ndarray]:
    """Closed-form results of (many) cases at once, pure numpy.

    Parameters
    ----------
    case : AlignmentCase
        One case or N cases (SI arrays).
    model : str
        One of :data:`models.MODELS`.

    Returns
    -------
    dict of ndarray
        ``azimuth_error_rad`` (steady state of ``model``: (1.21) for the simplified
        model, the closed form of (1.18) for the full ones), ``azimuth_error_analytic_rad``
        ((1.21)), ``level_error_beta_rad`` (beta_y of ``model``), ``level_error_beta_analytic_rad``
        ((1.25)), ``settling_time_s`` (5/h or the corrected aperiodic formula),
        ``c_gamma``, ``c_a`` (1/s), ``time_constant_s``, ``damping``.

    Examples
    --------
    >>> r = analytic_results(AlignmentCase(drift_east=np.radians(0.01) / 3600))
    >>> round(float(np.degrees(r["azimuth_error_rad"]) * 60), 3), round(float(r["settling_time_s"]), 1)
    (3.556, 187.5)
    """
    check_model(model)
    c_gamma, c_a = case.gains()
    drift_x, drift_y = case.platform_drifts()
    A = np.asarray(case.azimuth, dtype=float)
    drift_east = drift_x * np.cos(A) + drift_y * np.sin(A)
    drift_north = -drift_x * np.sin(A) + drift_y * np.cos(A)
    eps_beta, eps_alpha = analytic.accelerometer_tilts(A, case.accel_error_x, case.accel_error_y, case.gravity)
    delta_y, beta_y = analytic.steady_state(case.latitude, c_gamma, c_a, drift_east, case.drift_z,
                                            case.latitude_error, eps_beta, case.earth_rate)
    if model == "simplified":
        delta, beta = delta_y, beta_y
    else:
        delta, beta, _ = analytic.full_steady_state(case.latitude, c_gamma, c_a, drift_east, drift_north, case.drift_z,
                                                    case.latitude_error, eps_beta, eps_alpha, case.earth_rate)
    time_constant, damping = loop_design(case.latitude, c_gamma, c_a, case.earth_rate)
    shape = np.broadcast_shapes(*(np.shape(x) for x in (delta, c_gamma, c_a)))
    result = {
        "azimuth_error_rad": delta,
        "azimuth_error_analytic_rad": delta_y,
        "level_error_beta_rad": beta,
        "level_error_beta_analytic_rad": beta_y,
        "settling_time_s": analytic.settling_time(c_gamma, c_a, case.latitude, case.earth_rate),
        "c_gamma": c_gamma,
        "c_a": c_a,
        "time_constant_s": time_constant,
        "damping": damping,
    }
    return {key: np.broadcast_to(value, shape).astype(float) for key, value in result.items()}


def automatic_duration(settling_time) -> float:
    """2 h, or 3 analytic settling times when longer, at most 48 h (s).

    Parameters
    ----------
    settling_time : float or ndarray
        Analytic settling times of the cases, s (the longest counts).

    Examples
    --------
    >>> automatic_duration(187.5), automatic_duration(1e4), automatic_duration(1e9)
    (7200.0, 30000.0, 172800.0)
    """
    longest = float(np.max(settling_time))
    return float(min(max(DEFAULT_DURATION, 3.0 * longest), MAX_DURATION))


def sweep_grid(axes: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The Cartesian product of parameter axes as flat arrays of equal length (first axis slowest).

    Parameters
    ----------
    axes : dict of ndarray
        Values of each swept parameter, in its own unit (SI for the system's parameters).

    Examples
    --------
    >>> g = sweep_grid({"a": np.array([1.0, 2.0]), "b": np.array([10.0, 20.0, 30.0])})
    >>> g["a"].tolist(), g["b"].tolist()
    ([1.0, 1.0, 1.0, 2.0, 2.0, 2.0], [10.0, 20.0, 30.0, 10.0, 20.0, 30.0])
    """
    # mesh the indices, so that axes of names (models) work like numbers
    mesh = np.meshgrid(*(np.arange(len(values)) for values in axes.values()), indexing="ij")
    return {name: np.asarray(values)[index.ravel()] for (name, values), index in zip(axes.items(), mesh)}
