"""Torque-pulse shapes of the pulse generator, their symmetry and exact integrals.

A pulse of duration tau has the current ``i(t) = amplitude * shape(t / tau)``
with ``shape`` defined on normalised time ``u = t / tau`` in [0, 1]. Every shape
is stored as a piecewise-linear function (jumps allowed at the knots), so that
rectangular and triangular pulses are represented exactly and a user-defined
pulse is its linear interpolation between given samples. Piecewise-linear
shapes let the time-domain simulation be exact (an integrator state carries the
ramp part, a held input the steps: see :mod:`schuler.drift_calibration.stabilizer`)
and every integral of the source's equations (6)-(12) be evaluated in closed
form here.

The quantity that decides whether the method works is the bracket of the
source's (11)/(12),

    B = 2 * int_0^tau int_0^t i ds dt - tau * int_0^tau i dt
      = int_0^tau (tau - 2 t) i(t) dt,

(the second form by integrating by parts): it vanishes for any pulse symmetric
in time, i(t) = i(tau - t), because (tau - 2t) is odd about tau/2.

Examples
--------
>>> p = triangular()
>>> p.area(), round(p.first_moment(), 12), p.is_symmetric()
(0.5, 0.25, True)
>>> p.symmetry_bracket()
0.0
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.exceptions import InvalidParameter


@dataclass(frozen=True)
class PulseShape:
    """A piecewise-linear pulse shape on normalised time u in [0, 1].

    Parameters
    ----------
    knots : array_like, shape (k + 1,)
        Segment boundaries, strictly increasing from 0 to 1.
    start_values, end_values : array_like, shape (k,)
        Shape value (dimensionless, relative to the amplitude) just after the
        left knot and just before the right knot of each segment; a jump at a
        knot is a difference between neighbouring end and start values.
    name : str
        Shown in results and plots.
    """

    knots: np.ndarray
    start_values: np.ndarray
    end_values: np.ndarray
    name: str = "user-defined"

    def __post_init__(self):
        knots = np.asarray(self.knots, dtype=float)
        start = np.asarray(self.start_values, dtype=float)
        end = np.asarray(self.end_values, dtype=float)
        if knots.ndim != 1 or knots.size < 2 or knots[0] != 0.0 or knots[-1] != 1.0 or np.any(np.diff(knots) <= 0):
            raise InvalidParameter("pulse_shape", "knots must increase strictly from 0 to 1")
        if start.shape != (knots.size - 1,) or end.shape != start.shape:
            raise InvalidParameter("pulse_shape", "need one start and one end value per segment")
        if not (np.all(np.isfinite(start)) and np.all(np.isfinite(end))):
            raise InvalidParameter("pulse_shape", "values must be finite")
        object.__setattr__(self, "knots", knots)
        object.__setattr__(self, "start_values", start)
        object.__setattr__(self, "end_values", end)
        if self.area() <= 0.0:
            raise InvalidParameter("pulse_shape", "the pulse must have a positive area")

    @property
    def slopes(self) -> np.ndarray:
        """d shape / du on each segment."""
        return (self.end_values - self.start_values) / np.diff(self.knots)

    def __call__(self, u) -> np.ndarray:
        """Shape value at normalised times ``u`` (right-continuous at jumps, 0 outside)."""
        u = np.asarray(u, dtype=float)
        index = np.clip(np.searchsorted(self.knots, u, side="right") - 1, 0, self.knots.size - 2)
        value = self.start_values[index] + self.slopes[index] * (u - self.knots[index])
        return np.where((u >= 0.0) & (u <= 1.0), value, 0.0)

    def _segment_moments(self, power: int) -> float:
        """Exact int_0^1 u**power shape(u) du over the linear segments."""
        a, b = self.knots[:-1], self.knots[1:]
        slope = self.slopes
        offset = self.start_values - slope * a  # shape = offset + slope * u on a segment
        p = power
        total = offset * (b ** (p + 1) - a ** (p + 1)) / (p + 1) + slope * (b ** (p + 2) - a ** (p + 2)) / (p + 2)
        return float(np.sum(total))

    def area(self) -> float:
        """int_0^1 shape du (so int_0^tau i dt = amplitude * tau * area)."""
        return self._segment_moments(0)

    def first_moment(self) -> float:
        """int_0^1 u shape du (so int_0^tau t i dt = amplitude * tau**2 * first_moment)."""
        return self._segment_moments(1)

    def double_integral(self) -> float:
        """int_0^1 int_0^u shape ds du = area - first_moment (the double integral of (7))."""
        return self.area() - self.first_moment()

    def symmetry_bracket(self) -> float:
        """Normalised bracket of (11): int_0^1 (1 - 2u) shape du; zero for a time-symmetric pulse.

        The dimensional bracket is ``amplitude * tau**2 * symmetry_bracket()``.
        """
        return self.area() - 2.0 * self.first_moment()

    def is_symmetric(self, tolerance: float = 1e-12) -> bool:
        """Whether shape(u) == shape(1 - u) at every knot (both sides) and mid-segment.

        Parameters
        ----------
        tolerance : float
            Largest difference allowed, in units of the pulse amplitude (dimensionless).
        """
        probes = np.concatenate([self.knots, 0.5 * (self.knots[:-1] + self.knots[1:])])
        inside = np.clip(probes, 1e-300, 1.0 - 1e-16)
        scale = max(np.max(np.abs(self.start_values)), np.max(np.abs(self.end_values)))
        left = self(inside)
        right = self(np.clip(1.0 - inside, 0.0, 1.0))
        mirrored_knots = np.allclose(np.sort(1.0 - self.knots), self.knots, atol=tolerance)
        return bool(mirrored_knots and np.allclose(left[1:-1], right[1:-1], atol=tolerance * scale)
                    and abs(self.symmetry_bracket()) <= tolerance * scale)


def rectangular() -> PulseShape:
    """The rectangular pulse of the source's Fig. 4: shape = 1 on [0, 1].

    >>> rectangular().area()
    1.0
    """
    return PulseShape(np.array([0.0, 1.0]), np.array([1.0]), np.array([1.0]), name="rectangular")


def triangular() -> PulseShape:
    """The triangular pulse of the source's Fig. 5: rising to 1 at u = 1/2, back to 0.

    >>> triangular()(0.25)
    array(0.5)
    """
    return PulseShape(np.array([0.0, 0.5, 1.0]), np.array([0.0, 1.0]), np.array([1.0, 0.0]), name="triangular")


def from_samples(times, values, name: str = "user-defined") -> PulseShape:
    """A user-defined shape through samples (linear interpolation between them).

    Parameters
    ----------
    times : array_like
        Normalised sample times (dimensionless, time / tau), strictly increasing from 0 to 1.
    values : array_like
        Shape values at those times (dimensionless, relative to the amplitude).
    name : str
        Label of the shape.

    Examples
    --------
    >>> p = from_samples([0, 0.2, 1], [1, 1, 0])
    >>> round(p.area(), 12), p.is_symmetric()
    (0.6, False)
    """
    times = np.asarray(times, dtype=float)
    values = np.asarray(values, dtype=float)
    if values.shape != times.shape:
        raise InvalidParameter("pulse_shape", "need one value per sample time")
    return PulseShape(times, values[:-1], values[1:], name=name)


def from_function(function, samples: int = 201, name: str = "user-defined") -> PulseShape:
    """A user-defined shape from a callable on [0, 1], linearly interpolated at ``samples`` points.

    Parameters
    ----------
    function : callable
        ``function(u)`` for the normalised time u = t / tau in [0, 1] (dimensionless), returning the shape
        relative to the amplitude.
    samples : int
        Number of interpolation points.
    name : str
        Label of the shape.

    Examples
    --------
    >>> p = from_function(lambda u: np.sin(np.pi * u), samples=101)
    >>> p.is_symmetric()
    True
    """
    if samples < 2:
        raise InvalidParameter("samples", "need at least two samples")
    u = np.linspace(0.0, 1.0, samples)
    return from_samples(u, np.asarray(function(u), dtype=float) * np.ones_like(u), name=name)


SHAPES = {"rectangular": rectangular, "triangular": triangular}
"""Named shapes selectable from the CLI."""
