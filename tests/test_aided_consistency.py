"""The aided filter's consistency over 1,000 members whose sensors and fixes it models exactly (slow).

Ten chunks of 100 members, each member with its own filter, its own biases, scale factors, white noise,
fixes and initial errors, drawn from one seeded generator per chunk. The members' mean NEES at an epoch is
the mean of the chunks' means (equal chunks), compared with the 99 % band of a chi-square with 3,000 degrees
of freedom divided by 1,000 ([2.82, 3.19] for 3 states); the outage's predicted horizontal 1-sigma at its end
against the members' RMS horizontal error there (1,000 members, 2 axes: the RMS is known to 1.6 % at 1 sigma).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.stats

from schuler.aided import analysis
from schuler.aided.ekf import Start, run_filter
from schuler.aided.error_state import ErrorProcess, FilterModel
from schuler.aided.gnss import GnssRecord
from schuler.core.attitude import quaternion_from_rotation_vector, quaternion_multiply
from schuler.core.earth import radii_of_curvature
from schuler.navigate.trajectory import WaypointProfile
from schuler.navigate.truth import ideal_imu

D = np.radians
G0 = 9.80665
RATE = 50.0  # Hz: the filter's consistency does not depend on the rate; 1,000 members at 200 Hz would hold 5 GB
DURATION = 300.0
CHUNKS, CHUNK = 10, 100
OUTAGE = (150.0, 60.0)
MODEL = FilterModel(D(0.05) / 60, 0.05 / 60, ErrorProcess("constant", D(5.0) / 3600),
                    ErrorProcess("constant", 1e-3 * G0), ErrorProcess("constant", 300e-6),
                    ErrorProcess("constant", 300e-6))
POSITION_SIGMA, VELOCITY_SIGMA = np.array([0.5, 0.5, 1.0]), np.full(3, 0.05)
ATTITUDE_SIGMA = D([0.1, 0.1, 1.0])


def drive() -> WaypointProfile:
    """From rest, two right turns, a reversal and a stop on a level road (the filter tests' drive)."""
    times = np.array([0.0, 0.2, 0.4, 0.5, 0.7, 1.0]) * DURATION
    return WaypointProfile(latitude=D(30.5), longitude=D(114.5), height=20.0, times=times,
                           speeds=[0.0, 10.0, 15.0, 15.0, 10.0, 0.0],
                           headings=[0.0, 0.0, D(90.0), D(90.0), D(180.0), D(180.0)], flight_path_angles=[0.0] * 6)


def chunk_run(path, imu, fixes_times, rng):
    """One chunk: CHUNK members' measured increments and fixes drawn from ``rng``, filtered."""
    dt = 1.0 / RATE
    ideal = np.concatenate([imu.angle_increment_rad, imu.velocity_increment_m_s], axis=1)
    white = np.concatenate([np.broadcast_to(MODEL.angle_random_walk, (3,)),
                            np.broadcast_to(MODEL.velocity_random_walk, (3,))])
    measured = ideal[None] + rng.normal(size=(CHUNK,) + ideal.shape) * dt**0.5 * white
    for cols, bias, scale in ((slice(0, 3), MODEL.gyro_bias, MODEL.gyro_scale),
                              (slice(3, 6), MODEL.accel_bias, MODEL.accel_scale)):
        b = rng.normal(size=(CHUNK, 3)) * bias.sigma
        s = rng.normal(size=(CHUNK, 3)) * scale.sigma
        measured[..., cols] += ideal[None, :, cols] * s[:, None] + b[:, None] * dt
    lat = np.interp(fixes_times, imu.t_s, imu.latitude_rad)
    lon = np.interp(fixes_times, imu.t_s, imu.longitude_rad)
    h = np.interp(fixes_times, imu.t_s, imu.height_m)
    v = np.stack([np.interp(fixes_times, imu.t_s, imu.velocity_ned_m_s[:, i]) for i in range(3)], axis=1)
    k = fixes_times.size
    shared = GnssRecord(fixes_times, lat, lon, h, np.tile(POSITION_SIGMA, (k, 1)), v, np.tile(VELOCITY_SIGMA, (k, 1)))
    R_N, R_E = radii_of_curvature(lat)
    fixes = [dataclasses.replace(
        shared, latitude_rad=lat + rng.normal(size=k) * POSITION_SIGMA[0] / R_N,
        longitude_rad=lon + rng.normal(size=k) * POSITION_SIGMA[1] / (R_E * np.cos(lat)),
        height_m=h + rng.normal(size=k) * POSITION_SIGMA[2],
        velocity_ned_m_s=v + rng.normal(size=(k, 3)) * VELOCITY_SIGMA) for _ in range(CHUNK)]
    v0, q0 = path.kinematics(np.array([0.0]))
    psi0 = rng.normal(size=(CHUNK, 3)) * ATTITUDE_SIGMA
    q = quaternion_multiply(quaternion_from_rotation_vector(-psi0), np.repeat(q0, CHUNK, axis=0))
    start = Start(np.full(CHUNK, path.latitude), np.full(CHUNK, path.longitude), np.full(CHUNK, path.height),
                  np.repeat(v0, CHUNK, axis=0), q, np.full(3, 1e-6), np.full(3, 1e-6), ATTITUDE_SIGMA)
    return run_filter(measured, dt, start, MODEL, fixes, output_every=int(RATE), gate=1.0)


@pytest.mark.slow
def test_a_thousand_members_are_consistent_through_an_outage():
    path = drive()
    imu = ideal_imu(path, DURATION, RATE)
    every = int(RATE)
    pick = slice(every - 1, None, every)  # the output epochs: every second, after its last sample
    truth = analysis.Truth(imu.latitude_rad[pick], imu.longitude_rad[pick], imu.height_m[pick],
                           imu.velocity_ned_m_s[pick], imu.quaternion[pick])
    times = np.arange(1.0, DURATION) + 0.37
    times = times[(times < OUTAGE[0]) | (times > OUTAGE[0] + OUTAGE[1])]
    mean_nees, end_squares, sigma_squares = {}, [], []
    for chunk in range(CHUNKS):
        run = chunk_run(path, imu, times, np.random.default_rng([2026, chunk]))
        found = analysis.errors(run, truth)
        check = analysis.consistency(run, found)
        for group, values in check.nees.items():
            mean_nees[group] = mean_nees.get(group, 0.0) + values / CHUNKS
        (drift,) = analysis.outage_drift(run, found, [OUTAGE])
        end_squares.append(drift.horizontal_error_end_m**2)
        sigma_squares.append(drift.horizontal_error_sigma_m**2)
    members = CHUNKS * CHUNK
    low, high = scipy.stats.chi2.ppf([0.005, 0.995], 3 * members) / members
    predicted, spread = np.sqrt(np.mean(sigma_squares)), np.sqrt(np.mean(end_squares))
    print(f"band [{low:.3f}, {high:.3f}]; outage 1-sigma {predicted:.3f} m predicted, {spread:.3f} m RMS")
    for group, values in mean_nees.items():
        inside = np.mean((values >= low) & (values <= high))
        print(f"{group}: {inside:.1%} of epochs inside, mean NEES {values.mean():.3f}")
        assert inside >= 0.97, (group, inside, float(values.mean()), (low, high))
    assert predicted == pytest.approx(spread, rel=0.10)
