"""Six-position static calibration with a rate test: biases, scale factors and misalignments of both triads.

Each body axis points up, then down (x up: pitch +90 deg; x down: pitch -90 deg;
y up: roll -90 deg; y down: roll +90 deg; z up: roll 180 deg; z down: level),
held still for a dwell, then turned once about the vertical on the rate table
(known rate). Each triad's model (measured - true convention, spec 06
"Sensor errors") is

    y = K u + b,   K = I + S + M

with u the true input (specific force C^T (0, 0, -g) at rest; angular rate
C^T omega_ie plus the table rate along the vertical body axis), S the scale
errors (diagonal), M the misalignments (off-diagonal) and b the bias. Stacking
the dwell means, Y (3 x p) = [K b] [U; 1] is linear in (K, b): least squares
gives all twelve numbers per triad. Their 1-sigma propagates each mean's own
noise through the least-squares gain (dwell and turn means differ in
length, so in noise), or, without a noise figure, follows from the residual
variance. With the six static means alone this is the classic

    b = (f_up + f_down) / 2,   scale error = (f_up - f_down) / (2 g) - 1

(Titterton and Weston 2004, sec. 8.6; spec 06 "Multi-position calibration");
the gyros need the rate test, the Earth rate being too small to scale them.

Examples
--------
>>> import numpy as np
>>> plan = SixPositionPlan(latitude_rad=0.8, dwell_s=10.0, turn_s=20.0, sample_interval_s=0.1)
>>> gyro, accel = plan.truth()
>>> K = np.diag([1.001, 0.999, 1.0]); b = np.array([0.01, -0.02, 0.03])
>>> result = calibrate_six_position(gyro @ np.eye(3), accel @ K.T + b, plan)
>>> np.round(result.accel_bias, 12).tolist(), np.round(np.diag(result.accel_matrix), 12).tolist()
([0.01, -0.02, 0.03], [1.001, 0.999, 1.0])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.core.attitude import dcm_from_euler
from schuler.core.earth import earth_rate_ned, normal_gravity
from schuler.exceptions import InvalidParameter

ORIENTATIONS = {
    "x up": (0.0, math.pi / 2), "x down": (0.0, -math.pi / 2),
    "y up": (-math.pi / 2, 0.0), "y down": (math.pi / 2, 0.0),
    "z up": (math.pi, 0.0), "z down": (0.0, 0.0),
}
"""(roll, pitch) of each position, rad; the heading is the plan's."""


