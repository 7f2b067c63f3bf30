"""``schuler errors optimal``: the baro-aided vertical channel's k1, k2, k3 beside the Kalman filter's.

The project's loop (:mod:`schuler.navigation_errors.vertical_channel`, beyond Bollay (1966), who shows in
Problem 4 the divergence delta_h'' = 2 omega_s^2 delta_h + b that it cures) feeds the difference between the
indicated and the barometric height, e = delta_h - delta_h_baro, back with fixed gains k1 (1/s), k2 (1/s^2)
and, third order, k3 (1/s^3) into an estimate of the accelerometer error; ``schuler errors vertical`` puts
every pole at -1 / tau (tau = 100 s by default).

It is the steady-state Kalman-Bucy filter (spec 07, "Steady-state gains") of the error states
x = (delta_h, delta_v, b),

    delta_h' = delta_v + w_h,    delta_v' = 2 omega_s^2 delta_h + b + w_v,    b' = w_b    (third order)

measured as z = delta_h + n (the barometric height, white noise of 1-sigma ``baro_noise`` at every
``baro_interval``, PSD r = sigma^2 dt): its error x_hat - x obeys the loop's equations with the gain
K = (k1, k2, k3) (the third state's error is b_hat - b). The accelerometer's white noise N_a (velocity
random walk) drives delta_v'; its slow bias is a random walk (the loop's b_hat is an integrator), of PSD
q_b that of the IMU's Gauss-Markov bias, 2 sigma^2 / T, plus K^2 (:func:`bias_psd`). As q_b falls to 0
the optimal k3 = sqrt(q_b / r) goes to 0 (spec 07: a constant bias drives the integral gain to zero; the
Riccati equation degenerates): the constant
turn-on bias b0 and a constant barometric error are therefore added deterministically, by
:func:`schuler.navigation_errors.vertical_channel.aided_steady_state_error` (third order: the barometer's
error alone; second order, whose model has no bias state: (b0 + k2 delta_h_baro) / (k2 - 2 omega_s^2)).

The inverse map (:func:`schuler.core.steady_state.noise_ratios_for_gain`, the return-difference identity):
with a(s) = s (s^2 - 2 omega_s^2) and Delta(s) = s^3 + a1 s^2 + a2 s + a3 (a1 = k1, a2 = k2 - 2 omega_s^2,
a3 = k3), Delta(s) Delta(-s) - a(s) a(-s) = (q_h / r) s^4 - (q_v / r) s^2 + q_b / r gives

    q_h / r = a1^2 - 2 a2 - 4 omega_s^2,    q_v / r = a2^2 - 2 a1 a3 - 4 omega_s^4,    q_b / r = a3^2.

The critically damped design (all poles at -1 / tau) is thus optimal only with a height random walk
q_h / r = 3 / tau^2 - 4 omega_s^2 that no IMU has (and needs tau < sqrt(3) / (2 omega_s), 11.6 min): on a real
IMU (q_h = 0) it is not the Kalman filter of any noise; q_v / r = 3 / tau^4 - 4 omega_s^4, q_b / r = 1 / tau^6.

References
----------
R. E. Kalman and R. S. Bucy, "New results in linear filtering and prediction theory", *Trans. ASME, J. Basic
Eng.* 83(1), 1961. T. Kailath, A. H. Sayed and B. Hassibi, *Linear Estimation*, Prentice Hall, 2000, ch. 16.
R. W. Bollay, "The story of 84 minutes", 1966 (Problem 4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from schuler.alignment.gyrocompass import SETTLING_DECREMENTS
from schuler.contract import Action
from schuler.core.steady_state import (
    loop_error_covariance,
    noise_ratios_for_gain,
    riccati_solution,
    steady_state_gain,
)
from schuler.exceptions import InvalidParameter
from schuler.imu.error_model import GAUSS_MARKOV_PEAK, SensorErrors, gauss_markov_for_bias_instability
from schuler.imu.instrument import resolve_model
from schuler.navigation_errors.actions import loop_gains
from schuler.navigation_errors.inputs import EARTH_PARAMETERS, earth_constants
from schuler.navigation_errors.vertical_channel import BaroLoopGains, aided_steady_state_error
from schuler.params import Parameter, ParameterSet
from schuler.results import Result

DEFAULT_IMU = "tactical"
"""The IMU when ``--imu`` is not given."""

INITIAL_VELOCITY_SIGMA = 0.1
"""1-sigma vertical-velocity error when the time-varying filter starts, m/s (a vehicle at rest, roughly levelled)."""

VERTICAL_AXIS = 2
"""The body axis of the vertical accelerometer (z, down; its bias magnitude serves the up axis)."""


def bias_psd(errors: SensorErrors, axis: int) -> float:
    """PSD of the random walk that stands for one accelerometer's slow bias, (m/s^2)^2/s (module docstring).

    A published Gauss-Markov bias (sigma, T) or the one of a bias instability B (the same Allan-deviation
    peak, :func:`schuler.imu.error_model.gauss_markov_for_bias_instability`, peak at the top of the flicker
    range, T = tau_max / 1.893) has PSD 2 sigma^2 / T; a rate random walk K adds K^2.

    Parameters
    ----------
    errors : SensorErrors
        The accelerometer triad's errors, SI.
    axis : int
        Body axis index, 0 x, 1 y, 2 z.

    Examples
    --------
    >>> from schuler.imu.spec import preset
    >>> f"{bias_psd(preset('tactical').accel, 2):.3g}"
    '1.06e-09'
    """
    if errors.gm_sigma[axis] > 0:
        sigma, time = float(errors.gm_sigma[axis]), float(errors.gm_correlation_time_s[axis])
    else:
        sigma = gauss_markov_for_bias_instability(float(errors.bias_instability[axis]))
        time = errors.flicker_tau_range_s[1] / GAUSS_MARKOV_PEAK[0]
    return 2.0 * sigma**2 / time + float(errors.rate_random_walk[axis]) ** 2


@dataclass(frozen=True)
class BaroLoop:
    """The baro-aided channel's linear model (module docstring), SI.

    Attributes
    ----------
    A, C, Q, R : ndarray
        x' = A x + w (PSD Q), z = C x + v (PSD R); states (delta_h, delta_v[, b]).
    accel_bias : float
        The constant turn-on bias b0 at +1 sigma, m/s^2.
    radius, gravity : float
        R (m) and g0 (m/s^2).
    """

    A: np.ndarray
    C: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    accel_bias: float
    radius: float
    gravity: float


def baro_loop(imu: str | None, baro_noise: float, baro_interval: float, order: int, radius: float,
              gravity: float) -> BaroLoop:
    """The model of the module docstring for an IMU and a barometer.

    Parameters
    ----------
    imu : str or None
        A grade, a TOML spec file or a recording (:func:`schuler.imu.instrument.resolve_model`); None: tactical.
    baro_noise : float
        1-sigma white noise of each barometric height, m (> 0).
    baro_interval : float
        Interval of the barometric heights, s (> 0): the PSD is baro_noise^2 baro_interval.
    order : {2, 3}
        3: with the bias state; 2: without (the bias is constant).
    radius, gravity : float
        R (m) and g0 (m/s^2).

    Examples
    --------
    >>> loop = baro_loop("navigation", 1.0, 1.0, 3, 6.371e6, 9.80665)
    >>> loop.A.shape, f"{loop.Q[1, 1]:.3g}"
    ((3, 3), '9.62e-09')
    """
    for name, value in (("baro_noise", baro_noise), ("baro_interval", baro_interval)):
        if not (math.isfinite(value) and value > 0):
            raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    if order not in (2, 3):
        raise InvalidParameter("order", f"must be 2 or 3, got {order!r}")
    accel = resolve_model(imu or DEFAULT_IMU).accel
    omega_squared = gravity / radius
    A = np.array([[0.0, 1.0, 0.0], [2.0 * omega_squared, 0.0, 1.0], [0.0, 0.0, 0.0]])
    Q = np.diag([0.0, float(accel.random_walk[VERTICAL_AXIS]) ** 2, bias_psd(accel, VERTICAL_AXIS)])
    C = np.array([[1.0, 0.0, 0.0]])
    n = order
    return BaroLoop(A[:n, :n], C[:, :n], Q[:n, :n], np.array([[baro_noise**2 * baro_interval]]),
                    float(accel.bias[VERTICAL_AXIS]), radius, gravity)


def _design(loop: BaroLoop, gains: BaroLoopGains, baro_bias: float) -> dict[str, Any]:
    """One design's JSON part: gains, height errors (noise and constant biases), poles, settling time."""
    n = loop.A.shape[0]
    K = np.array([gains.k1, gains.k2, gains.k3])[:n, None]
    P = loop_error_covariance(loop.A, K, loop.C, loop.Q, loop.R)
    poles = np.linalg.eigvals(loop.A - K @ loop.C)
    try:
        ratios = noise_ratios_for_gain(loop.A, loop.C, K, np.eye(n)).tolist()
    except InvalidParameter:
        ratios = None
    return {
        "k1_per_s": gains.k1, "k2_per_s2": gains.k2, "k3_per_s3": gains.k3,
        "height_error_sigma_m": float(np.sqrt(P[0, 0])),
        "velocity_error_sigma_m_s": float(np.sqrt(P[1, 1])),
        "height_error_bias_m": float(aided_steady_state_error(gains, loop.accel_bias, baro_bias, loop.radius,
                                                              loop.gravity)),
        "settling_time_s": SETTLING_DECREMENTS / float(np.min(-poles.real)),
        "poles_real_per_s": poles.real.tolist(), "poles_imag_rad_s": poles.imag.tolist(),
        # q_h / r, q_v / r (, q_b / r) for which these gains are optimal; None: for no noise
        "optimal_for_noise_ratios": ratios,
    }


