"""How much memory a command may hold and how long it may run, and a clear refusal before it starts.

Every command that allocates in proportion to its inputs (time points,
members, samples) estimates what it will hold and calls :func:`require`
*before* allocating. The budget is half the memory the machine has available
when the process starts (``MemAvailable`` of ``/proc/meminfo``; 4 GiB where
that cannot be read), or what the environment variable ``SCHULER_MEMORY_BUDGET``
says (``"8 GiB"``, ``"500 MB"``, or a number of bytes).

Time works the same way: a command estimates its work (a system's declared
seconds per member, see :attr:`schuler.contract.System.member_seconds`) and
calls :func:`require_time` before it starts. The time budget is
:data:`DEFAULT_TIME_BUDGET` (10 minutes), or what ``SCHULER_TIME_BUDGET`` says
(``"2 h"``, ``"90 s"``, a number of seconds, or ``"none"``); within
:func:`no_time_limit` (the CLI's ``--no-time-limit``) there is none.

Examples
--------
>>> require(10 * 2**20, "a small run", "`duration`")  # 10 MiB: fine
>>> require(2**60, "this run", "`duration` or `output_step`")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
schuler.memory.MemoryBudgetExceeded: this run would hold 1 EiB, more than the memory budget ...
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from functools import lru_cache

from schuler.exceptions import SchulerError

ENVIRONMENT = "SCHULER_MEMORY_BUDGET"
FALLBACK_AVAILABLE = 4 * 2**30
_UNITS = {"": 1, "b": 1, "kb": 10**3, "mb": 10**6, "gb": 10**9, "tb": 10**12,
          "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}


TIME_ENVIRONMENT = "SCHULER_TIME_BUDGET"
DEFAULT_TIME_BUDGET = 600.0
"""Longest run accepted without ``--no-time-limit``, s (10 minutes)."""

_UNLIMITED: ContextVar[bool] = ContextVar("schuler_no_time_limit", default=False)
_SECONDS = {"": 1.0, "s": 1.0, "sec": 1.0, "min": 60.0, "h": 3600.0, "hour": 3600.0, "hours": 3600.0,
            "d": 86400.0, "day": 86400.0, "days": 86400.0}


class MemoryBudgetExceeded(SchulerError):
    """A command would hold more memory than the budget allows."""


class TimeBudgetExceeded(SchulerError):
    """A command would run longer than the time budget allows."""


def parse_bytes(text: str) -> int:
    """``"8 GiB"`` -> 8589934592; ``"500 MB"`` -> 500000000; ``"1e9"`` -> 1000000000.

    Parameters
    ----------
    text : str
        A size with a unit (bytes, kB, MB, GB, KiB, MiB, GiB) or a bare number of bytes.
    """
    match = re.fullmatch(r"\s*([0-9.eE+]+)\s*([KkMmGgTt]?i?[Bb]?)\s*", str(text))
    if not match:
        raise SchulerError(f"{ENVIRONMENT}: cannot read {text!r} as a size such as '8 GiB'")
    try:
        number = float(match[1])
    except ValueError:
        raise SchulerError(f"{ENVIRONMENT}: cannot read {text!r} as a size such as '8 GiB'") from None
    unit = match[2].lower()
    if unit and not unit.endswith("b"):
        unit += "b"
    if unit not in _UNITS or number <= 0:
        raise SchulerError(f"{ENVIRONMENT}: cannot read {text!r} as a size such as '8 GiB'")
    return int(number * _UNITS[unit])


def _available() -> int:
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return FALLBACK_AVAILABLE


@lru_cache(maxsize=1)
def _budget_from_environment(setting: str | None) -> int:
    return parse_bytes(setting) if setting else _available() // 2


def budget() -> int:
    """The memory budget in bytes (see the module notes)."""
    return _budget_from_environment(os.environ.get(ENVIRONMENT))


def format_bytes(n: float) -> str:
    """``1536`` -> ``'1.5 KiB'``.

    Parameters
    ----------
    n : float
        A size, bytes.
    """
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(n) < 1024:
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} EiB"


def require(nbytes: float, what: str, change: str) -> None:
    """Refuse (before allocating) when ``what`` would hold more than the budget.

    Parameters
    ----------
    nbytes : float
        Estimated bytes held at once.
    what : str
        What would hold them (``"this run"``).
    change : str
        The parameters that reduce it, each quoted as `name` (``"`duration` or `output_step`"``: the command
        line shows their options).
    """
    limit = budget()
    if nbytes > limit:
        raise MemoryBudgetExceeded(
            f"{what} would hold {format_bytes(nbytes)}, more than the memory budget of {format_bytes(limit)}; "
            f"change {change} (or set {ENVIRONMENT})")


def chunk_members(member_bytes: int, largest: int = 2_000) -> int:
    """Members to evaluate at once so that a chunk uses at most a quarter of the budget.

    Parameters
    ----------
    member_bytes : int
        Memory one member needs while evaluated, bytes.
    largest : int
        Most members per chunk (a count).
    """
    return int(max(1, min(largest, budget() // (4 * max(int(member_bytes), 1)))))


def parse_seconds(text: str) -> float:
    """``"2 h"`` -> 7200.0; ``"90"`` -> 90.0; ``"none"`` -> inf (no limit).

    Parameters
    ----------
    text : str
        A duration with a unit (s, min, h, d) or a bare number of seconds; ``none``, ``off`` or ``inf``: no limit.
    """
    spoken = str(text).strip().lower()
    if spoken in ("none", "off", "inf", "unlimited"):
        return math.inf
    match = re.fullmatch(r"([0-9]*\.?[0-9]+(?:e[+-]?[0-9]{1,3})?)\s*([a-z]*)", spoken)
    if not match or match[2] not in _SECONDS or float(match[1]) <= 0:
        raise SchulerError(f"{TIME_ENVIRONMENT}: cannot read {text!r} as a duration such as '10 min', '2 h' or 'none'")
    return float(match[1]) * _SECONDS[match[2]]


def time_budget() -> float:
    """The time budget in seconds (inf within :func:`no_time_limit`; see the module notes)."""
    if _UNLIMITED.get():
        return math.inf
    setting = os.environ.get(TIME_ENVIRONMENT)
    return parse_seconds(setting) if setting else DEFAULT_TIME_BUDGET


@contextmanager
def no_time_limit(enabled: bool = True) -> Iterator[None]:
    """Within this block (when ``enabled``), :func:`require_time` accepts any estimate (``--no-time-limit``).

    Parameters
    ----------
    enabled : bool
        Whether to lift the limit (False: the block changes nothing).
    """
    token = _UNLIMITED.set(True) if enabled else None
    try:
        yield
    finally:
        if token is not None:
            _UNLIMITED.reset(token)


def format_seconds(seconds: float) -> str:
    """``95`` -> ``'1.58 min'``; ``1e9`` -> ``'31.7 years'``: an estimate as people read it.

    Parameters
    ----------
    seconds : float
        A duration, s.
    """
    for unit, size in (("years", 365.25 * 86400.0), ("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 1.5 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.2g} s"


def require_time(seconds: float, what: str, change: str) -> None:
    """Refuse (before starting) when ``what`` would take longer than the time budget.

    Parameters
    ----------
    seconds : float
        Estimated time, s.
    what : str
        What would take it (``"this run (1e+09 members)"``).
    change : str
        The parameters that shorten it, each quoted as `name` (``"`monte_carlo` or `duration`"``).

    Examples
    --------
    >>> require_time(1e7, "this run", "`monte_carlo`")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    schuler.memory.TimeBudgetExceeded: this run would take about 116 days, more than the time budget of 10 min; ...
    """
    limit = time_budget()
    if seconds > limit:
        raise TimeBudgetExceeded(
            f"{what} would take about {format_seconds(seconds)}, more than the time budget of "
            f"{format_seconds(limit)}; change {change}, or add `no_time_limit` (or set {TIME_ENVIRONMENT})")
