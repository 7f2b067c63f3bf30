"""The lab's tasks (source 003, Sec. 3) as functions: one case, sweeps, Monte Carlo, phase trajectory.

A :class:`AlignmentCase` holds one case or N cases (every field a float or an
array of length N, SI). :func:`run_case` simulates one case on the chosen model
and checks the lab's constraints over the whole run; :func:`evaluate_cases`
evaluates many cases at once, in closed form (pure numpy, for 10^6 cases) and
optionally by simulating them in batches on :mod:`schuler.core.lti`;
:func:`monte_carlo` samples residual drifts and accelerometer errors. The phase
trajectory of task 5 is the (delta, beta) history of a :class:`CaseRun`
(plotted by :func:`schuler.gyrocompassing.plots.phase_trajectory`).

Constraints (task 1): |delta| < 0.4 rad, |beta| < 0.01 rad and an azimuth
slew rate |delta'| < 0.2 rad/s. The source writes the last "0.2 1/s" in the
style it uses for c_a; control question 14 asks for the azimuth correction rate
in rad/s, and since delta' ~ -c_a beta, beta < 0.01 with c_a ~ 20 1/s is
consistent only with a rate in rad/s.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.lti import StateSpace, simulate
from schuler.exceptions import InvalidParameter, NotObservable
from schuler.gyrocompassing import analytic, models

DEFAULT_LATITUDE = math.radians(50.0)
DEFAULT_TIME_CONSTANT = 30.0
"""T, s (source 003: "often T = 30 s, zeta = 0.8")."""
DEFAULT_DAMPING = 0.8
DEFAULT_INITIAL_AZIMUTH_ERROR = math.radians(1.0)
DEFAULT_MAX_LATITUDE = math.radians(85.0)
"""Above this latitude gyrocompassing is refused as not observable (user-overridable)."""
DEGRADED_LATITUDE = math.radians(70.0)
"""Above this latitude a warning says that accuracy degrades as 1 / cos(latitude)."""
DEFAULT_DURATION = 7200.0
"""Simulated time, s, unless 3 settling times are longer."""
MAX_DURATION = 48 * 3600.0
"""Longest automatic run, s: a case that settles slower is reported as not settled."""
MAX_TIME_POINTS = 2_000_000
MAX_DELTA = 0.4
"""Constraint |delta| < 0.4 rad (task 1)."""
MAX_BETA = 0.01
"""Constraint |beta| < 0.01 rad (task 1)."""
MAX_DELTA_RATE = 0.2
"""Constraint |delta'| < 0.2 rad/s (task 1)."""
SETTLING_BAND = 0.01
"""Simulated settling: |delta - delta_ss| within 1 % of |delta0 - delta_ss| from then on, where delta_ss is
the model's exact steady state -A^-1 B u (so a run too short to settle reports inf, not a wrong time)."""
_CHUNK_FLOATS = 15_000_000  # floats of history per batch chunk (~120 MB): bounds memory for 10^4+ cases


class DegradedAccuracyWarning(UserWarning):
    """Gyrocompassing works but its accuracy or time is poor (high latitude, slow settling)."""


