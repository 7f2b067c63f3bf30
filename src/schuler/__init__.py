"""schuler: model, simulate and analyse gyroscopic navigation instruments.

Each instrument system is a :class:`~schuler.contract.System` (the contract in
:mod:`schuler.contract`), reached by name with :func:`get_system`; the names
are :func:`list_systems`::

    >>> import schuler
    >>> result = schuler.get_system("align").run(latitude="50 deg", drift_east="0.01 deg/h")

Values are SI (rad, rad/s, m, s), or carry their unit as text (``"50 deg"``)
or as a pint Quantity. The shared numerical core (Earth constants, the exact
linear-systems engine, streaming statistics, addressed random numbers) is
:mod:`schuler.core`; it works in SI units only. Unit parsing lives at the
boundary in :mod:`schuler.units`.
"""

from schuler.registry import SYSTEM_MODULES as _SYSTEM_MODULES
from schuler.registry import list_systems

__version__ = "0.2.0"


def _systems_listing() -> str:
    """The registered systems, one line each: command name and subpackage."""
    lines = [f"- ``{name}``  :mod:`{module.rsplit('.', 1)[0]}`" for name, module in _SYSTEM_MODULES.items()]
    return f"\n{len(lines)} instrument systems, one subpackage each (``schuler NAME`` on the command line):\n\n" \
        + "\n".join(lines) + "\n"


__doc__ = (__doc__ or "") + _systems_listing()


def get_system(name: str):
    """The system registered under ``name`` (one of :func:`list_systems`: ``errors``, ``align``, ``north`` ...).

    Parameters
    ----------
    name : str
        Command name of the system.
    """
    from schuler.registry import get_system as lookup

    return lookup(name)


__all__ = ["__version__", "get_system", "list_systems"]
