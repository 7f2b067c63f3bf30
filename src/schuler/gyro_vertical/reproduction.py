"""The source's worked example and friction estimate, recomputed, with its errata flagged.

Drozdovich (1959), "On an inertial method of measuring velocities" (JPRS 2912):
v_y = 10 m/s, v_x = 0, phi = 60 deg, R = 6.4e6 m, Omega = 7.3e-5 1/s,
psi + gamma = 0 (here theta = 0, gamma = 90 deg: x0 north, v due west), and
g = 9.81 m/s^2 (the source gives none). All constants are the
:data:`~schuler.core.earth.DROZDOVICH` preset.

Examples
--------
>>> e = worked_example()
>>> round(e["W_star_x"], 4), round(e["beta_r"], 5), round(e["dv_y"], 3)
(0.0135, 0.00138, 0.557)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from schuler.core.earth import DROZDOVICH, EarthModel
from schuler.core.geometry import ARCSEC, DEG_PER_HOUR, earth_rate_north_up, time_grid
from schuler.gyro_vertical.friction import friction_from_velocity_error
from schuler.gyro_vertical.model import GyroVertical
from schuler.gyro_vertical.quasi_steady import Analysis, analyse, split_schuler_frequencies, steady_errors
from schuler.gyro_vertical.trajectory import GreatCircleTrajectory, transport_coriolis_acceleration
from schuler.registry import ReproductionRow
from schuler.results import Footnotes, Result

SOURCE = "Drozdovich (1959), 'On an inertial method of measuring velocities', JPRS 2912 (source 000)"
LATITUDE = math.radians(60.0)
SPEED = 10.0
FRICTION_VELOCITY_ERROR = 0.01
PRINTED = {
    "W_star_x": 0.0136,
    "beta_r": 0.0014,
    "dv_y": 0.67,
    "schuler_period_min": 84.4,
    "friction_q": 1.6e-6,
}
"""Numbers as printed in the source (m/s^2, rad, m/s, min, 1/s)."""

LEVELLING_ERROR = 1.0 * ARCSEC
"""A 1-arcsec levelling error about y in both compensation runs, rad: without any
error the compensated run is identically zero and a ratio of means says nothing."""
SIMULATION_HOURS = 48.0
OUTPUT_STEP = 10.0


def worked_example(earth: EarthModel = DROZDOVICH, latitude: float = LATITUDE, speed: float = SPEED) -> dict:
    """The worked example by the slowly-varying form of (29): W*, tilts and velocity errors.

    Parameters
    ----------
    earth : EarthModel
        Constants (default: the source's).
    latitude : float
        rad.
    speed : float
        m/s, along +y0 with x0 north.

    Returns
    -------
    dict of float
        ``W_star_x``, ``W_star_y`` (m/s^2), ``alpha_r``, ``beta_r`` (rad), ``dv_x``,
        ``dv_y`` (m/s), ``source_chain_dv_y``: the source's own rounded chain
        6.4e6 x 7.3e-5 x 0.87 x 1.4e-3 (m/s).
    """
    path = GreatCircleTrajectory.from_source(latitude, speed, radius=earth.radius, rate=earth.rate, frozen=True)
    kinematics = path.kinematics(0.0)
    W_x, W_y = (float(w) for w in transport_coriolis_acceleration(kinematics, earth.radius))
    steady = steady_errors(W_x, W_y, float(kinematics.omega_2), earth.gravity, earth.radius)
    values = {"W_star_x": W_x, "W_star_y": W_y}
    values.update({key: float(value) for key, value in steady.items()})
    values["source_chain_dv_y"] = earth.radius * earth.rate * 0.87 * PRINTED["beta_r"]
    return values


@dataclass
class VerticalReproduction(Result):
    """The worked example, the oscillation modes and the friction estimate, recomputed."""

    W_star_x: float
    W_star_y: float
    alpha_r: float
    beta_r: float
    dv_x: float
    dv_y: float
    printed_dv_y: float
    printed_W_star_x: float
    printed_beta_r: float
    source_chain_dv_y: float
    schuler_period_min: float
    printed_schuler_period_min: float
    split_period_fast_min: float
    split_period_slow_min: float
    beat_period_h: float
    printed_periods: str
    simulated_period_fast_min: float
    simulated_period_slow_min: float
    simulated_beat_period_h: float
    amplitude_24h: float
    mode_amplitude: float
    simulated_mean_dv_y: float
    quasi_steady_mean_dv_y: float
    compensated_mean_dv: float
    compensation_ratio: float
    friction_velocity_error: float
    friction_q: float
    friction_q_deg_per_h: float
    printed_friction_q: float
    constants: str
    errata: list[str]
    analysis: Analysis = field(repr=False)
    compensated: Analysis = field(repr=False)

    units: ClassVar[dict[str, str]] = {
        "W_star_x": "m/s^2", "W_star_y": "m/s^2", "alpha_r": "rad", "beta_r": "rad", "dv_x": "m/s",
        "dv_y": "m/s", "printed_dv_y": "m/s", "printed_W_star_x": "m/s^2", "printed_beta_r": "rad",
        "source_chain_dv_y": "m/s", "amplitude_24h": "m/s", "mode_amplitude": "m/s",
        "simulated_mean_dv_y": "m/s", "quasi_steady_mean_dv_y": "m/s", "compensated_mean_dv": "m/s",
        "friction_velocity_error": "m/s", "friction_q": "1/s", "printed_friction_q": "1/s",
    }

    def rows(self) -> list[ReproductionRow]:
        """Printed value beside the computed one, for the table and the report."""
        def close(computed, printed, digits):
            return round(computed, digits) == round(printed, digits)

        return [
            ReproductionRow("W*_x (21)", self.printed_W_star_x, self.W_star_x, "m/s^2",
                            abs(self.W_star_x / self.printed_W_star_x - 1) < 0.01,
                            "source rounds sin 60 = 0.87 (gives 0.01357); exact 0.01350"),
            ReproductionRow("beta_r = W*_x / g", self.printed_beta_r, self.beta_r, "rad",
                            close(self.beta_r, self.printed_beta_r, 4), "g = 9.81 m/s^2 assumed"),
            ReproductionRow("Delta v_y = R omega_2 beta_r (29)", self.printed_dv_y, self.dv_y, "m/s",
                            close(self.dv_y, self.printed_dv_y, 2),
                            f"ERRATUM: the source's own chain gives {self.source_chain_dv_y:.3f} m/s; "
                            "0.67 is a misprint of 0.57"),
            ReproductionRow("Delta v_x", 0.0, self.dv_x, "m/s", abs(self.dv_x) < 1e-9, ""),
            ReproductionRow("Schuler period 2 pi sqrt(R/g)", self.printed_schuler_period_min,
                            self.schuler_period_min, "min", close(self.schuler_period_min, 84.4, 1),
                            "84.4 min belongs to R = 6.371e6 m; R = 6.4e6 m gives 84.6 min"),
            ReproductionRow("oscillation periods (27)", self.printed_periods,
                            self.split_period_fast_min, "min", False,
                            f"ERRATUM: split Schuler modes {self.split_period_fast_min:.2f} and "
                            f"{self.split_period_slow_min:.2f} min (simulated {self.simulated_period_fast_min:.2f}, "
                            f"{self.simulated_period_slow_min:.2f}), beating with 2 pi/(Omega sin phi) = "
                            f"{self.beat_period_h:.1f} h; no 24 h line (its amplitude {self.amplitude_24h:.1e} m/s)"),
            ReproductionRow("M_fr / H for |Delta v| = 0.01 m/s (32)", self.printed_friction_q, self.friction_q,
                            "1/s", close(self.friction_q, self.printed_friction_q, 8),
                            f"ERRATUM: 0.01 / 6.4e6 = 1.56e-9 1/s ({self.friction_q_deg_per_h:.1e} deg/h), "
                            "not 1.6e-6; (32) as printed drops the factor R"),
            ReproductionRow("mean |Delta v| with W* compensated (conclusions)", "removed",
                            self.compensated_mean_dv, "m/s", self.compensation_ratio >= 100,
                            f"{self.compensation_ratio:.0f} times smaller than without (both runs with a "
                            "1-arcsec levelling error)"),
        ]

    def render(self):
        from rich.console import Group
        from rich.table import Table

        table = Table(title=f"Gyro vertical: worked example of {SOURCE}")
        for column in ("quantity", "source", "computed", "unit", "agrees", "note"):
            table.add_column(column, overflow="fold")
        # notes are long: the table refers to them by number and lists them below it
        footnotes = Footnotes()
        for row in self.rows():
            printed = row.printed if isinstance(row.printed, str) else f"{row.printed:.4g}"
            table.add_row(row.quantity, printed, f"{row.computed:.4g}", row.unit, "yes" if row.agrees else "NO",
                          footnotes.reference(row.note))
        return Group(table, *footnotes.lines(), f"Constants: {self.constants}")


def mean_velocity_error(response) -> float:
    """Magnitude of the time-averaged velocity-error vector (the systematic error), m/s."""
    return float(np.hypot(np.mean(response.velocity_error_x), np.mean(response.velocity_error_y)))


def reproduce(earth: EarthModel = DROZDOVICH) -> VerticalReproduction:
    """Recompute the worked example, simulate it for 48 h along its great circle, and check the errata.

    The simulation starts levelled on the accelerometers with the integrators
    preset to the true velocity. The source's conclusion is checked by two more
    runs, with and without the transport and Coriolis terms compensated, both
    with a 1-arcsec levelling error (:data:`LEVELLING_ERROR`).
    """
    example = worked_example(earth)
    _, omega_2 = earth_rate_north_up(LATITUDE, earth.rate)
    fast, slow = (float(w) for w in split_schuler_frequencies(earth.gravity, earth.radius, omega_2))
    time = time_grid(SIMULATION_HOURS * 3600.0, OUTPUT_STEP)
    path = GreatCircleTrajectory.from_source(LATITUDE, SPEED, radius=earth.radius, rate=earth.rate)
    analysis = analyse(GyroVertical(path, earth.gravity), time)
    tilt = (0.0, LEVELLING_ERROR)
    uncompensated = GyroVertical(path, earth.gravity, initial_tilt=tilt).simulate(time)
    compensated = analyse(GyroVertical(path, earth.gravity, transport_coriolis_compensation=True,
                                       initial_tilt=tilt), time)
    fit = analysis.fit
    simulated = np.sort(fit.periods)
    r, rc = analysis.response, compensated.response
    mean_error = mean_velocity_error(uncompensated)
    mean_compensated = mean_velocity_error(rc)
    q = float(friction_from_velocity_error(FRICTION_VELOCITY_ERROR, earth.radius))
    return VerticalReproduction(
        W_star_x=example["W_star_x"], W_star_y=example["W_star_y"], alpha_r=example["alpha_r"],
        beta_r=example["beta_r"], dv_x=example["dv_x"], dv_y=example["dv_y"], printed_dv_y=PRINTED["dv_y"],
        printed_W_star_x=PRINTED["W_star_x"], printed_beta_r=PRINTED["beta_r"],
        source_chain_dv_y=example["source_chain_dv_y"],
        schuler_period_min=2 * math.pi * math.sqrt(earth.radius / earth.gravity) / 60,
        printed_schuler_period_min=PRINTED["schuler_period_min"],
        split_period_fast_min=2 * math.pi / fast / 60, split_period_slow_min=2 * math.pi / slow / 60,
        beat_period_h=2 * math.pi / (fast - slow) / 3600, printed_periods="24 h and 84.4 min",
        simulated_period_fast_min=float(simulated[0]) / 60, simulated_period_slow_min=float(simulated[1]) / 60,
        simulated_beat_period_h=float(2 * math.pi / abs(abs(fit.frequencies[0]) - abs(fit.frequencies[1])) / 3600),
        amplitude_24h=max(analysis.spectrum.amplitude_at(1 / 86400), analysis.spectrum.amplitude_at(-1 / 86400)),
        mode_amplitude=float(fit.amplitudes.max()),
        simulated_mean_dv_y=float(np.mean(r.velocity_error_y)),
        quasi_steady_mean_dv_y=float(np.mean(analysis.quasi_steady.dv_y)),
        compensated_mean_dv=mean_compensated,
        compensation_ratio=mean_error / mean_compensated,
        friction_velocity_error=FRICTION_VELOCITY_ERROR, friction_q=q, friction_q_deg_per_h=q / DEG_PER_HOUR,
        printed_friction_q=PRINTED["friction_q"],
        constants=f"R = {earth.radius:g} m, g = {earth.gravity:g} m/s^2, Omega = {earth.rate:g} 1/s, "
                  f"phi = 60 deg, v = 10 m/s due west (theta = 0, gamma = 90 deg); "
                  f"simulation {SIMULATION_HOURS:g} h along the great circle, output every {OUTPUT_STEP:g} s",
        errata=[
            f"Delta v_y: printed 0.67 m/s; R omega_2 beta_r = {example['dv_y']:.3f} m/s "
            f"(the source's rounded chain gives {example['source_chain_dv_y']:.3f} m/s).",
            f"Friction: printed M_fr/H = 1.6e-6 1/s; 0.01/6.4e6 = {q:.3g} 1/s. Eq. (32) drops the factor R.",
            "Periods: printed '24 h and 84.4 min'; the modes are the split Schuler periods "
            f"{2 * math.pi / fast / 60:.2f} and {2 * math.pi / slow / 60:.2f} min beating every "
            f"{2 * math.pi / (fast - slow) / 3600:.1f} h (2 pi / (Omega sin phi)); there is no 24-h mode.",
            f"Schuler period: 84.4 min needs R = 6.371e6 m; with R = 6.4e6 m and g = 9.81 it is "
            f"{2 * math.pi * math.sqrt(earth.radius / earth.gravity) / 60:.2f} min.",
        ],
        analysis=analysis,
        compensated=compensated,
    )