@dataclass(frozen=True)
class AlignmentCase:
    """One gyrocompassing case, or N cases when any field is an array of length N (all SI).

    Parameters
    ----------
    latitude : float or ndarray
        phi, rad.
    azimuth : float or ndarray
        A, rad: azimuth of the platform's x_g axis.
    drift_x, drift_y, drift_z : float or ndarray
        Residual drifts Delta omega_d = estimate - true, platform axes, rad/s (z up).
    drift_east, drift_north : float or ndarray
        Residual drifts about east (Delta omega_dxi) and north (Delta omega_deta),
        rad/s; added to the platform-axis ones.
    latitude_error : float or ndarray
        Delta phi, rad.
    accel_error_x, accel_error_y : float or ndarray
        Delta a_x, Delta a_y, m/s^2.
    time_constant, damping : float or ndarray
        T (s) and zeta, used for the gains not given.
    c_gamma, c_a : float, ndarray or None
        Gains, 1/s; None (or NaN entries of an array) means "from T and zeta".
    initial_azimuth_error, initial_beta, initial_alpha : float or ndarray
        delta0, beta0, alpha0, rad (levelled platform: beta0 = alpha0 = 0).
    max_latitude : float
        Latitude limit, rad, above which azimuth is reported not observable.
    earth_rate, gravity : float
        U (rad/s) and g (m/s^2).

    Examples
    --------
    >>> case = AlignmentCase(latitude=np.radians([30.0, 60.0]))
    >>> case.size, case.inputs().shape, case.model("full").A.shape
    (2, (2, 6), (2, 3, 3))
    """

    latitude: object = DEFAULT_LATITUDE
    azimuth: object = 0.0
    drift_x: object = 0.0
    drift_y: object = 0.0
    drift_z: object = 0.0
    drift_east: object = 0.0
    drift_north: object = 0.0
    latitude_error: object = 0.0
    accel_error_x: object = 0.0
    accel_error_y: object = 0.0
    time_constant: object = DEFAULT_TIME_CONSTANT
    damping: object = DEFAULT_DAMPING
    c_gamma: object = None
    c_a: object = None
    initial_azimuth_error: object = DEFAULT_INITIAL_AZIMUTH_ERROR
    initial_beta: object = 0.0
    initial_alpha: object = 0.0
    max_latitude: float = DEFAULT_MAX_LATITUDE
    earth_rate: float = EARTH_RATE
    gravity: float = STANDARD_GRAVITY

    def __post_init__(self):
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None:
                continue
            array = np.asarray(value, dtype=float)
            if array.ndim > 1:
                raise InvalidParameter(f.name, "must be a number or a 1-D array of cases")
            allow_unset = f.name in ("c_gamma", "c_a")
            if np.any(np.isinf(array)) or (np.any(np.isnan(array)) and not allow_unset):
                raise InvalidParameter(f.name, "must be a finite number")
            object.__setattr__(self, f.name, array if array.ndim else float(array))
        for name in ("c_gamma", "c_a"):
            value = getattr(self, name)
            if value is not None and np.any(np.asarray(value) <= 0):
                raise InvalidParameter(name, "must be positive (a negative gain makes the loop unstable)")
        if not 0 < self.max_latitude < math.pi / 2:
            raise InvalidParameter("max_latitude", "must be between 0 and 90 deg")

    @property
    def size(self) -> int | None:
        """N for a batch of cases, None for a single case."""
        sizes = {np.size(getattr(self, f.name)) for f in dataclasses.fields(self)
                 if isinstance(getattr(self, f.name), np.ndarray)}
        if len(sizes) > 1:
            raise InvalidParameter("cases", f"arrays of different lengths: {sorted(sizes)}")
        return sizes.pop() if sizes else None

    def check_observable(self) -> None:
        """Raise NotObservable above the latitude limit; warn when accuracy degrades."""
        phi = np.abs(np.asarray(self.latitude, dtype=float))
        analytic.horizontal_earth_rate(phi, self.earth_rate)  # raises at the poles
        worst = float(np.max(phi))
        if worst > self.max_latitude:
            raise NotObservable(
                f"latitude: {math.degrees(worst):g} deg is beyond the gyrocompassing limit "
                f"{math.degrees(self.max_latitude):g} deg (--max-latitude): the horizontal Earth rate "
                f"U cos(latitude) = {self.earth_rate * math.cos(worst):.3g} rad/s is too small to find north"
            )
        if worst > DEGRADED_LATITUDE:
            warnings.warn(
                f"latitude {math.degrees(worst):g} deg: azimuth accuracy degrades as 1/cos(latitude), "
                f"{1 / math.cos(worst):.1f} times the equator's error for the same drifts",
                DegradedAccuracyWarning, stacklevel=3,
            )

    def gains(self) -> tuple[np.ndarray, np.ndarray]:
        """(c_gamma, c_a), 1/s: the given ones, else from T and zeta (c_a = 1/(T^2 U_eta), c_gamma = 2 zeta/T)."""
        from_design = analytic.gains_from_design(self.time_constant, self.damping, self.latitude, self.earth_rate)
        gains = []
        for given, designed in zip((self.c_gamma, self.c_a), from_design):
            if given is None:
                gains.append(designed)
            else:
                gains.append(np.where(np.isnan(given), designed, given))
        return gains[0], gains[1]

    def platform_drifts(self) -> tuple[np.ndarray, np.ndarray]:
        """Residual drifts about the platform's x and y axes, rad/s."""
        return models.platform_drifts(self.azimuth, self.drift_x, self.drift_y, self.drift_east, self.drift_north)

    def inputs(self) -> np.ndarray:
        """The six model inputs (:data:`models.INPUTS`), shape (6,) or (N, 6), SI."""
        drift_x, drift_y = self.platform_drifts()
        columns = np.stack(np.broadcast_arrays(
            drift_x, drift_y, self.drift_z, self.latitude_error, self.accel_error_x, self.accel_error_y
        ), axis=-1).astype(float)
        return columns if self.size is None else np.broadcast_to(columns, (self.size, 6)).copy()

    def model(self, name: str) -> StateSpace:
        """The state-space model ``name`` (one of :data:`models.MODELS`) of this case (batched for N cases)."""
        c_gamma, c_a = self.gains()
        return models.build_model(name, self.latitude, self.azimuth, c_gamma, c_a,
                                  earth_rate=self.earth_rate, gravity=self.gravity)

    def initial_state(self, name: str) -> np.ndarray:
        """Initial state of the model ``name``: (delta0, beta0, alpha0) in its coordinates, rad."""
        return models.initial_state(name, self.initial_azimuth_error, self.initial_beta, self.initial_alpha, self.azimuth)


