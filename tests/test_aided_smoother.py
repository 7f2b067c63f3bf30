"""The Rauch-Tung-Striebel smoother over the closed-loop aided filter (spec 07, "Smoother").

A linear-Gaussian chain filtered in closed loop with the package's own predict and update, smoothed, against the
batch weighted least-squares solution of the whole interval (the fixed-interval smoother is that solution), for
any chain P^s below P^+; the feedback's signs as a round trip; the interpolation between stored times; the
smoothed outage drift and its 1-sigma on seeded drives (1,000 members: slow); the memory refusals; ``aided run
--smooth``'s JSON and error columns, on simulated data and on files.
"""

from __future__ import annotations

import functools
import types

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.aided import analysis, kalman, smoother
from schuler.aided.ekf import run_filter
from schuler.exceptions import InvalidParameter, SimulationError
from schuler.memory import MemoryBudgetExceeded
from schuler.navigate.trajectory import WaypointProfile
from schuler.navigate.truth import ideal_imu
from schuler.registry import get_system
from test_aided_filter import gnss_from, increments_of, start_of, tactical_model

AIDED = get_system("aided")


def closed_loop_chain(rng, members=3, n=4, m=2, steps=40):
    """x_k = Phi_k x_(k-1) + w_k, z_k = H x_k + v_k (every third step without a measurement), filtered in closed
    loop: the solution s is propagated by Phi_k, the error s - x estimated from h(s) - z, fed back, reset."""
    Phi = np.eye(n) + 0.15 * rng.normal(size=(steps + 1, n, n))
    noise = rng.normal(size=(n, n))
    Q = 0.05 * noise @ noise.T + 0.01 * np.eye(n)
    H = rng.normal(size=(m, n))
    R = np.diag(rng.uniform(0.2, 0.6, m)) ** 2
    P0 = np.diag(rng.uniform(0.5, 2.0, n)) ** 2
    mean0 = rng.normal(size=n)
    x = mean0 + rng.normal(size=(members, n)) @ np.sqrt(P0)
    s, P = np.broadcast_to(mean0, (members, n)).copy(), np.broadcast_to(P0, (members, n, n)).copy()
    kept = {"posterior": [P], "prior": [P], "transition": [np.broadcast_to(np.eye(n), (members, n, n))],
            "correction": [np.zeros((members, n))], "solution": [s], "z": [None]}
    chol_Q, chol_R = np.linalg.cholesky(Q), np.linalg.cholesky(R)
    for k in range(1, steps + 1):
        x = x @ Phi[k].T + rng.normal(size=(members, n)) @ chol_Q.T
        s = s @ Phi[k].T
        P = kalman.predict(P, Phi[k], Q)
        kept["prior"].append(P)
        correction, z = np.zeros((members, n)), None
        if k % 3:
            z = x @ H.T + rng.normal(size=(members, m)) @ chol_R.T
            outcome = kalman.update(P, s @ H.T - z, H, R, gate=1.0)
            P, correction = outcome.covariance, outcome.correction
            s = s - correction
        for name, value in (("posterior", P), ("transition", np.broadcast_to(Phi[k], (members, n, n))),
                            ("correction", correction), ("solution", s), ("z", z)):
            kept[name].append(value)
    return kept, dict(Phi=Phi, Q=Q, H=H, R=R, P0=P0, mean0=mean0)


