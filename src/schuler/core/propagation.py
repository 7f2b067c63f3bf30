"""Exact propagation of linear models on plain arrays: the methods behind :func:`schuler.core.lti.simulate`.

Every method here is exact for inputs held constant over each step (zero-order
hold); they differ only in how the matrix exponentials are arranged. Shapes:
a leading axis of length 1 on a matrix shares it among all members, a leading
axis of length N gives each member its own.

**Block exponentials** (inputs constant over the run, uniform grid of step h).
With the inputs in the state, z = [x; u] (or z = [x; 1] and the column B u),
z' = M z and z(t_k) = expm(M k h) z(t_0). Writing k = b L + j with
L ~ sqrt(n_time) samples per block,

    y(t_(bL+j)) = [R expm(M h)^j] [expm(M L h)^b z(t_0)]:

L fine rows times ceil(n_time / L) block starts, both built by products of two
exact exponentials, Phi = expm(M h) and Psi = expm(M L h) (for a batch of
models Psi = Phi^L by squaring, as scipy's expm loops over a batch in Python).
No product chain is longer than ~2 sqrt(n_time). The samples are filled by the
compiled :func:`~schuler.core._lti_kernels.fill_blocks`, which adds the
constant inputs' share of each sample once per member, so a sample costs n
multiply-adds whatever the number of inputs. A batch of models (M of shape
(N, q, q)) costs the same per member as a shared one: no loop over time steps
or members in Python.

**Balancing.** Error models mix channels of very different magnitude
(position errors in km, attitude errors in microradians). Before any
exponential, M is balanced by an exact diagonal similarity D^-1 M D (powers of
two, so no rounding; Parlett and Reinsch's algorithm, LAPACK ``gebal`` through
:func:`scipy.linalg.matrix_balance`), one D for a whole batch; propagation runs
on D^-1 z and the rows become R D. Measured on the 13-state psi-angle model
over 48 h against an extended-precision reference, in units of each channel's
maximum: unbalanced 1e-8 with z = [x; u] and 2-4e-10 with the inputs folded
into one column; balanced 2e-13 for either, and 9e-12 for steps at 1 s
(unbalanced 3e-8).

**Point exponentials** (constant inputs, non-uniform grid): expm(M (t_k - t_0))
at each point, in groups so that the workspace stays small.

**Steps** (inputs that vary in time, or a batch of models on a long
non-uniform grid): the recursion x_(k+1) = Ad x_k + Bd u_k, balanced as above,
with one exact (Ad, Bd) per distinct step, run by the compiled
:func:`~schuler.core._lti_kernels.propagate_steps`.

References
----------
B. N. Parlett and C. Reinsch, "Balancing a matrix for calculation of
eigenvalues and eigenvectors", Numerische Mathematik 13, 1969.
C. F. Van Loan, "Computing integrals involving the matrix exponential",
IEEE Transactions on Automatic Control 23(3), 1978.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from schuler.core._lti_kernels import fill_blocks, final_and_peak_blocks, propagate_steps

POINT_EXPONENTIALS = 200_000
"""Most matrix exponentials spent on the non-uniform points of one propagation (about 2 s);
a batch of models on a longer non-uniform grid is stepped instead."""
_GROUP_FLOATS = 4_000_000  # workspace of one group of point exponentials (32 MB)


def zoh_discretize(A: np.ndarray, B: np.ndarray, dt) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretisation by the augmented matrix exponential.

    Parameters
    ----------
    A : ndarray, shape (..., n, n)
        State matrix, 1/s.
    B : ndarray, shape (..., n, m)
        Input matrix, SI (state unit per input unit and second).
    dt : float or ndarray of shape (k,)
        Step(s), s. With k steps the results gain a leading axis of length k.

    Returns
    -------
    Ad : ndarray, shape ([k,] ..., n, n)
        expm(A dt).
    Bd : ndarray, shape ([k,] ..., n, m)
        integral_0^dt expm(A s) ds B.

    Notes
    -----
    expm([[A, B], [0, 0]] dt) = [[Ad, Bd], [0, I]] (Van Loan, "Computing integrals
    involving the matrix exponential", IEEE Trans. Automatic Control 23(3), 1978).

    Examples
    --------
    >>> Ad, Bd = zoh_discretize(np.array([[0.0]]), np.array([[2.0]]), 0.5)
    >>> float(Ad[0, 0]), float(Bd[0, 0])
    (1.0, 1.0)
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


TAYLOR_ORDER = 12
"""Most terms of the Taylor series of :func:`discretise_noise` after scaling: with the scaled step's norm at most
:data:`TAYLOR_RADIUS`, the first term left out is below 0.25^13 / 13! = 2.4e-18 of the terms kept (fewer terms
where the norm is smaller: the first left out below 1e-17)."""

TAYLOR_RADIUS = 0.25
"""Largest 1-norm of F dt / 2^s over which :func:`discretise_noise` sums its series before doubling s times."""


def discretise_noise(F: np.ndarray, noise_input: np.ndarray, dt) -> tuple[np.ndarray, np.ndarray]:
    """Exact transition matrix and process noise of x' = F x + w over dt (Van Loan's block exponential).

    Parameters
    ----------
    F : ndarray, shape ([k,] n, n)
        System matrix held over the step, 1/s (each state's rate per unit of each state).
    noise_input : ndarray, shape ([k,] n, n)
        G Q_c G^T: the white input's power spectral density mapped onto the state
        derivatives, (state unit)^2 / s.
    dt : float
        Step length, s (> 0).

    Returns
    -------
    Phi : ndarray, shape ([k,] n, n)
        expm(F dt).
    Q : ndarray, shape ([k,] n, n)
        integral_0^dt expm(F s) G Q_c G^T expm(F^T s) ds, (state unit)^2, symmetrised.

    Notes
    -----
    This is the exponential of Van Loan's block matrix [[-F, W], [0, F^T]] dt (Van Loan, "Computing
    integrals involving the matrix exponential", IEEE Trans. Automatic Control 23(3), 1978), taken by scaling
    and squaring on its two blocks instead of the 2n x 2n matrix: over h = dt / 2^s, with ||F h||_1 <=
    :data:`TAYLOR_RADIUS`, Phi_h = sum (F h)^k / k! and Q_h = sum h^(k+1) / (k+1)! L^k(W) with
    L(X) = F X + X F^T (the series of Q' = F Q + Q F^T + W, Q(0) = 0), both to :data:`TAYLOR_ORDER`, on F
    balanced by one exact diagonal similarity for the batch (:func:`balance`); then s doublings
    Q_2h = Phi_h Q_h Phi_h^T + Q_h, Phi_2h = Phi_h^2. Every product is a stacked n x n matrix product (no
    loop over a batch in Python, where scipy's ``expm`` loops): three n x n products a doubling instead of
    one of 2n x 2n, and within 1e-13 of ``expm`` on the block matrix (tests). W must be symmetric.

    Examples
    --------
    >>> Phi, Q = discretise_noise(np.array([[0.0, 1.0], [0.0, 0.0]]), np.diag([0.0, 2.0]), 3.0)
    >>> Phi.round(12).tolist(), Q.round(12).tolist()   # q dt^3/3, q dt^2/2, q dt for a random walk integrated once
    ([[1.0, 3.0], [0.0, 1.0]], [[18.0, 9.0], [9.0, 6.0]])
    """
    F = np.asarray(F, dtype=float)
    W = np.asarray(noise_input, dtype=float)
    shape = np.broadcast_shapes(F.shape, W.shape)
    n = shape[-1]
    # balanced first (one exact diagonal similarity for the batch): the norm, so the doublings, shrink by orders
    # for error states of mixed units (metres beside radians)
    F, scale = balance(np.broadcast_to(F, shape).reshape(-1, n, n))
    F = F.reshape(shape)
    W = np.broadcast_to(W, shape) / np.multiply.outer(scale, scale)
    norm = float(np.max(np.sum(np.abs(F), axis=-2), initial=0.0)) * dt
    doublings = max(0, math.ceil(math.log2(norm / TAYLOR_RADIUS))) if norm > TAYLOR_RADIUS else 0
    h = dt / 2.0**doublings
    A = F * h
    Phi = np.broadcast_to(np.eye(n), shape).copy()
    power = Phi.copy()
    term = W * h  # h^(k+1)/(k+1)! L^k(W), k = 0
    Q = term.copy()
    for k in range(1, _series_order(norm / 2.0**doublings) + 1):
        power = power @ A / k
        Phi += power
        half = A @ term  # F h C: L(C) h = F h C + (F h C)^T, C symmetric
        term = (half + np.swapaxes(half, -1, -2)) / (k + 1)
        Q += term
    for _ in range(doublings):
        Q = Phi @ Q @ np.swapaxes(Phi, -1, -2) + Q
        Phi = Phi @ Phi
    Phi = Phi * (scale[:, None] / scale[None, :])
    Q = Q * np.multiply.outer(scale, scale)
    return Phi, 0.5 * (Q + np.swapaxes(Q, -1, -2))


def _series_order(norm: float) -> int:
    """Terms of the series for a scaled step of 1-norm ``norm`` (<= :data:`TAYLOR_RADIUS`): the first left out
    below 1e-17 of the sum (at most :data:`TAYLOR_ORDER`)."""
    term = 1.0
    for k in range(1, TAYLOR_ORDER + 1):
        term *= norm / (k + 1)
        if term <= 1e-17:
            return k
    return TAYLOR_ORDER


def uniform_step(t: np.ndarray) -> float | None:
    """The grid's step if all steps agree to rounding (linspace and arange grids), else None.

    Parameters
    ----------
    t : ndarray, shape (T,)
        Time points, s.

    Examples
    --------
    >>> uniform_step(np.linspace(0.0, 1.0, 11)), uniform_step(np.array([0.0, 1.0, 3.0]))
    (0.1, None)
    """
    if t.size < 2:
        return None
    dt = np.diff(t)
    step = (t[-1] - t[0]) / dt.size
    # a linspace grid's steps scatter by a few ulp of the largest time, not of the step
    tolerance = 1e-12 * step + 8 * np.finfo(float).eps * max(abs(t[0]), abs(t[-1]))
    return float(step) if np.all(np.abs(dt - step) <= tolerance) else None


@dataclass(frozen=True)
class Grid:
    """A time grid, analysed once: its uniform leading part and its distinct steps.

    Attributes
    ----------
    times : ndarray, shape (n_time,)
        Strictly increasing, s.
    n_uniform : int
        Length of the uniform leading part propagated by block exponentials:
        the whole grid, all but a shorter last step (a run ending between two
        output steps), or 0.
    step : float or None
        Step of that part, s.
    kinds : ndarray, shape (n_kinds,)
        The distinct steps, s.
    which : ndarray of int64, shape (n_time - 1,)
        Index into ``kinds`` of every step.

    Examples
    --------
    >>> grid = Grid.of(np.array([0.0, 1.0, 2.0, 3.0, 3.5]))
    >>> grid.n_uniform, grid.step, grid.kinds.tolist(), grid.which.tolist()
    (4, 1.0, [1.0, 0.5], [0, 0, 0, 1])
    """

    times: np.ndarray
    n_uniform: int
    step: float | None
    kinds: np.ndarray
    which: np.ndarray

    @classmethod
    def of(cls, t: np.ndarray) -> Grid:
        """The grid of the time points ``t``.

        Parameters
        ----------
        t : ndarray, shape (T,)
            Strictly increasing time points, s.
        """
        steps = t.size - 1
        step = uniform_step(t)
        if step is not None:
            return cls(t, t.size, step, np.array([step]), np.zeros(steps, dtype=np.int64))
        step = uniform_step(t[:-1]) if t.size > 3 else None
        if step is not None:
            which = np.zeros(steps, dtype=np.int64)
            which[-1] = 1
            return cls(t, t.size - 1, step, np.array([step, t[-1] - t[-2]]), which)
        kinds, which = np.unique(np.diff(t), return_inverse=True)
        return cls(t, 0, None, kinds, which.astype(np.int64))


def balance(M: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Balance a batch of matrices (N, q, q) by one exact diagonal similarity.

    Parameters
    ----------
    M : ndarray, shape (N, q, q)
        The matrices (SI, 1/s for a continuous model).

    Returns
    -------
    balanced : ndarray, shape (N, q, q)
        D^-1 M D.
    scale : ndarray, shape (q,)
        The diagonal of D (powers of two).
    """
    magnitude = np.abs(M).max(axis=0)
    _, (scale, _) = scipy.linalg.matrix_balance(magnitude, permute=False, separate=True)
    return M * (scale[None, None, :] / scale[None, :, None]), scale


def _apply(G: np.ndarray, z: np.ndarray) -> np.ndarray:
    """G_i z_i for matrices G (1 or N, k, r, q) and vectors z (N, q): shape (N, k, r)."""
    if G.shape[0] == 1:
        k, r, q = G.shape[1:]
        return (z @ G[0].reshape(k * r, q).T).reshape(z.shape[0], k, r)
    return np.matmul(G, z[:, None, :, None])[..., 0]


class ConstantInputPropagator:
    """Samples y_k = R expm(M (t_k - t_0)) z of z' = M z on a grid, for any batch of z.

    The exponentials are computed at construction; calling the propagator
    applies them to initial vectors.

    Parameters
    ----------
    M : ndarray, shape (1 or N, q, q)
        Generator (1/s): the state matrix with the constant inputs folded in.
    R : ndarray, shape (1 or N, r, q)
        Rows wanted (states, outputs).
    grid : Grid
        The time grid.
    n_moving : int
        Leading entries of z that change in time; the rest are constant
        inputs (zero rows of M).
    """

    def __init__(self, M: np.ndarray, R: np.ndarray, grid: Grid, n_moving: int):
        self.n_moving = n_moving
        self.M, self.scale = balance(M)
        self.R = np.ascontiguousarray(R * self.scale)
        self.t = grid.times
        self.n_uniform = grid.n_uniform
        if grid.step is not None:
            # L ~ sqrt(n_time) substeps per block: L fine and n_time / L block products per member
            self.substeps = math.isqrt(self.n_uniform - 1) + 1
            self.n_blocks = -(-self.t.size // self.substeps)
            self.step_transition = scipy.linalg.expm(self.M * grid.step)
            if self.M.shape[0] == 1:
                self.block_transition = scipy.linalg.expm(self.M * (grid.step * self.substeps))
            else:  # scipy's expm loops over a batch in Python: square the step transitions instead
                self.block_transition = np.linalg.matrix_power(self.step_transition, self.substeps)
        self.point_offsets = self.t[self.n_uniform :] - self.t[0]

    @property
    def n_rows(self) -> int:
        return self.R.shape[1]

    def __call__(self, z0: np.ndarray) -> np.ndarray:
        """Rows at every time, shape (N, n_time, r), for initial vectors z0 of shape (N, q).

        The result is a view of a channel-major buffer (N, r, n_time + padding to
        whole blocks): each channel's history is contiguous, so reductions over
        time read memory in order.
        """
        z = np.ascontiguousarray(z0 / self.scale)
        members, T, r = z.shape[0], self.t.size, self.n_rows
        if not self.n_uniform:
            out = np.empty((members, r, T))
            self._fill_points(z, out)
            return out.transpose(0, 2, 1)
        out = np.empty((members, r, self.n_blocks * self.substeps))
        fill_blocks(self.step_transition, self.block_transition, self.R, z, self.n_moving, self.substeps, out)
        if self.point_offsets.size:
            self._fill_points(z, out[:, :, self.n_uniform : T])
        return out[:, :, :T].transpose(0, 2, 1)

    @property
    def summarises(self) -> bool:
        """Whether :meth:`final_and_peak` applies: a grid that is uniform throughout."""
        return bool(self.n_uniform) and not self.point_offsets.size

    def final_and_peak(self, z0: np.ndarray, rows: slice) -> tuple[np.ndarray, np.ndarray]:
        """Each member's last value and largest magnitude over time of the rows ``rows``, without histories.

        Parameters
        ----------
        z0 : ndarray, shape (N, q)
            Initial vectors, SI.
        rows : slice
            Which of the propagator's rows (indices into its r rows).

        Returns
        -------
        final, peak : ndarray, shape (N, r')
            Row values at the last time and max over time of their magnitude, SI.
        """
        z = np.ascontiguousarray(z0 / self.scale)
        R = np.ascontiguousarray(self.R[:, rows])
        final, peak = np.empty((z.shape[0], R.shape[1])), np.empty((z.shape[0], R.shape[1]))
        final_and_peak_blocks(self.step_transition, self.block_transition, R, z, self.n_moving, self.substeps,
                              self.t.size, final, peak)
        return final, peak

    def _fill_points(self, z: np.ndarray, out: np.ndarray) -> None:
        """Rows at the point times into ``out`` of shape (N, r, n_points)."""
        q = self.M.shape[-1]
        group = max(1, _GROUP_FLOATS // (self.M.shape[0] * q * q))
        for lo in range(0, self.point_offsets.size, group):
            offsets = self.point_offsets[lo : lo + group]
            transitions = scipy.linalg.expm(self.M[:, None] * offsets[None, :, None, None])
            out[:, :, lo : lo + offsets.size] = _apply(self.R[:, None] @ transitions, z).transpose(0, 2, 1)


def propagate_steps_exact(A: np.ndarray, B: np.ndarray, grid: Grid, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """States of x' = A x + B u at every time, stepping exactly from point to point.

    Parameters
    ----------
    A : ndarray, shape (1 or N, n, n)
        State matrices, SI (1/s for states in their units).
    B : ndarray, shape (1 or N, n, m)
        Input matrices, SI (state unit per input unit and second).
    grid : Grid
        The time grid (n_time points).
    x0 : ndarray, shape (N, n)
        Initial states, SI.
    u : ndarray, shape (1 or N, 1 or n_time, m)
        Inputs, SI; ``u[:, k]`` holds on [t_k, t_(k+1)); a time length of 1 holds over the run.

    Returns
    -------
    ndarray, shape (N, n_time, n)
        A view of a time-major buffer (the kernel steps all members at once).
    """
    n, m = A.shape[-1], B.shape[-1]
    members = x0.shape[0]
    out = np.empty((grid.times.size, n, members))
    generator = np.zeros((max(A.shape[0], B.shape[0]), n + m, n + m))
    generator[:, :n, :n], generator[:, :n, n:] = A, B
    scale = balance(generator)[1][:n]  # step in D^-1 x, as the exponentials do
    Ad, Bd = zoh_discretize(A * (scale / scale[:, None]), B / scale[:, None], grid.kinds)
    propagate_steps(np.ascontiguousarray(Ad.transpose(0, 2, 3, 1)), np.ascontiguousarray(Bd.transpose(0, 2, 3, 1)),
                    grid.which, np.ascontiguousarray((x0 / scale).T),
                    np.require(u.transpose(1, 2, 0), np.float64, ["C", "W"]), out)  # one compiled signature
    out *= scale[:, None]
    return out.transpose(2, 0, 1)


def propagate_constant_input(M: np.ndarray, R: np.ndarray, grid: Grid, n_moving: int):
    """A propagator ``z0 (N, q) -> rows (N, n_time, r)`` for z' = M z, the cheapest exact one.

    Exponentials at block and point times (:class:`ConstantInputPropagator`),
    unless a batch of models would need more than :data:`POINT_EXPONENTIALS`
    point exponentials on a non-uniform grid: then exact steps.

    Parameters
    ----------
    M : ndarray, shape (q, q) or (N, q, q)
        The augmented matrix [[A, B], [0, 0]], 1/s.
    R : ndarray, shape (r, q) or (N, r, q)
        Rows of z wanted at each time (outputs in SI).
    grid : Grid
        The time points, s.
    n_moving : int
        Number of leading entries of z that evolve (the states); the rest are the held inputs.

    """
    if M.shape[0] * (grid.times.size - grid.n_uniform) <= POINT_EXPONENTIALS:
        return ConstantInputPropagator(M, R, grid, n_moving)

    def stepped(z0: np.ndarray) -> np.ndarray:
        no_input = np.zeros((1, 1, 0))
        z = propagate_steps_exact(M, np.zeros((1, M.shape[-1], 0)), grid, z0, no_input)
        return z @ R[0].T if R.shape[0] == 1 else np.matmul(z, np.swapaxes(R, -1, -2))

    return stepped
