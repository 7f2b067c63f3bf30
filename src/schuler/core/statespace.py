"""Linear time-invariant models in state-space form, single or batched, with named channels (SI)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from schuler.core.propagation import zoh_discretize
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

    # array_like (or None) as given; float ndarrays of the documented shapes once constructed
    A: Any
    B: Any = None
    C: Any = None
    D: Any = None
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
        """Exact zero-order-hold matrices (Ad, Bd) for the step ``dt`` (s).

        Parameters
        ----------
        dt : float
            Step, s.
        """
        return zoh_discretize(self.A, self.B, np.asarray(dt, dtype=float))

    def subset(self, start: int, stop: int) -> StateSpace:
        """Models start:stop of a batch (the model itself when not batched).

        Parameters
        ----------
        start, stop : int
            Index range of the models in the batch.
        """
        if self.batch_size is None:
            return self
        def cut(M: np.ndarray) -> np.ndarray:
            return M[start:stop] if M.ndim == 3 else M

        return StateSpace(cut(self.A), cut(self.B), cut(self.C), cut(self.D), self.states, self.inputs,
                          self.outputs, self.state_units, self.output_units)
