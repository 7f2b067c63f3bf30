"""The one noise source: Monte Carlos on the compiled normals give the statistics numpy's generator gave.

The reference is the generator :class:`~schuler.core.random.RandomStreams` used before (numpy's SFC64
seeded by SeedSequence per block of 65,536 samples), written out here and swapped in by monkeypatching.
Both draw the same members independently, so each statistic pair is two independent samples of one
distribution: spreads are compared by the F test and means by Welch's t test, each at the 0.1 % level.
The error models carry noise only (no constant errors, which the parameter streams draw unchanged),
so every statistic is the noise's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from schuler.contract import Cases
from schuler.core.random import BLOCK, RandomStreams, _stream_key
from schuler.imu.error_model import ErrorModel, SensorErrors

LEVEL = 1e-3
NOISE_ONLY = ErrorModel(
    gyro=SensorErrors(random_walk=math.radians(0.125) / 60, bias_instability=math.radians(0.5) / 3600,
                      flicker_tau_range_s=(1.0, 1000.0)),
    accel=SensorErrors(random_walk=0.065 * 0.3048 / 60, bias_instability=5e-4),
    name="tactical noise alone")
"""The tactical grade's white noise and a flicker bias instability, no constant error."""


def _numpy_generator(key: int, member: int, block: int) -> np.random.Generator:
    return np.random.Generator(np.random.SFC64(np.random.SeedSequence([key, member, block])))


def _numpy_series(self, stream, members, start, stop):
    key, out = _stream_key(self.seed, stream), np.empty((len(np.atleast_1d(members)), stop - start))
    for row, member in enumerate(np.atleast_1d(members)):
        for block in range(start // BLOCK, (stop - 1) // BLOCK + 1):
            values = _numpy_generator(key, int(member), block).standard_normal(BLOCK)
            lo, hi = max(start, block * BLOCK), min(stop, (block + 1) * BLOCK)
            out[row, lo - start:hi - start] = values[lo - block * BLOCK:hi - block * BLOCK]
    return out


def _numpy_block(self, stream, member, block, size):
    return _numpy_generator(_stream_key(self.seed, stream), int(member), int(block)).standard_normal(int(size))


def both_generators(monkeypatch, run):
    """``run()`` on the compiled normals, then on numpy's generator."""
    ours = run()
    with monkeypatch.context() as patch:
        patch.setattr(RandomStreams, "normal_series", _numpy_series)
        patch.setattr(RandomStreams, "normal_block", _numpy_block)
        theirs = run()
    return ours, theirs


def assert_same_distribution(ours: np.ndarray, theirs: np.ndarray) -> None:
    ratio = np.var(ours, ddof=1) / np.var(theirs, ddof=1)
    low, high = stats.f.ppf([LEVEL / 2, 1 - LEVEL / 2], ours.size - 1, theirs.size - 1)
    assert low < ratio < high, f"variance ratio {ratio:.3f} outside [{low:.3f}, {high:.3f}]"
    assert stats.ttest_ind(ours, theirs, equal_var=False).pvalue > LEVEL
    assert not np.array_equal(ours, theirs)  # two generators indeed


def test_the_reference_is_the_former_generator():
    # the swapped-in methods keep the addressing rules: a window is the slice of the whole series
    streams = RandomStreams(3)
    whole = _numpy_series(streams, "s", [4], 0, BLOCK + 100)
    assert np.array_equal(_numpy_series(streams, "s", [4], BLOCK - 50, BLOCK + 100)[0], whole[0, BLOCK - 50:])
    assert np.array_equal(_numpy_block(streams, "s", 4, 1, 100), whole[0, BLOCK:])


SPEC = """name = "tactical noise alone"
[gyro]
random_walk = "0.125 deg/h^0.5"
bias_instability = "0.5 deg/h"
flicker_tau_range = ["1 s", "1000 s"]
[accel]
random_walk = "0.065 ft/s/h^0.5"
bias_instability = "50 ug"
flicker_tau_range = ["1 s", "1000 s"]
"""


@pytest.mark.slow
def test_navigate_with_the_imu_layers_full_noise_model(monkeypatch, tmp_path):
    from schuler.navigate.api import SYSTEM

    # navigate --imu SPEC --monte-carlo: the IMU layer's simulator, white noise and the flicker's slow processes
    spec = tmp_path / "noise.toml"
    spec.write_text(SPEC)
    case = SYSTEM.case(imu=str(spec), duration=300.0, imu_rate=100.0, output_step=60.0)
    ours, theirs = both_generators(monkeypatch, lambda: SYSTEM.evaluate(Cases.from_case(case, 300,
                                                                                         random=RandomStreams(5))))
    for name in ("final_position_error_north_m", "final_velocity_error_east_m_s", "final_heading_error_rad",
                 "final_roll_error_rad"):
        assert_same_distribution(np.asarray(ours[name]), np.asarray(theirs[name]))


def test_the_coarse_alignment_of_simulated_records(monkeypatch):
    from schuler.alignment.coarse import align_coarse
    from schuler.alignment.comparison import simulated_batch

    def run():
        batch, _ = simulated_batch(NOISE_ONLY, latitude=math.radians(45.0), heading=math.radians(30.0),
                                   duration=60.0, sample_interval=0.01, members=300, seed=2)
        estimate = align_coarse(batch)
        return estimate.heading_rad, estimate.roll_rad

    ours, theirs = both_generators(monkeypatch, run)
    for mine, former in zip(ours, theirs):
        assert_same_distribution(np.ravel(mine), np.ravel(former))
