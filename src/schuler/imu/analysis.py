"""The IMU layer's everyday functions: read a record, its Allan deviation, its IEEE 952 terms.

Options are Python values, not command-line text: a CSV file's ``columns``
and ``units`` are dicts (``units={"gyro": "deg/s", "accel": "g"}``: a unit as
text or a pint unit, ``gyro`` and ``accel`` standing for their three axes),
``kind`` and ``axes`` names (``"increment"``, ``"RFU"``), a site in SI
(``latitude``). ``schuler imu allan`` parses its options and calls
:func:`allan_deviation`, so the command and the function give the same numbers.

>>> from schuler.imu.simulate import simulate_record
>>> from schuler.imu.spec import preset
>>> record = simulate_record(preset("consumer"), duration=60.0, sample_interval=0.01, seed=2)
>>> terms = identify(record, channels=["gyro_x"])
>>> round(terms.terms["gyro_x"]["N"] / float(preset("consumer").gyro.random_walk[0]), 1)
1.0
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from pathlib import Path

from schuler.exceptions import InvalidParameter
from schuler.imu.characterise import analyse_record, analyse_source
from schuler.imu.files import open_record, read_record
from schuler.imu.plots import figures
from schuler.imu.readers import CHUNK_ROWS
from schuler.imu.record import ImuRecord
from schuler.imu.results import CHANNELS, AllanResult, IdentifiedTerms
from schuler.memory import require
from schuler.params import Parameter

ALLAN_BYTES_PER_SAMPLE = 32
"""Memory an Allan analysis holds per sample of the file: six channels' angles over twice the longest lag
(1/8 of the samples), and their copy while a chunk is added, bytes."""

CHUNK_BYTES = CHUNK_ROWS * 7 * 8 * 4
"""Memory one chunk of a file holds while read and converted, bytes."""

PER_OCTAVE = Parameter("per_octave", "", 2, "Averaging times per octave of tau.", minimum=1, maximum=16,
                       kind="integer")
"""How densely the Allan curve samples tau (``--per-octave``)."""


def _channels(channels: Iterable[str] | None) -> tuple[str, ...]:
    if channels is None:
        return CHANNELS
    chosen = (channels,) if isinstance(channels, str) else tuple(channels)
    for name in chosen:
        if name not in CHANNELS:
            close = difflib.get_close_matches(str(name), CHANNELS, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise InvalidParameter("channels", f"{name!r} is not a channel; {hint}channels are {', '.join(CHANNELS)}")
    if not chosen or len(set(chosen)) < len(chosen):
        raise InvalidParameter("channels", f"give one or more different channels of {', '.join(CHANNELS)}")
    return tuple(name for name in CHANNELS if name in chosen)


def allan_deviation(record: ImuRecord | str | Path, *, channels: Iterable[str] | None = None, per_octave: int = 2,
                    **options) -> AllanResult:
    """Overlapping Allan deviation with 68 % confidence intervals and the IEEE 952 terms of a record's channels.

    A file is streamed chunk by chunk: the memory it holds (the longest lag's
    angles per channel) is estimated and refused beyond the budget first.

    Parameters
    ----------
    record : ImuRecord, str or Path
        A record in memory, or an IMU file: the project's CSV (any CSV with ``columns`` and ``units``), PSINS
        ``.imu`` or ``.parquet``.
    channels : sequence of str, optional
        The channels to analyse, of ``gyro_x`` .. ``accel_z`` (default all six); the grade is judged on the gyro
        channels among them (None without one).
    per_octave : int
        Averaging times per octave of tau, number of (1 to 16).
    **options
        CSV files only, the reader's keywords (:func:`~schuler.imu.readers.open_csv`): ``columns`` (channel ->
        the file's column), ``units`` (channel, ``gyro`` or ``accel`` -> unit text or pint unit), ``kind``
        ("rate" or "increment"), ``axes`` (where the file's x, y, z point, e.g. "RFU"), ``latitude`` (rad).

    Returns
    -------
    AllanResult
        Per channel the curve (tau in s, deviation and bounds in rad/s or m/s^2, edf) and the terms (SI units of
        :data:`~schuler.imu.results.TERM_UNITS`), and the grade; ``to_dataframe()`` indexed by ``tau_s``,
        ``plot()`` the gyro figure.
    """
    chosen = _channels(channels)
    per_octave = PER_OCTAVE.check(per_octave)
    if isinstance(record, ImuRecord):
        if options:
            raise InvalidParameter(sorted(options)[0], "applies to a file, not to a record in memory")
        result = analyse_record(record, per_octave=per_octave, channels=chosen)
    else:
        source = open_record(record, **options)
        require(source.estimated_samples * ALLAN_BYTES_PER_SAMPLE * len(chosen) // len(CHANNELS) + CHUNK_BYTES,
                "this Allan analysis", "the file (analyse a part of it)")
        result = analyse_source(source, per_octave=per_octave, channels=chosen)
    result.attach_figures(figures)
    return result


def identify(record: ImuRecord | str | Path, *, channels: Iterable[str] | None = None, per_octave: int = 2,
             **options) -> IdentifiedTerms:
    """The IEEE 952 terms N, B, K, Q, R of a record's channels, with uncertainties and resolvability.

    The terms are fitted by weighted least squares to the Allan curves of
    :func:`allan_deviation` (:func:`~schuler.imu.noise_terms.identify_terms`).

    Parameters
    ----------
    record : ImuRecord, str or Path
        A record in memory or an IMU file (any format of :func:`allan_deviation`).
    channels : sequence of str, optional
        The channels to identify, of ``gyro_x`` .. ``accel_z`` (default all six).
    per_octave : int
        Averaging times per octave of tau of the curves fitted, number of (1 to 16).
    **options
        CSV files only, the reader's keywords (see :func:`allan_deviation`).

    Returns
    -------
    IdentifiedTerms
        Per channel N (rad/s^0.5, m/s^1.5), B (rad/s, m/s^2), K (rad/s^1.5, m/s^2.5), Q (rad, m/s), R (rad/s^2,
        m/s^3) with ``sigma``, ``upper_bound`` and ``resolved``; ``to_dataframe()`` one row per channel and term.
    """
    terms = allan_deviation(record, channels=channels, per_octave=per_octave, **options).terms()
    terms.attach_figures(figures)
    return terms


__all__ = ["allan_deviation", "identify", "read_record"]
