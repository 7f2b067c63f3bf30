"""Quasi-steady velocity error (28)/(29), the split Schuler modes, and their identification.

Equation numbers are those of Drozdovich (1959) (:data:`schuler.references.DROZDOVICH_1959`);
frames and signs are the model's (:mod:`schuler.gyro_vertical.model`).

Closed forms (all vectorised over arrays of cases):

* :func:`steady_errors`: the slowly-varying approximation of (29) at a point of the
  path, beta_r = W*_x / g, alpha_r = -W*_y / g, Delta v_x = R omega_2 alpha_r,
  Delta v_y = R omega_2 beta_r, generalised to sensor biases and drifts.
* :func:`split_schuler_frequencies`: the modes of (27) with omega_2' = 0. With
  z = eta + i xi (eta, xi the variations of beta, alpha), z'' - i omega_2 z' +
  (g/R) z = 0, so the Schuler frequency splits into
  sqrt(g/R + omega_2^2/4) +- omega_2/2 and the two modes beat with the Foucault
  period 2 pi / omega_2. There is no 24-hour mode.
* :func:`tilt_oscillation`: the exact response to an initial tilt beta_0 (22)/(23).

Along a great circle the forcing and omega_2 change slowly, and
:func:`quasi_steady_response` builds the forced motion (26) by the adiabatic
expansion x_r = -A^-1 w + A^-1 d/dt(-A^-1 w) of the error model
x' = A(t) x + w(t), then evaluates (29) with the derivatives of the tilts.

The oscillation about the forced motion is identified from a simulation by
:func:`velocity_error_spectrum` (FFT of the complex error u = Delta v_x - i
Delta v_y, where the two split modes fall on opposite sides of zero frequency)
and refined by :func:`fit_modes` (non-linear least squares on the frequencies).

Examples
--------
>>> w_fast, w_slow = split_schuler_frequencies(9.81, 6.4e6, 7.3e-5 * np.sin(np.radians(60)))
>>> round(float(2 * np.pi / w_fast / 60), 2), round(float(2 * np.pi / w_slow / 60), 2)
(82.45, 86.77)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from schuler.core.geometry import uniform_step
from schuler.exceptions import InvalidParameter
from schuler.gyro_vertical.model import GyroVertical, error_state_space
from schuler.gyro_vertical.trajectory import transport_coriolis_acceleration


def steady_errors(W_star_x, W_star_y, omega_2, gravity, radius, accelerometer_bias=(0.0, 0.0),
                  gyro_drift=(0.0, 0.0), schuler_tuning=1.0) -> dict:
    """Steady tilts and velocity errors for constant forcing (slowly-varying (29)).

    Parameters
    ----------
    W_star_x, W_star_y : float or ndarray
        Transport + Coriolis acceleration W* (21) acting on the accelerometers, m/s^2.
    omega_2 : float or ndarray
        Vertical Earth rate Omega sin phi, rad/s.
    gravity : float or ndarray
        g, m/s^2.
    radius : float or ndarray
        R, m.
    accelerometer_bias : pair of float or ndarray
        (b_x, b_y), m/s^2.
    gyro_drift : pair of float or ndarray
        (eps_x, eps_y), rad/s.
    schuler_tuning : float
        kappa = k R / H, dimensionless.

    Returns
    -------
    dict
        ``alpha_r``, ``beta_r`` (rad), ``dv_x``, ``dv_y`` (m/s): beta_r = (W*_x + b_x)/g,
        alpha_r = -(W*_y + b_y)/g, Delta v_x = R (omega_2 alpha_r - eps_y)/kappa,
        Delta v_y = R (omega_2 beta_r + eps_x)/kappa.

    Examples
    --------
    >>> e = steady_errors(0.013504, 0.0, 7.3e-5 * np.sin(np.radians(60)), 9.81, 6.4e6)
    >>> round(float(e["beta_r"]), 6), round(float(e["dv_y"]), 3)
    (0.001377, 0.557)
    """
    beta_r = (np.asarray(W_star_x) + accelerometer_bias[0]) / gravity
    alpha_r = -(np.asarray(W_star_y) + accelerometer_bias[1]) / gravity
    dv_x = radius * (omega_2 * alpha_r - gyro_drift[1]) / schuler_tuning
    dv_y = radius * (omega_2 * beta_r + gyro_drift[0]) / schuler_tuning
    return {"alpha_r": alpha_r, "beta_r": beta_r, "dv_x": dv_x, "dv_y": dv_y}


def split_schuler_frequencies(gravity, radius, omega_2, schuler_tuning=1.0):
    """Angular frequencies of the two split Schuler modes, rad/s.

    Parameters
    ----------
    gravity : float or ndarray
        g, m/s^2.
    radius : float or ndarray
        R, m.
    omega_2 : float or ndarray
        Vertical Earth rate, rad/s.
    schuler_tuning : float
        kappa, dimensionless; the loop frequency is sqrt(kappa g / R).

    Returns
    -------
    fast, slow : ndarray
        sqrt(kappa g/R + omega_2^2/4) + |omega_2|/2 and the same minus |omega_2|/2.
        Their difference |omega_2| is the beat (Foucault) frequency.
    """
    centre = np.sqrt(schuler_tuning * np.asarray(gravity) / radius + np.asarray(omega_2) ** 2 / 4.0)
    half = np.abs(omega_2) / 2.0
    return centre + half, centre - half


def mode_frequencies(system) -> np.ndarray:
    """Oscillation frequencies (rad/s) of a state-space model, from its eigenvalues.

    Returns the distinct positive imaginary parts, fastest first, shape (n_modes,)
    or (N, n_modes) for a batch.

    Parameters
    ----------
    system : StateSpace
        A model or a batch of models (1/s).

    Examples
    --------
    >>> from schuler.gyro_vertical.model import error_state_space
    >>> w = mode_frequencies(error_state_space(0.0, 9.81, 6.4e6))
    >>> round(float(2 * np.pi / w[0]), 1)
    5075.0
    """
    imaginary = np.sort(np.abs(np.imag(system.eigenvalues())), axis=-1)[..., ::-1]
    return imaginary[..., ::2]


def tilt_oscillation(beta_0, time, gravity, radius, omega_2=0.0):
    """Exact oscillation error after an initial tilt beta_0 (alpha_0 = 0, Delta v(0) = 0).

    Solves (24) without forcing. With z = beta + i alpha the solution is
    z = a e^{i w+ t} + b e^{-i w- t}, a = beta_0 w+/(2 W'), b = beta_0 w-/(2 W'),
    W' = sqrt(g/R + omega_2^2/4), and Delta v_x - i Delta v_y = R (z' - i omega_2 z).
    For omega_2 = 0 this is beta = beta_0 cos(sqrt(g/R) t) (22) and
    Delta v_x = -beta_0 sqrt(g R) sin(sqrt(g/R) t): eq. (23) with the sign of (28)
    (the source writes the magnitude). The largest |Delta v| is
    beta_0 sqrt(g R) sqrt(g/R) / W', within (omega_2/2)^2 R/g of beta_0 sqrt(g R).

    Parameters
    ----------
    beta_0 : float
        Initial tilt about y, rad.
    time : ndarray
        s.
    gravity, radius : float
        g (m/s^2), R (m).
    omega_2 : float
        Vertical Earth rate, rad/s.

    Returns
    -------
    alpha, beta, dv_x, dv_y : ndarray
        rad, rad, m/s, m/s.

    Examples
    --------
    >>> t = np.array([0.0, 5075.0 / 4])
    >>> _, beta, dv_x, _ = tilt_oscillation(1e-4, t, 9.81, 6.4e6)
    >>> round(float(dv_x[1]), 4), round(float(-1e-4 * np.sqrt(9.81 * 6.4e6)), 4)
    (-0.7924, -0.7924)
    """
    t = np.asarray(time, dtype=float)
    fast, slow = split_schuler_frequencies(gravity, radius, abs(omega_2))
    centre = (fast + slow) / 2.0
    if omega_2 < 0:  # the mode structure mirrors: z'' - i omega_2 z' with omega_2 < 0
        fast, slow = slow, fast
    a, b = beta_0 * fast / (2 * centre), beta_0 * slow / (2 * centre)
    z = a * np.exp(1j * fast * t) + b * np.exp(-1j * slow * t)
    z_dot = 1j * fast * a * np.exp(1j * fast * t) - 1j * slow * b * np.exp(-1j * slow * t)
    u = radius * (z_dot - 1j * omega_2 * z)
    return z.imag, z.real, u.real, -u.imag


@dataclass(frozen=True)
class QuasiSteady:
    """Forced (quasi-steady) motion of the vertical along its path (arrays over time).

    Attributes
    ----------
    time : s. alpha_r, beta_r : forced tilts (26), rad.
    dv_x, dv_y : quasi-steady velocity errors by (29) with the tilt rates, m/s.
    slow_dv_x, slow_dv_y : the slowly-varying approximation R omega_2 (alpha_r, beta_r), m/s.
    W_star_x, W_star_y : transport + Coriolis acceleration (21), m/s^2.
    """

    time: np.ndarray
    alpha_r: np.ndarray
    beta_r: np.ndarray
    dv_x: np.ndarray
    dv_y: np.ndarray
    slow_dv_x: np.ndarray
    slow_dv_y: np.ndarray
    W_star_x: np.ndarray
    W_star_y: np.ndarray


def _solve_error_matrix(omega_2, gravity, radius, kappa, y):
    """Solve A x = y for the error model's A (see model.error_state_space), vectorised."""
    k = kappa / radius
    beta = -y[2] / gravity
    alpha = y[3] / gravity
    dv_y = (omega_2 * beta - y[0]) / k
    dv_x = (y[1] + omega_2 * alpha) / k
    return np.array([alpha, beta, dv_x, dv_y])


