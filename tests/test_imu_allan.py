"""Allan deviation: the streamed estimator against allantools, invariances, confidence intervals."""

from __future__ import annotations

import allantools
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.exceptions import InvalidParameter
from schuler.imu.allan import AllanAccumulator, allan_deviation, allan_lags, noise_types


def noisy(n=200_000, seed=1, mean=0.0):
    rng = np.random.default_rng(seed)
    return mean + 1e-3 * rng.normal(size=n) + 1e-6 * np.cumsum(rng.normal(size=n))


@pytest.mark.parametrize("chunk", [1 << 20, 65_536, 9_999])
def test_matches_allantools_to_1e12(chunk):
    y, dt = noisy(), 0.01
    lags = allan_lags(y.size)
    curve = allan_deviation(y, dt, lags=lags, chunk=chunk)
    taus, adev, _, terms = allantools.oadev(y, rate=1 / dt, data_type="freq", taus=lags * dt)
    assert np.array_equal(curve.terms, terms)
    assert np.max(np.abs(curve.adev / adev - 1.0)) < 1e-12


def test_large_offset_does_not_cost_digits():
    # 9.8 m/s^2 on z with 1e-5 m/s^2 noise: the offset is removed before integrating
    y, dt = noisy(mean=0.0) * 1e-2, 0.01
    base = allan_deviation(y, dt).adev
    shifted = allan_deviation(y + 9.8, dt, chunk=50_000).adev
    assert np.max(np.abs(shifted / base - 1.0)) < 1e-9


@settings(max_examples=10, deadline=None)
@given(offset=st.floats(-100, 100), scale=st.floats(1e-6, 1e3), cut=st.integers(1, 4999))
def test_invariant_to_offset_scaled_by_scale_and_independent_of_cut(offset, scale, cut):
    y = noisy(n=5000, seed=3)
    lags = allan_lags(5000)
    base = allan_deviation(y, 0.1, lags=lags).adev
    accumulator = AllanAccumulator(0.1, lags, channels=1)
    accumulator.update(scale * y[:cut] + offset)
    accumulator.update(scale * y[cut:] + offset)
    assert accumulator.curves(with_confidence=False)[0].adev == pytest.approx(scale * base, rel=1e-7)


def test_white_noise_curve_and_interval_coverage():
    # white rate noise of per-sample sigma s: sigma_A(tau) = s sqrt(tau0 / tau); about 68 % of the
    # points' 68 % intervals should cover the truth (30 seeds x 12 lags; 3-sigma binomial band 0.60-0.76)
    covered, total = 0, 0
    for seed in range(30):
        y = np.random.default_rng(seed).normal(size=20_000)
        curve = allan_deviation(y, 1.0, lags=allan_lags(20_000, per_octave=1))
        truth = 1.0 / np.sqrt(curve.tau_s)
        covered += int(np.sum((curve.adev_lower <= truth) & (truth <= curve.adev_upper)))
        total += truth.size
        assert np.all(curve.alpha[:8] == 0)  # white FM everywhere the curve is well determined
    assert 0.60 <= covered / total <= 0.76


def test_noise_types_from_slopes():
    tau = np.geomspace(1, 1000, 31)
    assert set(noise_types(tau, 1 / tau**2)) == {2}
    assert set(noise_types(tau, 1 / tau)) == {0}
    assert set(noise_types(tau, np.ones_like(tau))) == {-1}
    assert set(noise_types(tau, tau)) == {-2}


def test_lags_and_bad_input():
    assert allan_lags(1000, per_octave=2).tolist() == [1, 2, 3, 4, 6, 8, 11, 16, 23, 32, 45, 64, 91]
    with pytest.raises(InvalidParameter, match="at least 4"):
        allan_lags(3)
    accumulator = AllanAccumulator(1.0, [1, 2], channels=2)
    with pytest.raises(InvalidParameter, match="shape"):
        accumulator.update(np.zeros((10, 3)))
    with pytest.raises(InvalidParameter, match="finite"):
        accumulator.update(np.full((10, 2), np.nan))


def test_memory_is_bounded_by_the_longest_lag():
    accumulator = AllanAccumulator(1.0, [1, 4, 16], channels=1)
    for _ in range(5):
        accumulator.update(np.random.default_rng(0).normal(size=100_000))
    assert accumulator._tails[0].size == 2 * 16 + 1
    assert accumulator.samples == 500_000
