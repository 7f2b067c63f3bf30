"""What ``schuler imu run`` evaluates: its parameters, outputs and ``evaluate``.

A case is an IMU (a grade preset or a TOML spec file, :mod:`~schuler.imu.spec`)
recording at rest and level at a site for ``duration`` at ``imu_rate``. Its
evaluation is the round trip of :func:`~schuler.imu.characterise.round_trip`:
simulate the record from the known terms, compute the overlapping Allan
deviation of its six channels and identify the IEEE Std 952 terms N, B, K, Q,
R by weighted least squares. The outputs are the identified terms per channel
in SI (``noise_gyro_x_N`` in rad/sqrt(s) ... ``noise_accel_z_R`` in m/s^3), NaN
where the record does not resolve a term (too short for K and R, B hidden
under N), and the fraction of the resolved terms that lie within their
tolerance of the true values (3 standard uncertainties plus the method's bias).

Randomness: a record is random by nature, so even the nominal case draws
numbers. Every case simulates its record from addressed streams
(:class:`~schuler.core.random.RandomStreams`): seed :data:`NOMINAL_SEED` when
``cases.random`` is None (the nominal case), the Monte Carlo's seed otherwise,
at the case's member number (``cases.members``: 0 for a single run, the global
case number in a sweep, the member number in a Monte Carlo). So ``schuler imu
run`` characterises record (seed 0, member 0), which is exactly Monte Carlo
member 0 of seed 0, and ``--monte-carlo N --seed S`` adds the statistics of
the identified terms over N independent records (seed S, members 0 .. N-1):
the scatter of the estimator, from which the tolerances are judged. A case's
numbers never depend on chunking or executor.

A run in full (``histories=True``) keeps the first case's Allan curves as
histories over the averaging time (``imu_allan``, indexed by ``tau_s``: the
columns of ``imu_allan.csv``) and, as extras, the record (model, seed, member,
samples, site), the round trip's checks, the true and identified terms and the
grade the gyro curves belong to: ``schuler imu run --json``'s keys.

Memory: one record is simulated and analysed at a time, about
:data:`BYTES_PER_SAMPLE` bytes per sample (measured with tracemalloc on a
one-hour 100 Hz industrial record: 223 bytes), refused beyond the budget
before anything is allocated.
"""

from __future__ import annotations

import math

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.exceptions import InvalidParameter
from schuler.imu.characterise import round_trip, true_terms
from schuler.imu.error_model import ErrorModel
from schuler.imu.instrument import resolve_model
from schuler.imu.results import (
    CHANNELS,
    CHECK_UNITS,
    DISPLAY_UNITS,
    GRADE_MARGIN_UNITS,
    NOISE_UNITS,
    TERM_UNITS,
    RoundTripResult,
    curves_histories,
    sensor_of,
)
from schuler.imu.spec import GRADES
from schuler.memory import require
from schuler.params import Case, Parameter, ParameterSet
from schuler.results import json_safe

NOMINAL_SEED = 0
"""Seed of the nominal case's record (``cases.random`` is None)."""

BYTES_PER_SAMPLE = 256
"""Memory one sample of a simulated and analysed record holds at the peak, bytes (measured: 223)."""

MIN_SAMPLES = 256
"""Fewest samples of a record: below, an Allan curve has too few points for five terms."""

MAX_DURATION = 30 * 86400.0
"""Longest record, s (30 days)."""

OUTPUT_TERMS = ("N", "B", "K", "Q", "R")
"""The IEEE 952 terms in the order of the outputs (the issue's order)."""

TERM_NAMES = {"N": "random walk N", "B": "bias instability B", "K": "rate random walk K", "Q": "quantisation Q",
              "R": "rate ramp R"}