def quasi_steady_response(vertical: GyroVertical, time) -> QuasiSteady:
    """Forced motion (26) and the quasi-steady velocity error (29) along the path.

    The forced motion of x' = A(omega_2(t)) x + w(t) is taken to first order in
    the slowness of the path, x_r = x_0 + A^-1 x_0' with x_0 = -A^-1 w; the
    velocity errors then follow from (29), generalised to drift and gain:
    Delta v_x = R (beta_r' + omega_2 alpha_r - eps_y)/kappa,
    Delta v_y = R (omega_2 beta_r - alpha_r' + eps_x)/kappa.

    Parameters
    ----------
    vertical : GyroVertical
    time : ndarray
        s; fine enough to differentiate the forcing (the tilts change over hours).

    Returns
    -------
    QuasiSteady

    Examples
    --------
    >>> from schuler.gyro_vertical.trajectory import GreatCircleTrajectory
    >>> path = GreatCircleTrajectory.from_source(np.radians(60), 10.0, frozen=True)
    >>> q = quasi_steady_response(GyroVertical(path, 9.81), np.linspace(0, 3600, 5))
    >>> round(float(q.dv_y[0]), 3), round(float(q.beta_r[0]), 6)
    (0.557, 0.001377)
    """
    t = np.asarray(time, dtype=float)
    kin = vertical.trajectory.kinematics(t)
    omega_2 = np.broadcast_to(kin.omega_2, t.shape)
    g, R, kappa = vertical.gravity, vertical.radius, vertical.schuler_tuning
    f_x, f_y, e_x, e_y = (np.broadcast_to(x, t.shape) for x in vertical.forcing(kin))
    x_0 = _solve_error_matrix(omega_2, g, R, kappa, -np.array([e_x, e_y, f_x, f_y]))
    x_1 = _solve_error_matrix(omega_2, g, R, kappa, np.gradient(x_0, t, axis=1))
    alpha_r, beta_r = x_0[0] + x_1[0], x_0[1] + x_1[1]
    dv_x = R * (np.gradient(beta_r, t) + omega_2 * alpha_r - e_y) / kappa
    dv_y = R * (omega_2 * beta_r - np.gradient(alpha_r, t) + e_x) / kappa
    W_x, W_y = transport_coriolis_acceleration(kin, R)
    return QuasiSteady(t, alpha_r, beta_r, dv_x, dv_y, x_0[2], x_0[3], np.broadcast_to(W_x, t.shape),
                       np.broadcast_to(W_y, t.shape))


