"""Shared by the aiding measurement tests: a true solution and the computed one with a known error state."""

from __future__ import annotations

import numpy as np

from schuler.aided.error_state import ATTITUDE, GYRO_BIAS, GYRO_SCALE, POSITION, VELOCITY, ErrorProcess, FilterModel
from schuler.aided.measurements import Solution
from schuler.core.attitude import dcm_from_euler, dcm_from_rotation_vector
from schuler.core.earth import radii_of_curvature


def model(scale: bool = True, odometer: bool = False, barometer: bool = False) -> FilterModel:
    """A 15/21-state model with the aiding states asked for."""
    sensor = ErrorProcess("constant", 1e-4)
    return FilterModel(1e-4, 1e-3, sensor, sensor, sensor if scale else None, sensor if scale else None,
                       ErrorProcess("constant", 0.01, axes=1) if odometer else None,
                       ErrorProcess("constant", 2.0, axes=1) if barometer else None)


def truth(members: int = 3, seed: int = 1) -> Solution:
    """A moving, turning, tilted vehicle at several latitudes."""
    rng = np.random.default_rng(seed)
    C = dcm_from_euler(rng.uniform(-0.2, 0.2, members), rng.uniform(-0.2, 0.2, members), rng.uniform(-3, 3, members))
    return Solution(rng.uniform(-1.0, 1.0, members), rng.uniform(-3, 3, members), rng.uniform(0, 500, members),
                    rng.normal(0, 10, (members, 3)), C, rng.normal(0, 0.3, (members, 3)))


def computed(true: Solution, dx: np.ndarray) -> Solution:
    """The solution with error state dx (computed - true).

    C_hat = exp(-[psi x]) C; omega_hat = omega + b + diag(omega) s.
    """
    R_N, R_E = radii_of_curvature(true.latitude)
    h = true.height
    dr = dx[:, POSITION]
    C = dcm_from_rotation_vector(-dx[:, ATTITUDE]) @ true.body_to_ned
    rate = true.angular_rate + dx[:, GYRO_BIAS]
    if dx.shape[1] >= 21:
        rate = rate + true.angular_rate * dx[:, GYRO_SCALE]
    longitude = true.longitude + dr[:, 1] / ((R_E + h) * np.cos(true.latitude))
    return Solution(true.latitude + dr[:, 0] / (R_N + h), longitude, h - dr[:, 2], true.velocity + dx[:, VELOCITY], C,
                    rate)


def assert_first_order(h, true: Solution, H: np.ndarray, n: int, scales: np.ndarray, rel: float = 2e-3,
                       seed: int = 2) -> None:
    """h(computed) - h(true) equals H dx to first order, state by state (central differences)."""
    rng = np.random.default_rng(seed)
    members = true.latitude.shape[0]
    for k in range(n):
        dx = np.zeros((members, n))
        dx[:, k] = scales[k] * rng.choice([-1.0, 1.0])
        plus, minus = h(computed(true, dx), dx), h(computed(true, -dx), -dx)
        numeric = (plus - minus) / 2.0
        analytic = np.einsum("nij,nj->ni", H, dx)
        tolerance = rel * np.abs(analytic).max() + 1e-9
        assert np.allclose(numeric, analytic, rtol=0, atol=tolerance + 1e-9 * np.abs(numeric).max()), (k, numeric,
                                                                                                          analytic)


def filtered_drive(values: dict, seed: int = 3):
    """One tactical member filtered on a simulated case with its aiding: the run and the filter's model."""
    from schuler.aided import aiding
    from schuler.aided import evaluation as ev
    from schuler.aided.ekf import run_filter
    from schuler.aided.error_state import filter_model
    from schuler.core.random import RandomStreams
    from schuler.imu.instrument import resolve_model

    case = ev.PARAMETERS.case(values)
    streams = RandomStreams(seed)
    data = ev.simulated_inputs(case, np.arange(1), streams)
    fm = aiding.with_states(filter_model(resolve_model("tactical")), case)
    extra = aiding.simulated_sources(case, data.path, data.increments, data.truth.interval_s, np.arange(1), streams,
                                     fm)
    run = run_filter(data.increments, data.truth.interval_s, ev._start(data.path, 1), fm, data.gnss,
                     use_velocity=False, sources=extra)
    return run, fm
