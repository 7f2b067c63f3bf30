"""The error state of the aided INS: its layout, the sensor-error processes and the linear model.

State (spec 07; Groves 2013, Sec. 14.2; Shin 2005, ch. 2), errors = computed - true:

=========  =====  =====================================================================
index      unit   state
=========  =====  =====================================================================
0-2        m      delta_r: position error, north, east, down
3-5        m/s    delta_v: velocity error, NED
6-8        rad    psi: attitude error, C_hat = (I - [psi x]) C (NED axes)
9-11       rad/s  b_g: residual gyro bias, body axes (measured - true, after compensation)
12-14      m/s^2  b_a: residual accelerometer bias, body axes
15-17      1      s_g: residual gyro scale-factor error (optional)
18-20      1      s_a: residual accelerometer scale-factor error (optional)
next       1      s_o: residual odometer scale-factor error (optional, after the 15 or 21)
next       m      b_h: residual barometric height bias (optional, last)
=========  =====  =====================================================================

The aiding states (``FilterModel.odometer_scale``, ``FilterModel.barometer_bias``) are
appended after the 15 or 21 in that order, each only when modelled: 15 to 23 states. Like the
sensor states they are the residual errors of the compensated measurement (speed / (1 + s_hat_o),
height - b_hat_h), have no coupling in F but their own process, and are fed back s_hat += delta_s.

Continuous model delta_x' = F delta_x + w (the psi-angle model of spec 06):

* delta_r' = -omega_en x delta_r + delta_v;
* delta_v' = -(2 omega_ie + omega_en) x delta_v - psi x f^n + delta_g + C_b^n (b_a + diag(f^b) s_a),
  delta_g = (-(g/R) delta_r_N, -(g/R) delta_r_E, +(2 g/R) delta_r_D);
* psi' = -(omega_ie + omega_en) x psi - C_b^n (b_g + diag(omega_ib^b) s_g);
* each bias or scale state x: random constant (x' = 0), random walk (x' = w, PSD q) or
  first-order Gauss-Markov (x' = -x/T + w, PSD q = 2 sigma^2 / T: steady standard deviation sigma).

The angle and velocity random walks N_g (rad/sqrt(s)) and N_a (m/s/sqrt(s)) enter psi' and
delta_v' through C_b^n with PSD N^2.

The sensors' misalignments M (and the gyros' g-sensitivity G) are not states: their error M omega
(G a, M a) follows the motion, so the filter takes it as motion-dependent white noise of PSD
q_i = tau sum_j M_ij^2 u_j^2 on body axis i, u the step's mean angular rate omega_ib^b (gyro
misalignment) or kinematic acceleration a^b = f^b + C_n^b g^n (accelerometer misalignment, gyro
g-sensitivity: gravity's constant part acts as a bias and is left to the bias states), resolved
through C_b^n like N^2, with tau = :data:`ROTATION_NOISE_TIME` for the angular rate's terms and
:data:`ACCELERATION_NOISE_TIME` for the acceleration's. A misalignment's error is correlated
over a manoeuvre, which white noise cannot follow; without this term a 20-mrad consumer IMU tilts
by 2 % of every turn the filter believes it knows (tests/test_aided_motion_noise.py).

With C_hat = (I - [psi x]) C, the heading error
(computed - true) is -psi_D to first order, and the roll and pitch errors follow from
psi resolved in body axes: every plot and NEES of "attitude error" in this package uses psi.

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*,
2nd ed., Artech House, 2013, Sec. 14.2.
E.-H. Shin, *Estimation Techniques for Low-Cost Inertial Navigation*, PhD thesis, University of
Calgary, 2005, ch. 2.
B. W. Benson, "A comparison of two approaches to pure-inertial and Doppler-inertial error
analysis", *IEEE Transactions on Aerospace and Electronic Systems* AES-11(4), 1975.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from schuler.core.attitude import skew
from schuler.core.earth import EARTH_RATE, radii_of_curvature, somigliana_gravity
from schuler.core.propagation import discretise_noise
from schuler.exceptions import InvalidParameter
from schuler.imu.error_model import ErrorModel, SensorErrors, gauss_markov_for_bias_instability

POSITION, VELOCITY, ATTITUDE = slice(0, 3), slice(3, 6), slice(6, 9)
GYRO_BIAS, ACCEL_BIAS = slice(9, 12), slice(12, 15)
GYRO_SCALE, ACCEL_SCALE = slice(15, 18), slice(18, 21)

STATE_NAMES = ("position_north", "position_east", "position_down",
               "velocity_north", "velocity_east", "velocity_down",
               "psi_north", "psi_east", "psi_down",
               "gyro_bias_x", "gyro_bias_y", "gyro_bias_z",
               "accel_bias_x", "accel_bias_y", "accel_bias_z",
               "gyro_scale_x", "gyro_scale_y", "gyro_scale_z",
               "accel_scale_x", "accel_scale_y", "accel_scale_z")
STATE_UNITS = ("m",) * 3 + ("m/s",) * 3 + ("rad",) * 3 + ("rad/s",) * 3 + ("m/s^2",) * 3 + ("1",) * 6

KINDS = ("constant", "random-walk", "gauss-markov")

ROTATION_NOISE_TIME = 0.5
"""tau of the noise the gyros' misalignment makes of the angular rate, s (module docstring): a tuning constant,
measured on the simulated drive. At 0.5 s the tactical grade's predicted outage 1-sigma is 8 % above its 64 members'
RMS (19 % at 1 s, 41 % at 5 s); at 0.25 s the consumer grade's filter rejects GNSS fixes after its turns."""