def batch_solution(model, measurements, member):
    """The posterior mean and covariance of x_0 ... x_K given every z: the normal equations of the weighted
    least-squares problem (prior of x_0, each step's process noise, each measurement), solved by Cholesky."""
    Phi, Q, H, R, P0, mean0 = (model[k] for k in ("Phi", "Q", "H", "R", "P0", "mean0"))
    n, K = mean0.size, Phi.shape[0] - 1
    J = np.zeros((n * (K + 1), n * (K + 1)))
    y = np.zeros(n * (K + 1))
    J[:n, :n] += np.linalg.solve(P0, np.eye(n))
    y[:n] += np.linalg.solve(P0, mean0)
    Qi, Ri = np.linalg.solve(Q, np.eye(n)), np.linalg.solve(R, np.eye(R.shape[0]))
    for k in range(1, K + 1):
        block = np.zeros((n, n * (K + 1)))  # x_k - Phi_k x_(k-1)
        block[:, n * (k - 1):n * k], block[:, n * k:n * (k + 1)] = -Phi[k], np.eye(n)
        J += block.T @ Qi @ block
        z = measurements[k]
        if z is not None:
            rows = slice(n * k, n * (k + 1))
            J[rows, rows] += H.T @ Ri @ H
            y[rows] += H.T @ Ri @ z[member]
    factor = scipy.linalg.cho_factor(J)
    mean = scipy.linalg.cho_solve(factor, y).reshape(K + 1, n)
    covariance = scipy.linalg.cho_solve(factor, np.eye(J.shape[0]))
    return mean, np.stack([covariance[n * k:n * (k + 1), n * k:n * (k + 1)] for k in range(K + 1)])


def test_the_fixed_interval_smoother_is_the_batch_least_squares_solution():
    kept, model = closed_loop_chain(np.random.default_rng(27))
    stack = {name: np.stack(kept[name], axis=1) for name in ("posterior", "prior", "transition", "correction",
                                                             "solution")}
    errors, covariance = smoother.rts(stack["posterior"], stack["prior"], stack["transition"], stack["correction"])
    smoothed = stack["solution"] - errors  # errors are computed - true: the smoothed state is s - x^s
    for member in range(3):
        mean, blocks = batch_solution(model, kept["z"], member)
        assert np.max(np.abs(smoothed[member] - mean)) < 1e-9 * max(1.0, np.max(np.abs(mean)))
        assert np.max(np.abs(covariance[member] - blocks)) < 1e-9 * np.max(np.abs(blocks))
    # the last time's smoothed estimate is the filter's; earlier ones are better than the filter's alone
    assert np.all(errors[:, -1] == 0.0)
    filtered = np.trace(stack["posterior"][:, :-1], axis1=-2, axis2=-1)
    assert np.all(np.trace(covariance[:, :-1], axis1=-2, axis2=-1) <= filtered + 1e-12)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 6), m=st.integers(1, 3), steps=st.integers(1, 25))
def test_any_chain_smoothed_is_its_batch_solution_and_no_less_certain_than_filtered(seed, n, m, steps):
    kept, model = closed_loop_chain(np.random.default_rng(seed), members=2, n=n, m=m, steps=steps)
    stack = {name: np.stack(kept[name], axis=1) for name in ("posterior", "prior", "transition", "correction",
                                                             "solution")}
    errors, covariance = smoother.rts(stack["posterior"], stack["prior"], stack["transition"], stack["correction"])
    mean, blocks = batch_solution(model, kept["z"], 1)
    assert np.max(np.abs(stack["solution"][1] - errors[1] - mean)) < 1e-8 * max(1.0, np.max(np.abs(mean)))
    assert np.max(np.abs(covariance[1] - blocks)) < 1e-8 * np.max(np.abs(blocks))
    # P^+ - P^s is positive semi-definite at every time (the smoother adds information)
    gap = np.linalg.eigvalsh(stack["posterior"] - covariance)
    assert np.all(gap >= -1e-10 * np.max(np.abs(stack["posterior"])))


def test_a_prior_without_variance_or_not_positive_definite_is_refused_in_one_line():
    kept, _ = closed_loop_chain(np.random.default_rng(3), members=2, steps=6)
    stack = {name: np.stack(kept[name], axis=1) for name in ("posterior", "prior", "transition", "correction")}
    flat = stack["prior"].copy()
    flat[1, 4, 2, :] = flat[1, 4, :, 2] = 0.0  # member 1, time 4: a state that never varied
    with pytest.raises(SimulationError, match="prior variance > 0"):
        smoother.rts(stack["posterior"], flat, stack["transition"], stack["correction"])
    indefinite = stack["prior"].copy()
    indefinite[0, 3, 0, 1] = indefinite[0, 3, 1, 0] = 2.0 * np.sqrt(indefinite[0, 3, 0, 0] * indefinite[0, 3, 1, 1])
    with pytest.raises(SimulationError, match="stored time 3 is not positive definite"):
        smoother.rts(stack["posterior"], indefinite, stack["transition"], stack["correction"])


