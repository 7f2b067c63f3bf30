"""Simulating gyrocompassing cases on the exact engine and checking the lab's constraints (the KPI manual, Sec. 3).

:func:`run_case` simulates one case on the chosen model and checks the lab's
constraints over the whole run; :func:`evaluate_cases` evaluates many cases at
once, in closed form and optionally by simulating them, streamed in chunks of
members through :func:`schuler.core.lti.simulate_reduce` so that no history is
kept (:func:`simulate_cases`). Output times follow the core's rule
(:func:`schuler.core.geometry.time_grid`), at most :data:`MAX_TIME_POINTS` of them.

Constraints (task 1): |delta| < 0.4 rad, |beta| < 0.01 rad and an azimuth
slew rate |delta'| < 0.2 rad/s. The source writes the last "0.2 1/s" in the
style it uses for c_a; control question 14 asks for the azimuth correction rate
in rad/s, and since delta' ~ -c_a beta, beta < 0.01 with c_a ~ 20 1/s is
consistent only with a rate in rad/s.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from schuler.core.geometry import time_grid
from schuler.core.lti import Response, StateSpace, simulate, simulate_reduce
from schuler.exceptions import InvalidParameter
from schuler.gyrocompassing import analytic
from schuler.gyrocompassing.case import (
    AlignmentCase,
    GyrocompassingAccuracyWarning,
    analytic_results,
    automatic_duration,
    check_model,
)

MAX_TIME_POINTS = 2_000_000
"""Most output times of a run (a longer grid is refused before it is allocated)."""
GRID_NAMES = ("duration", "time_step")
"""The grid's parameters, as the core's time grid names them in its messages."""
MAX_DELTA = 0.4
"""Constraint |delta| < 0.4 rad (task 1)."""
MAX_BETA = 0.01
"""Constraint |beta| < 0.01 rad (task 1)."""
MAX_DELTA_RATE = 0.2
"""Constraint |delta'| < 0.2 rad/s (task 1)."""
SETTLING_BAND = 0.01
"""Simulated settling: |delta - delta_ss| within 1 % of |delta0 - delta_ss| from then on, where delta_ss is
the model's exact steady state -A^-1 B u (so a run too short to settle reports inf, not a wrong time)."""


@dataclass
class SimulatedCases:
    """Per-case reductions of a batched simulation (arrays of length N, SI)."""

    azimuth_error: np.ndarray
    level_error_beta: np.ndarray
    settling_time: np.ndarray
    max_abs_delta: np.ndarray
    max_abs_beta: np.ndarray
    max_abs_delta_rate: np.ndarray

    @property
    def constraints_ok(self) -> np.ndarray:
        return ((self.max_abs_delta < MAX_DELTA) & (self.max_abs_beta < MAX_BETA)
                & (self.max_abs_delta_rate < MAX_DELTA_RATE))


def _steady_delta(system: StateSpace, inputs: np.ndarray) -> np.ndarray:
    """Exact steady azimuth error -A^-1 B u of each member (shape of the batch), rad."""
    gains = analytic.steady_state_gain_matrix(system.A, system.B)
    steady = np.einsum("...ij,...j->...i", gains, inputs)
    return steady[..., system.states.index("delta")]


def _max_abs(x: np.ndarray) -> np.ndarray:
    """max |x| along the last axis without an |x| temporary."""
    return np.maximum(x.max(axis=-1), -x.min(axis=-1))


