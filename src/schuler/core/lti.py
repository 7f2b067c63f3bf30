"""The exact linear-systems engine: state-space models simulated by matrix exponential.

A continuous linear time-invariant model

    x' = A x + B u,    y = C x + D u

is discretised exactly for piecewise-constant inputs (zero-order hold) by the
matrix exponential of the augmented matrix

    expm([[A, B], [0, 0]] dt) = [[Ad, Bd], [0, I]],

so that x(t_k+1) = Ad x(t_k) + Bd u_k holds to rounding for any step. Members of
a batch (Monte Carlo samples, sweep cases) are propagated together as arrays:
initial states ``(N, n)``, inputs ``(N, n_time, m)``, even a different ``A`` per
member ``(N, n, n)``, without a Python loop over members.

Conventions: arrays are time-first per member: a single response's ``states``
has shape ``(n_time, n_states)``, a batch's ``(n_members, n_time, n_states)``.
The input ``u[k]`` acts on ``[t_k, t_k+1)``. Everything is SI.

Examples
--------
A Schuler oscillator x'' + (g/R) x = 0 started at x = 1 m, one period later:

>>> import numpy as np
>>> w = np.sqrt(9.80665 / 6.371e6)
>>> sys = StateSpace([[0, 1], [-w**2, 0]], states=("x", "v"), state_units=("m", "m/s"))
>>> r = simulate(sys, np.linspace(0, 2 * np.pi / w, 101), initial_state=[1.0, 0.0])
>>> round(float(r["x"][-1]), 12)
1.0
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from schuler.core.stats import StreamingStatistics
from schuler.exceptions import InvalidParameter


def _as_matrix(value, name: str, ndim_single: int = 2) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim not in (ndim_single, ndim_single + 1):
        raise InvalidParameter(name, f"expected a {ndim_single}-D array or a batch of them, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InvalidParameter(name, "contains NaN or infinite entries")
    return array


@dataclass(frozen=True)
class StateSpace:
    """A linear time-invariant model x' = A x + B u, y = C x + D u (SI units).

    Parameters
    ----------
    A : array_like, shape (n, n) or (N, n, n)
        State matrix; a leading dimension makes a batch of N models.
    B : array_like, shape (n, m) or (N, n, m), optional
        Input matrix (default: no inputs).
    C : array_like, shape (p, n) or (N, p, n), optional
        Output matrix (default: the identity, outputs = states).
    D : array_like, shape (p, m) or (N, p, m), optional
        Feedthrough (default zero).
    states, inputs, outputs : tuple of str
        Channel names (defaults ``x0, x1, ...``, ``u0, ...``, the state names).
    state_units, output_units : tuple of str
        SI unit of each channel, for labels and tables.
    """

    A: np.ndarray
    B: np.ndarray | None = None
    C: np.ndarray | None = None
    D: np.ndarray | None = None
    states: tuple[str, ...] = ()
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    state_units: tuple[str, ...] = ()
    output_units: tuple[str, ...] = ()

    def __post_init__(self):
        A = _as_matrix(self.A, "A")
        n = A.shape[-1]
        if A.shape[-2] != n:
            raise InvalidParameter("A", f"must be square, got shape {A.shape}")
        batch = A.shape[:-2]
        B = np.zeros((*batch, n, 0)) if self.B is None else _as_matrix(self.B, "B")
        if B.shape[-2] != n:
            raise InvalidParameter("B", f"must have {n} rows, got shape {B.shape}")
        m = B.shape[-1]
        C = np.eye(n) if self.C is None else _as_matrix(self.C, "C")
        if C.shape[-1] != n:
            raise InvalidParameter("C", f"must have {n} columns, got shape {C.shape}")
        p = C.shape[-2]
        D = np.zeros((p, m)) if self.D is None else _as_matrix(self.D, "D")
        if D.shape[-2:] != (p, m):
            raise InvalidParameter("D", f"must have shape ({p}, {m}), got {D.shape}")
        sizes = {M.shape[0] for M in (A, B, C, D) if M.ndim == 3}
        if len(sizes) > 1:
            raise InvalidParameter("A", f"batched matrices disagree in batch size: {sorted(sizes)}")
        states = tuple(self.states) or tuple(f"x{i}" for i in range(n))
        inputs = tuple(self.inputs) or tuple(f"u{i}" for i in range(m))
        outputs = tuple(self.outputs) or (states if self.C is None else tuple(f"y{i}" for i in range(p)))
        state_units = tuple(self.state_units) or ("",) * n
        output_units = tuple(self.output_units) or (state_units if self.C is None else ("",) * p)
        for label, names, size in (
            ("states", states, n),
            ("inputs", inputs, m),
            ("outputs", outputs, p),
            ("state_units", state_units, n),
            ("output_units", output_units, p),
        ):
            if len(names) != size:
                raise InvalidParameter(label, f"needs {size} entries, got {len(names)}")
        for name, value in (
            ("A", A), ("B", B), ("C", C), ("D", D), ("states", states), ("inputs", inputs),
            ("outputs", outputs), ("state_units", state_units), ("output_units", output_units),
        ):
            object.__setattr__(self, name, value)

    @property
    def n_states(self) -> int:
        return self.A.shape[-1]

    @property
    def n_inputs(self) -> int:
        return self.B.shape[-1]

    @property
    def n_outputs(self) -> int:
        return self.C.shape[-2]

    @property
    def batch_size(self) -> int | None:
        """Number of models in a batch, or None for a single model."""
        sizes = [M.shape[0] for M in (self.A, self.B, self.C, self.D) if M.ndim == 3]
        return sizes[0] if sizes else None

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of A (rad/s), shape (n,) or (N, n)."""
        return np.linalg.eigvals(self.A)

    def discretize(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Exact zero-order-hold matrices (Ad, Bd) for the step ``dt`` (s)."""
        return zoh_discretize(self.A, self.B, np.asarray(dt, dtype=float))


def zoh_discretize(A: np.ndarray, B: np.ndarray, dt) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation by the augmented matrix exponential.

    Parameters
    ----------
    A : ndarray, shape (..., n, n)
    B : ndarray, shape (..., n, m)
    dt : float or ndarray of shape (k,)
        Step(s), s. With k steps the results gain a leading axis of length k.

    Returns
    -------
    Ad : ndarray, shape ([k,] ..., n, n)
    Bd : ndarray, shape ([k,] ..., n, m)
    """
    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    n, m = A.shape[-1], B.shape[-1]
    batch = np.broadcast_shapes(A.shape[:-2], B.shape[:-2])
    M = np.zeros((*batch, n + m, n + m))
    M[..., :n, :n] = A
    M[..., :n, n:] = B
    dt = np.asarray(dt, dtype=float)
    scaled = M * dt.reshape(dt.shape + (1,) * M.ndim)
    phi = scipy.linalg.expm(scaled)
    return phi[..., :n, :n], phi[..., :n, n:]


def _check_time(time) -> np.ndarray:
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 1:
        raise InvalidParameter("time", "must be a 1-D array with at least one point")
    if not np.all(np.isfinite(t)):
        raise InvalidParameter("time", "contains NaN or infinite entries")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        raise InvalidParameter("time", "must be strictly increasing")
    return t


def _prepare(system: StateSpace, t: np.ndarray, initial_state, inputs):
    """Shape initial states and inputs; return (x0, u, n_members or None, constant inputs or None)."""
    n, m = system.n_states, system.n_inputs
    x0 = np.zeros(n) if initial_state is None else np.asarray(initial_state, dtype=float)
    if x0.shape[-1:] != (n,) or x0.ndim > 2:
        raise InvalidParameter("initial_state", f"expected shape ({n},) or (N, {n}), got {x0.shape}")
    if not np.all(np.isfinite(x0)):
        raise InvalidParameter("initial_state", "contains NaN or infinite entries")
    constant = None  # inputs constant in time: (m,) or (N, m)
    if inputs is None:
        constant = np.zeros(m)
        u = np.broadcast_to(constant, (t.size, m))
    else:
        u = np.asarray(inputs, dtype=float)
        if not np.all(np.isfinite(u)):  # checked before broadcasting: cheap for constant inputs
            raise InvalidParameter("inputs", "contains NaN or infinite entries")
        if u.ndim == 1:
            constant = u
            u = np.broadcast_to(u, (t.size, m))
        elif u.ndim == 2 and x0.ndim == 2 and u.shape == (x0.shape[0], m) and u.shape != (t.size, m):
            constant = u
            u = np.broadcast_to(u[:, None, :], (u.shape[0], t.size, m))
        if u.shape[-2:] != (t.size, m):
            raise InvalidParameter("inputs", f"expected shape ({m},), ({t.size}, {m}) or (N, {t.size}, {m}), got {u.shape}")
    sizes = {s for s in (system.batch_size, x0.shape[0] if x0.ndim == 2 else None, u.shape[0] if u.ndim == 3 else None) if s}
    if len(sizes) > 1:
        raise InvalidParameter("initial_state", f"batch sizes disagree: {sorted(sizes)}")
    return x0, u, (sizes.pop() if sizes else None), constant


def _apply(M: np.ndarray, v: np.ndarray) -> np.ndarray:
    """M v for a single (n, k) or batched (N, n, k) matrix and vectors (..., k)."""
    if M.ndim == 2:
        return v @ M.T
    return np.matmul(M, v[..., None])[..., 0]


def _uniform_step(t: np.ndarray) -> float | None:
    """The grid's step if all steps agree to rounding (linspace grids), else None."""
    dt = np.diff(t)
    step = (t[-1] - t[0]) / dt.size
    # a linspace grid's steps scatter by a few ulp of the largest time, not of the step
    tolerance = 1e-12 * step + 8 * np.finfo(float).eps * max(abs(t[0]), abs(t[-1]))
    return step if np.all(np.abs(dt - step) <= tolerance) else None


def _transition_matrices(M: np.ndarray, t: np.ndarray) -> np.ndarray:
    """expm(M (t_k - t_0)) for every k, shape (n_time, q, q).

    On a uniform grid the k-th matrix is Phi^k, Phi = expm(M dt), built by
    doubling: the block of powers 2^j..2^(j+1)-1 is the block 0..2^j-1 times
    expm(M 2^j dt). That takes log2(n_time) exponentials and batched products;
    each power is a product of at most log2(n_time) exact exponentials, so
    rounding stays at a few ulp times log2(n_time).
    Otherwise one exponential per time point.
    """
    q = M.shape[-1]
    step = _uniform_step(t) if t.size > 2 else None
    if step is None:
        return scipy.linalg.expm(M * (t - t[0])[:, None, None])
    powers = np.empty((t.size, q, q))
    powers[0] = np.eye(q)
    filled = 1
    while filled < t.size:
        block = min(filled, t.size - filled)
        # the factor Phi^filled is itself an exact exponential, not a repeated square
        powers[filled : filled + block] = powers[:block] @ scipy.linalg.expm(M * (step * filled))
        filled += block
    return powers


def _propagate_constant_input(system: StateSpace, t: np.ndarray, x0: np.ndarray, u0: np.ndarray, members):
    """States at every time for inputs constant in time, shape ([N,] n_time, n).

    With z = [x; u] and u' = 0, z(t) = expm(M (t - t0)) z(t0), M = [[A, B], [0, 0]]:
    the transition matrices are computed once per time point (not per member)
    and applied to all members in a single matrix product.
    """
    n, m = system.n_states, system.n_inputs
    M = np.zeros((n + m, n + m))
    M[:n, :n] = system.A
    M[:n, n:] = system.B
    transition = _transition_matrices(M, t)[:, :n, :].reshape(t.size * n, n + m)
    lead = () if members is None else (members,)
    z0 = np.concatenate([np.broadcast_to(x0, (*lead, n)), np.broadcast_to(u0, (*lead, m))], axis=-1)
    return (z0 @ transition.T).reshape(*lead, t.size, n)


def _propagate(system: StateSpace, t: np.ndarray, x0: np.ndarray, u: np.ndarray, members: int | None):
    """States at every time, shape (n_time, [N,] n), by exact ZOH steps."""
    n = system.n_states
    lead = () if members is None else (members,)
    x = np.broadcast_to(x0, (*lead, n)).copy()
    out = np.empty((t.size, *lead, n))
    out[0] = x
    if t.size == 1:
        return out
    dt = np.diff(t)
    step = _uniform_step(t)
    if step is not None:  # steps equal to rounding share one discretisation
        unique_dt, step_kind = np.array([step]), np.zeros(dt.size, dtype=int)
    else:
        unique_dt, step_kind = np.unique(dt, return_inverse=True)
    Ad_all, Bd_all = zoh_discretize(system.A, system.B, unique_dt)
    has_input = system.n_inputs > 0 and np.any(u)
    # inputs as (n_time, [N,] m) so that u_t[k] is the input on step k
    u_t = np.moveaxis(u, -2, 0) if u.ndim == 3 else u
    for k in range(t.size - 1):
        kind = step_kind[k]
        x = _apply(Ad_all[kind], x)
        if has_input:
            x += _apply(Bd_all[kind], u_t[k])
        out[k + 1] = x
    return out


def _outputs(system: StateSpace, states: np.ndarray, u: np.ndarray) -> np.ndarray:
    """y = C x + D u for states (..., n_time, n) and inputs (..., n_time, m)."""
    C, D = system.C, system.D
    identity_output = C.ndim == 2 and C.shape[0] == C.shape[1] and np.array_equal(C, np.eye(C.shape[0]))
    if identity_output and not np.any(D):
        return states  # outputs are the states: share the array rather than copy a large batch
    y = states @ np.swapaxes(C, -1, -2) if C.ndim == 2 else np.einsum("bpn,btn->btp", C, states)
    if system.n_inputs and np.any(D):
        y = y + (u @ np.swapaxes(D, -1, -2) if D.ndim == 2 else np.einsum("bpm,btm->btp", D, np.broadcast_to(u, (*states.shape[:-1], D.shape[-1]))))
    return y


@dataclass(frozen=True)
class Response:
    """Time response of a (batch of) state-space model(s).

    Attributes
    ----------
    time : ndarray, shape (n_time,)
        Time points, s.
    states : ndarray, shape (n_time, n) or (N, n_time, n)
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
        return self.states.ndim == 3

    def __getitem__(self, name: str) -> np.ndarray:
        """A named output (or, failing that, state), shape (n_time,) or (N, n_time)."""
        if name in self.output_names:
            return self.outputs[..., self.output_names.index(name)]
        if name in self.state_names:
            return self.states[..., self.state_names.index(name)]
        raise KeyError(f"no channel {name!r}; outputs are {self.output_names}, states {self.state_names}")

    def unit(self, name: str) -> str:
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
        """Plot outputs against time (all members of a batch, thinly). Returns the Figure."""
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


def simulate(system: StateSpace, time, initial_state=None, inputs=None) -> Response:
    """Propagate a model exactly on a time grid with piecewise-constant inputs.

    Parameters
    ----------
    system : StateSpace
        The model, or a batch of models.
    time : array_like, shape (n_time,)
        Strictly increasing time points, s; the response starts at ``time[0]``.
    initial_state : array_like, shape (n,) or (N, n), optional
        State at ``time[0]`` (default zero); 2-D makes a batch.
    inputs : array_like, optional
        Shape (m,) constant, (n_time, m) a time series shared by all members,
        (N, m) constant per member, or (N, n_time, m); ``inputs[k]`` holds on
        ``[time[k], time[k+1])``.

    Returns
    -------
    Response
        Single if neither system, initial state nor inputs is batched.
    """
    t = _check_time(time)
    x0, u, members, constant = _prepare(system, t, initial_state, inputs)
    if constant is not None and system.batch_size is None:
        states = _propagate_constant_input(system, t, x0, constant, members)
    else:
        states = _propagate(system, t, x0, u, members)
        if members is not None:
            states = np.moveaxis(states, 0, 1)
    if members is not None:
        u = np.broadcast_to(u, (members, t.size, system.n_inputs))
    return Response(
        time=t,
        states=states,
        outputs=_outputs(system, states, u),
        state_names=system.states,
        output_names=system.outputs,
        state_units=system.state_units,
        output_units=system.output_units,
    )


@dataclass(frozen=True)
class StatisticsResponse:
    """Per-time statistics of a batch's outputs, computed without keeping histories.

    Attributes
    ----------
    time : ndarray, shape (n_time,)
    statistics : StreamingStatistics
        Over members, each sample of shape (n_time, p).
    output_names, output_units : tuple of str
    """

    time: np.ndarray
    statistics: StreamingStatistics
    output_names: tuple[str, ...]
    output_units: tuple[str, ...]
    final_outputs: np.ndarray = field(repr=False)

    def _channel(self, array: np.ndarray, name: str) -> np.ndarray:
        return array[..., self.output_names.index(name)]

    def mean(self, name: str) -> np.ndarray:
        return self._channel(self.statistics.mean, name)

    def std(self, name: str) -> np.ndarray:
        return self._channel(self.statistics.std, name)

    def percentile(self, q, name: str) -> np.ndarray:
        return self._channel(self.statistics.percentile(q), name)


def simulate_statistics(
    system: StateSpace,
    time,
    initial_state,
    inputs=None,
    *,
    chunk_size: int = 4096,
    reservoir_size: int = 2048,
    seed: int = 0,
) -> StatisticsResponse:
    """Monte Carlo statistics of a batch, propagated chunk by chunk of members.

    Memory is bounded by ``chunk_size`` full histories plus the statistics, so a
    100,000-member Monte Carlo needs no 100,000 histories. Inputs as in
    :func:`simulate`; batched arrays are split along their member axis.

    Returns
    -------
    StatisticsResponse
        Mean, std, min, max and (reservoir) percentiles per time and output,
        and the final outputs of every member, shape (N, p).
    """
    t = _check_time(time)
    x0, u, members, constant = _prepare(system, t, initial_state, inputs)
    if constant is not None:
        u = constant  # keep constant inputs compact so each chunk takes the same exact path
    if members is None:
        raise InvalidParameter("initial_state", "simulate_statistics needs a batch (N, n) of members")
    stats = StreamingStatistics((t.size, system.n_outputs), reservoir_size=reservoir_size, seed=seed)
    finals = np.empty((members, system.n_outputs))

    def take(array, lo, hi, batched_ndim):
        return array[lo:hi] if array.ndim == batched_ndim else array

    for lo in range(0, members, chunk_size):
        hi = min(lo + chunk_size, members)
        chunk_system = system
        if system.batch_size is not None:
            chunk_system = StateSpace(
                take(system.A, lo, hi, 3), take(system.B, lo, hi, 3), take(system.C, lo, hi, 3),
                take(system.D, lo, hi, 3), system.states, system.inputs, system.outputs,
                system.state_units, system.output_units,
            )
        x_chunk = np.broadcast_to(x0, (members, system.n_states))[lo:hi]
        u_chunk = take(u, lo, hi, 3 if constant is None else 2)
        response = simulate(chunk_system, t, x_chunk, u_chunk)
        stats.update(response.outputs)
        finals[lo:hi] = response.outputs[:, -1, :]
    return StatisticsResponse(t, stats, system.outputs, system.output_units, finals)