@dataclass(frozen=True)
class Spectrum:
    """Amplitude spectrum of the complex velocity error u = Delta v_x - i Delta v_y.

    Attributes
    ----------
    frequency : signed frequency, Hz (positive: u turns from x0 toward -y0).
    amplitude : amplitude of the line at each frequency, m/s (Hann window, corrected).
    """

    frequency: np.ndarray
    amplitude: np.ndarray

    def peak(self, sign: int) -> float:
        """Frequency (Hz) of the strongest line on the positive (+1) or negative (-1) side.

        Parameters
        ----------
        sign : {1, -1}
        """
        side = self.frequency * sign > 0
        return float(self.frequency[side][np.argmax(self.amplitude[side])])

    def amplitude_at(self, frequency: float) -> float:
        """Amplitude (m/s) of the bin nearest ``frequency`` (Hz).

        Parameters
        ----------
        frequency : float
            Frequency, Hz.
        """
        return float(self.amplitude[np.argmin(np.abs(self.frequency - frequency))])


def velocity_error_spectrum(time, dv_x, dv_y, padding: int = 8) -> Spectrum:
    """Hann-windowed, zero-padded FFT of u = Delta v_x - i Delta v_y (mean removed).

    The two split Schuler modes appear as one line at +w+/(2 pi) and one at
    -w-/(2 pi): they separate even when the record is shorter than their beat.

    Parameters
    ----------
    time : ndarray
        Uniformly spaced, s.
    dv_x, dv_y : ndarray
        Velocity error components (usually minus the quasi-steady part), m/s.
    padding : int
        Zero-padding factor (interpolates the spectrum).
    """
    t = np.asarray(time, dtype=float)
    step = uniform_step(t)
    if t.size < 8 or step is None:
        raise InvalidParameter("time", "the spectrum needs at least 8 uniformly spaced samples")
    u = np.asarray(dv_x) - 1j * np.asarray(dv_y)
    u = u - u.mean()
    window = np.hanning(t.size)
    n_fft = padding * t.size
    values = np.fft.fftshift(np.fft.fft(u * window, n_fft))
    frequency = np.fft.fftshift(np.fft.fftfreq(n_fft, step))
    return Spectrum(frequency, np.abs(values) / window.sum())