@dataclass
class ErrorsOptimalResult(Result):
    """The baro loop's seed gains (critically damped at tau, or given) beside the Kalman filter's.

    ``seed`` and ``optimal`` hold ``k1_per_s``, ``k2_per_s2``, ``k3_per_s3`` (as ``errors vertical`` names
    them), ``height_error_sigma_m`` (the noise part, Lyapunov), ``height_error_bias_m`` (the constant turn-on
    accelerometer bias at +1 sigma and the constant barometric error, added deterministically), the
    velocity error, ``settling_time_s`` (5 / the slowest decay rate), the poles and the noise ratios for
    which the gains are optimal (None: for none). ``time_varying_gain_error`` is the largest relative
    difference between the time-varying filter's gain at ``duration_s`` and the steady one.
    """

    imu: str
    order: int
    baro_noise_m: float
    baro_interval_s: float
    duration_s: float
    seed: dict
    optimal: dict
    time_varying_gain_error: float
    curves: dict = field(default_factory=dict, repr=False)

    def render(self):
        from rich.table import Table

        table = Table(title=f"Baro-aided vertical channel, order {self.order}: seed gains beside the Kalman "
                            f"filter ({self.imu}, barometer {self.baro_noise_m:g} m at {self.baro_interval_s:g} s)")
        for heading in ("quantity", "seed", "optimal", "unit"):
            table.add_column(heading, justify="left" if heading in ("quantity", "unit") else "right")
        for label, key, unit in (("k1", "k1_per_s", "1/s"), ("k2", "k2_per_s2", "1/s^2"), ("k3", "k3_per_s3", "1/s^3"),
                                 ("height error, noise (1 sigma)", "height_error_sigma_m", "m"),
                                 ("height error, constant biases", "height_error_bias_m", "m"),
                                 ("vertical velocity error, noise", "velocity_error_sigma_m_s", "m/s"),
                                 ("settling time (5 / slowest decay)", "settling_time_s", "s")):
            table.add_row(label, f"{self.seed[key]:.4g}", f"{self.optimal[key]:.4g}", unit)
        ratios = self.seed["optimal_for_noise_ratios"]
        table.caption = ("seed gains optimal for no noise of this model" if ratios is None else
                         "seed gains optimal for q/r = " + ", ".join(f"{q:.3g}" for q in ratios)
                         + " (height, velocity[, bias] random walks)")
        return table