@dataclass(frozen=True)
class SixPositionPlan:
    """The procedure: six dwells, each followed by one turn of the table about the vertical.

    Parameters
    ----------
    latitude_rad : float
        L, rad.
    dwell_s : float
        Static time per position, s.
    turn_s : float
        Duration of each table turn (one full turn), s.
    sample_interval_s : float
        dt, s.
    heading_rad : float
        Heading of the fixture at the dwells, rad.
    gravity_m_s2 : float, optional
        g (default: WGS-84 normal gravity at L).
    """

    latitude_rad: float
    dwell_s: float = 60.0
    turn_s: float = 36.0
    sample_interval_s: float = 0.01
    heading_rad: float = 0.0
    gravity_m_s2: float | None = None

    def __post_init__(self):
        for name in ("dwell_s", "turn_s", "sample_interval_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise InvalidParameter(name.removesuffix("_s"), f"must be finite and > 0 s, got {value!r}")
        if self.dwell_samples < 2 or self.turn_samples < 2:
            raise InvalidParameter("sample_interval", "dwells and turns must hold at least 2 samples each")

    @property
    def gravity(self) -> float:
        return float(normal_gravity(self.latitude_rad)) if self.gravity_m_s2 is None else float(self.gravity_m_s2)

    @property
    def dwell_samples(self) -> int:
        return int(round(self.dwell_s / self.sample_interval_s))

    @property
    def turn_samples(self) -> int:
        return int(round(self.turn_s / self.sample_interval_s))

    @property
    def samples(self) -> int:
        return len(ORIENTATIONS) * (self.dwell_samples + self.turn_samples)

    def segments(self) -> list[tuple[str, bool, int, int]]:
        """(position, turning, first sample, stop) of each dwell and turn, in order."""
        out, start = [], 0
        for name in ORIENTATIONS:
            out.append((name, False, start, start + self.dwell_samples))
            start += self.dwell_samples
            out.append((name, True, start, start + self.turn_samples))
            start += self.turn_samples
        return out

    def truth(self) -> tuple[np.ndarray, np.ndarray]:
        """True mean angular rate (n, 3), rad/s, and specific force (n, 3), m/s^2, of every sample.

        During a turn the table turns clockwise (seen from above) at 2 pi / turn_s; the
        body's Earth rate follows the heading at each sample's middle.
        """
        omega = earth_rate_ned(self.latitude_rad)
        gyro, accel = np.empty((self.samples, 3)), np.empty((self.samples, 3))
        down = np.array([0.0, 0.0, -self.gravity])
        for name, turning, first, stop in self.segments():
            roll, pitch = ORIENTATIONS[name]
            count = stop - first
            heading = self.heading_rad + (2.0 * math.pi * (np.arange(count) + 0.5) / count if turning else 0.0)
            C = dcm_from_euler(roll, pitch, heading) * np.ones((count, 1, 1))
            gyro[first:stop] = np.einsum("kji,j->ki", C, omega)
            accel[first:stop] = np.einsum("kji,j->ki", C, down)
            if turning:   # the table's rate about the vertical (down), in body axes: C^T (0, 0, rate)
                gyro[first:stop] += np.einsum("kji,j->ki", C, np.array([0.0, 0.0, 2.0 * math.pi / self.turn_s]))
        return gyro, accel


@dataclass
class TriadCalibration:
    """A triad's y = K u + b, estimated, with 1-sigma of every entry.

    Attributes
    ----------
    gyro_matrix, accel_matrix : ndarray (3, 3)
        K = I + S + M.
    gyro_bias, accel_bias : ndarray (3,)
        b, rad/s and m/s^2.
    gyro_matrix_sigma, accel_matrix_sigma : ndarray (3, 3)
    gyro_bias_sigma, accel_bias_sigma : ndarray (3,)
    """

    gyro_matrix: np.ndarray
    gyro_bias: np.ndarray
    accel_matrix: np.ndarray
    accel_bias: np.ndarray
    gyro_matrix_sigma: np.ndarray
    gyro_bias_sigma: np.ndarray
    accel_matrix_sigma: np.ndarray
    accel_bias_sigma: np.ndarray


def fit_triad(inputs: np.ndarray, outputs: np.ndarray, noise: np.ndarray | None = None):
    """Least squares of Y = [K b] [U; 1]: inputs U (p, 3), outputs Y (p, 3) -> K, b and their 1-sigma.

    ``noise`` (p, 3) gives the 1-sigma of each mean (else the residuals' spread is used).

    Parameters
    ----------
    inputs : ndarray of shape (p, 3)
        True input U of each position, body axes: angular rate in rad/s (gyros) or specific force in
        m/s^2 (accelerometers).
    outputs : ndarray of shape (p, 3)
        Measured mean Y of each position, in the same unit and axes.
    noise : ndarray of shape (p, 3), optional
        1-sigma of each measured mean, same unit; each mean's own value is propagated through the gain.

    Returns
    -------
    K : ndarray of shape (3, 3)
        Scale factor and misalignment matrix, plain numbers.
    b : ndarray of shape (3,)
        Bias (measured - true), in the outputs' unit.
    K_sigma : ndarray of shape (3, 3)
        1-sigma of each entry of K, plain numbers.
    b_sigma : ndarray of shape (3,)
        1-sigma of b, in the outputs' unit.

    Raises
    ------
    InvalidParameter
        The inputs do not span three axes and a constant (rank below 4).
    """
    design = np.hstack([inputs, np.ones((inputs.shape[0], 1))])
    solution, _, rank, _ = np.linalg.lstsq(design, outputs, rcond=None)
    if rank < 4:
        raise InvalidParameter("positions", "the dwell inputs do not span three axes and a constant")
    covariance = np.linalg.inv(design.T @ design)
    if noise is None:
        dof = max(1, design.shape[0] - 4)
        variance = ((outputs - design @ solution) ** 2).sum(axis=0) / dof
        sigma = np.sqrt(np.outer(np.diag(covariance), variance))   # (4, 3): row j of [K b]^T, column axis
    else:
        # each mean its own variance (dwells and turns differ in length): (X^T X)^-1 X^T diag(s^2) X (X^T X)^-1
        gain = covariance @ design.T
        sigma = np.sqrt(np.einsum("ji,ia->ja", gain**2, noise**2))
    return solution[:3].T, solution[3], sigma[:3].T, sigma[3]


def _means(samples: np.ndarray, segments) -> np.ndarray:
    return np.stack([samples[first:stop].mean(axis=0) for _, _, first, stop in segments])


def calibrate_six_position(gyro, accel, plan: SixPositionPlan, gyro_random_walk=None,
                           accel_random_walk=None) -> TriadCalibration:
    """Calibrate both triads from a six-position record made to ``plan``.

    Parameters
    ----------
    gyro, accel : ndarray (n, 3)
        Measured mean rates (rad/s) and specific forces (m/s^2) of every sample.
    plan : SixPositionPlan
    gyro_random_walk, accel_random_walk : array_like (3,), optional
        N of the sensors: the 1-sigma of each dwell mean is N / sqrt(duration);
        not given, the fit's residuals set it.

    Returns
    -------
    TriadCalibration
        Accelerometers from the six dwells; gyros from the dwells and the turns.
    """
    gyro, accel = np.asarray(gyro, dtype=float), np.asarray(accel, dtype=float)
    if gyro.shape != (plan.samples, 3) or accel.shape != (plan.samples, 3):
        raise InvalidParameter("samples", f"the plan has {plan.samples} samples of 3 axes; got {gyro.shape}, "
                               f"{accel.shape}")
    true_gyro, true_accel = plan.truth()
    segments = plan.segments()
    dwells = [s for s in segments if not s[1]]

    def noise(density, chosen):
        if density is None:
            return None
        spans = np.array([(stop - first) * plan.sample_interval_s for _, _, first, stop in chosen])
        return np.asarray(density, dtype=float)[None, :] / np.sqrt(spans)[:, None]

    accel_fit = fit_triad(_means(true_accel, dwells), _means(accel, dwells), noise(accel_random_walk, dwells))
    gyro_fit = fit_triad(_means(true_gyro, segments), _means(gyro, segments), noise(gyro_random_walk, segments))
    return TriadCalibration(gyro_fit[0], gyro_fit[1], accel_fit[0], accel_fit[1], gyro_fit[2], gyro_fit[3],
                            accel_fit[2], accel_fit[3])

