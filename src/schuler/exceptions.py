"""The exception hierarchy used by the whole package.

Every error a user can cause derives from :class:`SchulerError`; the CLI turns
each into one line on stderr and exit code 2.
"""

from __future__ import annotations

import functools
import re


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


_QUOTED_NAME = re.compile(r"`([a-z][a-z0-9_]*)`")


def as_options(text: str) -> str:
    """A library message as the command line shows it: each parameter quoted as `name` becomes its option.

    The library speaks of parameters (its messages quote each in backticks, as in the example), the command line
    of options; every option is its parameter's name with dashes (:attr:`schuler.params.Parameter.option`).

    Parameters
    ----------
    text : str
        The message, its parameters quoted as `name`.

    Examples
    --------
    >>> as_options("give `stop_intervals` or find them (`stops_from` imu)")
    'give --stop-intervals or find them (--stops-from imu)'
    """
    return _QUOTED_NAME.sub(lambda match: "--" + match[1].replace("_", "-"), text)


def renamed_keywords(**renamed: str):
    """A function's former keyword arguments refused with the name that replaced each (see CHANGELOG.md).

    Keyword arguments are SI and carry no unit suffix (``duration``, not ``duration_s``); a caller still
    writing a former name is told the new one instead of Python's bare "unexpected keyword argument".

    Parameters
    ----------
    **renamed : str
        Each former name with its replacement.

    Examples
    --------
    >>> @renamed_keywords(duration_s="duration")
    ... def hold(duration):
    ...     return duration
    >>> hold(duration=2.0)
    2.0
    >>> hold(duration_s=2.0)
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: duration_s: renamed to 'duration' (see CHANGELOG.md)
    """

    def decorate(function):
        @functools.wraps(function)
        def refusing(*args, **kwargs):
            for name in kwargs.keys() & renamed.keys():
                raise InvalidParameter(name, f"renamed to {renamed[name]!r} (see CHANGELOG.md)")
            return function(*args, **kwargs)

        return refusing

    return decorate
