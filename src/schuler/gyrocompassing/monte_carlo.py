"""Monte Carlo over residual drifts and accelerometer errors (source 003, Sec. 3), batched on the engine."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.gyrocompassing import analytic
from schuler.gyrocompassing.case import AlignmentCase, analytic_results, automatic_duration, check_model, time_grid
from schuler.gyrocompassing.simulation import simulate_cases


@dataclass
class MonteCarloRun:
    """Azimuth errors of N sampled cases (SI) and the analytic 1-sigma beside them."""

    azimuth_errors: np.ndarray
    sigma_analytic: float
    sigma_simplified: float
    constraints_ok_fraction: float

    @property
    def mean(self) -> float:
        return float(np.mean(self.azimuth_errors))

    @property
    def std(self) -> float:
        return float(np.std(self.azimuth_errors, ddof=1)) if self.azimuth_errors.size > 1 else 0.0


def monte_carlo(case: AlignmentCase, model: str = "full", members: int = 1000, *, sigma_drift: float = 0.0,
                sigma_drift_z: float = 0.0, sigma_accel: float = 0.0, seed: int = 0,
                duration: float | None = None, time_step: float = 1.0) -> MonteCarloRun:
    """Monte Carlo over residual drifts and accelerometer errors, batched on the engine.

    Each member draws Delta omega_dx, Delta omega_dy ~ N(mean, sigma_drift),
    Delta omega_dz ~ N(mean, sigma_drift_z) and Delta a_x, Delta a_y ~
    N(mean, sigma_accel) about the case's values, independently (so the east drift has 1-sigma
    sigma_drift at any azimuth); all members are
    simulated at once and their final azimuth errors collected. The analytic
    1-sigma is that of the model's linear steady state x_ss = -A^{-1} B u; for the
    simplified model it is (1.21)'s, without the accelerometers.

    Parameters
    ----------
    case : AlignmentCase
        A single case: the means.
    model : str
        One of :data:`models.MODELS`.
    members : int
        N (>= 2).
    sigma_drift, sigma_drift_z : float
        1-sigma of the horizontal (x, y) and vertical residual drifts, rad/s.
    sigma_accel : float
        1-sigma of each accelerometer error, m/s^2.
    seed : int
        Random seed.
    duration, time_step : float
        As in :func:`run_case`.

    Examples
    --------
    >>> mc = monte_carlo(AlignmentCase(), "simplified", 200, sigma_drift=np.radians(0.01) / 3600, duration=1500)
    >>> abs(mc.std / mc.sigma_analytic - 1) < 0.15
    True
    """
    check_model(model)
    if members < 2:
        raise InvalidParameter("monte_carlo", "needs at least 2 members")
    for name, value in (("sigma_drift", sigma_drift), ("sigma_drift_z", sigma_drift_z), ("sigma_accel", sigma_accel)):
        if not (math.isfinite(value) and value >= 0):
            raise InvalidParameter(name, "must be a non-negative number")
    case.check_observable()
    settling = float(analytic_results(case, model)["settling_time_s"])
    duration = automatic_duration(settling) if duration is None else duration
    rng = np.random.default_rng(seed)
    sigmas = np.array([sigma_drift, sigma_drift, sigma_drift_z, 0.0, sigma_accel, sigma_accel])
    inputs = case.inputs() + rng.standard_normal((members, 6)) * sigmas
    system = case.model(model)
    simulated = simulate_cases(system, time_grid(duration, time_step), case.initial_state(model), inputs, members)
    gains = analytic.steady_state_gain_matrix(system.A, system.B)
    delta_row = gains[list(system.states).index("delta")]
    c_gamma, c_a = case.gains()
    return MonteCarloRun(
        azimuth_errors=simulated.azimuth_error,
        sigma_analytic=float(np.sqrt(np.sum((delta_row * sigmas) ** 2))),
        sigma_simplified=float(analytic.azimuth_error_sigma(case.latitude, c_gamma, c_a, sigma_drift, sigma_drift_z,
                                                            0.0, case.earth_rate)),
        constraints_ok_fraction=float(np.mean(simulated.constraints_ok)),
    )
