"""The compiled normals of :class:`schuler.core.random.RandomStreams`: the ziggurat, the distribution, the addresses."""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats
from scipy.special import erfc

from schuler.core import _normal_kernels
from schuler.core.random import BLOCK, RandomStreams

DRAWS = 2_000_000


@pytest.fixture(scope="module")
def normals() -> np.ndarray:
    return RandomStreams(11).normal_series("gyro_x/white", [3], 0, DRAWS)[0]


@pytest.mark.parametrize(("layers", "tail_start", "area"), [
    (256, 3.6541528853610088, 4.92867323399e-3),   # Marsaglia and Tsang (2000), the 256-layer table
    (128, 3.442619855899, 9.91256303526217e-3),    # and the 128-layer one
])
def test_the_ziggurat_is_marsaglia_and_tsangs(layers, tail_start, area):
    r, v, x, f = _normal_kernels.ziggurat_tables(layers)
    assert r == pytest.approx(tail_start, rel=1e-11) and v == pytest.approx(area, rel=1e-10)
    # every layer holds the same area V: the base with its tail, the others as rectangles under the curve
    assert r * math.exp(-r * r / 2) + math.sqrt(math.pi / 2) * erfc(r / math.sqrt(2)) == pytest.approx(v, rel=1e-13)
    np.testing.assert_allclose(x[1:-1] * (f[2:] - f[1:-1]), v, rtol=1e-9)
    assert x[0] * f[1] == pytest.approx(v, rel=1e-13) and x[-1] == 0.0 and np.all(np.diff(x[1:]) < 0)


def test_the_draws_are_standard_normal(normals):
    n = normals.size
    # Kolmogorov-Smirnov statistic below its 0.1 % critical value 1.95 / sqrt(n)
    assert stats.kstest(normals, "norm").statistic < 1.95 / math.sqrt(n)
    # moments within 5 standard errors: mean 1/sqrt(n), variance sqrt(2/n), third sqrt(15/n), fourth sqrt(96/n)
    assert abs(normals.mean()) < 5 / math.sqrt(n)
    assert abs(normals.var() - 1) < 5 * math.sqrt(2 / n)
    assert abs(np.mean(normals**3)) < 5 * math.sqrt(15 / n)
    assert abs(np.mean(normals**4) - 3) < 5 * math.sqrt(96 / n)


@pytest.mark.parametrize("beyond", [1.0, 2.5, 3.6541528853610088, 4.0, 4.5])
def test_the_tails_and_wedges_have_their_probability(normals, beyond):
    # the fraction beyond each point, across the wedges and the exact tail (beyond R = 3.654), within 5 sigma
    p = 2 * stats.norm.sf(beyond)
    assert abs(np.mean(np.abs(normals) > beyond) - p) < 5 * math.sqrt(p * (1 - p) / normals.size) + 1 / normals.size


def test_members_streams_and_neighbouring_samples_are_uncorrelated():
    streams, n = RandomStreams(2), 200_000
    a, b = streams.normal_series("a", [0, 1], 0, n)
    c = streams.normal_series("b", [0], 0, n)[0]
    # two members, two streams, neighbours in time, the same position in two blocks: |r| within 5 / sqrt(n)
    for u, v in ((a, b), (a, c), (a[1:], a[:-1]), (a[BLOCK:2 * BLOCK], a[:BLOCK])):
        assert abs(np.corrcoef(u, v)[0, 1]) < 5 / math.sqrt(u.size)


@settings(max_examples=40, deadline=None)
@given(start=st.integers(0, 3 * BLOCK), length=st.integers(0, 2 * BLOCK), member=st.integers(0, 2**40))
def test_a_window_is_the_same_numbers_however_the_series_is_cut(start, length, member):
    streams = RandomStreams(9)
    whole = streams.normal_series("s", [member], 0, start + length)[0]
    assert np.array_equal(streams.normal_series("s", [member], start, start + length)[0], whole[start:])


def test_any_thread_draws_the_same_numbers():
    streams, members = RandomStreams(4), np.arange(8)
    together = streams.normal_series("s", members, 1000, 50_000)
    with ThreadPoolExecutor(4) as pool:
        apart = list(pool.map(lambda m: streams.normal_series("s", [m], 1000, 50_000)[0], members))
    assert np.array_equal(np.stack(apart), together)