ACCELERATION_NOISE_TIME = 5.0
"""tau of the noise the accelerometers' misalignment and the gyros' g-sensitivity make of the acceleration, s: the
seconds a vehicle speeds up, brakes or turns. At 0.5 s a consumer IMU's 2 % misalignment, read as heading while the
drive speeds up, leaves headings 1.5 deg off with a 1-sigma of 0.3 deg; at 5 s all 16 members of a consumer drive
(seed 5) keep the GNSS, against 11 at 0.5 s."""


def _cross_axis(name: str, value) -> np.ndarray:
    array = np.broadcast_to(np.asarray(value, dtype=float), (3, 3)).copy()
    if not np.all(np.isfinite(array)) or np.any(array < 0):
        raise InvalidParameter(name, f"must be a 3 x 3 matrix of finite 1-sigma >= 0, got {value!r}")
    return array


def _triple(name: str, value, axes: int = 3) -> np.ndarray:
    array = np.broadcast_to(np.asarray(value, dtype=float), (axes,)).copy()
    if not np.all(np.isfinite(array)) or np.any(array < 0):
        raise InvalidParameter(name, f"must be {axes} finite number(s) >= 0, got {value!r}")
    return array


@dataclass(frozen=True)
class ErrorProcess:
    """The model of one sensor-error triad (a bias or a scale factor) in the filter.

    Parameters
    ----------
    kind : str
        ``constant`` (x' = 0), ``random-walk`` (x' = w) or ``gauss-markov`` (x' = -x/T + w).
    sigma : array_like, shape (3,)
        Standard deviation of the initial value per axis (constant and random walk) or the steady
        standard deviation (Gauss-Markov), in the state's unit (rad/s, m/s^2 or 1).
    random_walk : array_like, shape (3,)
        Random-walk density sqrt(q) of ``random-walk``, state unit / sqrt(s) (ignored otherwise).
    correlation_time : float
        T of ``gauss-markov``, s (> 0; ignored otherwise).
    axes : int
        Number of states, 3 for a sensor triad, 1 for an aiding state (odometer scale, barometer bias).
    """

    kind: str = "constant"
    sigma: np.ndarray | float = 0.0
    random_walk: np.ndarray | float = 0.0
    correlation_time: float = np.inf
    axes: int = 3

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InvalidParameter("kind", f"{self.kind!r} is not a model; choose from {', '.join(KINDS)}")
        object.__setattr__(self, "sigma", _triple("sigma", self.sigma, self.axes))
        object.__setattr__(self, "random_walk", _triple("random_walk", self.random_walk, self.axes))
        if self.kind == "gauss-markov" and not (np.isfinite(self.correlation_time) and self.correlation_time > 0):
            raise InvalidParameter("correlation_time", f"a Gauss-Markov process needs T > 0 s, got "
                                                       f"{self.correlation_time!r}")

    @property
    def decay_rate(self) -> float:
        """1/T of a Gauss-Markov process, 1/s (0 otherwise)."""
        return 1.0 / self.correlation_time if self.kind == "gauss-markov" else 0.0

    @property
    def density(self) -> np.ndarray:
        """PSD q of the driving white noise per axis, (state unit)^2 / s."""
        if self.kind == "random-walk":
            return np.asarray(self.random_walk) ** 2
        if self.kind == "gauss-markov":
            return 2.0 * np.asarray(self.sigma) ** 2 / self.correlation_time
        return np.zeros(self.axes)