def simulate_cases(system: StateSpace, time: np.ndarray, initial_state: np.ndarray, inputs: np.ndarray,
                   members: int, chunk_size: int | None = None) -> SimulatedCases:
    """Simulate N members on the exact engine and reduce each history to scalars, chunk by chunk.

    Only the outputs delta, beta and delta' are computed; each chunk of members
    is reduced (final values, 1 % band settling time, largest magnitudes) and
    dropped, so memory stays at one chunk whatever N.

    Parameters
    ----------
    system : StateSpace
        A model of :mod:`models` (single or a batch of N).
    time : ndarray
        Output times, s.
    initial_state : ndarray, shape (n,) or (N, n)
        States at ``time[0]``, SI.
    inputs : ndarray, shape (6,) or (N, 6)
        Constant inputs, SI.
    members : int
        N.
    chunk_size : int, optional
        Members per chunk (default: the engine's, about 64 MiB of history).

    Examples
    --------
    >>> case = AlignmentCase(latitude=np.radians([20.0, 60.0]), drift_east=1e-8)
    >>> out = simulate_cases(case.model("simplified"), time_grid(1800, 1.0), case.initial_state("simplified"),
    ...                      case.inputs(), 2)
    >>> np.allclose(out.azimuth_error, 1e-8 / (7.292115e-5 * np.cos(np.radians([20.0, 60.0]))), rtol=1e-9)
    True
    """
    x0 = np.broadcast_to(initial_state, (members, system.n_states))
    u = np.broadcast_to(inputs, (members, system.n_inputs))
    steady = np.broadcast_to(_steady_delta(system, u), (members,))
    fields = {name: np.empty(members) for name in ("azimuth_error", "level_error_beta", "settling_time",
                                                   "max_abs_delta", "max_abs_beta", "max_abs_delta_rate")}

    def reduce(chunk: Response, part: slice) -> None:
        delta, beta = chunk["delta"], chunk["beta"]
        fields["azimuth_error"][part] = delta[:, -1]
        fields["level_error_beta"][part] = beta[:, -1]
        fields["settling_time"][part] = analytic.band_settling_time(time, delta, steady[part], delta[:, 0],
                                                                    SETTLING_BAND)
        fields["max_abs_delta"][part] = _max_abs(delta)
        fields["max_abs_beta"][part] = _max_abs(beta)
        fields["max_abs_delta_rate"][part] = _max_abs(chunk["delta_rate"])

    simulate_reduce(system, time, x0, u, reducer=reduce, outputs=("delta", "beta", "delta_rate"),
                    chunk_size=chunk_size)
    return SimulatedCases(**fields)


def evaluate_cases(case: AlignmentCase, model: str = "full", *, simulate_runs: bool = False,
                   duration: float | None = None, time_step: float = 1.0) -> dict[str, np.ndarray]:
    """Closed-form (and optionally simulated) results of N cases at once.

    The closed form (:func:`analytic_results`) is pure numpy: 10^6 cases take
    well under a second. With ``simulate_runs`` every case is also simulated on
    ``model`` (batched, chunked) over ``duration`` (default :func:`automatic_duration`)
    adding ``azimuth_error_simulated_rad``, ``level_error_beta_simulated_rad``,
    ``settling_time_simulated_s`` (1 % band), ``max_abs_delta_rad``,
    ``max_abs_beta_rad``, ``max_abs_delta_rate_rad_s`` and ``constraints_ok``.

    Parameters
    ----------
    case : AlignmentCase
        N cases (parameters in SI, broadcast to (N,)); it must leave the azimuth observable.
    model : {"full", "full-ab", "simplified"}
        The model simulated (:data:`~schuler.gyrocompassing.models.MODELS`); the closed form uses it too.
    simulate_runs : bool
        Whether to simulate every case as well.
    duration : float, optional
        Simulated time, s (default: :func:`automatic_duration` of the longest analytic settling time).
    time_step : float
        Output step of the simulation, s.

    Returns
    -------
    dict of str to numpy.ndarray
        Result name -> values, shape (N,), in the unit the name ends with (``_rad``, ``_s``, ``_rad_s`` for rad/s);
        the gains ``c_gamma`` and ``c_a`` in 1/s, ``damping`` a plain number, ``constraints_ok`` a bool array.

    Examples
    --------
    >>> case = AlignmentCase(latitude=np.radians([10.0, 50.0]), drift_east=np.radians(0.01) / 3600)
    >>> np.round(np.degrees(evaluate_cases(case)["azimuth_error_rad"]) * 60, 3)
    array([2.321, 3.556])
    """
    check_model(model)
    case.check_observable()
    members = case.size or 1
    result = {k: v if v.shape == (members,) else np.broadcast_to(v, (members,)).copy()
              for k, v in analytic_results(case, model).items()}
    if not simulate_runs:
        return result
    duration = automatic_duration(result["settling_time_s"]) if duration is None else duration
    time = time_grid(duration, time_step, names=GRID_NAMES, max_points=MAX_TIME_POINTS)
    system = case.model(model)
    simulated = simulate_cases(system, time, case.initial_state(model), case.inputs(), members)
    result.update({
        "azimuth_error_simulated_rad": simulated.azimuth_error,
        "level_error_beta_simulated_rad": simulated.level_error_beta,
        "settling_time_simulated_s": simulated.settling_time,
        "max_abs_delta_rad": simulated.max_abs_delta,
        "max_abs_beta_rad": simulated.max_abs_beta,
        "max_abs_delta_rate_rad_s": simulated.max_abs_delta_rate,
        "constraints_ok": simulated.constraints_ok,
    })
    return result