def test_taking_out_an_error_undoes_putting_it_in():
    # corrected(s, e) takes out errors computed - true: a solution made e away from the truth (by taking out -e,
    # the radii at the truth) has analysis.errors e to rounding, and taking out e returns the truth (the radii now
    # at the solution, 10 m away: 1e-11 rad)
    rng = np.random.default_rng(4)
    count = 50
    q = rng.normal(size=(count, 4))
    truth = np.column_stack([rng.uniform(-1.2, 1.2, count), rng.uniform(-3, 3, count), rng.uniform(-100, 3000, count),
                             rng.normal(size=(count, 3)) * 20, q / np.linalg.norm(q, axis=1, keepdims=True)])
    e = np.column_stack([rng.normal(size=(count, 3)) * 10, rng.normal(size=(count, 3)), rng.normal(size=(count, 3))
                         * 2e-3])
    away = smoother.corrected(truth, -e)
    run = types.SimpleNamespace(solution=away[None], t_s=np.arange(count))
    found = analysis.errors(run, analysis.Truth(truth[:, 0], truth[:, 1], truth[:, 2], truth[:, 3:6], truth[:, 6:]))
    assert np.allclose(found.position[0], e[:, :3], atol=1e-6)
    assert np.allclose(found.velocity[0], e[:, 3:6], atol=1e-12)
    assert np.allclose(found.psi[0], e[:, 6:9], atol=1e-8)
    back = smoother.corrected(away, e)
    assert np.allclose(back[:, :6], truth[:, :6], rtol=1e-12, atol=1e-8)
    assert np.allclose(np.abs(np.einsum("ij,ij->i", back[:, 6:], truth[:, 6:])), 1.0, atol=1e-10)


def test_between_covariance_times_the_interpolated_smoother_is_the_one_kept_at_every_sample():
    # a straight 80-s drive at 50 Hz (F constant: the 1-s step's Phi is exact) with a 30-s outage, biased and noisy
    # sensors, one member: the smoother kept every second and interpolated to the samples against the one kept at
    # every sample (measured: 0.6 % of the 1-sigma at most, the 1-sigma alike to 0.17 %)
    rate, duration = 50.0, 80.0
    path = WaypointProfile(latitude=np.radians(30.5), longitude=np.radians(114.5), height=20.0, times=[0, duration],
                           speeds=[10.0, 10.0], headings=[0.5, 0.5], flight_path_angles=[0.0, 0.0])
    imu = ideal_imu(path, duration, rate)
    rng = np.random.default_rng(5)
    dt = 1.0 / rate
    increments = increments_of(imu).copy()
    increments[:, :3] += np.radians(0.05) / 3600 * dt + rng.normal(size=(imu.t_s.size, 3)) * np.radians(0.003) / 60 \
        * dt**0.5
    increments[:, 3:] += 2e-4 * dt + rng.normal(size=(imu.t_s.size, 3)) * 0.03 / 60 * dt**0.5
    times = np.arange(1.0, duration) + 0.37
    fixes = gnss_from(imu, times[(times < 30.0) | (times > 60.0)], noise=rng)
    truth = analysis.Truth(imu.latitude_rad, imu.longitude_rad, imu.height_m, imu.velocity_ned_m_s, imu.quaternion)
    found = {}
    for step in (1.0, dt):
        run = run_filter(increments, dt, start_of(path), tactical_model(), fixes, covariance_interval=step,
                         keep_for_smoother=True)
        smoothed = smoother.smooth(run)
        errors = analysis.errors(smoothed, truth)
        found[step] = (np.concatenate([errors.position, errors.velocity, errors.psi], axis=-1)[0],
                       np.sqrt(smoother.output_variances(smoothed, smoothed.t_s))[0])
    (coarse, coarse_sigma), (fine, fine_sigma) = found[1.0], found[dt]
    assert np.max(np.abs(coarse - fine) / fine_sigma) < 0.01
    assert np.allclose(coarse_sigma, fine_sigma, rtol=0.005)