def _check_model(model: str) -> None:
    if model not in models.MODELS:
        raise InvalidParameter("model", f"{model!r} is not one of {', '.join(models.MODELS)}")


def analytic_results(case: AlignmentCase, model: str = "full") -> dict[str, np.ndarray]:
    """Closed-form results of (many) cases at once, pure numpy.

    Returns
    -------
    dict of ndarray
        ``azimuth_error_rad`` (steady state of ``model``: (1.21) for the simplified
        model, the closed form of (1.18) for the full ones), ``azimuth_error_analytic_rad``
        ((1.21)), ``level_error_beta_rad`` (beta_y of ``model``), ``level_error_beta_analytic_rad``
        ((1.25)), ``settling_time_s`` (5/h or the corrected aperiodic formula),
        ``c_gamma``, ``c_a`` (1/s), ``time_constant_s``, ``damping``.

    Examples
    --------
    >>> r = analytic_results(AlignmentCase(drift_east=np.radians(0.01) / 3600))
    >>> round(float(np.degrees(r["azimuth_error_rad"]) * 60), 3), round(float(r["settling_time_s"]), 1)
    (3.556, 187.5)
    """
    _check_model(model)
    c_gamma, c_a = case.gains()
    drift_x, drift_y = case.platform_drifts()
    A = np.asarray(case.azimuth, dtype=float)
    drift_east = drift_x * np.cos(A) + drift_y * np.sin(A)
    drift_north = -drift_x * np.sin(A) + drift_y * np.cos(A)
    eps_beta, eps_alpha = analytic.accelerometer_tilts(A, case.accel_error_x, case.accel_error_y, case.gravity)
    delta_y, beta_y = analytic.steady_state(case.latitude, c_gamma, c_a, drift_east, case.drift_z,
                                            case.latitude_error, eps_beta, case.earth_rate)
    if model == "simplified":
        delta, beta = delta_y, beta_y
    else:
        delta, beta, _ = analytic.full_steady_state(case.latitude, c_gamma, c_a, drift_east, drift_north, case.drift_z,
                                                    case.latitude_error, eps_beta, eps_alpha, case.earth_rate)
    time_constant, damping = analytic.design_from_gains(c_gamma, c_a, case.latitude, case.earth_rate)
    shape = np.broadcast_shapes(*(np.shape(x) for x in (delta, c_gamma, c_a)))
    result = {
        "azimuth_error_rad": delta,
        "azimuth_error_analytic_rad": delta_y,
        "level_error_beta_rad": beta,
        "level_error_beta_analytic_rad": beta_y,
        "settling_time_s": analytic.settling_time(c_gamma, c_a, case.latitude, case.earth_rate),
        "c_gamma": c_gamma,
        "c_a": c_a,
        "time_constant_s": time_constant,
        "damping": damping,
    }
    return {key: np.broadcast_to(value, shape).astype(float) for key, value in result.items()}


