"""The calibration procedure: runs at several platform azimuths, drift separation, azimuth.

Frame, azimuth and signs
------------------------
Site frame ENU (x east, y north, z up); Earth rate there ``Omega (0, cos phi, sin phi)``.
Platform frame X, Y, Z, right-handed, Z up (the platform normal). The azimuth
A0 is the angle from true north to the platform's Y axis, positive clockwise
seen from above (north towards east), in [0, 2 pi): at A0 = 0 the platform
axes are east, north, up, and the X axis points to azimuth A0 + 90 deg. (In
the source's Y-up labelling our Y is its Z and our Z its Y.)

A gyro-stabilised platform keeps its inertial attitude apart from its gyros'
own drift omega_d and the torquer command; relative to the Earth it therefore
turns at the *apparent drift* (source's "kazhushchiysya ukhod")
``omega_j0 = -Omega . e_j``, which for a level platform is (3):

    omega_X0 = Omega cos(phi) sin(A0),  omega_Y0 = -Omega cos(phi) cos(A0),  omega_Z0 = -Omega sin(phi),

so that (5) holds literally: alpha_X' = omega_dX + omega_X0 + (K_M/H) i. The
source's (2)-(3) call omega_X0 the base rate while (5) adds it to the platform
rate; reading it as the apparent drift keeps (3), (5) and (13)-(16) as printed.
The command-sensor angle alpha_X is the platform's angle relative to the
base, positive about +X (:mod:`schuler.drift_calibration.stabilizer`).

A 180-degree turn about the vertical reverses omega_X0 and omega_Y0 but not the
own drifts (14), whence (15) and (16). Three-axis mode measures the X and the
Y channel (one after the other, so that one channel's pulse excursion does
not tilt the other's axis) and takes A0 = atan2(omega_X0, -omega_Y0), well
conditioned everywhere; single-axis mode has only X and A0 = asin(omega_X0 /
(Omega cos phi)), ambiguous between A0 and 180 deg - A0 and ill-conditioned
near A0 = 90 deg. With N >= 3 equally spaced positions a least-squares fit
separates drift, Omega cos(phi) sin(A0) and Omega cos(phi) cos(A0) even from one channel.

Example
-------
>>> import numpy as np
>>> wx, wy, _ = apparent_drift(np.radians(70.0), np.radians(80.0))
>>> round(float(np.degrees(azimuth_from_channels(wx, wy))), 9)
80.0
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.core.attitude import wrap_angle
from schuler.core.earth import EARTH_RATE
from schuler.drift_calibration.draws import ProcedureErrors
from schuler.drift_calibration.stabilizer import NOISE_STEPS, Stabilizer, simulate_cycle
from schuler.exceptions import InvalidParameter, NotObservable

MODES = ("three-axis", "single-axis")


def apparent_drift(latitude, azimuth, earth_rate: float = EARTH_RATE):
    """Apparent drifts (omega_X0, omega_Y0, omega_Z0) of a level platform, rad/s (source's (3)).

    Parameters
    ----------
    latitude : float or ndarray
        Latitude phi, rad.
    azimuth : float or ndarray
        Azimuth A0 of the platform Y axis, clockwise from north, rad.
    earth_rate : float
        Omega, rad/s.

    Examples
    --------
    >>> [round(float(w) / EARTH_RATE, 12) for w in apparent_drift(0.0, np.pi / 2)]
    [1.0, -0.0, -0.0]
    """
    horizontal = earth_rate * np.cos(latitude)
    vertical = earth_rate * np.sin(latitude)
    return horizontal * np.sin(azimuth), -horizontal * np.cos(azimuth), -vertical * np.ones_like(azimuth)


def rate_from_reading(reading, k1: float, tau: float):
    """omega_d + omega_0 = -Delta U / (K1 tau^2) (source's (13)), rad/s.

    Parameters
    ----------
    reading : float or ndarray
        Integrator output Delta U, V s.
    k1 : float
        Command-sensor gain K1, V/rad.
    tau : float
        Pulse duration, s.

    Examples
    --------
    >>> float(rate_from_reading(-57.3 * 25 * 1e-5, 57.3, 5.0))
    1e-05
    """
    return -np.asarray(reading) / (k1 * tau**2)


def separate_drift(reading_1, reading_2, k1: float, tau: float):
    """Own and apparent drift from the runs at A0 and A0 + 180 deg (source's (15), (16)), rad/s.

    omega_d = -(Delta U1 + Delta U2) / (2 K1 tau^2),  omega_X0 = -(Delta U1 - Delta U2) / (2 K1 tau^2).

    Parameters
    ----------
    reading_1, reading_2 : float or ndarray
        Integrator outputs Delta U at A0 and at A0 + 180 deg, V s.
    k1 : float
        Command-sensor gain K1, V/rad.
    tau : float
        Pulse duration, s.

    Examples
    --------
    >>> [float(w) for w in separate_drift(-25.0 * 3.0, -25.0 * (-1.0), 1.0, 5.0)]
    [1.0, 2.0]
    """
    total = np.asarray(reading_1) + np.asarray(reading_2)
    difference = np.asarray(reading_1) - np.asarray(reading_2)
    return -total / (2.0 * k1 * tau**2), -difference / (2.0 * k1 * tau**2)


def azimuth_from_channels(omega_x0, omega_y0):
    """A0 = atan2(omega_X0, -omega_Y0) in [0, 2 pi), rad (three-axis mode).

    The latitude drops out: only the direction of the horizontal Earth rate counts.

    Parameters
    ----------
    omega_x0, omega_y0 : float or ndarray
        Apparent drifts of the X and Y channels, rad/s.

    Examples
    --------
    >>> round(float(np.degrees(azimuth_from_channels(-1.0, 0.0))), 9)
    270.0
    """
    return np.mod(np.arctan2(omega_x0, -np.asarray(omega_y0)), 2.0 * np.pi)


def azimuth_from_single_channel(omega_x0, latitude, earth_rate: float = EARTH_RATE):
    """A0 = asin(omega_X0 / (Omega cos phi)) and its twin 180 deg - A0, rad in [0, 2 pi).

    Parameters
    ----------
    omega_x0 : float or ndarray
        Apparent drift of the X channel, rad/s.
    latitude : float or ndarray
        phi, rad.
    earth_rate : float
        Omega, rad/s.

    Returns
    -------
    principal, alternative : ndarray
        The two azimuths with that sine (principal: A0 in [-90, 90] deg).
    saturated : ndarray of bool
        Where |omega_X0| exceeded Omega cos phi (errors near A0 = 90 deg) and was clipped.

    Examples
    --------
    >>> a, b, _ = azimuth_from_single_channel(0.5 * EARTH_RATE, 0.0)
    >>> round(float(np.degrees(a)), 9), round(float(np.degrees(b)), 9)
    (30.0, 150.0)
    """
    ratio = np.asarray(omega_x0) / (earth_rate * np.cos(latitude))
    saturated = np.abs(ratio) > 1.0
    principal = np.arcsin(np.clip(ratio, -1.0, 1.0))
    return np.mod(principal, 2 * np.pi), np.mod(np.pi - principal, 2 * np.pi), saturated


def azimuth_sensitivity(azimuth, latitude, mode: str = "three-axis", earth_rate: float = EARTH_RATE):
    """|dA0 / d omega| of the azimuth to an error in one apparent-drift estimate, rad per rad/s.

    Three-axis: 1 / (Omega cos phi) whatever A0. Single-axis: 1 / (Omega cos phi |cos A0|),
    infinite at A0 = 90 deg.

    Parameters
    ----------
    azimuth : float or ndarray
        A0, rad.
    latitude : float or ndarray
        phi, rad.
    mode : {"three-axis", "single-axis"}
    earth_rate : float
        Omega, rad/s.

    Examples
    --------
    >>> s3 = azimuth_sensitivity(np.radians(80), np.radians(70), "three-axis")
    >>> s1 = azimuth_sensitivity(np.radians(80), np.radians(70), "single-axis")
    >>> round(float(s1 / s3), 3)   # 1 / cos 80 deg
    5.759
    """
    base = 1.0 / (earth_rate * np.cos(latitude))
    if mode == "three-axis":
        return base * np.ones_like(np.asarray(azimuth, dtype=float))
    with np.errstate(divide="ignore"):
        return base / np.abs(np.cos(azimuth))


def turn_angles(positions: int) -> np.ndarray:
    """Equally spaced turns 2 pi k / N about the vertical (azimuth increasing), rad.

    Parameters
    ----------
    positions : int
        Number of positions N.
    """
    return 2.0 * np.pi * np.arange(positions) / positions


def position_design(positions: int, mode: str) -> np.ndarray:
    """Least-squares design matrix of the multi-position scheme.

    Unknowns (omega_dX, [omega_dY,] c, s) with c = Omega cos phi sin A0,
    s = Omega cos phi cos A0; at turn theta the X channel reads
    omega_dX + c cos theta + s sin theta and the Y channel omega_dY + c sin theta - s cos theta.
    Rows: X readings of every position, then (three-axis) the Y readings.

    Parameters
    ----------
    positions : int
        Number of positions N.
    mode : {"three-axis", "single-axis"}

    """
    theta = turn_angles(positions)
    ones, zeros = np.ones(positions), np.zeros(positions)
    if mode == "single-axis":
        return np.column_stack([ones, np.cos(theta), np.sin(theta)])
    x_rows = np.column_stack([ones, zeros, np.cos(theta), np.sin(theta)])
    y_rows = np.column_stack([zeros, ones, np.sin(theta), -np.cos(theta)])
    return np.vstack([x_rows, y_rows])


def fit_positions(rates_x, rates_y=None, mode: str = "three-axis"):
    """Separate drifts and the horizontal Earth rate from N >= 3 positions by least squares.

    Parameters
    ----------
    rates_x : ndarray, shape (M, N)
        omega_dX + omega_X0 measured at each position (rad/s), M members.
    rates_y : ndarray, shape (M, N), optional
        The Y channel (three-axis mode), rad/s.
    mode : {"three-axis", "single-axis"}

    Returns
    -------
    dict of ndarray (M,)
        ``drift_x``, ``drift_y`` (NaN in single-axis mode), ``c``, ``s`` (rad/s).

    Examples
    --------
    >>> th = turn_angles(4)
    >>> fit = fit_positions((1.0 + 2.0 * np.cos(th) + 3.0 * np.sin(th))[None, :], mode="single-axis")
    >>> [round(float(fit[k][0]), 12) for k in ("drift_x", "c", "s")]
    [1.0, 2.0, 3.0]
    """
    rates_x = np.atleast_2d(rates_x)
    positions = rates_x.shape[1]
    design = position_design(positions, mode)
    data = rates_x if mode == "single-axis" else np.hstack([rates_x, np.atleast_2d(rates_y)])
    # einsum, not a BLAS product: each member's numbers then do not depend on how many are fitted at once
    solution = np.einsum("mk,jk->mj", data, np.linalg.pinv(design))
    if mode == "single-axis":
        return {"drift_x": solution[:, 0], "drift_y": np.full(len(data), np.nan), "c": solution[:, 1],
                "s": solution[:, 2]}
    return {"drift_x": solution[:, 0], "drift_y": solution[:, 1], "c": solution[:, 2], "s": solution[:, 3]}


@dataclass(frozen=True)
class ProcedureOutcome:
    """What one procedure (or M Monte Carlo members of it) recovered, SI arrays of shape (M,).

    Attributes
    ----------
    drift_x, drift_y : ndarray
        Recovered own drifts omega_dX, omega_dY, rad/s (omega_dY NaN in single-axis mode).
    earth_rate_component : ndarray
        Recovered omega_X0 = Omega cos(phi) sin(A0) at the first position, rad/s.
    azimuth : ndarray
        Recovered A0 in [0, 2 pi), rad.
    azimuth_alternative : ndarray
        The other asin branch (single-axis, two positions), else equal to ``azimuth``.
    azimuth_error : ndarray
        Recovered minus true azimuth, wrapped to (-pi, pi], rad (single-axis: the
        branch nearer the truth, as coarse alignment would choose).
    saturated : ndarray of bool
        Single-axis asin argument beyond 1 (clipped).
    readings : ndarray, shape (M, channels, positions, cycles)
        Every integrator reading, V.
    """

    drift_x: np.ndarray
    drift_y: np.ndarray
    earth_rate_component: np.ndarray
    azimuth: np.ndarray
    azimuth_alternative: np.ndarray
    azimuth_error: np.ndarray
    saturated: np.ndarray
    readings: np.ndarray


def _validate_site(latitude, azimuth, mode, positions, cycles):
    latitude = np.asarray(latitude, dtype=float)
    if not np.all(np.isfinite(latitude)) or np.any(np.abs(latitude) >= np.pi / 2):
        raise NotObservable(
            "latitude: +/-90 deg (or beyond) leaves no horizontal Earth rate, the azimuth is not observable")
    if not np.all(np.isfinite(azimuth)):
        raise InvalidParameter("azimuth", "must be finite")
    if mode not in MODES:
        raise InvalidParameter("mode", f"{mode!r} is not one of {', '.join(MODES)}")
    if int(positions) < 2:
        raise InvalidParameter("positions", "need at least 2 platform positions")
    if int(cycles) < 1:
        raise InvalidParameter("cycles", "need at least 1 cycle per position")


def run_procedure(
    stabilizer: Stabilizer,
    latitude,
    azimuth,
    drift_x,
    drift_y=None,
    *,
    mode: str = "three-axis",
    positions: int = 2,
    cycles: int = 1,
    errors: ProcedureErrors | None = None,
    earth_rate: float = EARTH_RATE,
    steps: int = NOISE_STEPS,
) -> ProcedureOutcome:
    """Simulate the whole procedure and recover drifts and azimuth, vectorised over members.

    Each position k (turn 2 pi k / N about the vertical) runs ``cycles``
    measurement cycles of the X channel and, in three-axis mode, then of the Y
    channel; the readings are turned into rates by (13) (after the loop-lag
    compensation), averaged over the cycles, and separated by (15)/(16)
    (N = 2) or least squares (N >= 3). The azimuth comes from atan2
    (three-axis, or any mode with N >= 3) or asin (single-axis, N = 2). Every
    cycle of every member is independent given its errors, so all of them are
    simulated in one batch.

    Parameters
    ----------
    stabilizer : Stabilizer
        The instrument (also gives tau, K1 and the loop time constant).
    latitude, azimuth : float or ndarray (M,)
        Site latitude phi and true initial azimuth A0, rad.
    drift_x, drift_y : float or ndarray (M,)
        True own drifts of the X and Y gyros, rad/s (``drift_y`` defaults to ``drift_x``).
    mode : {"three-axis", "single-axis"}
    positions, cycles : int
        Number of equally spaced platform positions (>= 2) and cycles averaged at each.
    errors : ProcedureErrors, optional
        The drawn instrument and procedure errors of each member
        (:func:`~schuler.drift_calibration.draws.draw_errors`); None = error-free.
    earth_rate : float
        Omega, rad/s.
    steps : int
        Grid steps per pulse for the noise inputs (the ``samples`` of the errors follow from it).

    Returns
    -------
    ProcedureOutcome

    Examples
    --------
    >>> from schuler.drift_calibration.pulses import rectangular
    >>> stab = Stabilizer(57.3, 0.02, 0.1, 1e-3, 5.0, rectangular())
    >>> out = run_procedure(stab, np.radians(70), np.radians(80), np.radians(0.1) / 3600)
    >>> round(float(np.degrees(out.azimuth[0])), 9), round(float(np.degrees(out.drift_x[0]) * 3600), 12)
    (80.0, 0.1)
    """
    _validate_site(latitude, azimuth, mode, positions, cycles)
    drift_y = drift_x if drift_y is None else drift_y
    sizes = {np.size(v) for v in (latitude, azimuth, drift_x, drift_y)} - {1}
    count = errors.members if errors is not None else max(sizes, default=1)
    if sizes - {count}:
        raise InvalidParameter("latitude", f"array arguments disagree in length: {sorted(sizes | {count})}")
    latitude, azimuth, drift_x, drift_y = (np.broadcast_to(np.asarray(v, dtype=float), (count,)) for v in
                                           (latitude, azimuth, drift_x, drift_y))
    n_channels = 1 if mode == "single-axis" else 2
    shape = (count, n_channels, positions, cycles)
    if errors is None:
        errors = ProcedureErrors.zero(count, n_channels, positions, cycles)
    actual = azimuth[:, None] + turn_angles(positions)[None, :] + errors.turn_error
    omega_x0, omega_y0, omega_z0 = apparent_drift(latitude[:, None], actual, earth_rate)
    own = np.stack([drift_x, drift_y][:n_channels], axis=1)
    apparent = np.stack([omega_x0, omega_y0][:n_channels], axis=1)
    # a levelling residual e (elevation of the channel's axis) adds -Omega sin(phi) e by (2)
    rate = own[:, :, None] + apparent + omega_z0[:, None, :] * errors.elevation

    def per_cycle(values: np.ndarray) -> np.ndarray:
        """Member, channel or position values spread over every cycle, flattened."""
        values = np.asarray(values)
        return np.broadcast_to(values.reshape(values.shape + (1,) * (4 - values.ndim)), shape).reshape(-1)

    noise = None if errors.noise is None else errors.noise.reshape(-1, *errors.noise.shape[-3:])
    outcome = simulate_cycle(
        stabilizer, per_cycle(rate),
        initial_angle=errors.initial_angle.reshape(-1),
        sensor_scale_error=per_cycle(errors.sensor_scale_error),
        amplitude_mismatch=per_cycle(errors.amplitude_mismatch),
        duration_mismatch=per_cycle(errors.duration_mismatch),
        tilt=per_cycle(errors.tilt),
        integrator_offset=per_cycle(errors.integrator_offset),
        sway_angle=errors.sway_angle.reshape(-1),
        sway_rate=errors.sway_rate.reshape(-1),
        sensor_noise_density=per_cycle(errors.sensor_noise_density),
        angle_random_walk=per_cycle(errors.angle_random_walk),
        noise=noise, steps=steps,
    )
    samples = outcome.sensor_samples.reshape(*shape, 3)
    # first-order loop lag: int alpha = int beta - T (alpha(b) - alpha(a)) on each phase
    lag_known = stabilizer.loop_time_constant * (1.0 + errors.lag_compensation_error)[:, None, None, None]
    readings = outcome.reading.reshape(shape) + lag_known * (
        2.0 * samples[..., 1] - samples[..., 0] - samples[..., 2])
    rates = rate_from_reading(readings.mean(axis=-1), stabilizer.k1, stabilizer.tau)
    assumed_latitude = latitude + errors.latitude_error
    return _recover(rates, mode, positions, azimuth, assumed_latitude, earth_rate, readings)


def _recover(rates, mode, positions, azimuth, assumed_latitude, earth_rate, readings) -> ProcedureOutcome:
    """Drifts and azimuth from per-position rates (M, channels, N)."""
    count = rates.shape[0]
    saturated = np.zeros(count, dtype=bool)
    if positions == 2:
        # (15), (16) on the rates: omega_d = (r1 + r2) / 2, omega_0 = (r1 - r2) / 2
        drift_x = 0.5 * (rates[:, 0, 0] + rates[:, 0, 1])
        c = 0.5 * (rates[:, 0, 0] - rates[:, 0, 1])
        if mode == "single-axis":
            drift_y = np.full(count, np.nan)
            principal, alternative, saturated = azimuth_from_single_channel(c, assumed_latitude, earth_rate)
        else:
            drift_y = 0.5 * (rates[:, 1, 0] + rates[:, 1, 1])
            s = -0.5 * (rates[:, 1, 0] - rates[:, 1, 1])
            principal = alternative = azimuth_from_channels(c, -s)
    else:
        fit = fit_positions(rates[:, 0, :], None if mode == "single-axis" else rates[:, 1, :], mode)
        drift_x, drift_y, c = fit["drift_x"], fit["drift_y"], fit["c"]
        principal = alternative = azimuth_from_channels(fit["c"], -fit["s"])
    error_principal = wrap_angle(principal - azimuth)
    error_alternative = wrap_angle(alternative - azimuth)
    error = np.where(np.abs(error_principal) <= np.abs(error_alternative), error_principal, error_alternative)
    return ProcedureOutcome(drift_x, drift_y, c, principal, alternative, error, saturated, readings)


def cycle_time(tau: float) -> float:
    """One measurement cycle, two pulses of duration tau, s (the source's cycles: 8-15 s).

    Parameters
    ----------
    tau : float
        Pulse duration, s.
    """
    return 2.0 * tau


def procedure_time(tau: float, mode: str, positions: int, cycles: int) -> float:
    """Measuring time of the whole procedure (turns not counted), s.

    Parameters
    ----------
    tau : float
        Pulse duration, s.
    mode : {"three-axis", "single-axis"}
    positions : int
        Number of platform positions.
    cycles : int
        Number of measurement cycles per position.
    """
    return cycle_time(tau) * positions * cycles * (1 if mode == "single-axis" else 2)