@pytest.fixture(scope="module")
def consistency_members():
    """The 1,000-member consistency check's drive, truth and fixes (``test_aided_consistency``), runs kept for the
    smoother."""
    import test_aided_consistency as chunks

    path = chunks.drive()
    imu = chunks.ideal_imu(path, chunks.DURATION, chunks.RATE)
    every = int(chunks.RATE)
    pick = slice(every - 1, None, every)
    truth = analysis.Truth(imu.latitude_rad[pick], imu.longitude_rad[pick], imu.height_m[pick],
                           imu.velocity_ned_m_s[pick], imu.quaternion[pick])
    times = np.arange(1.0, chunks.DURATION) + 0.37
    times = times[(times < chunks.OUTAGE[0]) | (times > chunks.OUTAGE[0] + chunks.OUTAGE[1])]
    return chunks, path, imu, truth, times


def smoothed_chunk(consistency_members, chunk, monkeypatch, members=100):
    """One chunk of members: forward run, its smoothed run, both errors."""
    chunks, path, imu, truth, times = consistency_members
    monkeypatch.setattr(chunks, "run_filter", functools.partial(run_filter, keep_for_smoother=True))
    monkeypatch.setattr(chunks, "CHUNK", members)
    run = chunks.chunk_run(path, imu, times, np.random.default_rng([2026, chunk]))
    smoothed = smoother.smooth(run)
    return run, analysis.errors(run, truth), smoothed, analysis.errors(smoothed, truth)


def normalised_outage_errors(smoothed, errors, outage):
    """Smoothed position, velocity and psi errors over their smoothed 1-sigma at the output times in the outage."""
    inside = (smoothed.t_s > outage[0]) & (smoothed.t_s <= outage[0] + outage[1])
    sigma = np.sqrt(smoother.output_variances(smoothed, smoothed.t_s[inside]))
    found = np.concatenate([errors.position, errors.velocity, errors.psi], axis=-1)[:, inside]
    return found / sigma


def test_the_smoothed_outage_drift_is_a_fraction_of_the_forward_one(consistency_members, monkeypatch):
    # 20 members through the 60-s outage: the largest horizontal error (RMS over members of each one's largest) and
    # the 1-sigma at the outage's end, smoothed against forward (measured: 3.10 m forward, 0.36 m smoothed; the
    # 1-sigma 3.73 m and 0.17 m); the 1,000-member test below checks the smoothed 1-sigma against the errors
    chunks = consistency_members[0]
    run, found, smoothed, smoothed_found = smoothed_chunk(consistency_members, 0, monkeypatch, members=20)
    (forward,) = analysis.outage_drift(run, found, [chunks.OUTAGE])
    (backward,) = analysis.outage_drift(smoothed, smoothed_found, [chunks.OUTAGE])
    assert backward.horizontal_error_max_m < 0.15 * forward.horizontal_error_max_m
    assert backward.horizontal_error_sigma_m < 0.1 * forward.horizontal_error_sigma_m


