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


@dataclass(frozen=True)
class Histories:
    """Named time histories on one time grid, each channel with its SI unit: what a system's run keeps.

    Channel names carry their SI unit as output keys do (``delta_rad``,
    ``north_error_m``); the time column is :attr:`time_name` (``t_s``). A
    channel is shape ``(n_time,)``, or ``(members, n_time)`` for a batch.

    Attributes
    ----------
    time : ndarray, shape (n_time,)
        Time points, s.
    channels : mapping of str to ndarray
        Channel name -> values (SI).
    units : mapping of str to str
        Channel name -> SI unit (``"rad"``, ``"m"``, ``"1"``).
    time_name : str
        Name of the time column in tables and files.

    Examples
    --------
    >>> h = Histories(np.array([0.0, 1.0]), {"x_m": np.array([0.0, 2.0])}, {"x_m": "m"})
    >>> h["x_m"][-1], h.unit("x_m"), list(h.to_dataframe().columns)
    (np.float64(2.0), 'm', ['x_m'])
    """

    time: np.ndarray
    channels: dict[str, np.ndarray]
    units: dict[str, str]
    time_name: str = "t_s"

    def __post_init__(self) -> None:
        missing = [name for name in self.channels if name not in self.units]
        if missing:
            raise ValueError(f"histories without a unit: {', '.join(missing)}")
        n_time = np.shape(self.time)[0]
        wrong = [name for name, values in self.channels.items() if np.shape(values)[-1] != n_time]
        if wrong:
            raise ValueError(f"histories not on the time grid of {n_time} points: {', '.join(wrong)}")

    def __getitem__(self, name: str) -> np.ndarray:
        """The channel called ``name`` (KeyError naming the channels there are)."""
        try:
            return self.channels[name]
        except KeyError:
            raise KeyError(f"no history {name!r}; histories: {', '.join(self.channels)}") from None

    def __contains__(self, name: object) -> bool:
        return name in self.channels

    @property
    def names(self) -> tuple[str, ...]:
        """The channel names, in order."""
        return tuple(self.channels)

    def unit(self, name: str) -> str:
        """SI unit of channel ``name``.

        Parameters
        ----------
        name : str
            Channel name.
        """
        self[name]
        return self.units[name]

    def to_dataframe(self):
        """A pandas DataFrame indexed by time (``t_s``), one column per channel; units in ``attrs["units"]``.

        A batch (channels of shape ``(members, n_time)``) gets a ``(member, t_s)`` MultiIndex.
        """
        import pandas as pd

        batched = any(np.ndim(values) == 2 for values in self.channels.values())
        if not batched:
            frame = pd.DataFrame({name: np.asarray(values) for name, values in self.channels.items()},
                                 index=pd.Index(np.asarray(self.time), name=self.time_name))
        else:
            members = max(np.shape(values)[0] for values in self.channels.values() if np.ndim(values) == 2)
            index = pd.MultiIndex.from_product([np.arange(members), np.asarray(self.time)],
                                               names=["member", self.time_name])
            frame = pd.DataFrame({name: np.broadcast_to(values, (members, len(self.time))).ravel()
                                  for name, values in self.channels.items()}, index=index)
        frame.attrs["units"] = {self.time_name: "s", **self.units}
        return frame

    def plot(self, channels=None, ax=None):
        """Plot channels against time in hours (all members of a batch, thinly). Returns the Figure.

        Parameters
        ----------
        channels : sequence of str, optional
            Channel names to draw (default: all).
        ax : matplotlib.axes.Axes or sequence of them, optional
            Axes to draw into (default: a new figure, one panel per channel); values in SI.
        """
        import matplotlib.pyplot as plt

        channels = list(channels or self.names)
        if ax is None:
            fig, axes = plt.subplots(len(channels), 1, sharex=True, squeeze=False, figsize=(8, 2.2 * len(channels)))
            axes = axes[:, 0]
        else:
            axes = np.atleast_1d(ax)
            fig = axes[0].figure
        hours = np.asarray(self.time) / 3600.0
        for axis, name in zip(axes, channels):
            data = np.asarray(self[name])
            axis.plot(hours, data.T, lw=0.6 if data.ndim == 2 else 1.2)
            unit = self.units[name]
            axis.set_ylabel(f"{name} [{unit}]" if unit and unit != "1" else name)
            axis.grid(True, alpha=0.3)
        axes[-1].set_xlabel("time [h]")
        return fig