OPTIMAL_PARAMETERS = ParameterSet((
    Parameter("imu", "", None, "IMU: a grade (navigation, tactical, industrial, consumer), a TOML spec file or a "
              f"recording (its identified terms); not set: {DEFAULT_IMU}.", kind="text"),
    Parameter("baro_noise", "m", 1.0, "1-sigma white noise of each barometric height.", minimum=0.0,
              exclusive_minimum=True, maximum=1e4),
    Parameter("baro_interval", "s", 1.0, "Interval of the barometric heights (the PSD is noise^2 interval).",
              minimum=1e-3, maximum=1e3),
    Parameter("order", "", 3, "Order of the loop (3: with the accelerometer-bias state).", minimum=2, maximum=3,
              kind="integer"),
    Parameter("time_constant", "s", 100.0, "The seed design: critically damped, all poles at -1/tau (gains not "
              "given explicitly).", minimum=1.0, maximum=1e6),
    Parameter("k1", "1/s", None, "Seed altitude gain (not set: from tau).", minimum=0.0, exclusive_minimum=True,
              maximum=1e3),
    Parameter("k2", "1/s^2", None, "Seed velocity gain (not set: from tau).", minimum=0.0, exclusive_minimum=True,
              maximum=1e3),
    Parameter("k3", "1/s^3", None, "Seed bias gain, third order only (not set: from tau).", minimum=0.0,
              exclusive_minimum=True, maximum=1e3),
    Parameter("baro_bias", "m", 0.0, "Constant error of the barometric height, measured - true.", minimum=-1e4,
              maximum=1e4),
    Parameter("duration", "s", 7200.0, "Time over which the time-varying gain is shown converging.", minimum=10.0,
              maximum=1e6),
    *EARTH_PARAMETERS,
), owner="errors optimal", exclusive=(("time_constant", "k1"), ("time_constant", "k2"), ("time_constant", "k3")))
"""Options of ``schuler errors optimal``."""


