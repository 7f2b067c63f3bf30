"""schuler: model, simulate and analyse gyroscopic navigation instruments.

Five instrument systems, one subpackage each:

- :mod:`schuler.navigation_errors`  Schuler-tuned INS error propagation (Bollay).
- :mod:`schuler.gyro_vertical`      gyro vertical with integral correction (Drozdovich).
- :mod:`schuler.drift_calibration`  gyro drift calibration by alternating torque pulses.
- :mod:`schuler.gyrocompassing`     physical gyrocompassing of a platform INS.
- :mod:`schuler.ground_gyrocompass` ground gyrocompass during rotor run-down.

Each is a :class:`~schuler.contract.System` (the contract in
:mod:`schuler.contract`), reached by name with :func:`get_system`::

    >>> import math, schuler
    >>> result = schuler.get_system("align").run(latitude=math.radians(50), drift_east=math.radians(0.01) / 3600)

The shared numerical core (Earth constants, the exact linear-systems engine,
streaming statistics, addressed random numbers) is :mod:`schuler.core`; it
works in SI units only. Unit parsing lives at the boundary in :mod:`schuler.units`.
"""

__version__ = "0.2.0"


def get_system(name: str):
    """The system registered under ``name`` (``errors``, ``vertical``, ``calibrate``, ``align``, ``north``).

    Parameters
    ----------
    name : str
        Command name of the system.
    """
    from schuler.registry import get_system as lookup

    return lookup(name)


__all__ = ["__version__", "get_system"]
