"""The exception hierarchy used by the whole package.

Every error a user can cause derives from :class:`SchulerError`; the CLI turns
each into one line on stderr and exit code 2.
"""

from __future__ import annotations


class SchulerError(Exception):
    """Base class of every error schuler raises on purpose."""


class InvalidParameter(SchulerError, ValueError):
    """A parameter is out of its physical range, of the wrong unit, or not finite.

    Parameters
    ----------
    name : str
        The parameter's name as the user wrote it (option or scenario key).
    message : str
        What is wrong and what is allowed.
    """

    def __init__(self, name: str, message: str):
        self.name = name
        self.reason = message
        super().__init__(f"{name}: {message}")


class ScenarioError(SchulerError):
    """A scenario file is missing, malformed or fails validation."""


class NotObservable(SchulerError):
    """The requested quantity cannot be determined (e.g. azimuth at the pole)."""


class IdentificationError(SchulerError):
    """A parameter identification could not be carried out on the given data."""


class SimulationError(SchulerError):
    """A numerical simulation failed (the solver reported no success)."""