def optimal(*, imu: str | None = None, baro_noise: float = 1.0, baro_interval: float = 1.0, order: int = 3,
            time_constant: float = 100.0, k1: float | None = None, k2: float | None = None, k3: float | None = None,
            baro_bias: float = 0.0, duration: float = 7200.0, earth: str = "default", radius: float | None = None,
            gravity: float | None = None) -> ErrorsOptimalResult:
    """The seed's baro loop and the steady-state Kalman loop for one IMU and barometer (module docstring).

    Parameters
    ----------
    imu : str or None
        A grade, a TOML spec file or a recording; None: tactical.
    baro_noise : float
        1-sigma white noise of each barometric height, m.
    baro_interval : float
        Interval of the barometric heights, s.
    order : {2, 3}
        Order of both loops.
    time_constant : float
        tau of the seed's critically damped gains, s.
    k1, k2, k3 : float, optional
        Explicit seed gains, 1/s, 1/s^2, 1/s^3.
    baro_bias : float
        Constant barometric error, m (measured - true).
    duration : float
        Horizon of the time-varying gain, s.
    earth : str
        Earth preset (:func:`schuler.navigation_errors.inputs.earth_constants`).
    radius : float, optional
        R overriding the preset's, m.
    gravity : float, optional
        g0 overriding the preset's, m/s^2.

    Returns
    -------
    ErrorsOptimalResult

    Examples
    --------
    >>> r = optimal(imu="navigation")
    >>> r.optimal["height_error_sigma_m"] <= r.seed["height_error_sigma_m"]
    True
    """
    R, g = earth_constants(earth, radius, gravity)
    seed_gains = loop_gains(order, time_constant, k1, k2, k3, R, g)
    loop = baro_loop(imu, baro_noise, baro_interval, order, R, g)
    steady = steady_state_gain(loop.A, loop.C, loop.Q, loop.R)
    K = steady.gain[:, 0]
    optimal_gains = BaroLoopGains(float(K[0]), float(K[1]), float(K[2]) if order == 3 else 0.0, order)
    times = np.concatenate([[0.0], np.geomspace(baro_interval, duration, 400)])
    # the filter starts knowing the height to the barometer's noise, the rest from the IMU's figures
    P0 = np.diag([baro_noise**2, INITIAL_VELOCITY_SIGMA**2, loop.accel_bias**2][:order])
    gains = riccati_solution(loop.A, loop.C, loop.Q, loop.R, P0, times)[:, :, 0] / loop.R[0, 0]
    error = float(np.max(np.abs(gains[-1] - K) / np.abs(K)))
    noises = np.geomspace(0.1, 30.0, 16)
    scaled = [replace(loop, R=loop.R * (sigma / baro_noise) ** 2) for sigma in noises]
    seed_K = np.array([seed_gains.k1, seed_gains.k2, seed_gains.k3])[:order, None]
    sweep = {"noise_m": noises,
             "seed": np.array([loop_error_covariance(m.A, seed_K, m.C, m.Q, m.R)[0, 0] for m in scaled]) ** 0.5,
             "optimal": np.array([steady_state_gain(m.A, m.C, m.Q, m.R).covariance[0, 0] for m in scaled]) ** 0.5}
    return ErrorsOptimalResult(
        imu=str(imu or DEFAULT_IMU), order=order, baro_noise_m=baro_noise, baro_interval_s=baro_interval,
        duration_s=duration, seed=_design(loop, seed_gains, baro_bias), optimal=_design(loop, optimal_gains, baro_bias),
        time_varying_gain_error=error, curves={"time_s": times, "gains": gains, "steady": K, **sweep},
    )