PARAMETERS = ParameterSet((
    Parameter("imu", "", None, "The simulated IMU: a grade (" + ", ".join(GRADES) + "; data-sheet figures and "
              "their sources: schuler imu reproduce), a TOML spec file (figures in spec-sheet units) or a "
              "recording whose identified noise terms are simulated (not set: tactical).", kind="text"),
    Parameter("duration", "s", "1 h", "Length of the simulated record.", minimum=0, exclusive_minimum=True,
              maximum=MAX_DURATION),
    Parameter("imu_rate", "Hz", 100.0, "Sample rate of the record.", minimum=0, exclusive_minimum=True,
              maximum=1e5),
    Parameter("output_step", "s", None, "Sample interval of the record (instead of --imu-rate).", minimum=1e-5,
              maximum=3600),
    Parameter("latitude", "deg", 45.0, "Latitude of the site (the Earth rate and gravity the record shows).",
              minimum=-90, maximum=90),
    Parameter("azimuth", "deg", 0.0, "Heading of the body x axis, clockwise from north.", minimum=-360, maximum=360),
), owner="imu", exclusive=(("imu_rate", "output_step"),), renamed={"grade": "imu", "spec": "imu"})
"""Every option of ``schuler imu run`` (and key of an ``imu`` scenario)."""


DEFAULT_IMU = "tactical"
"""The grade simulated when ``imu`` is not set."""


def imu_of(value: str | None) -> str:
    """The IMU a case names (:func:`~schuler.imu.instrument.resolve_model` reads it), not set the default grade.

    Parameters
    ----------
    value : str or None
        The case's ``imu``.
    """
    return DEFAULT_IMU if value is None else str(value).strip()


def output_name(channel: str, term: str) -> str:
    """Flat output key of a channel's term: ``noise_gyro_x_N`` (the JSON's ``noise.gyro_x.N``).

    Parameters
    ----------
    channel : str
        One of :data:`~schuler.imu.results.CHANNELS` (``gyro_x`` .. ``accel_z``).
    term : str
        An IEEE 952 term letter, one of :data:`OUTPUT_TERMS`.

    Returns
    -------
    str
        The output's name.
    """
    return f"noise_{channel}_{term}"


OUTPUTS = (
    *(Output(output_name(channel, term), TERM_UNITS[sensor_of(channel)][term], DISPLAY_UNITS[sensor_of(channel)][term],
             f"identified {TERM_NAMES[term]} of {channel} (NaN: not resolved by the record)")
      for channel in CHANNELS for term in OUTPUT_TERMS),
    Output("fraction_within_tolerance", "1", "",
           "share of the resolved terms within 3 sigma + method bias of the true ones (1: all)"),
)


def sample_interval(imu_rate: float, output_step: float | None) -> float:
    """dt, s: ``output_step`` when set, else 1 / ``imu_rate``.

    Parameters
    ----------
    imu_rate : float
        Sample rate, Hz.
    output_step : float or None
        Sample interval, s; None or NaN: not set.

    Returns
    -------
    float
        Sample interval dt, s.
    """
    return float(output_step) if output_step is not None and not math.isnan(output_step) else 1.0 / float(imu_rate)


def record_samples(duration: float, dt: float) -> int:
    """Samples of a record, refused below :data:`MIN_SAMPLES` and beyond the memory budget.

    Parameters
    ----------
    duration : float
        Length of the record, s.
    dt : float
        Sample interval, s.

    Returns
    -------
    int
        round(duration / dt), number of samples.
    """
    samples = int(round(duration / dt))
    if samples < MIN_SAMPLES:
        raise InvalidParameter("duration", f"{duration:g} s at {dt:g} s per sample gives {samples:,} samples; an "
                               f"Allan analysis of five terms needs at least {MIN_SAMPLES}")
    require(samples * BYTES_PER_SAMPLE, "this record", "`duration` or `imu_rate`")
    return samples


def _round_trip(case: Case, seed: int, member: int, models: dict) -> tuple[ErrorModel, RoundTripResult]:
    key = imu_of(case["imu"])  # one model per IMU in a batch
    if key not in models:
        models[key] = resolve_model(key)
    model = models[key]
    dt = sample_interval(case["imu_rate"], case["output_step"])
    samples = record_samples(case["duration"], dt)
    trip = round_trip(model, duration=samples * dt, sample_interval=dt, seed=seed, member=member,
                      latitude=case["latitude"], heading=case["azimuth"])
    return model, trip