@dataclass
class CaseRun:
    """One simulated case: its histories (SI) and the closed-form results beside them."""

    case: AlignmentCase
    model: str
    time: np.ndarray
    delta: np.ndarray
    beta: np.ndarray
    alpha: np.ndarray | None
    delta_rate: np.ndarray
    analytic: dict[str, float]
    simulated: SimulatedCases
    duration: float
    mu: np.ndarray | None = None
    nu: np.ndarray | None = None
    violations: list[str] = field(default_factory=list)

    @property
    def constraints_ok(self) -> bool:
        return not self.violations


def constraint_violations(max_abs_delta: float, max_abs_beta: float, max_abs_delta_rate: float) -> list[str]:
    """Readable list of the task-1 constraints a run broke (empty when all hold).

    Parameters
    ----------
    max_abs_delta, max_abs_beta : float
        Largest azimuth error and level error of the run, rad.
    max_abs_delta_rate : float
        Largest azimuth error rate, rad/s.

    Examples
    --------
    >>> constraint_violations(0.5, 0.0, 0.0)
    ['|delta| reached 0.5 rad (limit 0.4 rad)']
    """
    checks = (("|delta|", max_abs_delta, MAX_DELTA, "rad"), ("|beta|", max_abs_beta, MAX_BETA, "rad"),
              ("|delta'|", max_abs_delta_rate, MAX_DELTA_RATE, "rad/s"))
    return [f"{label} reached {value:.4g} {unit} (limit {limit:g} {unit})"
            for label, value, limit, unit in checks if not value < limit]


def run_case(case: AlignmentCase, model: str = "full", *, duration: float | None = None,
             time_step: float = 1.0) -> CaseRun:
    """Simulate one case on ``model`` and check the task-1 constraints over the whole run.

    Parameters
    ----------
    case : AlignmentCase
        A single case (no arrays).
    model : {"full", "full-ab", "simplified"}
        (1.17) corrected in (mu, nu), (1.18) in (beta, alpha), or (1.19).
    duration : float, optional
        Simulated time, s (default :func:`automatic_duration`).
    time_step : float
        Output step, s (the simulation is exact between outputs).

    Examples
    --------
    >>> run = run_case(AlignmentCase(drift_east=np.radians(0.01) / 3600), "simplified")
    >>> round(float(np.degrees(run.simulated.azimuth_error[0]) * 60), 3), run.constraints_ok
    (3.556, True)
    """
    check_model(model)
    if case.size is not None:
        raise InvalidParameter("case", "run_case takes one case; use evaluate_cases for many")
    case.check_observable()
    closed = {k: float(v) for k, v in analytic_results(case, model).items()}
    duration = automatic_duration(closed["settling_time_s"]) if duration is None else float(duration)
    if closed["settling_time_s"] > duration:
        warnings.warn(
            f"the analytic settling time {closed['settling_time_s']:.4g} s exceeds the run ({duration:.4g} s): "
            "the simulated azimuth error is not yet the steady state",
            GyrocompassingAccuracyWarning, stacklevel=2,
        )
    time = time_grid(duration, time_step, names=GRID_NAMES, max_points=MAX_TIME_POINTS)
    system = case.model(model)
    response = simulate(system, time, case.initial_state(model), case.inputs())
    delta, beta, rate = response["delta"], response["beta"], response["delta_rate"]
    simulated = SimulatedCases(
        azimuth_error=delta[-1:], level_error_beta=beta[-1:],
        settling_time=np.atleast_1d(analytic.band_settling_time(time, delta, _steady_delta(system, case.inputs()),
                                                                delta[0], SETTLING_BAND)),
        max_abs_delta=np.abs(delta).max(keepdims=True), max_abs_beta=np.abs(beta).max(keepdims=True),
        max_abs_delta_rate=np.abs(rate).max(keepdims=True),
    )
    full = model != "simplified"
    return CaseRun(
        case=case, model=model, time=time, delta=delta, beta=beta,
        alpha=response["alpha"] if full else None, delta_rate=rate, analytic=closed, simulated=simulated,
        duration=duration, mu=response["mu"] if full else None, nu=response["nu"] if full else None,
        violations=constraint_violations(simulated.max_abs_delta[0], simulated.max_abs_beta[0],
                                         simulated.max_abs_delta_rate[0]),
    )