@dataclass(frozen=True)
class FilterModel:
    """What the filter assumes of the IMU: white noise densities and the sensor-error processes.

    Parameters
    ----------
    angle_random_walk : array_like, shape (3,)
        N_g per gyro axis, rad/sqrt(s).
    velocity_random_walk : array_like, shape (3,)
        N_a per accelerometer axis, m/s/sqrt(s).
    gyro_bias, accel_bias : ErrorProcess
        Bias models, rad/s and m/s^2.
    gyro_scale, accel_scale : ErrorProcess or None
        Scale-factor models (dimensionless); None leaves the scale states out (15 states).
    odometer_scale : ErrorProcess or None
        Model of the odometer's scale-factor error (one axis, dimensionless); None: no state.
    barometer_bias : ErrorProcess or None
        Model of the barometric height bias (one axis, m); None: no state.
    gyro_misalignment, accel_misalignment : array_like, shape (3, 3)
        1-sigma of each entry of the gyros' and accelerometers' misalignment M (plain numbers), taken as
        motion-dependent noise (module docstring); zero: none.
    gyro_g_sensitivity : array_like, shape (3, 3)
        1-sigma of each entry of the gyros' g-sensitivity G, rad/s per m/s^2, taken the same way.
    """

    angle_random_walk: np.ndarray | float
    velocity_random_walk: np.ndarray | float
    gyro_bias: ErrorProcess
    accel_bias: ErrorProcess
    gyro_scale: ErrorProcess | None = None
    accel_scale: ErrorProcess | None = None
    odometer_scale: ErrorProcess | None = None
    barometer_bias: ErrorProcess | None = None
    gyro_misalignment: np.ndarray | float = 0.0
    accel_misalignment: np.ndarray | float = 0.0
    gyro_g_sensitivity: np.ndarray | float = 0.0

    def __post_init__(self):
        for name in ("gyro_misalignment", "accel_misalignment", "gyro_g_sensitivity"):
            object.__setattr__(self, name, _cross_axis(name, getattr(self, name)))
        object.__setattr__(self, "angle_random_walk", _triple("angle_random_walk", self.angle_random_walk))
        object.__setattr__(self, "velocity_random_walk", _triple("velocity_random_walk", self.velocity_random_walk))
        if (self.gyro_scale is None) != (self.accel_scale is None):
            raise InvalidParameter("scale", "give both scale-factor models (21 states) or neither (15 states)")
        for name in ("odometer_scale", "barometer_bias"):
            process = getattr(self, name)
            if process is not None and process.axes != 1:
                raise InvalidParameter(name, f"is one state, got a model of {process.axes}")

    @property
    def has_motion_noise(self) -> bool:
        """Whether a misalignment or g-sensitivity 1-sigma is non-zero (:func:`motion_noise`)."""
        return bool(np.any(self.gyro_misalignment) or np.any(self.accel_misalignment)
                    or np.any(self.gyro_g_sensitivity))

    @property
    def sensor_size(self) -> int:
        """Number of navigation and IMU error states: 15, or 21 with the scale factors."""
        return 15 if self.gyro_scale is None else 21

    @property
    def size(self) -> int:
        """Number of error states: ``sensor_size`` and the aiding states (module docstring)."""
        return self.sensor_size + len(self.aiding_states())

    def aiding_states(self) -> dict[str, int]:
        """Index of each aiding state modelled: ``odometer_scale``, then ``barometer_bias``."""
        names = [name for name in ("odometer_scale", "barometer_bias") if getattr(self, name) is not None]
        return {name: self.sensor_size + k for k, name in enumerate(names)}

    def processes(self) -> list[tuple[slice, ErrorProcess]]:
        """The sensor-error and aiding processes with the state slices they occupy."""
        pairs = [(GYRO_BIAS, self.gyro_bias), (ACCEL_BIAS, self.accel_bias)]
        if self.gyro_scale is not None and self.accel_scale is not None:
            pairs += [(GYRO_SCALE, self.gyro_scale), (ACCEL_SCALE, self.accel_scale)]
        for name, index in self.aiding_states().items():
            pairs.append((slice(index, index + 1), getattr(self, name)))
        return pairs

    def initial_sigma(self) -> np.ndarray:
        """1-sigma of the sensor-error and aiding states at the start (sizes 6 or 12, then the aiding states)."""
        return np.concatenate([process.sigma for _, process in self.processes()])

    def names(self) -> tuple[str, ...]:
        """The states' names in their order (:data:`schuler.aided.error_state.STATE_NAMES`, then the aiding states')."""
        return STATE_NAMES[:self.sensor_size] + tuple(self.aiding_states())


