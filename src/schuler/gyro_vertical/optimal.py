"""``schuler vertical optimal``: Drozdovich's gyro vertical beside the Kalman filter that an external velocity allows.

Source: Drozdovich (1959) (:data:`schuler.references.DROZDOVICH_1959`). The seed's design is the
integral correction (6) with the Schuler condition (11), k1 / H = k2 / H = 1 / R, and the torques (8):
its error model is (24), written with the velocity errors as states in
:func:`schuler.gyro_vertical.model.error_state_space` (alpha, beta, Delta v_x, Delta v_y). The source
has no other information than its accelerometers, so its loop is undamped: two split Schuler modes.

Beside it (spec 07, "Steady-state gains"): the same vertical corrected from an external velocity
(a GNSS or Doppler velocity, white noise of 1-sigma ``velocity_noise`` at every ``update_interval``,
PSD r = sigma_v^2 dt), z = V - v_measured = Delta v + n. The loop's state is (24) with the platform
drifts eps_x, eps_y and accelerometer biases b_x, b_y appended as Gauss-Markov or random-walk states
(:func:`schuler.core.steady_state.bias_state`); white gyro noise N_g (angle random walk) drives
alpha', beta', white accelerometer noise N_a (velocity random walk) Delta v'. The steady-state
Kalman-Bucy gain K (8 x 2) of this model (:func:`schuler.core.steady_state.steady_state_gain`) feeds
the residual back: beta' gets -K_beta z_x, Delta v_x' gets -K_v z_x, and likewise on y, so that the
torque of (6) becomes M_x / H = (1 / R - K_beta) V_x + K_beta v_measured: an integral correction
that takes part of its velocity from outside. The seed is K = 0.

An accelerometer bias modelled as a random walk cannot be told from a tilt (only g beta - b reaches
the velocity): the Riccati equation then has no stabilising solution. It is modelled as Gauss-Markov
(its Allan-deviation peak at the top of the flicker range), and the constant turn-on biases are added
deterministically: the centre of the seed's oscillation, -A^-1 B u (the quasi-steady error in the
sense of (29)), and for the filter the steady error of a constant bias its model lets decay,
-(A - K C)^-1 d with d the decay the model applies to it.

The map between the gains and the seed's parameters, on one level channel (beta, Delta v_x; exact at the
equator, where (24) splits into two such channels), with omega_s^2 = g / R:
the loop's characteristic polynomial is s^2 + K_v s + g (1 / R - K_beta) (period T = 2 pi / omega_n,
omega_n^2 = g (1 / R - K_beta), damping zeta = K_v / (2 omega_n)); spectral factorisation of the
Riccati equation with gyro PSD q_g and accelerometer PSD q_a gives

    omega_n^2 = sqrt(omega_s^4 + g^2 q_g / r),    K_v^2 = 2 (omega_n^2 - omega_s^2) + q_a / r,

and back, for given gains, q_g / r = (omega_n^4 - omega_s^4) / g^2 and q_a / r = K_v^2 - 2 (omega_n^2 -
omega_s^2): gains are optimal for some sensors only if both are >= 0 (the return-difference condition:
a period no longer than Schuler's, zeta^2 >= (1 - omega_s^2 / omega_n^2) / 2, so zeta >= 1 / sqrt(2) for a
loop much faster than Schuler's). The seed's gains K = 0 give q_g = q_a = 0: the published design is
the Kalman filter of a noise-free instrument, or of an infinitely noisy velocity reference.

References
----------
R. E. Kalman and R. S. Bucy, "New results in linear filtering and prediction theory", *Trans. ASME, J. Basic
Eng.* 83(1), 1961. B. D. O. Anderson and J. B. Moore, *Optimal Filtering*, Prentice Hall, 1979, ch. 3-4
(the return difference of the optimal filter).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from schuler.alignment.gyrocompass import SETTLING_DECREMENTS
from schuler.contract import Action
from schuler.core.earth import PRESETS
from schuler.core.steady_state import (
    bias_state,
    loop_covariance_history,
    riccati_solution,
    steady_state_gain,
)
from schuler.exceptions import InvalidParameter
from schuler.gyro_vertical.model import error_state_space
from schuler.imu.error_model import GAUSS_MARKOV_PEAK, SensorErrors, gauss_markov_for_bias_instability
from schuler.imu.instrument import resolve_model
from schuler.params import Parameter, ParameterSet
from schuler.results import Result

DEFAULT_IMU = "tactical"
"""The IMU when ``--imu`` is not given."""

STATES = ("alpha", "beta", "velocity_error_x", "velocity_error_y", "drift_x", "drift_y", "accel_bias_x",
          "accel_bias_y")
"""The loop's states: (24)'s four, then eps_x, eps_y (rad/s) and b_x, b_y (m/s^2)."""

# the platform's x, y are the body's y, x (schuler.imu.system_inputs): the axis each platform axis takes
BODY_AXIS = (1, 0)


def bias_process(errors: SensorErrors, axis: int) -> tuple[float, float]:
    """Decay rate (1/s) and PSD of one sensor's bias state, from its Gauss-Markov, flicker and K terms.

    A published Gauss-Markov bias is used as it is; a bias instability B (IEEE 952 flicker) becomes the
    Gauss-Markov process of the same Allan-deviation peak
    (:func:`schuler.imu.error_model.gauss_markov_for_bias_instability`) with the peak at the top of the
    flicker range, T = tau_max / 1.893; a rate random walk K adds K^2 (spec 07).

    Parameters
    ----------
    errors : SensorErrors
        One triad's errors, SI (rad/s or m/s^2).
    axis : int
        Body axis index, 0 x, 1 y, 2 z.

    Examples
    --------
    >>> from schuler.imu.spec import preset
    >>> rate, psd = bias_process(preset("tactical").gyro, 0)
    >>> round(1 / rate), f"{psd:.3g}"
    (528, '9.28e-15')
    """
    if errors.gm_sigma[axis] > 0:
        sigma, time = float(errors.gm_sigma[axis]), float(errors.gm_correlation_time_s[axis])
    else:
        sigma = gauss_markov_for_bias_instability(float(errors.bias_instability[axis]))
        time = errors.flicker_tau_range_s[1] / GAUSS_MARKOV_PEAK[0]
    if sigma == 0 and errors.rate_random_walk[axis] == 0:
        # no slow term published: the bias is a constant, handled deterministically; a weak stable state
        # keeps the Riccati equation regular
        return 1.0 / time, 0.0
    return bias_state(sigma, time, float(errors.rate_random_walk[axis]))


@dataclass(frozen=True)
class VerticalLoop:
    """The aided gyro vertical's linear model (module docstring), SI.

    Attributes
    ----------
    A, C, Q, R : ndarray
        x' = A x + w (PSD Q), z = C x + v (PSD R); states :data:`STATES`, z = (Delta v_x, Delta v_y) + n.
    P0 : ndarray
        Covariance at the start: tilt (b / g)^2 from levelling on biased accelerometers, velocity 0
        (integrators preset (24)), each bias state's steady variance (0 for a random walk).
    constant_bias : ndarray, shape (8,)
        The constant turn-on biases at +1 sigma in the bias rows (rad/s, m/s^2), 0 elsewhere.
    gravity, radius : float
        g (m/s^2) and R (m).
    """

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    P0: np.ndarray
    constant_bias: np.ndarray
    gravity: float
    radius: float


def vertical_loop(imu: str | None, velocity_noise: float, update_interval: float, latitude: float,
                  earth: str = "default") -> VerticalLoop:
    """The model of the module docstring for an IMU, a velocity reference and a latitude.

    Parameters
    ----------
    imu : str or None
        A grade, a TOML spec file or a recording (:func:`schuler.imu.instrument.resolve_model`); None: tactical.
    velocity_noise : float
        1-sigma white noise of each velocity measurement, m/s (> 0).
    update_interval : float
        Interval of the velocity measurements, s (> 0): the PSD is velocity_noise^2 update_interval.
    latitude : float
        phi, rad: omega_2 = Omega sin phi couples the two channels (24).
    earth : str
        Earth constants (:data:`schuler.core.earth.PRESETS`).

    Examples
    --------
    >>> loop = vertical_loop("navigation", 0.1, 1.0, 0.0)
    >>> loop.A.shape, float(loop.R[0, 0])
    ((8, 8), 0.010000000000000002)
    """
    for name, value in (("velocity_noise", velocity_noise), ("update_interval", update_interval)):
        if not (math.isfinite(value) and value > 0):
            raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    if earth not in PRESETS:
        raise InvalidParameter("earth", f"{earth!r} is not one of {', '.join(PRESETS)}")
    model = resolve_model(imu or DEFAULT_IMU)
    constants = PRESETS[earth]
    g, radius = constants.gravity, constants.radius
    core = error_state_space(constants.rate * math.sin(latitude), g, radius)
    A = np.zeros((8, 8))
    A[:4, :4] = core.A
    A[:4, 4:] = core.B[:, [2, 3, 0, 1]]  # drifts enter alpha', beta' (e_x, e_y); biases Delta v' (f_x, f_y)
    Q = np.zeros((8, 8))
    P0 = np.zeros((8, 8))
    constant = np.zeros(8)
    for i, axis in enumerate(BODY_AXIS):
        Q[i, i] = float(model.gyro.random_walk[axis]) ** 2
        Q[2 + i, 2 + i] = float(model.accel.random_walk[axis]) ** 2
        for row, errors in ((4 + i, model.gyro), (6 + i, model.accel)):
            decay, psd = bias_process(errors, axis)
            A[row, row] = -decay
            Q[row, row] = psd
            P0[row, row] = psd / (2 * decay) if decay > 0 else 0.0
            constant[row] = float(errors.bias[axis])
        # levelling on the accelerometers leaves the tilt their bias over g (the other axis's accelerometer)
        P0[i, i] = (float(model.accel.bias[BODY_AXIS[1 - i]]) / g) ** 2
    C = np.zeros((2, 8))
    C[0, 2] = C[1, 3] = 1.0
    R = np.eye(2) * velocity_noise**2 * update_interval
    return VerticalLoop(A, C, Q, R, P0, constant, g, radius)


def level_gains(gyro_psd: float, accel_psd: float, velocity_psd: float, gravity: float,
                radius: float) -> tuple[float, float]:
    """Steady-state Kalman gains (K_beta, K_v) of one level channel, closed form (module docstring).

    Parameters
    ----------
    gyro_psd : float
        q_g = N_g^2, rad^2/s (>= 0).
    accel_psd : float
        q_a = N_a^2, (m/s)^2/s (>= 0).
    velocity_psd : float
        r, (m/s)^2 s (> 0).
    gravity, radius : float
        g (m/s^2) and R (m).

    Returns
    -------
    (float, float)
        K_beta, 1/m (rad/s per m/s), and K_v, 1/s.

    Examples
    --------
    >>> level_gains(0.0, 0.0, 1.0, 9.8, 6.4e6)   # a noise-free IMU: no correction, the seed
    (0.0, 0.0)
    """
    if not velocity_psd > 0 or gyro_psd < 0 or accel_psd < 0:
        raise InvalidParameter("velocity_psd", "needs r > 0 and q_g, q_a >= 0")
    schuler = gravity / radius
    natural = math.sqrt(schuler**2 + gravity**2 * gyro_psd / velocity_psd)
    return 1.0 / radius - natural / gravity, math.sqrt(2.0 * (natural - schuler) + accel_psd / velocity_psd)


def level_noise_ratios(tilt_gain: float, velocity_gain: float, gravity: float,
                       radius: float) -> tuple[float, float]:
    """The sensor noise (q_g / r, q_a / r) for which the level gains (K_beta, K_v) are optimal (module docstring).

    Parameters
    ----------
    tilt_gain : float
        K_beta, rad/s per m/s (1/m).
    velocity_gain : float
        K_v, 1/s.
    gravity, radius : float
        g (m/s^2) and R (m).

    Returns
    -------
    (float, float)
        q_g / r, rad^2 / (m/s)^2 / s^2, and q_a / r, 1/s^2: the noise only up to the velocity noise r.

    Raises
    ------
    InvalidParameter
        When no sensor noise makes the gains optimal (the return-difference condition fails).

    Examples
    --------
    >>> level_noise_ratios(0.0, 0.0, 9.8, 6.4e6)
    (0.0, 0.0)
    """
    schuler = gravity / radius
    natural = gravity * (1.0 / radius - tilt_gain)
    gyro = (natural**2 - schuler**2) / gravity**2
    accel = velocity_gain**2 - 2.0 * (natural - schuler)
    scale = max(schuler**2 / gravity**2, 1e-300)
    if gyro < -1e-12 * scale or accel < -1e-12 * max(velocity_gain**2, schuler):
        raise InvalidParameter("gain", f"K_beta = {tilt_gain:.6g} 1/m, K_v = {velocity_gain:.6g} 1/s are optimal for "
                               "no sensor noise: the return-difference condition fails (a period longer than "
                               "Schuler's, or damping below sqrt((1 - omega_s^2 / omega_n^2) / 2))")
    return max(gyro, 0.0), max(accel, 0.0)


def level_period_damping(tilt_gain: float, velocity_gain: float, gravity: float,
                         radius: float) -> tuple[float, float]:
    """Period T (s) and damping zeta of the level channel with gains (K_beta, K_v) (module docstring).

    Parameters
    ----------
    tilt_gain : float
        K_beta, rad/s per m/s (1/m; below 1 / R).
    velocity_gain : float
        K_v, 1/s.
    gravity, radius : float
        g (m/s^2) and R (m).

    Examples
    --------
    >>> round(level_period_damping(0.0, 0.0, 9.81, 6.4e6)[0] / 60, 2)   # the seed: Schuler's period, undamped
    84.58
    """
    stiffness = gravity * (1.0 / radius - tilt_gain)
    if not stiffness > 0:
        raise InvalidParameter("tilt_gain", f"K_beta = {tilt_gain:.6g} 1/m must be below 1 / R for a vertical")
    natural = math.sqrt(stiffness)
    return 2.0 * math.pi / natural, velocity_gain / (2.0 * natural)


def level_gains_from_period(period: float, damping: float, gravity: float, radius: float) -> tuple[float, float]:
    """The level gains (K_beta, K_v) of a period T and damping zeta: the inverse of :func:`level_period_damping`.

    Parameters
    ----------
    period : float
        T, s (> 0).
    damping : float
        zeta, plain number (>= 0).
    gravity, radius : float
        g (m/s^2) and R (m).

    Examples
    --------
    >>> level_gains_from_period(2 * math.pi * math.sqrt(6.4e6 / 9.81), 0.0, 9.81, 6.4e6)[1]
    0.0
    """
    if not (period > 0 and damping >= 0):
        raise InvalidParameter("period", "needs T > 0 s and zeta >= 0")
    natural = 2.0 * math.pi / period
    return 1.0 / radius - natural**2 / gravity, 2.0 * damping * natural


def _modes(closed: np.ndarray) -> tuple[float, float, float | None]:
    """Period (s) and damping of the least-damped oscillating pair, and the settling time (s; None: never)."""
    poles = np.linalg.eigvals(closed)
    pairs = poles[poles.imag > 1e-12]
    least = pairs[np.argmin(-pairs.real / np.abs(pairs))] if pairs.size else poles[0]
    decay = float(np.min(-poles.real))
    settling = SETTLING_DECREMENTS / decay if decay > 1e-15 * float(np.max(np.abs(poles))) else None
    return 2.0 * math.pi / float(abs(least.imag)), float(-least.real / abs(least)), settling


def _design(loop: VerticalLoop, K: np.ndarray, P: np.ndarray) -> dict[str, Any]:
    """One design's JSON part: its errors, gains in the source's terms, modes."""
    closed = loop.A - K @ loop.C
    if np.any(K):
        d = np.diag(loop.A) * loop.constant_bias  # the decay the model applies to a bias that stays
        bias_error = -np.linalg.solve(closed, d)
    else:
        # the undamped seed oscillates about its quasi-steady error: the centre -A^-1 B u of (24)
        u = loop.constant_bias[4:]
        bias_error = np.concatenate([-np.linalg.solve(loop.A[:4, :4], loop.A[:4, 4:] @ u), u])
    period, damping, settling = _modes(closed)
    tilt_gain, velocity_gain = float(K[1, 0]), float(K[2, 0])
    return {
        "velocity_error_sigma_m_s": float(np.sqrt((P[2, 2] + P[3, 3]) / 2)),
        "velocity_error_bias_m_s": float(np.max(np.abs(bias_error[2:4]))),
        "tilt_error_sigma_rad": float(np.sqrt((P[0, 0] + P[1, 1]) / 2)),
        "k1_over_h_per_m": 1.0 / loop.radius - tilt_gain,
        "tilt_gain_per_m": tilt_gain,
        "velocity_gain_per_s": velocity_gain,
        "drift_gain_per_m_s": float(K[5, 0]),
        "accel_bias_gain_per_s2": float(K[6, 0]),
        "period_s": period,
        "damping": damping,
        "settling_time_s": settling,
    }


@dataclass
class VerticalOptimalResult(Result):
    """The seed's undamped vertical and the velocity-aided Kalman loop for one IMU (module docstring).

    ``seed`` and ``optimal`` hold each design's ``velocity_error_sigma_m_s`` (noise part, rms of x and y:
    the seed's after ``horizon_s``, growing without bound; the optimal one's steady state), the constant-bias
    part ``velocity_error_bias_m_s``, the gains (``k1_over_h_per_m`` = k1 / H of (6) on the device's own
    velocity, ``tilt_gain_per_m`` = K_beta on the measured one, ``velocity_gain_per_s`` = K_v, the bias
    gains), the least-damped mode's ``period_s`` and ``damping`` and ``settling_time_s`` (5 / the slowest
    decay rate; None: never). ``seed_noise_ratios`` are the (q_g / r, q_a / r) for which each level design
    is optimal; ``time_varying_gain_error`` the largest relative difference between the time-varying
    filter's gain at the horizon and the steady one.
    """

    imu: str
    latitude_rad: float
    velocity_noise_m_s: float
    update_interval_s: float
    horizon_s: float
    seed: dict
    optimal: dict
    noise_ratios: dict
    time_varying_gain_error: float
    curves: dict = field(default_factory=dict, repr=False)

    def render(self):
        from rich.table import Table

        table = Table(title=f"Gyro vertical: the seed's design (6), (11) beside the Kalman filter ({self.imu}, "
                            f"velocity noise {self.velocity_noise_m_s:g} m/s at {self.update_interval_s:g} s)")
        for heading in ("quantity", "seed", "optimal", "unit"):
            table.add_column(heading, justify="left" if heading in ("quantity", "unit") else "right")
        rows = (("velocity error, noise (1 sigma)", "velocity_error_sigma_m_s", 1.0, "m/s"),
                ("velocity error, constant biases", "velocity_error_bias_m_s", 1.0, "m/s"),
                ("tilt error, noise (1 sigma)", "tilt_error_sigma_rad", 180 * 60 / math.pi, "arcmin"),
                ("k1 / H on the device's velocity (6)", "k1_over_h_per_m", 1.0, "1/m"),
                ("K_beta on the measured velocity", "tilt_gain_per_m", 1.0, "1/m"),
                ("K_v on the integrator", "velocity_gain_per_s", 1.0, "1/s"),
                ("period of the least-damped mode", "period_s", 1 / 60, "min"),
                ("its damping", "damping", 1.0, ""),
                ("settling time (5 / slowest decay)", "settling_time_s", 1 / 3600, "h"))
        for label, key, scale, unit in rows:
            cells = [self.seed[key], self.optimal[key]]
            table.add_row(label, *("never" if v is None else f"{v * scale:.4g}" for v in cells), unit)
        table.caption = (f"seed's noise part after {self.horizon_s / 3600:g} h (undamped: it grows); the level "
                         f"design is optimal for q_g/r = {self.noise_ratios['seed_gyro']:.3g}, q_a/r = "
                         f"{self.noise_ratios['seed_accel']:.3g} (seed)")
        return table


def optimal(imu: str | None = None, velocity_noise: float = 0.1, update_interval: float = 1.0,
            latitude: float = math.radians(60.0), duration: float = 172800.0,
            earth: str = "default") -> VerticalOptimalResult:
    """The seed's vertical (K = 0) and the steady-state Kalman loop for one IMU and velocity reference.

    Parameters
    ----------
    imu : str or None
        A grade, a TOML spec file or a recording; None: tactical.
    velocity_noise : float
        1-sigma white noise of each external velocity measurement, m/s.
    update_interval : float
        Interval of the velocity measurements, s.
    latitude : float
        phi, rad.
    duration : float
        Horizon of the seed's growing error and of the time-varying filter, s.
    earth : str
        Earth constants (:data:`schuler.core.earth.PRESETS`).

    Returns
    -------
    VerticalOptimalResult

    Examples
    --------
    >>> r = optimal("navigation", duration=86400.0)
    >>> r.optimal["velocity_error_sigma_m_s"] < r.seed["velocity_error_sigma_m_s"], r.seed["damping"]
    (True, 0.0)
    """
    if not (math.isfinite(duration) and duration >= 10 * update_interval):
        raise InvalidParameter("duration", f"must be at least 10 update intervals, got {duration!r} s")
    loop = vertical_loop(imu, velocity_noise, update_interval, latitude, earth)
    steady = steady_state_gain(loop.A, loop.C, loop.Q, loop.R)
    # logarithmic: the gain settles within minutes, the seed's error grows over days
    times = np.concatenate([[0.0], np.geomspace(update_interval, duration, 480)])
    zero = np.zeros((8, 2))
    seed_P = loop_covariance_history(loop.A, zero, loop.C, loop.Q, loop.R, loop.P0, times)
    filter_P = riccati_solution(loop.A, loop.C, loop.Q, loop.R, loop.P0, times)
    gains = filter_P @ loop.C.T @ np.linalg.inv(loop.R)
    gain_error = float(np.max(np.abs(gains[-1] - steady.gain)) / np.max(np.abs(steady.gain)))
    level = loop.Q[[1, 2], [1, 2]]
    r = float(loop.R[0, 0])
    opt_level = level_gains(float(level[0]), float(level[1]), r, loop.gravity, loop.radius)
    ratios = dict(zip(("seed_gyro", "seed_accel"), level_noise_ratios(0.0, 0.0, loop.gravity, loop.radius)))
    ratios.update(zip(("optimal_gyro", "optimal_accel"), level_noise_ratios(*opt_level, loop.gravity, loop.radius)))
    noises = np.geomspace(0.01, 10.0, 16)
    swept = [steady_state_gain(loop.A, loop.C, loop.Q, loop.R * (sigma / velocity_noise) ** 2).covariance
             for sigma in noises]
    curves = {"noise_m_s": noises, "optimal_noise_sigma": np.array([np.sqrt((P[2, 2] + P[3, 3]) / 2) for P in swept]),
              "time_s": times, "gain_velocity": gains[:, 2, 0], "gain_tilt": gains[:, 1, 0],
              "steady_velocity": float(steady.gain[2, 0]), "steady_tilt": float(steady.gain[1, 0]),
              "seed_sigma": np.sqrt((seed_P[:, 2, 2] + seed_P[:, 3, 3]) / 2),
              "filter_sigma": np.sqrt((filter_P[:, 2, 2] + filter_P[:, 3, 3]) / 2)}
    return VerticalOptimalResult(
        imu=str(imu or DEFAULT_IMU), latitude_rad=latitude, velocity_noise_m_s=velocity_noise,
        update_interval_s=update_interval, horizon_s=duration,
        seed=_design(loop, zero, seed_P[-1]), optimal=_design(loop, steady.gain, steady.covariance),
        noise_ratios=ratios, time_varying_gain_error=gain_error, curves=curves,
    )


OPTIMAL_PARAMETERS = ParameterSet((
    Parameter("imu", "", None, "IMU: a grade (navigation, tactical, industrial, consumer), a TOML spec file or a "
              f"recording (its identified terms); not set: {DEFAULT_IMU}.", kind="text"),
    Parameter("velocity_noise", "m/s", 0.1, "1-sigma white noise of each external velocity measurement (GNSS or "
              "Doppler; the default is a GNSS velocity).", minimum=0, exclusive_minimum=True, maximum=100),
    Parameter("update_interval", "s", 1.0, "Interval of the velocity measurements (the PSD is noise^2 interval).",
              minimum=1e-3, maximum=1e3),
    Parameter("latitude", "deg", 60.0, "Latitude phi (the source's example).", minimum=-90, maximum=90),
    Parameter("duration", "s", "48 h", "Horizon of the seed's growing error and of the time-varying filter.",
              minimum=60.0, maximum=30 * 86400.0),
    Parameter("earth", "", "default", "Earth constants (drozdovich: the source's).", choices=tuple(PRESETS),
              kind="choice"),
), owner="vertical optimal")
"""Options of ``schuler vertical optimal``."""


def figures(result: Result) -> dict[str, Any]:
    """The velocity error against the velocity noise (seed, optimal) and the time-varying gain, stem -> Figure.

    Parameters
    ----------
    result : Result
        What :func:`optimal` returned ({} for any other result).
    """
    if not isinstance(result, VerticalOptimalResult):
        return {}
    from matplotlib.figure import Figure

    c = result.curves
    noise = Figure(figsize=(8, 4.5))
    axis = noise.subplots()
    axis.loglog(c["noise_m_s"], c["optimal_noise_sigma"], "C0", label="Kalman loop (steady state)")
    axis.axhline(result.seed["velocity_error_sigma_m_s"], color="C3",
                 label=f"seed (6), (11): undamped, after {result.horizon_s / 3600:g} h")
    axis.plot([result.velocity_noise_m_s], [result.optimal["velocity_error_sigma_m_s"]], "ko", label="this case")
    axis.set(xlabel="velocity-measurement noise [m/s]", ylabel="velocity error, 1 sigma [m/s]",
             title=f"Gyro vertical, {result.imu} IMU: velocity error against the aiding noise")
    gain = Figure(figsize=(8, 4.5))
    left = gain.subplots()
    left.semilogx(c["time_s"][1:], c["gain_velocity"][1:] / c["steady_velocity"], "C0", label="K_v(t) / K_v")
    left.semilogx(c["time_s"][1:], c["gain_tilt"][1:] / c["steady_tilt"], "C1", label="K_beta(t) / K_beta")
    left.axhline(1.0, color="k", lw=0.8)
    left.set(xlabel="time [s]", ylabel="gain / steady-state gain",
             title="Time-varying Kalman gain converging to the steady-state one")
    for fig, ax in ((noise, axis), (gain, left)):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
    return {"vertical_optimal_noise": noise, "vertical_optimal_gain": gain}


OPTIMAL = Action(
    name="optimal",
    help="The seed's undamped vertical (6), (11) beside the steady-state Kalman loop that an external velocity "
         "allows: gains, errors, the noise for which each design is optimal.\n\n"
         "Example: schuler vertical optimal --imu navigation --velocity-noise 0.05 --json",
    function=optimal,
    parameters=OPTIMAL_PARAMETERS,
    figures=figures,
)
"""The ``optimal`` command of ``schuler vertical``."""
