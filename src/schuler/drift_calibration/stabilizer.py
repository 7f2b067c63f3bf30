"""Single-axis gyrostabilizer (source's Fig. 3) during one alternating-pulse measurement cycle.

Frame and signs (used throughout :mod:`schuler.drift_calibration`)
------------------------------------------------------------------
The channel is the platform's output axis OX. ``alpha`` is the angle of the
platform relative to the base about +X (right-hand rule); the command angle
sensor (KDU, gain ``k1`` in V/rad) gives ``U = K1 (1 + kappa) (alpha - theta_b + n)``
where ``theta_b`` is the base's own sway angle about X, ``kappa`` the scale
error and ``n`` the sensor noise. A positive torquer current precesses the
platform about +X. With ``rate = omega_dX + omega_X0`` (own drift plus the
apparent drift, see :mod:`schuler.drift_calibration.procedure`) the platform
obeys the source's (5) and (8):

    d alpha / dt = omega_dX + omega_X0 + (K_M / H) i(t).

Cycle: at t0 = 0 the integrator is zeroed, the generator makes the pulse
``+i(t)`` on [0, tau] while the switch feeds U to the adding input; then
``-(1 + epsilon) i(t - tau)`` with U on the subtracting input, the generator's
gate (current and switch) staying open for tau_2 = (1 + delta) tau, the current
holding its final value over the extra delta tau (for a rectangular pulse this
is exactly a pulse of duration tau_2). The integrator output at the end is the
reading Delta U of (11); for ideal electronics and ``delta = epsilon = 0``

    Delta U = -K1 (omega_dX + omega_X0) tau^2 + K1 (K_M / H) B,     (11)
    B = int_0^tau (tau - 2 t) i(t) dt,

and B = 0 for a time-symmetric pulse, so omega_dX + omega_X0 = -Delta U / (K1 tau^2) (13).

Simulation
----------
A linear state-space model on :mod:`schuler.core.lti`, simulated exactly
(matrix exponential) on a grid in normalised time u = t / D of each phase
(D = tau, then tau_2), so that members with different durations share one
grid. The pulse is piecewise linear (:mod:`schuler.drift_calibration.pulses`):
its ramp part is an integrator state driven by a held slope, its steps a held
input, and the pulse knots are grid points, so pulse edges are exact. States
(per unit u, each row scaled by the phase duration D):

    q' = slope input                     (torquer rate, ramp part, rad/s)
    beta' = D (rate + q + level)         (the gyro's reference angle, rad)
    alpha' = D (beta - alpha) / T_s      (first-order stabilization loop; alpha = beta when ideal)
    theta_b' = D thetadot_b, thetadot_b' = -D w_s^2 theta_b   (base sway)
    W' = D [s (alpha - theta_b + n) + b - W / T_L]

with switch sign s = +1 then -1, W = integrator output / (K1 (1 + kappa)) in
rad s, ``b`` the integrator's input offset (unswitched, as an angle) and
``T_L`` its leak time. Noise inputs (sensor noise, gyro angle random walk)
are held over each step with variance density / step, which reproduces the
variance of their integrals exactly.

Example
-------
>>> import numpy as np
>>> from schuler.drift_calibration.pulses import triangular
>>> stab = Stabilizer(k1=57.3, torquer_gain=0.02, angular_momentum=0.1, pulse_current=1e-3,
...                   tau=5.0, shape=triangular())
>>> out = simulate_cycle(stab, rate=np.array([1e-5]))
>>> float(-out.reading[0] / (stab.k1 * stab.tau**2)) / 1e-5   # (13)
1.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from schuler.core.lti import StateSpace, simulate
from schuler.drift_calibration.pulses import PulseShape
from schuler.exceptions import InvalidParameter

NOISE_STEPS = 40
"""Grid steps per pulse when noise is on: white noise held over each step (its integral's variance is exact)."""


def _positive(name: str, value: float, allow_zero: bool = False) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        raise InvalidParameter(name, f"must be {'>= 0' if allow_zero else '> 0'} and finite, got {value!r}")
    return value


@dataclass(frozen=True)
class Stabilizer:
    """The instrument: gyrostabilizer channel, pulse generator, sensor, integrator.

    Parameters
    ----------
    k1 : float
        Command angle sensor gain K1, V/rad (nonzero).
    torquer_gain : float
        Torque sensor (torquer) gain K_M, N m/A (> 0).
    angular_momentum : float
        Rotor angular momentum H, N m s (> 0).
    pulse_current : float
        Amplitude of the pulse current i(t), A (>= 0).
    tau : float
        Pulse duration tau, s (> 0).
    shape : PulseShape
        Normalised pulse shape.
    loop_time_constant : float
        Time constant T_s of the first-order stabilization loop, s (0 = ideal).
    integrator_leak_time : float
        Leak time constant T_L of the integrator, s (inf = ideal).
    sway_frequency : float
        Frequency of the base sway, Hz (> 0).
    """

    k1: float
    torquer_gain: float
    angular_momentum: float
    pulse_current: float
    tau: float
    shape: PulseShape
    loop_time_constant: float = 0.0
    integrator_leak_time: float = math.inf
    sway_frequency: float = 0.7

    def __post_init__(self):
        if not math.isfinite(self.k1) or self.k1 == 0.0:
            raise InvalidParameter("k1", f"the command-sensor gain K1 must be nonzero and finite, got {self.k1!r}")
        _positive("torquer_gain", self.torquer_gain)
        _positive("angular_momentum", self.angular_momentum)
        _positive("pulse_current", self.pulse_current, allow_zero=True)
        _positive("tau", self.tau)
        _positive("loop_time_constant", self.loop_time_constant, allow_zero=True)
        if not self.integrator_leak_time > 0:
            raise InvalidParameter("integrator_leak_time", f"must be > 0, got {self.integrator_leak_time!r}")
        _positive("sway_frequency", self.sway_frequency)

    @property
    def pulse_rate(self) -> float:
        """Peak torquer precession rate (K_M / H) * i_max of a unit shape, rad/s."""
        return self.torquer_gain * self.pulse_current / self.angular_momentum

    @property
    def cycle_time(self) -> float:
        """Duration of one measurement cycle (two pulses), s."""
        return 2.0 * self.tau


@dataclass(frozen=True)
class CycleOutcome:
    """The result of simulating one cycle for N members.

    Attributes
    ----------
    reading : ndarray, shape (N,)
        Integrator output Delta U at the end of the cycle, V s (the integral of U over the cycle).
    sensor_samples : ndarray, shape (N, 3)
        Command-sensor signal U at t0, t0 + tau and the end of the cycle, V
        (used by the loop-lag compensation).
    time, platform_angle, sensor_signal, integrator_output : ndarray
        Histories (time (n,) in s; the others (N, n) in rad, V, V s), empty unless requested.
    """

    reading: np.ndarray
    sensor_samples: np.ndarray
    time: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    platform_angle: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    sensor_signal: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    integrator_output: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)


