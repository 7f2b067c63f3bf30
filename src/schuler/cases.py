"""A batch of validated cases, one array per parameter: what a system's ``evaluate`` takes.

:class:`Cases` is the batch (SI arrays of one length, the member numbers that
address the random draws, the random streams and the fidelity);
:func:`default_arrays` fills a batch's parameters that were not given.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.params import Case, ParameterSet


class Cases:
    """A batch of validated cases: every parameter an array of length ``n`` (SI).

    Numbers are float arrays (NaN where a parameter is not set and its own rule
    applies, see :meth:`value_or`), integers int64 arrays, choices and text
    object arrays (None where not set), flags bool arrays.

    Attributes
    ----------
    members : ndarray of int64
        Global case or member numbers: the addresses of the random draws.
    random : RandomStreams or None
        Where random terms come from; None evaluates the nominal case (no noise).
    fidelity : str or None
        The system's evaluation fidelity (``"simulated"``, ``"closed"``) or None
        for its default.
    """

    def __init__(self, values: Mapping[str, Any], *, members=None, random: RandomStreams | None = None,
                 fidelity: str | None = None):
        arrays = {name: np.asarray(value) for name, value in values.items()}
        lengths = {a.shape[0] for a in arrays.values() if a.ndim == 1}
        if any(a.ndim != 1 for a in arrays.values()) or len(lengths) > 1:
            raise InvalidParameter("cases", "every parameter must be a 1-D array of the same length")
        self.n = lengths.pop() if lengths else 0
        self._values = arrays
        self.members = np.arange(self.n, dtype=np.int64) if members is None else np.asarray(members, dtype=np.int64)
        if self.members.shape != (self.n,):
            raise InvalidParameter("members", f"expected {self.n} member numbers, got shape {self.members.shape}")
        self.random = random
        self.fidelity = fidelity

    @classmethod
    def from_case(cls, case: Case, n: int = 1, **kwargs) -> Cases:
        """``n`` copies of one case (a Monte Carlo's members, or a single evaluation).

        Parameters
        ----------
        case : Case
            A validated case (SI values).
        n : int
            Number of copies (members).
        **kwargs
            ``members``, ``random`` and ``fidelity``, as in :class:`Cases`.
        """
        values = {}
        for name, value in case.items():
            if value is None:
                values[name] = np.full(n, None, dtype=object)
            elif isinstance(value, str):
                values[name] = np.full(n, value, dtype=object)
            else:
                values[name] = np.full(n, value)
        return cls(values, **kwargs)

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, name: str) -> np.ndarray:
        return self._values[name]

    def __contains__(self, name: object) -> bool:
        return name in self._values

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._values)

    def float(self, name: str) -> np.ndarray:
        """A numeric parameter as a float array (NaN where not set).

        Parameters
        ----------
        name : str
            Parameter name; its values are SI (the parameter's SI unit).
        """
        array = self._values[name]
        if array.dtype == object:
            # numpy's stubs leave out None, which object arrays compare elementwise
            unset = np.equal(array, None)  # type: ignore[call-overload]
            return np.where(unset, np.nan, array).astype(float) if unset.any() else array.astype(float)
        return array.astype(float)

    def value_or(self, name: str, fallback) -> np.ndarray:
        """A numeric parameter with its "not set" entries replaced by ``fallback`` (scalar or array).

        Parameters
        ----------
        name : str
            Parameter name.
        fallback : float or ndarray
            Value of the cases that do not set it, in the parameter's SI unit.
        """
        values = self.float(name)
        return np.where(np.isnan(values), fallback, values)

    def is_set(self, name: str) -> np.ndarray:
        """Which cases set the parameter (bool array).

        Parameters
        ----------
        name : str
            Parameter name.
        """
        array = self._values[name]
        if array.dtype == object:
            # numpy's stubs leave out None, which object arrays compare elementwise
            return ~np.equal(array, None)  # type: ignore[call-overload]
        if array.dtype.kind == "f":
            return ~np.isnan(array)
        return np.ones(self.n, dtype=bool)

    def take(self, index) -> Cases:
        """The cases at ``index`` (an index array or boolean mask), keeping their member numbers.

        Parameters
        ----------
        index : ndarray of int or bool
            Indices (or a mask of length ``len(self)``) of the cases kept.
        """
        return Cases({k: v[index] for k, v in self._values.items()}, members=self.members[index],
                     random=self.random, fidelity=self.fidelity)

    def groups(self, *names: str) -> Iterator[tuple[np.ndarray, Cases]]:
        """Split the batch by the distinct values of ``names``: (indices, sub-batch) pairs.

        For parameters that change the shape of a computation (a duration, an
        output step, a model choice), so each group is evaluated at once.

        Parameters
        ----------
        *names : str
            Parameters whose distinct values define the groups.

        """
        if not names or self.n == 0:
            yield np.arange(self.n), self
            return
        keys = [tuple(_key(self._values[name][i]) for name in names) for i in range(self.n)]
        order: dict[tuple, list[int]] = {}
        for i, key in enumerate(keys):
            order.setdefault(key, []).append(i)
        for indices in order.values():
            index = np.asarray(indices, dtype=np.int64)
            yield index, self.take(index)

    def case(self, i: int) -> Case:
        """Case ``i`` as a :class:`Case` (NaN and None become "not set").

        Parameters
        ----------
        i : int
            Index of the case in the batch.
        """
        values = {}
        for name, array in self._values.items():
            value = array[i]
            value = value.item() if isinstance(value, np.generic) else value
            values[name] = None if isinstance(value, float) and math.isnan(value) else value
        return Case(values, [k for k, v in values.items() if v is not None])


def _key(value):
    value = value.item() if isinstance(value, np.generic) else value
    return "nan" if isinstance(value, float) and math.isnan(value) else value


def default_arrays(parameters: ParameterSet, n: int) -> dict[str, np.ndarray]:
    """Every parameter's default, ``n`` times (an unset number NaN, an unset text None, as in a sweep's plan).

    Read-only views of one value each: a batch of a million cases costs no copies.

    Parameters
    ----------
    parameters : ParameterSet
        The system's parameters (their defaults, SI).
    n : int
        Number of cases.
    """
    arrays = {}
    for name, value in parameters.case().items():
        if value is None:
            unset = np.nan if parameters[name].kind in ("quantity", "integer") else None
            one = np.array([unset], dtype=None if unset is not None else object)
        else:
            one = np.array([value], dtype=object if isinstance(value, str) else None)
        arrays[name] = np.broadcast_to(one, (n,))
    return arrays