def time_grid(duration: float, time_step: float) -> np.ndarray:
    """Output times 0, dt, ..., duration (the last step shortened to end exactly at duration), s.

    >>> time_grid(2.5, 1.0)
    array([0. , 1. , 2. , 2.5])
    """
    if not duration > 0:
        raise InvalidParameter("duration", "must be positive")
    if not time_step > 0:
        raise InvalidParameter("time_step", "must be positive")
    n = int(math.floor(duration / time_step + 1e-9))
    if n + 1 > MAX_TIME_POINTS:
        raise InvalidParameter("time_step", f"{n + 1} output points exceed {MAX_TIME_POINTS}: use a longer step")
    t = time_step * np.arange(n + 1)
    return t if math.isclose(t[-1], duration, rel_tol=1e-12) else np.append(t, duration)


def automatic_duration(settling_time) -> float:
    """2 h, or 3 analytic settling times when longer, at most 48 h (s).

    >>> automatic_duration(187.5), automatic_duration(1e4), automatic_duration(1e9)
    (7200.0, 30000.0, 172800.0)
    """
    longest = float(np.max(settling_time))
    return float(min(max(DEFAULT_DURATION, 3.0 * longest), MAX_DURATION))


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
        return (self.max_abs_delta < MAX_DELTA) & (self.max_abs_beta < MAX_BETA) & (self.max_abs_delta_rate < MAX_DELTA_RATE)


SUBSTEPS = 60
"""Output samples per engine step in :func:`dense_outputs` (one engine step per minute at 1-s output)."""


def _take(array: np.ndarray, lo: int, hi: int, batched_ndim: int) -> np.ndarray:
    return array[lo:hi] if array.ndim == batched_ndim else array


def _part(system: StateSpace, lo: int, hi: int) -> StateSpace:
    """Members lo:hi of a batched model (the model itself when not batched)."""
    if system.batch_size is None:
        return system
    return StateSpace(*(_take(M, lo, hi, 3) for M in (system.A, system.B, system.C, system.D)), system.states,
                      system.inputs, system.outputs, system.state_units, system.output_units)