def _phase_model(duration: float | np.ndarray, switch: float, lag: float, leak: float, sway_omega: float, ideal: bool):
    """Normalised-time state-space model of one phase; duration (N,) or scalar."""
    # state order: q, beta, [alpha], theta_b, thetadot_b, W ; inputs: slope, level, rate, noise, offset
    n = 5 if ideal else 6
    A = np.zeros((n, n))
    B = np.zeros((n, 5))
    i_beta = 1
    i_alpha = 1 if ideal else 2
    i_theta, i_thetadot, i_w = n - 3, n - 2, n - 1
    A[i_beta, 0] = 1.0
    B[i_beta, 1] = B[i_beta, 2] = 1.0
    if not ideal:
        A[i_alpha, i_beta] = 1.0 / lag
        A[i_alpha, i_alpha] = -1.0 / lag
    A[i_theta, i_thetadot] = 1.0
    A[i_thetadot, i_theta] = -sway_omega**2
    A[i_w, i_alpha] = switch
    A[i_w, i_theta] = -switch
    A[i_w, i_w] = -1.0 / leak if math.isfinite(leak) else 0.0
    B[i_w, 3] = switch
    B[i_w, 4] = 1.0
    duration = np.asarray(duration, dtype=float)
    scale = duration[..., None, None]
    A_norm = A * scale
    B_norm = B * scale
    B_norm[..., 0, 0] = 1.0  # the slope input is already per unit of normalised time
    return StateSpace(A_norm, B_norm), i_alpha, i_theta, i_w