@dataclass(frozen=True)
class NavigationPoint:
    """The navigation solution the linear model is evaluated at (one member or a batch: leading axis N).

    Parameters
    ----------
    latitude : ndarray, shape ([N])
        rad.
    height : ndarray, shape ([N])
        m.
    velocity : ndarray, shape ([N,] 3)
        NED, m/s.
    body_to_ned : ndarray, shape ([N,] 3, 3)
        C_b^n, plain numbers.
    specific_force : ndarray, shape ([N,] 3)
        f^b, body axes, m/s^2 (mean over the step).
    angular_rate : ndarray, shape ([N,] 3)
        omega_ib^b, body axes, rad/s (mean over the step).
    """

    latitude: np.ndarray
    height: np.ndarray
    velocity: np.ndarray
    body_to_ned: np.ndarray
    specific_force: np.ndarray
    angular_rate: np.ndarray


DEFAULT_CORRELATION_TIME = 3600.0
"""T of a Gauss-Markov bias model when the IMU's error model gives none (s): an hour, KF-GINS's order."""


def _bias_process(sensor: SensorErrors, kind: str, correlation_time: float | None) -> ErrorProcess:
    """One triad's bias model from its error terms (see :func:`filter_model`)."""
    instability = np.array([gauss_markov_for_bias_instability(b) for b in sensor.bias_instability])
    slow = np.sqrt(sensor.gm_sigma**2 + instability**2)
    sigma = np.sqrt(sensor.bias**2 + slow**2)
    if correlation_time is None:
        times = [float(t) for t, s in zip(sensor.gm_correlation_time_s, sensor.gm_sigma) if s > 0]
        if np.any(sensor.bias_instability > 0):
            times.append(sensor.flicker_tau_range_s[1] / 1.893)  # the slowest flicker term's peak
        correlation_time = max(times) if times else DEFAULT_CORRELATION_TIME
    if kind == "gauss-markov":
        return ErrorProcess("gauss-markov", sigma, correlation_time=correlation_time)
    if kind == "random-walk":
        walk = np.sqrt(sensor.rate_random_walk**2 + 2.0 * slow**2 / correlation_time)
        return ErrorProcess("random-walk", sigma, random_walk=walk)
    return ErrorProcess("constant", sigma)