def dense_outputs(system: StateSpace, time_step: float, n_steps: int, initial_state: np.ndarray,
                  inputs: np.ndarray, names, substeps: int = SUBSTEPS) -> dict[str, np.ndarray]:
    """Outputs ``names`` of N members at t = 0, dt, ..., n_steps dt for constant inputs, exactly.

    The engine (:func:`schuler.core.lti.simulate`) propagates the members in steps
    of ``substeps`` x dt; the samples inside each step follow from the same exact
    zero-order-hold transition, y(t_k + j dt) = C Ad^j x(t_k) + (C Gamma_j + D) u
    with Ad = expm(A dt) from :meth:`StateSpace.discretize` and
    Gamma_(j+1) = Ad Gamma_j + Bd, evaluated for all steps as one batched matrix
    product per output. The Python loop over time is n_steps / substeps long and
    every sample stays exact to rounding.

    Parameters
    ----------
    system : StateSpace
        Single model or a batch of N.
    time_step : float
        dt, s.
    n_steps : int
        Number of output steps.
    initial_state : ndarray, shape (N, n)
    inputs : ndarray, shape (N, m)
        Constant over the run.
    names : sequence of str
        Output names.
    substeps : int
        Output samples per engine step.

    Returns
    -------
    dict of ndarray
        name -> shape (N, n_steps + 1).

    Examples
    --------
    >>> m = models.simplified_model(0.87, 0.0, 0.0533, 23.7)
    >>> y = dense_outputs(m, 1.0, 300, np.array([[0.0, 0.01]]), np.full((1, 6), 1e-8), ["delta"])
    >>> reference = simulate(m, np.arange(301.0), [0.0, 0.01], np.full(6, 1e-8))["delta"]
    >>> bool(np.allclose(y["delta"][0], reference, rtol=0, atol=1e-16))
    True
    """
    x0 = np.asarray(initial_state, dtype=float)
    u = np.asarray(inputs, dtype=float)
    members, n = x0.shape
    K = max(1, min(substeps, n_steps))
    n_coarse = -(-n_steps // K) + 1  # engine points; samples past n_steps are cut
    # inputs as (N, n_time, m): an (N, m) array would be read as a time series when N == n_time
    held = np.broadcast_to(u[:, None, :], (members, n_coarse, u.shape[-1]))
    coarse = simulate(system, time_step * K * np.arange(n_coarse), x0, held).states  # (N, n_coarse, n)
    Ad, Bd = system.discretize(time_step)
    Ad = np.broadcast_to(Ad, (members, n, n))
    Bu = np.broadcast_to(np.einsum("...ij,...j->...i", Bd, u), (members, n))
    powers = np.empty((members, K, n, n))
    forced = np.empty((members, K, n))
    powers[:, 0], forced[:, 0] = np.eye(n), 0.0
    for j in range(1, K):
        powers[:, j] = Ad @ powers[:, j - 1]
        forced[:, j] = np.einsum("nij,nj->ni", Ad, forced[:, j - 1]) + Bu
    C, D = _output_rows(system, names)
    C = np.broadcast_to(C, (members, *C.shape[1:]))
    feedthrough = np.einsum("nkm,nm->nk", np.broadcast_to(D, (members, *D.shape[1:])), u)
    result = {}
    for k, name in enumerate(names):
        gains = np.einsum("ni,njik->nkj", C[:, k], powers)  # (N, n, K): C_k Ad^j as columns
        offsets = np.einsum("ni,nji->nj", C[:, k], forced) + feedthrough[:, k, None]  # (N, K)
        samples = coarse @ gains  # (N, n_coarse, K): sample (coarse step, substep) in time order
        samples += offsets[:, None, :]
        result[name] = samples.reshape(members, n_coarse * K)[:, : n_steps + 1]
    return result


def _output_rows(system: StateSpace, names) -> tuple[np.ndarray, np.ndarray]:
    """Rows of C and D for the outputs ``names``, shapes (N or 1, k, n) and (N or 1, k, m)."""
    rows = [system.outputs.index(name) for name in names]
    C, D = system.C[..., rows, :], system.D[..., rows, :]
    return (C if C.ndim == 3 else C[None]), (D if D.ndim == 3 else D[None])


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
    """Simulate N members in chunks on the exact engine and reduce each history to scalars.

    Parameters
    ----------
    system : StateSpace
        A model of :mod:`models` (single or a batch of N).
    time : ndarray
        Output times 0, dt, ..., s (uniform but for a shorter last step).
    initial_state : ndarray, shape (n,) or (N, n)
    inputs : ndarray, shape (6,) or (N, 6)
        Constant inputs, SI.
    members : int
        N.
    chunk_size : int, optional
        Members per chunk (default: about 120 MB of history).

    Examples
    --------
    >>> case = AlignmentCase(latitude=np.radians([20.0, 60.0]), drift_east=1e-8)
    >>> out = simulate_cases(case.model("simplified"), time_grid(1800, 1.0), case.initial_state("simplified"),
    ...                      case.inputs(), 2)
    >>> np.allclose(out.azimuth_error, 1e-8 / (7.292115e-5 * np.cos(np.radians([20.0, 60.0]))), rtol=1e-9)
    True
    """
    n = system.n_states
    chunk = chunk_size or max(1, _CHUNK_FLOATS // (time.size * (n + 4)))
    x0 = np.broadcast_to(initial_state, (members, n))
    u = np.broadcast_to(inputs, (members, system.n_inputs))
    steps = np.diff(time)
    uniform = time.size > 1 and np.allclose(steps, steps[0], rtol=1e-12, atol=0)
    names = ("delta", "beta", "delta_rate")
    fields = {name: np.empty(members) for name in
              ("azimuth_error", "level_error_beta", "settling_time", "max_abs_delta", "max_abs_beta", "max_abs_delta_rate")}
    for lo in range(0, members, chunk):
        hi = min(lo + chunk, members)
        part = _part(system, lo, hi)
        if uniform:
            outputs = dense_outputs(part, steps[0], time.size - 1, x0[lo:hi], u[lo:hi], names)
        else:
            held = np.broadcast_to(u[lo:hi, None, :], (hi - lo, time.size, system.n_inputs))
            response = simulate(part, time, x0[lo:hi], held)
            outputs = {name: response[name] for name in names}
        delta, beta = outputs["delta"], outputs["beta"]
        fields["azimuth_error"][lo:hi] = delta[:, -1]
        fields["level_error_beta"][lo:hi] = beta[:, -1]
        steady = _steady_delta(part, u[lo:hi])
        fields["settling_time"][lo:hi] = analytic.band_settling_time(time, delta, steady, delta[:, 0], SETTLING_BAND)
        fields["max_abs_delta"][lo:hi] = _max_abs(delta)
        fields["max_abs_beta"][lo:hi] = _max_abs(beta)
        fields["max_abs_delta_rate"][lo:hi] = _max_abs(outputs["delta_rate"])
    return SimulatedCases(**fields)


def evaluate_cases(case: AlignmentCase, model: str = "full", *, simulate_runs: bool = False,
                   duration: float | None = None, time_step: float = 1.0) -> dict[str, np.ndarray]:
    """Closed-form (and optionally simulated) results of N cases at once.

    The closed form (:func:`analytic_results`) is pure numpy: 10^6 cases take
    well under a second. With ``simulate_runs`` every case is also simulated on
    ``model`` (batched, chunked) over ``duration`` (default :func:`automatic_duration`)
    adding ``azimuth_error_simulated_rad``, ``level_error_beta_simulated_rad``,
    ``settling_time_simulated_s`` (1 % band), ``max_abs_delta_rad``,
    ``max_abs_beta_rad``, ``max_abs_delta_rate_rad_per_s`` and ``constraints_ok``.

    Examples
    --------
    >>> case = AlignmentCase(latitude=np.radians([10.0, 50.0]), drift_east=np.radians(0.01) / 3600)
    >>> np.round(np.degrees(evaluate_cases(case)["azimuth_error_rad"]) * 60, 3)
    array([2.321, 3.556])
    """
    _check_model(model)
    case.check_observable()
    members = case.size or 1
    result = {k: v if v.shape == (members,) else np.broadcast_to(v, (members,)).copy()
              for k, v in analytic_results(case, model).items()}
    if not simulate_runs:
        return result
    duration = automatic_duration(result["settling_time_s"]) if duration is None else duration
    time = time_grid(duration, time_step)
    system = case.model(model)
    simulated = simulate_cases(system, time, case.initial_state(model), case.inputs(), members)
    result.update({
        "azimuth_error_simulated_rad": simulated.azimuth_error,
        "level_error_beta_simulated_rad": simulated.level_error_beta,
        "settling_time_simulated_s": simulated.settling_time,
        "max_abs_delta_rad": simulated.max_abs_delta,
        "max_abs_beta_rad": simulated.max_abs_beta,
        "max_abs_delta_rate_rad_per_s": simulated.max_abs_delta_rate,
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
    _check_model(model)
    if case.size is not None:
        raise InvalidParameter("case", "run_case takes one case; use evaluate_cases for many")
    case.check_observable()
    closed = {k: float(v) for k, v in analytic_results(case, model).items()}
    duration = automatic_duration(closed["settling_time_s"]) if duration is None else float(duration)
    if closed["settling_time_s"] > duration:
        warnings.warn(
            f"the analytic settling time {closed['settling_time_s']:.4g} s exceeds the run ({duration:.4g} s): "
            "the simulated azimuth error is not yet the steady state",
            DegradedAccuracyWarning, stacklevel=2,
        )
    time = time_grid(duration, time_step)
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


@dataclass
class MonteCarloRun:
    """Azimuth errors of N sampled cases (SI) and the analytic 1-sigma beside them."""

    azimuth_errors: np.ndarray
    sigma_analytic: float
    sigma_simplified: float
    constraints_ok_fraction: float

    @property
    def mean(self) -> float:
        return float(np.mean(self.azimuth_errors))

    @property
    def std(self) -> float:
        return float(np.std(self.azimuth_errors, ddof=1)) if self.azimuth_errors.size > 1 else 0.0


def monte_carlo(case: AlignmentCase, model: str = "full", members: int = 1000, *, sigma_drift: float = 0.0,
                sigma_drift_z: float = 0.0, sigma_accel: float = 0.0, seed: int = 0,
                duration: float | None = None, time_step: float = 1.0) -> MonteCarloRun:
    """Monte Carlo over residual drifts and accelerometer errors, batched on the engine.

    Each member draws Delta omega_dx, Delta omega_dy ~ N(mean, sigma_drift),
    Delta omega_dz ~ N(mean, sigma_drift_z) and Delta a_x, Delta a_y ~
    N(mean, sigma_accel) about the case's values, independently (so the east drift has 1-sigma
    sigma_drift at any azimuth); all members are
    simulated at once and their final azimuth errors collected. The analytic
    1-sigma is that of the model's linear steady state x_ss = -A^{-1} B u; for the
    simplified model it is (1.21)'s, without the accelerometers.

    Parameters
    ----------
    case : AlignmentCase
        A single case: the means.
    model : str
        One of :data:`models.MODELS`.
    members : int
        N (>= 2).
    sigma_drift, sigma_drift_z : float
        1-sigma of the horizontal (x, y) and vertical residual drifts, rad/s.
    sigma_accel : float
        1-sigma of each accelerometer error, m/s^2.
    seed : int
        Random seed.
    duration, time_step : float
        As in :func:`run_case`.

    Examples
    --------
    >>> mc = monte_carlo(AlignmentCase(), "simplified", 200, sigma_drift=np.radians(0.01) / 3600, duration=1500)
    >>> abs(mc.std / mc.sigma_analytic - 1) < 0.15
    True
    """
    _check_model(model)
    if members < 2:
        raise InvalidParameter("monte_carlo", "needs at least 2 members")
    for name, value in (("sigma_drift", sigma_drift), ("sigma_drift_z", sigma_drift_z), ("sigma_accel", sigma_accel)):
        if not (math.isfinite(value) and value >= 0):
            raise InvalidParameter(name, "must be a non-negative number")
    case.check_observable()
    settling = float(analytic_results(case, model)["settling_time_s"])
    duration = automatic_duration(settling) if duration is None else duration
    rng = np.random.default_rng(seed)
    sigmas = np.array([sigma_drift, sigma_drift, sigma_drift_z, 0.0, sigma_accel, sigma_accel])
    inputs = case.inputs() + rng.standard_normal((members, 6)) * sigmas
    system = case.model(model)
    simulated = simulate_cases(system, time_grid(duration, time_step), case.initial_state(model), inputs, members)
    gains = analytic.steady_state_gain_matrix(system.A, system.B)
    delta_row = gains[list(system.states).index("delta")]
    c_gamma, c_a = case.gains()
    return MonteCarloRun(
        azimuth_errors=simulated.azimuth_error,
        sigma_analytic=float(np.sqrt(np.sum((delta_row * sigmas) ** 2))),
        sigma_simplified=float(analytic.azimuth_error_sigma(case.latitude, c_gamma, c_a, sigma_drift, sigma_drift_z,
                                                            0.0, case.earth_rate)),
        constraints_ok_fraction=float(np.mean(simulated.constraints_ok)),
    )


def sweep_grid(axes: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The Cartesian product of parameter axes as flat arrays of equal length (first axis slowest).

    >>> g = sweep_grid({"a": np.array([1.0, 2.0]), "b": np.array([10.0, 20.0, 30.0])})
    >>> g["a"].tolist(), g["b"].tolist()
    ([1.0, 1.0, 1.0, 2.0, 2.0, 2.0], [10.0, 20.0, 30.0, 10.0, 20.0, 30.0])
    """
    # mesh the indices, so that axes of names (models) work like numbers
    mesh = np.meshgrid(*(np.arange(len(values)) for values in axes.values()), indexing="ij")
    return {name: np.asarray(values)[index.ravel()] for (name, values), index in zip(axes.items(), mesh)}