@pytest.mark.slow
def test_a_thousand_members_smoothed_errors_match_their_smoothed_sigma(consistency_members, monkeypatch):
    # 10 chunks of 100 members (the forward consistency test's): in the outage, the RMS over members and epochs of
    # each smoothed error over its smoothed 1-sigma (position, velocity, psi; NED) within 10 % of 1 (1,000 members:
    # the RMS of unit normals is known to 2.2 % at 1 sigma, the epochs correlated); the smoothed drift below the
    # forward one in every chunk
    chunks = consistency_members[0]
    squares, forward_max, smoothed_max = [], [], []
    for chunk in range(chunks.CHUNKS):
        run, found, smoothed, smoothed_found = smoothed_chunk(consistency_members, chunk, monkeypatch)
        squares.append(np.mean(normalised_outage_errors(smoothed, smoothed_found, chunks.OUTAGE) ** 2, axis=(0, 1)))
        (forward,) = analysis.outage_drift(run, found, [chunks.OUTAGE])
        (backward,) = analysis.outage_drift(smoothed, smoothed_found, [chunks.OUTAGE])
        forward_max.append(forward.horizontal_error_max_m)
        smoothed_max.append(backward.horizontal_error_max_m)
    ratio = np.sqrt(np.mean(squares, axis=0))
    print("RMS of smoothed error / smoothed 1-sigma in the outage (position, velocity, psi; NED):",
          np.round(ratio, 3), f"; largest horizontal error forward {np.sqrt(np.mean(np.square(forward_max))):.3f} m, "
          f"smoothed {np.sqrt(np.mean(np.square(smoothed_max))):.3f} m")
    assert np.all(np.abs(ratio - 1.0) < 0.10), ratio
    assert np.all(np.array(smoothed_max) < np.array(forward_max))


def test_the_memory_is_estimated_before_the_run_and_refused_above_the_budget(consistency_members, monkeypatch):
    chunks, path, imu, _, times = consistency_members
    increments, fixes = increments_of(imu), gnss_from(imu, times)
    # one member over 300 s at 50 Hz, 540 stored times (300 steps, 239 epochs, the start): the forward run holds
    # 8 (540 (21^2 + 12) + 15,001 x 10) bytes, 3.2 MB; the smoother's prior P, Phi and corrections 8 x 540 x 903
    # more, 3.9 MB
    monkeypatch.setenv("SCHULER_MEMORY_BUDGET", "6 MB")
    run = run_filter(increments, 1.0 / chunks.RATE, start_of(path), tactical_model(), fixes)
    assert run.prior_covariance is None and run.transition is None and run.correction is None
    with pytest.raises(InvalidParameter, match="keep_for_smoother"):
        smoother.smooth(run)
    with pytest.raises(MemoryBudgetExceeded, match="with the smoother's"):
        run_filter(increments, 1.0 / chunks.RATE, start_of(path), tactical_model(), fixes, keep_for_smoother=True)
    monkeypatch.setenv("SCHULER_MEMORY_BUDGET", "10 MB")
    kept = run_filter(increments, 1.0 / chunks.RATE, start_of(path), tactical_model(), fixes,
                      keep_for_smoother=True)
    assert kept.correction is not None and kept.correction.shape == (1, 540, 21)
    assert np.array_equal(kept.solution, run.solution) and np.array_equal(kept.covariance, run.covariance)
    # the smoother's own arrays: 8 (540 x 903 + 15,000 x 48) bytes, 9.7 MB
    monkeypatch.setenv("SCHULER_MEMORY_BUDGET", "5 MB")
    with pytest.raises(MemoryBudgetExceeded, match="the smoother's covariances"):
        smoother.smooth(kept)