def figures(result: Result) -> dict[str, Any]:
    """The height error against the barometer's noise (seed, optimal) and the time-varying gains, stem -> Figure.

    Parameters
    ----------
    result : Result
        What :func:`optimal` returned ({} for any other result).
    """
    if not isinstance(result, ErrorsOptimalResult):
        return {}
    from matplotlib.figure import Figure

    c = result.curves
    noise = Figure(figsize=(8, 4.5))
    axis = noise.subplots()
    axis.loglog(c["noise_m"], c["seed"], "C3", label="seed gains")
    axis.loglog(c["noise_m"], c["optimal"], "C0", label="Kalman gains for each noise")
    axis.plot([result.baro_noise_m], [result.optimal["height_error_sigma_m"]], "ko", label="this case")
    axis.set(xlabel="barometer noise [m]", ylabel="height error, 1 sigma [m]",
             title=f"Baro-aided vertical channel, {result.imu} IMU: height error against the barometer's noise")
    gain = Figure(figsize=(8, 4.5))
    lower = gain.subplots()
    for index in range(result.order):
        lower.semilogx(c["time_s"][1:], c["gains"][1:, index] / c["steady"][index], f"C{index}",
                       label=f"k{index + 1}(t) / k{index + 1}")
    lower.axhline(1.0, color="k", lw=0.8)
    lower.set(xlabel="time [s]", ylabel="gain / steady-state gain", title="Time-varying gains converging")
    for fig, ax in ((noise, axis), (gain, lower)):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
    return {"errors_optimal_noise": noise, "errors_optimal_gain": gain}


OPTIMAL = Action(
    "optimal", "The baro loop's k1, k2, k3 beside the steady-state Kalman gains for an IMU and a barometer.\n\n"
    "Height errors (noise part from the Lyapunov equation, constant biases apart), settling times, the noise for "
    "which the seed's gains are optimal. Example: schuler errors optimal --imu navigation --baro-noise 0.5 --json",
    optimal, OPTIMAL_PARAMETERS, figures=figures)
"""The ``optimal`` command of ``schuler errors``."""
