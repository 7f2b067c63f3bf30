"""Reducers for :func:`schuler.core.lti.simulate_reduce`: what is kept of each chunk of members.

A reducer is any callable ``reducer(chunk, members)``: ``chunk`` is a batched
:class:`~schuler.core.response.Response` of shape (k, T, .) holding members
``members`` (a slice of range(N)); it keeps what it needs and lets the
histories go. Three common ones are here. The first two also take a
summary, ``take_summary(final, peak, members)``: the engine then reduces the
samples as it makes them and writes no history at all.

Examples
--------
>>> import numpy as np
>>> from schuler.core.response import Response
>>> t = np.array([0.0, 1.0])
>>> chunk = Response(t, np.zeros((2, 2, 0)), np.array([[[0.0], [1.0]], [[0.0], [3.0]]]), (), ("y",), (), ("m",))
>>> finals = FinalOutputs(2, 1)
>>> finals(chunk, slice(0, 2))
>>> finals.values[:, 0]
array([1., 3.])
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from schuler.core._lti_kernels import final_and_peak
from schuler.core.response import Response
from schuler.core.stats import StreamingStatistics

Reducer = Callable[[Response, slice], None]
"""The reducer protocol: called with each chunk's response and the slice of members it holds."""


class FinalOutputs:
    """Every member's outputs at the last time point.

    Parameters
    ----------
    members : int
        N.
    n_outputs : int
        Outputs per member (those passed to the reducer).

    Attributes
    ----------
    values : ndarray, shape (N, n_outputs)
    """

    def __init__(self, members: int, n_outputs: int):
        self.values = np.full((members, n_outputs), np.nan)

    def __call__(self, chunk: Response, members: slice) -> None:
        self.values[members] = chunk.outputs[:, -1, :]

    def take_summary(self, final: np.ndarray, peak: np.ndarray, members: slice) -> None:
        """Keep the final outputs of members ``members``, computed without histories.

        Parameters
        ----------
        final, peak : ndarray, shape (k, n_outputs)
            Outputs at the last time and max over time of |output|, SI units of the outputs.
        members : slice
            Which members (of range(N)).
        """
        self.values[members] = final


class PeakOutputs:
    """Every member's final outputs and their largest magnitude over the run (what a Monte Carlo keeps).

    One compiled pass over each chunk's histories.

    Parameters
    ----------
    members : int
        N.
    n_outputs : int
        Outputs per member (those passed to the reducer).

    Attributes
    ----------
    final : ndarray, shape (N, n_outputs)
        Outputs at the last time point.
    peak : ndarray, shape (N, n_outputs)
        max over time of |output|.
    """

    def __init__(self, members: int, n_outputs: int):
        self.final = np.full((members, n_outputs), np.nan)
        self.peak = np.full((members, n_outputs), np.nan)

    def __call__(self, chunk: Response, members: slice) -> None:
        k = chunk.outputs.shape[0]
        final, peak = np.empty((k, self.final.shape[1])), np.empty((k, self.final.shape[1]))
        final_and_peak(chunk.outputs, final, peak)
        self.take_summary(final, peak, members)

    def take_summary(self, final: np.ndarray, peak: np.ndarray, members: slice) -> None:
        """Keep the final and peak outputs of members ``members``, computed without histories.

        Parameters
        ----------
        final, peak : ndarray, shape (k, n_outputs)
            Outputs at the last time and max over time of |output|, SI units of the outputs.
        members : slice
            Which members (of range(N)).
        """
        self.final[members], self.peak[members] = final, peak


class OutputStatistics:
    """Per-time statistics of the outputs over members (:class:`StreamingStatistics`).

    Parameters
    ----------
    shape : tuple of int
        (T, p): time points and outputs of one member.
    reservoir_size : int
        Members kept for percentiles.
    seed : int
        Seed of the reservoir's draw.

    Attributes
    ----------
    statistics : StreamingStatistics
    """

    def __init__(self, shape: tuple[int, int], reservoir_size: int = 0, seed: int = 0):
        self.statistics = StreamingStatistics(shape, reservoir_size=reservoir_size, seed=seed)

    def __call__(self, chunk: Response, members: slice) -> None:
        self.statistics.update(chunk.outputs)