def outputs_of(trip: RoundTripResult) -> dict[str, float]:
    """The flat outputs of one round trip: identified terms (NaN unless resolved) and the share within tolerance.

    Parameters
    ----------
    trip : RoundTripResult
        The simulated record's analysis and its checks against the true terms.

    Returns
    -------
    dict of str to float
        Output name (:data:`OUTPUTS`) -> value, SI (NaN: a term not resolved; the share NaN without checks).
    """
    out = {}
    for channel in CHANNELS:
        terms = trip.analysis.noise[channel].terms
        for term in OUTPUT_TERMS:
            out[output_name(channel, term)] = float(terms.values[term]) if terms.resolved[term] else math.nan
    checks = trip.checks
    out["fraction_within_tolerance"] = sum(c.within for c in checks) / len(checks) if checks else math.nan
    return out


EXTRA_UNITS = {**NOISE_UNITS, **CHECK_UNITS, **GRADE_MARGIN_UNITS, "samples": "1", "seed": "1", "member": "1",
               "fraction_within_tolerance": "1"}
"""Units of a run's extras whose key does not name one (the terms by letter, the checks, the grade margins)."""


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases: one simulated record per case (see the module notes).

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values); the record's random numbers from ``cases.random`` (seed
        :data:`NOMINAL_SEED` when None) at ``cases.members``.
    histories : bool
        Whether to give the first case in full: its Allan curves (``imu_allan``) and the record's analysis as
        extras (an :class:`~schuler.contract.Evaluation`).

    Returns
    -------
    dict of str to ndarray, or Evaluation
        Output name -> values of shape (number of cases,), SI.

    Examples
    --------
    >>> run = evaluate(Cases.from_case(PARAMETERS.case(imu="consumer", duration=600.0)), histories=True)
    >>> round(float(run["noise_gyro_x_N"][0] / run.extras["true_terms"]["gyro_x"]["N"]), 2)
    1.0
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    seed = NOMINAL_SEED if cases.random is None else cases.random.seed
    models: dict = {}
    first = None
    for i in range(n):
        model, trip = _round_trip(cases.case(i), seed, int(cases.members[i]), models)
        first = first or (model, trip)
        for name, value in outputs_of(trip).items():
            out[name][i] = value
    if not histories:
        return out
    assert first is not None, "a batch holds at least one case"
    return _in_full(cases.case(0), *first, out)


def _in_full(case: Case, model: ErrorModel, trip: RoundTripResult, outputs: dict[str, np.ndarray]) -> Evaluation:
    """The first case in full: its Allan curves over tau and the record's analysis (JSON-safe extras)."""
    analysis = trip.analysis
    truth = {}
    for channel in CHANNELS:
        errors = model.gyro if sensor_of(channel) == "gyro" else model.accel
        terms = true_terms(errors, "xyz".index(channel[-1]))
        truth[channel] = {term: float(terms[term]) for term in OUTPUT_TERMS}
    extras = {"model": model.name, "model_source": model.source, "seed": trip.seed, "member": trip.member,
              "samples": analysis.samples, "duration_s": trip.duration_s, "sample_interval_s": trip.sample_interval_s,
              "latitude_rad": case["latitude"], "azimuth_rad": case["azimuth"], "all_within": trip.all_within,
              "grade": analysis.grade, "grade_margin": json_safe(analysis.grade_margin), "true_terms": truth,
              "checks": json_safe(trip.checks), "noise": analysis.to_dict()["noise"]}
    return Evaluation(outputs, histories={"imu_allan": curves_histories(analysis.noise)}, extras=extras,
                      units=EXTRA_UNITS)


def member_bytes(case: Case) -> int:
    """Memory one member holds while evaluated: its record and analysis (:data:`BYTES_PER_SAMPLE` per sample).

    Parameters
    ----------
    case : Case
        The member's parameters, SI (``duration`` s, ``imu_rate`` Hz, ``output_step`` s).

    Returns
    -------
    int
        Memory, bytes.
    """
    dt = sample_interval(case["imu_rate"], case["output_step"])
    return int(BYTES_PER_SAMPLE * max(1.0, case["duration"] / dt))


__all__ = ["NOMINAL_SEED", "OUTPUTS", "PARAMETERS", "evaluate", "member_bytes", "outputs_of"]