def _pulse_inputs(shape: PulseShape, grid: np.ndarray, amplitude: np.ndarray, tilt: np.ndarray):
    """Held slope (per unit u) and level inputs (N, n_grid) of ``amplitude * (shape + tilt (2u - 1))``."""
    slopes = shape.slopes[None, :] + 2.0 * tilt[:, None]
    starts = shape.start_values[None, :] + tilt[:, None] * (2.0 * shape.knots[None, :-1] - 1.0)
    widths = np.diff(shape.knots)
    # continuous ramp part Q at the left knot of each segment
    ramp_at_knot = np.concatenate([np.zeros((tilt.size, 1)), np.cumsum(slopes * widths, axis=1)[:, :-1]], axis=1)
    levels = starts - ramp_at_knot
    segment = np.clip(np.searchsorted(shape.knots, grid, side="right") - 1, 0, widths.size - 1)
    return amplitude[:, None] * slopes[:, segment], amplitude[:, None] * levels[:, segment]


def _short_step(model: StateSpace, state: np.ndarray, inputs: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Exact step of per-member length with held inputs: expm by its Taylor series, scaled and squared.

    A per-member step would cost one matrix exponential per member; for the
    microsecond tails of a duration mismatch the series sum_k (L M)^k / k! of
    the augmented matrix M = [[A, B], [0, 0]] reaches rounding in a few terms.
    A longer tail is cut into 2^s equal parts whose transition is squared s times.
    """
    n, m = model.n_states, model.n_inputs
    augmented = np.zeros((n + m, n + m))
    augmented[:n, :n] = model.A
    augmented[:n, n:] = model.B
    size = np.max(np.abs(length)) * np.linalg.norm(augmented, 1)
    squarings = max(0, math.ceil(math.log2(size / 0.05))) if size > 0.05 else 0
    terms = 10  # (0.05)^11 / 11! < 1e-22: the series has converged to rounding
    powers = [np.eye(n + m)]
    for k in range(1, terms):
        powers.append(powers[-1] @ augmented / k)
    part = np.asarray(length, dtype=float) / 2.0**squarings
    transition = np.einsum("nk,kij->nij", part[:, None] ** np.arange(terms)[None, :], np.stack(powers))
    for _ in range(squarings):
        transition = transition @ transition
    extended = np.concatenate([state, inputs], axis=1)
    return np.einsum("nij,nj->ni", transition[:, :n, :], extended)


def cycle_grid(shape: PulseShape, steps: int = NOISE_STEPS) -> np.ndarray:
    """Normalised time grid of one phase when noise is on: the pulse knots and ``steps`` equal steps.

    Parameters
    ----------
    shape : PulseShape
        The pulse shape (its knots on the normalised time 0..1).
    steps : int
        Number of equal steps.

    Examples
    --------
    >>> from schuler.drift_calibration.pulses import triangular
    >>> cycle_grid(triangular(), 4)
    array([0.  , 0.25, 0.5 , 0.75, 1.  ])
    """
    return np.union1d(shape.knots, np.linspace(0.0, 1.0, steps + 1))


def simulate_cycle(
    stabilizer: Stabilizer,
    rate,
    *,
    initial_angle=0.0,
    sensor_scale_error=0.0,
    amplitude_mismatch=0.0,
    duration_mismatch=0.0,
    tilt=0.0,
    integrator_offset=0.0,
    sway_angle=0.0,
    sway_rate=0.0,
    sensor_noise_density=0.0,
    angle_random_walk=0.0,
    noise: np.ndarray | None = None,
    steps: int = NOISE_STEPS,
    keep_history: bool = False,
) -> CycleOutcome:
    """Simulate one measurement cycle (two pulses, switch, integrator) for N members at once.

    Parameters
    ----------
    stabilizer : Stabilizer
        The instrument.
    rate : array_like, shape (N,) or scalar
        omega_dX + omega_X0 (plus any tilt coupling) about +X, rad/s.
    initial_angle : array_like
        alpha at t0 (U0 = K1 alpha0), rad.
    sensor_scale_error : array_like
        kappa, relative error of K1 (dimensionless).
    amplitude_mismatch, duration_mismatch : array_like
        epsilon and delta: the second pulse is -(1 + epsilon) i, its gate open
        (1 + delta) tau with the final current held (dimensionless).
    tilt : array_like
        Pulse asymmetry: both pulses get the ramp ``tilt * (2u - 1)`` (dimensionless).
    integrator_offset : array_like
        Input offset of the integrator, as an angle of the command sensor, rad.
    sway_angle, sway_rate : array_like
        Base sway angle (rad) and rate (rad/s) about X at t0.
    sensor_noise_density : array_like
        White noise of the command sensor, rad/sqrt(Hz) (scalar or per member).
    angle_random_walk : array_like
        Gyro angle random walk, rad/sqrt(s) (scalar or per member).
    noise : ndarray, shape (N, 2, 2, S), optional
        Standard normal samples held over the S steps of each phase: ``noise[:, p, 0]``
        drives the angle random walk and ``noise[:, p, 1]`` the sensor noise of phase p;
        S = ``cycle_grid(stabilizer.shape, steps).size - 1``. Required when a noise
        density is nonzero (the caller draws them, so that they are addressed per member).
    steps : int
        Grid steps per phase when noise is on (noise-free cycles need only the pulse knots).
    keep_history : bool
        Also return the time histories (for plots).

    Returns
    -------
    CycleOutcome
    """
    arrays = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(v, dtype=float)) for v in (
            rate, initial_angle, sensor_scale_error, amplitude_mismatch, duration_mismatch, tilt,
            integrator_offset, sway_angle, sway_rate))
    )
    rate, angle0, kappa, eps, delta, tilt, offset, sway0, swayrate0 = (a.copy() for a in arrays)
    members = rate.size
    _check_duration_mismatch(delta)
    densities = np.broadcast_to(np.asarray(angle_random_walk, dtype=float), (members,)), \
        np.broadcast_to(np.asarray(sensor_noise_density, dtype=float), (members,))
    noisy = bool(np.any(densities[0] > 0.0) or np.any(densities[1] > 0.0))
    grid = cycle_grid(stabilizer.shape, steps) if noisy or keep_history else stabilizer.shape.knots
    if noisy and (noise is None or noise.shape != (members, 2, 2, grid.size - 1)):
        raise InvalidParameter("noise", f"need standard normal samples of shape ({members}, 2, 2, {grid.size - 1}) "
                                        "when a noise density is nonzero")
    ideal = stabilizer.loop_time_constant == 0.0
    omega_sway = 2.0 * math.pi * stabilizer.sway_frequency
    amplitude = np.full(members, stabilizer.pulse_rate)
    n_state = 5 if ideal else 6
    state = np.zeros((members, n_state))
    state[:, 1] = angle0
    if not ideal:
        state[:, 2] = angle0  # the loop has settled before the start: alpha = beta
    state[:, -3] = sway0
    state[:, -2] = swayrate0
    samples = np.empty((members, 3))
    history = []
    for phase, (switch, sign) in enumerate(((1.0, 1.0), (-1.0, -1.0))):
        model, i_alpha, i_theta, i_w = _phase_model(
            stabilizer.tau, switch, stabilizer.loop_time_constant, stabilizer.integrator_leak_time, omega_sway, ideal)
        gain = sign * amplitude * (1.0 if phase == 0 else (1.0 + eps))
        slope, level = _pulse_inputs(stabilizer.shape, grid, gain, tilt)
        inputs = np.zeros((members, grid.size, 5))
        inputs[:, :, 0] = slope
        inputs[:, :, 1] = level
        inputs[:, :, 2] = rate[:, None]
        inputs[:, :, 4] = offset[:, None]
        if noise is not None and noisy:
            step = np.diff(grid) * stabilizer.tau
            inputs[:, :-1, 2] += densities[0][:, None] * noise[:, phase, 0] / np.sqrt(step)
            inputs[:, :-1, 3] = densities[1][:, None] * noise[:, phase, 1] / np.sqrt(step)
        state[:, 0] = 0.0  # each pulse's ramp part starts from zero
        states = simulate(model, grid, state, input_series=inputs).states
        measured = states[:, :, i_alpha] - states[:, :, i_theta] + inputs[:, :, 3]
        signal = stabilizer.k1 * (1.0 + kappa)[:, None] * measured
        samples[:, phase] = signal[:, 0]
        if keep_history:
            history.append((phase * stabilizer.tau + grid * stabilizer.tau, states[:, :, i_alpha], signal,
                            stabilizer.k1 * (1.0 + kappa)[:, None] * states[:, :, i_w]))
        state = states[:, -1, :].copy()
        if phase == 1 and np.any(delta != 0.0):
            tail_inputs = np.zeros((members, 5))
            tail_inputs[:, 1] = inputs[:, -2, 1]  # the current keeps its final value
            tail_inputs[:, 2] = rate
            tail_inputs[:, 4] = offset
            real_time, *_ = _phase_model(1.0, switch, stabilizer.loop_time_constant,
                                         stabilizer.integrator_leak_time, omega_sway, ideal)
            state = _short_step(real_time, state, tail_inputs, stabilizer.tau * delta)
        samples[:, 2] = stabilizer.k1 * (1.0 + kappa) * (state[:, i_alpha] - state[:, i_theta]) if phase else 0.0
    reading = stabilizer.k1 * (1.0 + kappa) * state[:, -1]
    if not keep_history:
        return CycleOutcome(reading, samples)
    time, angle, signal, integral = (np.concatenate(parts, axis=-1) for parts in zip(*history))
    return CycleOutcome(reading, samples, time, angle, signal, integral)


def _check_duration_mismatch(delta: np.ndarray) -> None:
    # NaN fails the comparison too, so it is refused rather than carried into the reading
    if not np.all(1.0 + delta > 0.0):
        raise InvalidParameter("duration_mismatch", f"must be > -1 (the second pulse must last a positive time), "
                                                    f"got {float(np.min(delta)):g}")


def reading_closed_form(
    stabilizer: Stabilizer,
    rate,
    *,
    initial_angle=0.0,
    sensor_scale_error=0.0,
    amplitude_mismatch=0.0,
    duration_mismatch=0.0,
    tilt=0.0,
    integrator_offset=0.0,
    sway_angle=0.0,
    sway_rate=0.0,
):
    """Delta U in closed form for an ideal loop and a leak-free integrator, V s.

    Generalises the source's (11) to unequal pulses (phase 2 of length
    tau_2 = tau + L, L = delta tau, amplitude (1 + epsilon)), a tilted pulse top, an
    integrator offset b and base sway theta_b:

        Delta U / (K1 (1 + kappa)) = alpha0 (tau - tau_2) - rate (tau tau_2 + (tau_2^2 - tau^2) / 2)
            + R1 (tau - tau_2) - M1 + tau_2 R2 - M2 + r_end L^2 / 2 + b (tau + tau_2) - S,

    with R_k = int i_k (K_M/H) dt and M_k = int t i_k (K_M/H) dt of each pulse on
    its own time axis over [0, tau], r_end the torquer rate held over the tail L,
    and S = int_0^tau theta_b - int_tau^{tau+tau_2} theta_b.
    Parameters as in :func:`simulate_cycle` (no noise).

    Parameters
    ----------
    stabilizer : Stabilizer
        The instrument (its loop time constant and integrator leak are taken as ideal here).
    rate : array_like, shape (N,) or scalar
        omega_dX + omega_X0 (plus any tilt coupling) about +X, rad/s.
    initial_angle : array_like
        alpha0, the angle at t0, rad.
    sensor_scale_error : array_like
        kappa, relative error of K1 (dimensionless).
    amplitude_mismatch, duration_mismatch : array_like
        epsilon and delta = L / tau: the second pulse is -(1 + epsilon) i, its gate open tau_2 = (1 + delta) tau
        with the final current held (dimensionless).
    tilt : array_like
        Pulse asymmetry: both pulses get the ramp ``tilt * (2u - 1)`` (dimensionless).
    integrator_offset : array_like
        b, input offset of the integrator as an angle of the command sensor, rad.
    sway_angle, sway_rate : array_like
        Base sway angle theta_b (rad) and rate (rad/s) about X at t0.

    Returns
    -------
    numpy.ndarray
        Delta U, the integrator's reading over the cycle, V s, in the broadcast shape of the arguments.

    Raises
    ------
    InvalidParameter
        ``duration_mismatch`` not above -1 (or NaN), as in :func:`simulate_cycle`.

    Examples
    --------
    >>> from schuler.drift_calibration.pulses import rectangular
    >>> stab = Stabilizer(57.3, 0.02, 0.1, 1e-3, 5.0, rectangular())
    >>> float(reading_closed_form(stab, 1e-5) / (-57.3 * 25 * 1e-5))
    1.0
    """
    rate, angle0, kappa, eps, delta, tilt, offset, sway0, swayrate0 = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (rate, initial_angle, sensor_scale_error, amplitude_mismatch,
                                              duration_mismatch, tilt, integrator_offset, sway_angle, sway_rate)))
    _check_duration_mismatch(delta)
    tau = stabilizer.tau
    tau2 = tau * (1.0 + delta)
    area = stabilizer.shape.area()  # a tilt keeps the area
    moment = stabilizer.shape.first_moment() + tilt / 6.0  # int u * tilt (2u - 1) du = tilt / 6
    p = stabilizer.pulse_rate
    r1, m1 = p * tau * area, p * tau**2 * moment
    r2, m2 = (1.0 + eps) * p * tau * area, (1.0 + eps) * p * tau**2 * moment
    tail = tau2 - tau
    r_end = (1.0 + eps) * p * (stabilizer.shape.end_values[-1] + tilt)
    w = 2.0 * math.pi * stabilizer.sway_frequency

    def sway_integral(t):
        return sway0 * np.sin(w * t) / w - swayrate0 * np.cos(w * t) / w**2

    sway = 2.0 * sway_integral(tau) - sway_integral(0.0) - sway_integral(tau + tau2)
    per_gain = (angle0 * (tau - tau2) - rate * (tau * tau2 + 0.5 * (tau2**2 - tau**2))
                + r1 * (tau - tau2) - m1 + tau2 * r2 - m2 + 0.5 * r_end * tail**2 + offset * (tau + tau2) - sway)
    return stabilizer.k1 * (1.0 + kappa) * per_gain


def loop_lag_error_rectangular(stabilizer: Stabilizer, rate):
    """Extra Delta U of a first-order stabilization loop, rectangular pulses, V s.

    From int_a^b alpha = int_a^b beta - T_s (alpha(b) - alpha(a)) for alpha' = (beta - alpha)/T_s,
    the lag adds -K1 T_s [2 alpha(tau) - alpha(0) - alpha(2 tau)], which for a
    rectangular pulse of rate p and a drift rate w with E = exp(-tau / T_s) is

        K1 [w T_s^2 (1 - E)^2 + p T_s^2 (1 - E)^2 - 2 p T_s (tau - T_s (1 - E))].

    The pulse part is the same in both runs of the procedure: it biases omega_d
    and cancels in omega_X0; the w part scales both by 1 - (T_s/tau)^2 (1 - E)^2.

    Parameters
    ----------
    stabilizer : Stabilizer
        The instrument (SI).
    rate : float or ndarray
        w, the drift rate about the measured axis, rad/s.

    Examples
    --------
    >>> from schuler.drift_calibration.pulses import rectangular
    >>> stab = Stabilizer(1.0, 0.02, 0.1, 1e-3, 5.0, rectangular(), loop_time_constant=0.0)
    >>> float(loop_lag_error_rectangular(stab, 1e-5))
    0.0
    """
    lag = stabilizer.loop_time_constant
    tau = stabilizer.tau
    p = stabilizer.pulse_rate
    decay = math.exp(-tau / lag) if lag > 0 else 0.0
    square = lag**2 * (1.0 - decay) ** 2
    return stabilizer.k1 * (np.asarray(rate) * square + p * square - 2.0 * p * lag * (tau - lag * (1.0 - decay)))


def leak_error_initial_angle(stabilizer: Stabilizer, initial_angle):
    """Delta U from a constant sensor signal U0 = K1 alpha0 through a leaky integrator, V s.

    int_0^{2 tau} s(t) U0 exp(-(2 tau - t)/T_L) dt = -U0 T_L (1 - exp(-tau/T_L))^2;
    an ideal integrator (T_L = inf) cancels U0 exactly.

    Parameters
    ----------
    stabilizer : Stabilizer
        The instrument (SI).
    initial_angle : float or ndarray
        alpha0, the platform angle at the start of the cycle, rad.

    Examples
    --------
    >>> from schuler.drift_calibration.pulses import rectangular
    >>> stab = Stabilizer(1.0, 0.02, 0.1, 0.0, 5.0, rectangular(), integrator_leak_time=100.0)
    >>> round(float(leak_error_initial_angle(stab, 1e-3) / (-1e-3 * 25 / 100)), 2)   # ~ -U0 tau^2 / T_L
    0.9
    """
    leak = stabilizer.integrator_leak_time
    if not math.isfinite(leak):
        return np.zeros_like(np.asarray(initial_angle, dtype=float))
    return -stabilizer.k1 * np.asarray(initial_angle) * leak * (1.0 - math.exp(-stabilizer.tau / leak)) ** 2