def filter_model(error_model: ErrorModel, bias: str = "random-walk", correlation_time: float | None = None,
                 scale_factors: bool | None = None) -> FilterModel:
    """The filter's IMU model from the IMU layer's error model (a grade, a spec sheet or an identification).

    The white noises are the model's N (angle and velocity random walk). Each bias state
    lumps the turn-on bias b, the Gauss-Markov terms and the bias instability B (as a
    Gauss-Markov sigma = B / 0.9294, :func:`~schuler.imu.error_model.gauss_markov_for_bias_instability`):
    its 1-sigma is sqrt(b^2 + sigma_GM^2 + sigma_B^2), and it is

    * ``gauss-markov``: that steady sigma with T = ``correlation_time``, else the model's longest
      Gauss-Markov time or its flicker range's upper end / 1.893 (the Allan peak of a Gauss-Markov
      process sits at 1.893 T), else :data:`DEFAULT_CORRELATION_TIME`;
    * ``random-walk``: that initial sigma driven by the rate random walk K and the slow terms'
      spread 2 sigma^2 / T;
    * ``constant``: that initial sigma and no process noise.

    ``random-walk`` is the default because the turn-on bias b is a random constant: a Gauss-Markov
    state of the lumped sigma forgets it (the estimate fed back decays as exp(-t/T), its variance
    relaxes to sigma^2) and is driven with 2 b^2 / T, a walk of 1.2 deg/s/sqrt(s) for the consumer
    grade's 20 deg/s and T = 528 s; such a filter rejects the GNSS and diverges to kilometres
    (tests/test_aided_motion_noise.py). The misalignment and g-sensitivity 1-sigma become the
    motion-dependent noise (:func:`motion_noise`).

    Scale factors are random constants of the model's 1-sigma; they are states (21) when
    ``scale_factors`` is True, or when None and the model has scale-factor errors.

    Parameters
    ----------
    error_model : ErrorModel
        The IMU's error terms (SI).
    bias : str
        ``random-walk``, ``gauss-markov`` or ``constant``.
    correlation_time : float, optional
        T of the Gauss-Markov bias model (or of the random walk's spread), s.
    scale_factors : bool, optional
        Whether the scale-factor states are carried.

    Examples
    --------
    >>> from schuler.imu.spec import preset
    >>> model = filter_model(preset("tactical"))
    >>> model.size, round(float(np.degrees(model.angle_random_walk[0]) * 60), 4)   # deg/sqrt(h)
    (21, 0.125)
    """
    if bias not in KINDS:
        raise InvalidParameter("bias", f"{bias!r} is not a model; choose from {', '.join(KINDS)}")
    gyro, accel = error_model.gyro, error_model.accel
    off_diagonal = 1.0 - np.eye(3)  # M's diagonal is the scale factor's
    with_scale = bool(np.any(gyro.scale_factor > 0) or np.any(accel.scale_factor > 0)) if scale_factors is None \
        else scale_factors
    return FilterModel(gyro.random_walk, accel.random_walk, _bias_process(gyro, bias, correlation_time),
                       _bias_process(accel, bias, correlation_time),
                       ErrorProcess("constant", gyro.scale_factor) if with_scale else None,
                       ErrorProcess("constant", accel.scale_factor) if with_scale else None,
                       gyro_misalignment=gyro.misalignment * off_diagonal,
                       accel_misalignment=accel.misalignment * off_diagonal,
                       gyro_g_sensitivity=gyro.g_sensitivity)



def overridden(model: FilterModel, *, angle_random_walk=None, velocity_random_walk=None, gyro_bias_sigma=None,
               accel_bias_sigma=None, bias: str | None = None, correlation_time: float | None = None) -> FilterModel:
    """``model`` with the values a user states explicitly in place of those derived from the IMU's error model.

    Each argument left None keeps the model's own. A bias sigma is the 1-sigma of the initial value
    (constant, random walk) or the steady 1-sigma (Gauss-Markov). A bias changed to ``random-walk``, or
    a random walk given a new ``correlation_time``, is driven with the density sqrt(2 sigma^2 / T) of
    the Gauss-Markov process of that sigma and time (as :func:`filter_model` builds it).

    Parameters
    ----------
    model : FilterModel
        The model derived from the IMU layer (:func:`filter_model`, or KF-GINS's configuration).
    angle_random_walk : float or array_like, shape (3,), optional
        N_g, rad/sqrt(s).
    velocity_random_walk : float or array_like, shape (3,), optional
        N_a, m/s/sqrt(s).
    gyro_bias_sigma : float or array_like, shape (3,), optional
        Gyro bias 1-sigma, rad/s.
    accel_bias_sigma : float or array_like, shape (3,), optional
        Accelerometer bias 1-sigma, m/s^2.
    bias : str, optional
        Bias model of both triads: ``gauss-markov``, ``random-walk`` or ``constant``.
    correlation_time : float, optional
        T of both triads' Gauss-Markov (or random-walk spread) model, s.

    Examples
    --------
    >>> from schuler.imu.spec import preset
    >>> model = overridden(filter_model(preset("tactical")), angle_random_walk=np.radians(0.5) / 60, bias="constant")
    >>> round(float(np.degrees(model.angle_random_walk[0]) * 60), 6), model.gyro_bias.kind   # deg/sqrt(h)
    (0.5, 'constant')
    """
    if bias is not None and bias not in KINDS:
        raise InvalidParameter("bias", f"{bias!r} is not a model; choose from {', '.join(KINDS)}")

    def process(old: ErrorProcess, sigma) -> ErrorProcess:
        if sigma is None and bias is None and correlation_time is None:
            return old
        kind = bias or old.kind
        sigma = old.sigma if sigma is None else sigma
        time = correlation_time if correlation_time is not None else \
            old.correlation_time if np.isfinite(old.correlation_time) else DEFAULT_CORRELATION_TIME
        if kind == "gauss-markov":
            return ErrorProcess(kind, sigma, correlation_time=time)
        if kind == "random-walk":
            keep = old.kind == "random-walk" and correlation_time is None
            walk = old.random_walk if keep else np.sqrt(2.0 * np.asarray(sigma, dtype=float) ** 2 / time)
            return ErrorProcess(kind, sigma, random_walk=walk)
        return ErrorProcess(kind, sigma)

    return replace(
        model,
        angle_random_walk=model.angle_random_walk if angle_random_walk is None else angle_random_walk,
        velocity_random_walk=model.velocity_random_walk if velocity_random_walk is None else velocity_random_walk,
        gyro_bias=process(model.gyro_bias, gyro_bias_sigma), accel_bias=process(model.accel_bias, accel_bias_sigma))

