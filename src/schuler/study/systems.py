"""Which systems this installation has.

A system is *not available* only when its ``api`` module (or the subpackage
holding it) does not exist. Any other failure while importing it, including a
missing third-party module it needs, is a real error and propagates.
"""

from __future__ import annotations

from schuler.contract import System
from schuler.registry import SYSTEM_MODULES, get_system


def load_system(name: str) -> System | None:
    """The system registered under ``name``, or None when its module does not exist.

    Parameters
    ----------
    name : str
        A registered system's name (a key of ``SYSTEM_MODULES``: ``"align"``, ``"errors"``, ...).

    Returns
    -------
    System or None
        The system; None when its module (or the subpackage holding it) is not installed.

    Raises
    ------
    InvalidParameter
        ``name`` is not registered (the message lists the registered names and suggests a close one).
    ModuleNotFoundError
        A module the system needs (other than its own) is missing.

    Examples
    --------
    >>> load_system("errors") is None or load_system("errors").name == "errors"
    True
    """
    try:
        return get_system(name)  # refuses an unregistered name before importing anything
    except ModuleNotFoundError as error:
        if error.name in _module_and_parents(SYSTEM_MODULES[name]):
            return None
        raise


def _module_and_parents(module: str) -> set[str]:
    """``a.b.c`` -> {"a.b.c", "a.b"}: the module and its parent packages below the top one."""
    parts = module.split(".")
    return {".".join(parts[:i]) for i in range(2, len(parts) + 1)}
