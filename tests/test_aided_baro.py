"""Barometric height: residual and H, the bias state's sign, a round trip on the filter."""

import numpy as np
import pytest

from aided_measurement_helpers import assert_first_order, filtered_drive, model, truth
from schuler.aided import kalman, measurements, sources


def test_barometer_h_matches_its_residual_to_first_order():
    filter_model = model(scale=False, barometer=True)
    true = truth(3)
    index = filter_model.aiding_states()["barometer_bias"]
    assert index == 15 and filter_model.size == 16

    def h(solution, dx):
        # the residual bias b_h: the height compensated with b_hat = -b_h reads h + b_h
        return measurements.barometer(solution, true.height, filter_model, -dx[:, index])[0]

    _, H = measurements.barometer(true, true.height, filter_model)
    assert_first_order(h, true, H, filter_model.size, np.r_[np.ones(3), np.full(3, 0.1), np.full(9, 1e-3), 1.0])


def test_a_height_one_metre_high_reads_plus_one_and_down_error_minus_one():
    """Computed 1 m above the barometer's height: residual +1 m; a delta_r_D of +1 m (down) gives H delta_x = -1."""
    filter_model = model(scale=False)
    true = truth(1)
    residual, H = measurements.barometer(true, true.height - 1.0, filter_model)
    assert residual[0, 0] == pytest.approx(1.0)
    assert H[0, 0, 2] == -1.0 and np.count_nonzero(H) == 1


def test_barometer_bias_is_estimated_back_beside_gnss_height():
    """Round trip: a 4 m barometer bias, GNSS height (1 m) and barometer (0.3 m) at 1 Hz for 100 epochs of a static
    linear model: the bias estimate within its 1-sigma (0.1 m) of 4 m."""
    filter_model = model(scale=False, barometer=True)
    n = filter_model.size
    true = truth(1, seed=8)
    rng = np.random.default_rng(12)
    P = np.diag(np.r_[np.full(3, 25.0), np.full(12, 1e-6), 100.0])[None]
    estimate = np.zeros(n)
    gnss_H = np.zeros((1, 1, n))
    gnss_H[0, 0, 2] = 1.0
    source = sources.barometer_source(np.arange(1.0, 101.0), true.height[:, None] + 4.0
                                      + 0.3 * rng.standard_normal((1, 100)), 0.3, filter_model)
    for j in range(100):
        context = sources.Context(true, np.zeros((1, 3)), 1.0, {"barometer_bias": np.array([estimate[15]])})
        baro = source.measure(j, context)
        gnss = (np.array([[-1.0 * rng.standard_normal()]]), gnss_H, np.eye(1))
        joint, _ = kalman.stacked_update(P, [baro, gnss], 1.0)
        P = joint.covariance
        estimate[15] += joint.correction[0, 15]  # fed back: the bias compensated at the next epoch
    sigma = np.sqrt(P[0, 15, 15])
    assert sigma < 0.15
    assert abs(estimate[15] - 4.0) < sigma


@pytest.mark.slow
def test_the_command_takes_every_aiding_and_counts_rejections_per_source(run_cli):
    """``--aiding`` with the vehicle, stop and barometer measurements: the JSON's per-source counts add up to
    ``rejected_measurements``; a barometer bias of 6 m is estimated with its state; files refuse them in one line."""
    import json

    out = run_cli("aided", "run", "--duration", "300", "--outage-start", "120", "--aiding",
                  "gnss-position,gnss-velocity,zupt,zaru,nhc,odometer,baro", "--baro-bias", "6",
                  "--baro-bias-state", "--seed", "3", "--json")
    assert out.code == 0, out.stderr
    data = json.loads(out.stdout)
    counts = data["rejected_by_source"]
    assert set(counts) == {"gnss", "zupt", "zaru", "vehicle", "baro"}
    assert sum(counts.values()) == data["rejected_measurements"]
    assert data["position_error_vertical_rms_m"] < 1.0
    out = run_cli("aided", "run", "--gnss-file", "missing.txt", "--record", "missing.txt", "--aiding",
                  "gnss-position,nhc")
    assert out.code == 2 and out.stderr.count("\n") == 1


def test_barometer_bias_state_converges_on_the_drive():
    """A 6 m barometer bias beside GNSS on a 300-s tactical drive (seed 3): measured 5.92 m, 1-sigma 0.072 m
    (1.07 sigma off, one member); asserted within 2 sigma."""
    run, fm = filtered_drive({"duration": 300.0, "outage_start": 120.0, "aiding": "gnss-position,baro",
                              "baro_bias": 6.0, "baro_bias_state": True})
    index = fm.aiding_states()["barometer_bias"]
    estimate, sigma = run.aiding_estimates[0, -1, 0], np.sqrt(run.covariance[0, -1, index, index])
    assert sigma < 0.3
    assert abs(estimate - 6.0) < 2.0 * sigma