def system_matrix(model: FilterModel, point: NavigationPoint, earth_rate: float = EARTH_RATE) -> np.ndarray:
    """F of the error state at a navigation point (module docstring), shape ([N,] n, n).

    Parameters
    ----------
    model : FilterModel
        Sensor-error processes (which states exist, the Gauss-Markov decay rates).
    point : NavigationPoint
        Where the model is linearised (SI).
    earth_rate : float
        Omega, rad/s.
    """
    L = np.asarray(point.latitude, dtype=float)
    h = np.asarray(point.height, dtype=float)
    v = np.asarray(point.velocity, dtype=float)
    C = np.asarray(point.body_to_ned, dtype=float)
    R_N, R_E = radii_of_curvature(L)
    omega_ie = np.stack([earth_rate * np.cos(L), np.zeros_like(L), -earth_rate * np.sin(L)], axis=-1)
    omega_en = np.stack([v[..., 1] / (R_E + h), -v[..., 0] / (R_N + h), -v[..., 1] * np.tan(L) / (R_E + h)], axis=-1)
    f_n = np.einsum("...ij,...j->...i", C, point.specific_force)
    g = somigliana_gravity(L, h)
    radius = np.sqrt((R_N + h) * (R_E + h))
    n = model.size
    F = np.zeros(L.shape + (n, n))
    F[..., POSITION, POSITION] = -skew(omega_en)
    F[..., POSITION, VELOCITY] = np.eye(3)
    F[..., VELOCITY, VELOCITY] = -skew(2.0 * omega_ie + omega_en)
    F[..., VELOCITY, ATTITUDE] = skew(f_n)  # -psi x f = f x psi
    gravity_gain = g / radius
    F[..., 3, 0] = -gravity_gain
    F[..., 4, 1] = -gravity_gain
    F[..., 5, 2] = 2.0 * gravity_gain
    F[..., ATTITUDE, ATTITUDE] = -skew(omega_ie + omega_en)
    F[..., ATTITUDE, GYRO_BIAS] = -C
    F[..., VELOCITY, ACCEL_BIAS] = C
    if model.sensor_size == 21:
        F[..., ATTITUDE, GYRO_SCALE] = -C * np.asarray(point.angular_rate)[..., None, :]
        F[..., VELOCITY, ACCEL_SCALE] = C * np.asarray(point.specific_force)[..., None, :]
    for states, process in model.processes():
        index = np.arange(states.start, states.stop)
        F[..., index, index] = -process.decay_rate
    return F


