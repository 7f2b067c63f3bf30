"""The time response of a (batch of) linear model(s): named channels, units, table and plot."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Response:
    """Time response of a (batch of) state-space model(s).

    Attributes
    ----------
    time : ndarray, shape (n_time,)
        Time points, s.
    states : ndarray, shape (n_time, n) or (N, n_time, n)
        State channels (``n`` may be 0 when only outputs were asked for).
    outputs : ndarray, shape (n_time, p) or (N, n_time, p)
    state_names, output_names, state_units, output_units : tuple of str
    """

    time: np.ndarray
    states: np.ndarray
    outputs: np.ndarray
    state_names: tuple[str, ...]
    output_names: tuple[str, ...]
    state_units: tuple[str, ...]
    output_units: tuple[str, ...]

    @property
    def batched(self) -> bool:
        return self.outputs.ndim == 3

    def __getitem__(self, name: str) -> np.ndarray:
        """A named output (or, failing that, state), shape (n_time,) or (N, n_time)."""
        if name in self.output_names:
            return self.outputs[..., self.output_names.index(name)]
        if name in self.state_names:
            return self.states[..., self.state_names.index(name)]
        raise KeyError(f"no channel {name!r}; outputs are {self.output_names}, states {self.state_names}")

    def unit(self, name: str) -> str:
        """SI unit of a state or output channel.

        Parameters
        ----------
        name : str
            Channel name.
        """
        if name in self.output_names:
            return self.output_units[self.output_names.index(name)]
        return self.state_units[self.state_names.index(name)]

    def to_dataframe(self):
        """A pandas DataFrame: one row per time (and member for a batch), one column per output."""
        import pandas as pd

        if not self.batched:
            frame = pd.DataFrame(self.outputs, columns=list(self.output_names))
            frame.insert(0, "time", self.time)
            return frame
        members, n_time, p = self.outputs.shape
        frame = pd.DataFrame(self.outputs.reshape(-1, p), columns=list(self.output_names))
        frame.insert(0, "time", np.tile(self.time, members))
        frame.insert(0, "member", np.repeat(np.arange(members), n_time))
        return frame

    def plot(self, channels=None, ax=None):
        """Plot outputs against time (all members of a batch, thinly). Returns the Figure.

        Parameters
        ----------
        channels : sequence of str, optional
            Output names to draw (default: all outputs).
        ax : matplotlib.axes.Axes, optional
            Axes to draw into (default: a new figure); time in s, outputs in their SI units.
        """
        import matplotlib.pyplot as plt

        channels = list(channels or self.output_names)
        if ax is None:
            fig, axes = plt.subplots(len(channels), 1, sharex=True, squeeze=False, figsize=(8, 2.2 * len(channels)))
            axes = axes[:, 0]
        else:
            axes = np.atleast_1d(ax)
            fig = axes[0].figure
        for axis, name in zip(axes, channels):
            data = self[name]
            axis.plot(self.time, data.T if self.batched else data, lw=0.6 if self.batched else 1.2)
            axis.set_ylabel(f"{name} [{self.unit(name)}]" if self.unit(name) else name)
            axis.grid(True, alpha=0.3)
        axes[-1].set_xlabel("time [s]")
        return fig