def test_aided_run_smooth_gives_the_forward_keys_smoothed_and_the_smoothed_columns(run_cli, tmp_path):
    out = run_cli("aided", "run", "--duration", "300", "--outage-start", "120", "--seed", "3", "--smooth", "--json",
                  "--out", str(tmp_path))
    assert out.code == 0, out.stderr
    data = out.json()
    forward = {key: value for key, value in data.items()
               if key not in ("smoothed", "inputs", "units", "monte_carlo", "schuler_version", "files", "start")}
    smoothed = data["smoothed"]
    assert set(smoothed) == set(forward)
    assert set(smoothed["outages"][0]) == set(forward["outages"][0]) and set(smoothed["nees"]) == set(forward["nees"])
    assert smoothed["nis"] == forward["nis"] and smoothed["rejected_measurements"] == forward["rejected_measurements"]
    # this seed's 60-s outage: 11.6 m forward, 0.54 m smoothed; the smoothed 1-sigma at its end 0.21 m
    assert smoothed["outages"][0]["horizontal_error_max_m"] < 0.1 * forward["outages"][0]["horizontal_error_max_m"]
    assert smoothed["position_error_horizontal_rms_m"] < forward["position_error_horizontal_rms_m"]
    header = (tmp_path / "aided_errors.csv").read_text().split("\n", 1)[0].split(",")
    forward_columns = [name for name in header if name != "t_s" and not name.startswith("smoothed_")]
    assert sorted(name for name in header if name.startswith("smoothed_")) == sorted(
        f"smoothed_{name}" for name in forward_columns)
    result = AIDED.run(duration=300.0, outage_start=120.0, seed=3, smooth=True)
    errors = result.histories["aided_errors"]
    inside = (errors.time > 120.0) & (errors.time <= 180.0)
    assert smoothed["outages"][0]["horizontal_error_max_m"] == pytest.approx(
        errors["smoothed_horizontal_error_m"][inside].max(), rel=1e-12)
    plain = AIDED.run(duration=300.0, outage_start=120.0, seed=3)
    assert "smoothed" not in plain.extras and plain.outputs == result.outputs


def test_a_run_on_files_is_smoothed_against_its_reference_and_without_one(tmp_path):
    from schuler.aided.outputs import write_simulated_files

    paths = write_simulated_files(AIDED.case(duration=300.0, outage_start=120.0), tmp_path, week_start=456_300.0)
    result = AIDED.run(kf_gins_config=str(paths["configuration"]), reference=str(paths["reference"]), smooth=True)
    (forward,), (smoothed,) = result.outages, result.smoothed["outages"]
    # KF-GINS's model on the tactical IMU's data (measured: 15.9 m forward, 0.80 m smoothed)
    assert smoothed["horizontal_error_max_m"] < 0.1 * forward["horizontal_error_max_m"]
    assert smoothed["start_s"] == forward["start_s"] == 456_420.0
    alone = AIDED.run(kf_gins_config=str(paths["configuration"]), smooth=True)
    (outage,) = alone.smoothed["outages"]
    assert outage["horizontal_error_max_m"] is None
    assert outage["horizontal_error_sigma_m"] == pytest.approx(smoothed["horizontal_error_sigma_m"], rel=1e-12)
    assert "smoothed_north_sigma_m" in alone.histories["aided_errors"] \
        and "smoothed_north_error_m" not in alone.histories["aided_errors"]


def test_the_aiding_states_are_smoothed_and_end_where_the_filter_ends():
    """With the odometer-scale and barometer-bias states (23 states) the smoother carries them too: at the last
    stored time the smoothed estimates are the filter's, and earlier they move toward the truth."""
    from schuler.aided.evaluation import _simulated_group
    from schuler.core.random import RandomStreams
    from schuler.registry import get_system

    case = get_system("aided").case(duration=400.0, outage_start=250.0,
                                    aiding="gnss-position,gnss-velocity,nhc,odometer,baro",
                                    odometer_scale_state=True, baro_bias_state=True)
    forward, _, _, (smoothed, _) = _simulated_group(case, np.arange(1), RandomStreams(4), smooth=True)
    assert forward.n_states == 23 and smoothed.aiding_estimates.shape[-1] == 2
    np.testing.assert_allclose(smoothed.aiding_estimates[0, -1], forward.aiding_estimates[0, -1], rtol=1e-9,
                               atol=1e-12)
    np.testing.assert_allclose(smoothed.sensor_estimates[0, -1], forward.sensor_estimates[0, -1], rtol=1e-9,
                               atol=1e-15)
    # the start: the smoother has seen the whole drive, the filter nothing yet
    assert not np.allclose(smoothed.aiding_estimates[0, 0], forward.aiding_estimates[0, 0])