def motion_noise(model: FilterModel, angular_rate: np.ndarray, acceleration: np.ndarray) -> tuple[np.ndarray,
                                                                                                   np.ndarray]:
    """The misalignment and g-sensitivity PSD per body axis: gyro (rad^2/s) and accelerometer ((m/s^2)^2 s).

    q_i = tau sum_j M_ij^2 u_j^2 (module docstring), shapes ([N,] 3), tau :data:`ROTATION_NOISE_TIME` for the rate's
    terms and :data:`ACCELERATION_NOISE_TIME` for the acceleration's.

    Parameters
    ----------
    model : FilterModel
        The sensors' misalignment and g-sensitivity 1-sigma.
    angular_rate : ndarray, shape ([N,] 3)
        omega_ib^b over the step, rad/s.
    acceleration : ndarray, shape ([N,] 3)
        Kinematic acceleration a^b = f^b + C_n^b g^n over the step, body axes, m/s^2.
    """
    rate2, acceleration2 = np.asarray(angular_rate) ** 2, np.asarray(acceleration) ** 2
    gyro = ROTATION_NOISE_TIME * rate2 @ (np.asarray(model.gyro_misalignment) ** 2).T \
        + ACCELERATION_NOISE_TIME * acceleration2 @ (np.asarray(model.gyro_g_sensitivity) ** 2).T
    accel = ACCELERATION_NOISE_TIME * acceleration2 @ (np.asarray(model.accel_misalignment) ** 2).T
    return gyro, accel


def noise_input(model: FilterModel, body_to_ned: np.ndarray, angular_rate: np.ndarray | None = None,
                acceleration: np.ndarray | None = None) -> np.ndarray:
    """G Q_c G^T: the white noises' PSD on the state derivatives, shape ([N,] n, n), (state unit)^2/s.

    Parameters
    ----------
    model : FilterModel
        Noise densities and sensor-error processes.
    body_to_ned : ndarray, shape ([N,] 3, 3)
        C_b^n (plain numbers), through which the sensor noises enter psi' and delta_v'.
    angular_rate, acceleration : ndarray, shape ([N,] 3), optional
        omega_ib^b (rad/s) and a^b (m/s^2) over the step, for the misalignment and g-sensitivity noise
        (:func:`motion_noise`); None: that noise left out.
    """
    C = np.asarray(body_to_ned, dtype=float)
    n = model.size
    Q = np.zeros(C.shape[:-2] + (n, n))
    Ct = np.swapaxes(C, -1, -2)
    gyro_psd = np.asarray(model.angle_random_walk) ** 2
    accel_psd = np.asarray(model.velocity_random_walk) ** 2
    if angular_rate is not None and acceleration is not None:
        gyro_motion, accel_motion = motion_noise(model, angular_rate, acceleration)
        gyro_psd, accel_psd = gyro_psd + gyro_motion, accel_psd + accel_motion
    # C diag(q) C^T: the body-axis densities resolved in NED
    Q[..., ATTITUDE, ATTITUDE] = (C * gyro_psd[..., None, :]) @ Ct
    Q[..., VELOCITY, VELOCITY] = (C * accel_psd[..., None, :]) @ Ct
    for states, process in model.processes():
        index = np.arange(states.start, states.stop)
        Q[..., index, index] = process.density
    return Q


def transition(model: FilterModel, point: NavigationPoint, dt: float,
               earth_rate: float = EARTH_RATE) -> tuple[np.ndarray, np.ndarray]:
    """Exact (Phi, Q_d) of the error state over dt with F held at ``point`` (Van Loan), shapes ([N,] n, n).

    Parameters
    ----------
    model : FilterModel
        Sensor-error processes and noise densities.
    point : NavigationPoint
        Where F is evaluated (the solution at the step's start, the sensors' means over it).
    dt : float
        Covariance step, s.
    earth_rate : float
        Omega, rad/s.
    """
    C = np.asarray(point.body_to_ned, dtype=float)
    F = system_matrix(model, point, earth_rate)
    if not model.has_motion_noise:
        return discretise_noise(F, noise_input(model, C), dt)
    g = np.asarray(somigliana_gravity(point.latitude, point.height))
    gravity_body = np.swapaxes(C, -1, -2)[..., :, 2] * g[..., None]  # C_n^b (0, 0, g)
    acceleration = np.asarray(point.specific_force) + gravity_body
    return discretise_noise(F, noise_input(model, C, point.angular_rate, acceleration), dt)