@dataclass(frozen=True)
class ModeFit:
    """Complex exponentials fitted to u = Delta v_x - i Delta v_y.

    Attributes
    ----------
    frequencies : signed angular frequencies of the modes, rad/s.
    amplitudes : |complex amplitude| of each mode, m/s.
    offset : complex constant, m/s. rms_residual : m/s.
    """

    frequencies: np.ndarray
    amplitudes: np.ndarray
    offset: complex
    rms_residual: float

    @property
    def periods(self) -> np.ndarray:
        """Periods of the modes, s."""
        return 2.0 * np.pi / np.abs(self.frequencies)


def fit_modes(time, dv_x, dv_y, guesses, max_samples: int = 20000) -> ModeFit:
    """Fit u(t) = c + sum_j a_j exp(i w_j t) by variable projection.

    The amplitudes enter linearly and are solved for at each trial of the
    frequencies, which are refined by :func:`scipy.optimize.least_squares`.

    Parameters
    ----------
    time : ndarray
        s.
    dv_x, dv_y : ndarray
        m/s.
    guesses : sequence of float
        Signed angular frequencies to start from, rad/s (e.g. spectral peaks).
    max_samples : int
        Longer records are decimated to about this many samples.

    Examples
    --------
    >>> t = np.arange(0.0, 20000.0, 20.0)
    >>> u = 0.5 * np.exp(1.27e-3j * t) + 0.3 * np.exp(-1.21e-3j * t)
    >>> fit = fit_modes(t, u.real, -u.imag, [1.26e-3, -1.22e-3])
    >>> fit.frequencies.round(8).tolist(), fit.amplitudes.round(6).tolist()
    ([0.00127, -0.00121], [0.5, 0.3])
    """
    t = np.asarray(time, dtype=float)
    stride = max(1, t.size // max_samples)
    t = t[::stride]
    u = (np.asarray(dv_x) - 1j * np.asarray(dv_y))[::stride]
    origin = t[0]
    tau = t - origin
    # the unknowns are the phases w T accumulated over the record (order 100 rad), well scaled
    record = tau[-1] if tau[-1] > 0 else 1.0

    def basis(w):
        return np.column_stack([np.ones_like(tau), np.exp(1j * np.outer(tau, w))])

    def residual(x):
        M = basis(x / record)
        coef = np.linalg.lstsq(M, u, rcond=None)[0]
        r = M @ coef - u
        return np.concatenate([r.real, r.imag])

    guesses = np.asarray(guesses, dtype=float)
    solution = least_squares(residual, guesses * record, xtol=1e-12, ftol=1e-12, gtol=1e-12)
    w = solution.x / record
    coef = np.linalg.lstsq(basis(w), u, rcond=None)[0]
    rms = float(np.sqrt(np.mean(solution.fun**2) * 2))
    return ModeFit(w, np.abs(coef[1:]), complex(coef[0]), rms)


@dataclass(frozen=True)
class Analysis:
    """A simulation with its forced motion, the oscillation about it, and the modes found.

    Attributes
    ----------
    response : VerticalResponse
    quasi_steady : QuasiSteady
    spectrum : Spectrum or None
        Of the oscillation (simulation minus forced motion); None for short or coarsely sampled records.
    fit : ModeFit or None
        The two split Schuler modes fitted to the oscillation; None when there is no
        oscillation to speak of, the record is shorter than two Schuler periods, or
        its output step is not below half the faster period (the modes would alias).
    eigen_periods : ndarray
        Periods (s) of the error model's modes at the mean omega_2, fastest first.
    """

    response: object
    quasi_steady: QuasiSteady
    spectrum: Spectrum | None
    fit: ModeFit | None
    eigen_periods: np.ndarray

    @property
    def oscillation(self):
        """(Delta v_x, Delta v_y) minus the quasi-steady error (29), m/s."""
        r, q = self.response, self.quasi_steady
        return r.velocity_error_x - q.dv_x, r.velocity_error_y - q.dv_y


def analyse(vertical: GyroVertical, time, method: str = "auto") -> Analysis:
    """Simulate ``vertical`` on ``time`` (s) and identify the oscillation modes of its velocity error.

    The spectrum's strongest line on each side of zero frequency seeds
    :func:`fit_modes` (with records under six Schuler periods the model's
    eigenfrequencies seed it instead, the FFT being too coarse).

    Parameters
    ----------
    vertical : GyroVertical
        The instrument on its trajectory.
    time : ndarray
        Times, s.
    method : str
        Simulation method: ``"auto"``, ``"exact"`` or a ``solve_ivp`` method.

    """
    return analyse_response(vertical, vertical.simulate(time, method=method))


def analyse_response(vertical: GyroVertical, response, fit_modes_too: bool = True) -> Analysis:
    """The forced motion, spectrum and (with ``fit_modes_too``) fitted modes of a simulation of ``vertical``.

    Parameters
    ----------
    vertical : GyroVertical
        The instrument on its trajectory.
    response : VerticalResponse
        Its simulation (times s, tilts rad, velocities m/s).
    fit_modes_too : bool
        Fit the two split Schuler modes (figures need only the spectrum: False).
    """
    t = response.time
    q = quasi_steady_response(vertical, t)
    omega_2 = float(np.mean(np.broadcast_to(vertical.trajectory.kinematics(t).omega_2, t.shape)))
    system = error_state_space(omega_2, vertical.gravity, vertical.radius, vertical.schuler_tuning)
    eigen = mode_frequencies(system)
    periods = 2 * np.pi / eigen
    ox, oy = Analysis(response, q, None, None, periods).oscillation
    uniform = uniform_step(t) is not None
    # the modes are seen only in a record of two slow periods sampled below half the fast one (no aliasing)
    resolved = t.size >= 8 and np.max(np.diff(t)) < periods[0] / 2 and t[-1] >= 2 * periods[-1]
    spectrum = velocity_error_spectrum(t, ox, oy) if uniform and resolved else None
    fit = None
    moving = np.sqrt(np.mean(ox**2 + oy**2)) > 1e-9
    if fit_modes_too and moving and resolved:
        # sign of each mode on the complex axis: the fast one turns with omega_2
        signs = (1, -1) if omega_2 >= 0 else (-1, 1)
        guesses = [s * w for s, w in zip(signs, eigen)]
        if spectrum is not None and t[-1] >= 6 * periods[-1]:
            guesses = [2 * np.pi * spectrum.peak(s) for s in signs]
        fit = fit_modes(t, ox, oy, guesses)
    return Analysis(response, q, spectrum, fit, periods)
