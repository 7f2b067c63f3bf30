"""Coulomb friction in the gimbal bearings, eqs. (30)-(32), solved as a differential inclusion.

Equation numbers are those of Drozdovich (1959) (:data:`schuler.references.DROZDOVICH_1959`).

With the simplest base motion (no Earth rotation, Schuler-tuned) the vertical obeys

    beta'  = Delta v_x / R - q_1 sign(alpha'),      Delta v_x' = -g beta + W_x(t),
    alpha' = -Delta v_y / R + q_2 sign(beta'),      Delta v_y' =  g alpha + W_y(t),

which is (30) with Delta v_x = -g int beta dt, Delta v_y = g int alpha dt (the
velocity errors of (28)) and q_i = M_fr,i / H (31): q_1 for the outer axis x (the
alpha axis), q_2 for the inner axis y (the beta axis). W_x, W_y are accelerations
acting on the accelerometers besides the compensated ones (a test input).

Each bearing's friction torque precesses the gyro about the *other* axis, so the
sign terms are coupled. Write a = Delta v_x / R, b = -Delta v_y / R. Solving the
inclusion (sign(0) = [-1, 1]) shows:

* both axes stick together (alpha' = beta' = 0) exactly when |a| <= q_1 and
  |b| <= q_2 (|g int beta dt| / R <= q_1, |g int alpha dt| / R <= q_2);
* outside that box both axes slip and the signs are fixed by (a, b) alone:
  for a > q_1, sign(beta') = +1 and sign(alpha') = sign(b + q_2); for a < -q_1,
  sign(beta') = -1 and sign(alpha') = sign(b - q_2); for |a| <= q_1 and b > q_2,
  (sign alpha', sign beta') = (+1, -1); for b < -q_2, (-1, +1).

Because a' and b' do not contain the friction terms, the lines a = +-q_1,
b = +-q_2 are crossed transversally: there is no sliding mode and no chattering.
The solver integrates each cell of the (a, b) plane with its fixed signs and
switches cells at the crossings, located as solve_ivp events. Taking each axis
stuck whenever its own rate vanishes would be wrong: the friction torque of one
bearing acts through the other axis's rate.

While stuck, the integrators keep integrating the tilt, so the vertical rests
only when its tilts also balance the input; its velocity errors then lie inside
the dead zone |Delta v_x| <= R q_1, |Delta v_y| <= R q_2 (32, with the factor R
the source drops). Where inside depends on the history.

The rest is not stable, though: in slip, each bearing's friction drives the other
axis's Schuler loop with a square wave at that loop's own frequency. The coning
of the spin axis locks into the sense in which both drives are in resonant phase,
and the velocity-error amplitudes grow by 2 q_i sqrt(g R) / pi per second, 4 R q_i
per Schuler period (:func:`friction_growth_rate`). The source's model has no
damping to stop it.

Examples
--------
A tilt of 1e-6 rad: the gimbals stick while the x integrator runs up to the edge
-R q_1 = -0.01 m/s, where the gyro breaks away:

>>> sim = simulate_friction(q=(1.5625e-9, 1.5625e-9), initial_tilt=(0.0, 1e-6),
...                         time=np.linspace(0, 3600, 7))
>>> sim.stick_intervals[0].round(1).tolist(), round(float(sim.stick_velocity_errors[0, 2]), 9)
([0.0, 1019.4], -0.01)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np
from scipy.integrate import solve_ivp

from schuler.exceptions import InvalidParameter, SimulationError
from schuler.gyro_vertical.model import ATOL_TILT, ATOL_VELOCITY, RTOL

# Signs (sign alpha', sign beta') of the slipping cells, keyed by the cell
# (A, B) of (a, b): A = +1 for a > q_1, 0 inside [-q_1, q_1], -1 below; B likewise.
_SIGNS = {
    (1, 1): (1, 1), (1, 0): (1, 1), (1, -1): (-1, 1),
    (-1, 1): (1, -1), (-1, 0): (-1, -1), (-1, -1): (-1, -1),
    (0, 1): (1, -1), (0, -1): (-1, 1),
}
_MAX_EVENTS = 100_000
# Each cell's exits lie up to this far (as a velocity error, m/s) beyond its edges, so that a
# state resting exactly on an edge (e.g. q = 0 on a quiet axis) cannot trigger an exit
# that is no crossing; it shifts the dead zone's edges by a negligible 1e-12 m/s.
EVENT_HYSTERESIS = 1e-12


def friction_from_velocity_error(velocity_error, radius):
    """Friction torque over angular momentum q = M_fr / H (1/s) for a dead-zone half-width.

    From (32) with the factor R: |Delta v| = R q.

    Parameters
    ----------
    velocity_error : float or ndarray
        m/s.
    radius : float
        R, m.

    Examples
    --------
    >>> friction_from_velocity_error(0.01, 6.4e6)
    1.5625e-09
    """
    return np.asarray(velocity_error) / radius if np.ndim(velocity_error) else velocity_error / radius


def friction_growth_rate(q, gravity, radius):
    """Growth rate of the velocity-error amplitudes under coupled Coulomb friction, m/s^2.

    In slip the x bearing's friction drives the beta loop (Delta v_x) with the
    square wave -q_1 sign(alpha'), and the y bearing's the alpha loop (Delta v_y)
    with q_2 sign(beta'). Both loops run at the Schuler frequency, so the motion
    locks into the sense in which each square wave is in resonant phase: the
    fundamental 4 q_i / pi of a square wave raises a tilt amplitude by
    (4 q_i / pi) / 2 per second, and the velocity amplitudes grow by
    2 q_i sqrt(g R) / pi per second, i.e. by 4 R q_i per Schuler period. Stick
    phases are neglected (they are short once the amplitude exceeds R q).

    Parameters
    ----------
    q : pair of float or ndarray
        (q_1, q_2), 1/s (both > 0 for the lock-in).
    gravity, radius : float or ndarray
        g (m/s^2), R (m).

    Returns
    -------
    rate_x, rate_y : float or ndarray
        Growth of the amplitudes of Delta v_x and Delta v_y, m/s per s.

    Examples
    --------
    >>> rate_x, _ = friction_growth_rate((1.5625e-9, 1.5625e-9), 9.81, 6.4e6)
    >>> round(float(rate_x * 2 * np.pi * np.sqrt(6.4e6 / 9.81)), 4)   # per Schuler period: 4 R q_1
    0.04
    """
    scale = 2.0 * np.sqrt(np.asarray(gravity) * radius) / np.pi
    return scale * np.asarray(q[0]), scale * np.asarray(q[1])


@dataclass(frozen=True)
class AccelerationInput:
    """Piecewise-linear accelerations W_x(t), W_y(t) on the accelerometers, held after the last knot.

    Parameters
    ----------
    times : array_like
        Knot times, s (first 0, increasing).
    W_x, W_y : array_like
        Values at the knots, m/s^2.
    """

    times: np.ndarray
    W_x: np.ndarray
    W_y: np.ndarray

    def __post_init__(self):
        arrays = [np.atleast_1d(np.asarray(a, dtype=float)) for a in (self.times, self.W_x, self.W_y)]
        if len({a.shape for a in arrays}) != 1 or not all(np.all(np.isfinite(a)) for a in arrays):
            raise InvalidParameter("acceleration", "needs finite W_x, W_y values, one per knot time")
        if arrays[0][0] != 0.0 or np.any(np.diff(arrays[0]) <= 0):
            raise InvalidParameter("acceleration", "knot times must start at 0 and increase")
        for name, value in zip(("times", "W_x", "W_y"), arrays):
            object.__setattr__(self, name, value)

    @classmethod
    def constant(cls, W_x: float = 0.0, W_y: float = 0.0) -> AccelerationInput:
        """Constant accelerations.

        Parameters
        ----------
        W_x, W_y : float
            Accelerations on the x and y accelerometers, m/s^2.
        """
        return cls(np.zeros(1), np.array([W_x], dtype=float), np.array([W_y], dtype=float))

    @classmethod
    def ramp(cls, W_x_final: float, W_y_final: float, duration: float) -> AccelerationInput:
        """From zero to the final values over ``duration`` (s), then held.

        Parameters
        ----------
        W_x_final, W_y_final : float
            Accelerations reached at the end of the ramp, m/s^2.
        duration : float
            Length of the ramp, s.
        """
        return cls(np.array([0.0, duration]), np.array([0.0, W_x_final]), np.array([0.0, W_y_final]))

    def piece(self, index: int):
        """Start (s), values (m/s^2) and slopes (m/s^3) of piece ``index``.

        Parameters
        ----------
        index : int
            Index of the piece (of the knot it starts at).
        """
        start = self.times[index]
        if index + 1 < self.times.size:
            span = self.times[index + 1] - start
            slope = ((self.W_x[index + 1] - self.W_x[index]) / span, (self.W_y[index + 1] - self.W_y[index]) / span)
        else:
            slope = (0.0, 0.0)
        return start, (self.W_x[index], self.W_y[index]), slope


@dataclass(frozen=True)
class FrictionResponse:
    """Result of :func:`simulate_friction` (SI).

    Attributes
    ----------
    time, alpha, beta, velocity_error_x, velocity_error_y : arrays on the output grid.
    switch_times : times of the cell changes, s.
    cells : cell (A, B) entered at each switch (the first entry is the start cell).
    stick_intervals : (start, end) of every interval with both axes stuck, s.
    stick_velocity_errors : (Delta v_x, Delta v_y) at the start, then at the end, of each
        stick interval, m/s, shape (n_intervals, 4).
    nfev : right-hand-side evaluations.
    """

    time: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    velocity_error_x: np.ndarray
    velocity_error_y: np.ndarray
    switch_times: np.ndarray
    cells: list
    stick_intervals: np.ndarray
    stick_velocity_errors: np.ndarray
    nfev: int

    @property
    def stuck_at_end(self) -> bool:
        return bool(self.cells[-1] == (0, 0))


def _cell(a: float, b: float, q_1: float, q_2: float) -> tuple[int, int]:
    side_a = 1 if a > q_1 else (-1 if a < -q_1 else 0)
    side_b = 1 if b > q_2 else (-1 if b < -q_2 else 0)
    return side_a, side_b


def simulate_friction(q, time, initial_tilt=(0.0, 0.0), initial_velocity_error=(0.0, 0.0),
                      acceleration: AccelerationInput | None = None, gravity: float = 9.81,
                      radius: float = 6.4e6) -> FrictionResponse:
    """Simulate the vertical with Coulomb friction (30), switching exactly between stick and slip.

    Parameters
    ----------
    q : pair of float
        (q_1, q_2) = (M_fr,x / H, M_fr,y / H), 1/s (>= 0): outer (alpha) and inner (beta) axis.
    time : array_like
        Output times, s, starting at 0.
    initial_tilt : pair of float
        (alpha_0, beta_0), rad.
    initial_velocity_error : pair of float
        (Delta v_x, Delta v_y) at t = 0, m/s.
    acceleration : AccelerationInput, optional
        W_x, W_y on the accelerometers (default none).
    gravity, radius : float
        g (m/s^2), R (m); defaults are the source's.

    Returns
    -------
    FrictionResponse
    """
    q_1, q_2 = (float(x) for x in q)
    if not (np.isfinite(q_1) and np.isfinite(q_2)) or q_1 < 0 or q_2 < 0:
        raise InvalidParameter("friction", "q_1 and q_2 must be finite and >= 0")
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 2 or t[0] != 0.0 or np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
        raise InvalidParameter("duration", "the time grid must start at 0 and increase")
    acceleration = acceleration or AccelerationInput.constant()
    g, R = gravity, radius
    state = np.array([initial_tilt[0], initial_tilt[1], initial_velocity_error[0], initial_velocity_error[1]], float)
    if not np.all(np.isfinite(state)):
        raise InvalidParameter("initial_tilt", "initial tilts and velocity errors must be finite")
    atol = np.array([ATOL_TILT, ATOL_TILT, ATOL_VELOCITY, ATOL_VELOCITY])
    out = np.empty((t.size, 4))
    out[0] = state
    cell = _cell(state[2] / R, -state[3] / R, q_1, q_2)
    switch_times, switch_states, cells = [0.0], [state.copy()], [cell]
    nfev = 0
    knots = acceleration.times[acceleration.times < t[-1]]
    edges = np.append(knots, t[-1])

    # the cell's friction signs and the acceleration piece are bound with partial, not read
    # from the loop's variables, so each integration sees the values it was started with
    # (solve_ivp's args= would also pass them to the event functions)
    def rhs(time_, x, *, stuck, sign_alpha, sign_beta, piece_start, w_0, slope):
        tau = time_ - piece_start
        alpha_rate = 0.0 if stuck else -x[3] / R + q_2 * sign_beta
        beta_rate = 0.0 if stuck else x[2] / R - q_1 * sign_alpha
        return np.array([alpha_rate, beta_rate, -g * x[1] + w_0[0] + slope[0] * tau,
                         g * x[0] + w_0[1] + slope[1] * tau])

    for index in range(knots.size):
        piece_start, w_0, slope = acceleration.piece(index)
        start, stop = edges[index], edges[index + 1]
        while start < stop:
            if len(switch_times) > _MAX_EVENTS:
                raise SimulationError("friction simulation: too many stick/slip switches")
            sign_alpha, sign_beta = _SIGNS.get(cell, (0, 0))
            events = _exit_events(cell, q_1, q_2, R)
            cell_rhs = partial(rhs, stuck=cell == (0, 0), sign_alpha=sign_alpha, sign_beta=sign_beta,
                               piece_start=piece_start, w_0=w_0, slope=slope)
            solution = solve_ivp(cell_rhs, (start, stop), state, method="DOP853", dense_output=True,
                                 events=[e for e, _ in events], rtol=RTOL, atol=atol)
            if solution.status == -1:
                raise SimulationError(f"friction simulation failed: {solution.message}")
            nfev += solution.nfev
            end = float(solution.t[-1])
            inside = (t > start) & (t <= end)
            if inside.any():
                out[inside] = solution.sol(t[inside]).T
            state = solution.y[:, -1]
            if solution.status == 1:
                fired = [k for k, times in enumerate(solution.t_events) if times.size and times[0] <= end]
                side_a, side_b = cell
                for k in fired:
                    axis, step = events[k][1]
                    if axis == 0:
                        side_a += step
                    else:
                        side_b += step
                cell = (side_a, side_b)
                switch_times.append(end)
                switch_states.append(state.copy())
                cells.append(cell)
            start = end
    return _response(t, out, switch_times, switch_states, cells, nfev)


def _exit_events(cell, q_1, q_2, R):
    """Event functions for leaving ``cell``, each with the cell step it causes: [(event, (axis, step))]."""
    events = []
    for axis, side, limit in ((0, cell[0], q_1), (1, cell[1], q_2)):
        # (line crossed, direction of crossing, step to the next cell) for each way out
        exits = {0: ((limit, 1.0, 1), (-limit, -1.0, -1)), 1: ((limit, -1.0, -1),), -1: ((-limit, 1.0, 1),)}[side]
        for line, direction, step in exits:
            # exits from the zone lie a full step out, exits back into it half a step in: the
            # point where a cell is entered then never lies on one of its own exits, even for q = 0
            shifted = line + direction * EVENT_HYSTERESIS / R * (1.0 if side == 0 else 0.5)

            def event(t, x, axis=axis, shifted=shifted):
                return (x[2] if axis == 0 else -x[3]) / R - shifted

            event.terminal = True
            event.direction = direction
            events.append((event, (axis, step)))
    return events


def _response(t, out, switch_times, switch_states, cells, nfev) -> FrictionResponse:
    bounds = list(switch_times) + [t[-1]]
    states = list(switch_states) + [out[-1]]
    stuck = [k for k, cell in enumerate(cells) if cell == (0, 0)]
    stick = np.array([(bounds[k], bounds[k + 1]) for k in stuck]).reshape(-1, 2)
    errors = np.array([[states[k][2], states[k][3], states[k + 1][2], states[k + 1][3]] for k in stuck]).reshape(-1, 4)
    return FrictionResponse(t, out[:, 0], out[:, 1], out[:, 2], out[:, 3], np.array(switch_times), cells,
                            stick, errors, nfev)
