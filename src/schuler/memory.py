"""How much memory a command may hold, and a clear refusal before it allocates more.

Every command that allocates in proportion to its inputs (time points,
members, samples) estimates what it will hold and calls :func:`require`
*before* allocating. The budget is half the memory the machine has available
when the process starts (``MemAvailable`` of ``/proc/meminfo``; 4 GiB where
that cannot be read), or what the environment variable ``SCHULER_MEMORY_BUDGET``
says (``"8 GiB"``, ``"500 MB"``, or a number of bytes).

Examples
--------
>>> require(10 * 2**20, "a small run", "--duration")  # 10 MiB: fine
>>> require(2**60, "this run", "--duration or --output-step")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
schuler.memory.MemoryBudgetExceeded: this run would hold 1 EiB, more than the memory budget ...
"""

from __future__ import annotations

import os
import re
from functools import lru_cache

from schuler.exceptions import SchulerError

ENVIRONMENT = "SCHULER_MEMORY_BUDGET"
FALLBACK_AVAILABLE = 4 * 2**30
_UNITS = {"": 1, "b": 1, "kb": 10**3, "mb": 10**6, "gb": 10**9, "tb": 10**12,
          "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}


class MemoryBudgetExceeded(SchulerError):
    """A command would hold more memory than the budget allows."""


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
        The options that reduce it (``"--duration or --output-step"``).
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
