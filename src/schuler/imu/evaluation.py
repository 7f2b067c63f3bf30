"""What ``schuler imu run`` evaluates: its parameters, outputs, ``evaluate`` and ``run_case``.

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

Memory: one record is simulated and analysed at a time, about
:data:`BYTES_PER_SAMPLE` bytes per sample (measured with tracemalloc on a
one-hour 100 Hz industrial record: 223 bytes), refused beyond the budget
before anything is allocated.
"""

from __future__ import annotations

import math

import numpy as np

from schuler.contract import Cases, Output
from schuler.exceptions import InvalidParameter
from schuler.imu.characterise import round_trip, true_terms
from schuler.imu.error_model import ErrorModel
from schuler.imu.results import CHANNELS, DISPLAY_UNITS, TERM_UNITS, RoundTripResult, sensor_of
from schuler.imu.run_results import ImuRunResult
from schuler.imu.spec import GRADES, load_spec_file, preset
from schuler.memory import require
from schuler.params import Case, Parameter, ParameterSet

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
    Parameter("grade", "", "tactical", "Grade preset of the simulated IMU (data-sheet figures and their sources: "
              "schuler imu reproduce).", choices=GRADES, kind="choice"),
    Parameter("spec", "", None, "TOML spec file of the simulated IMU, figures in spec-sheet units (instead of "
              "--grade).", kind="text"),
    Parameter("duration", "s", "1 h", "Length of the simulated record.", minimum=0, exclusive_minimum=True,
              maximum=MAX_DURATION),
    Parameter("imu_rate", "Hz", 100.0, "Sample rate of the record.", minimum=0, exclusive_minimum=True,
              maximum=1e5),
    Parameter("output_step", "s", None, "Sample interval of the record (instead of --imu-rate).", minimum=1e-5,
              maximum=3600),
    Parameter("latitude", "deg", 45.0, "Latitude of the site (the Earth rate and gravity the record shows).",
              minimum=-90, maximum=90),
    Parameter("azimuth", "deg", 0.0, "Heading of the body x axis, clockwise from north.", minimum=-360, maximum=360),
), owner="imu", exclusive=(("grade", "spec"), ("imu_rate", "output_step")))
"""Every option of ``schuler imu run`` (and key of an ``imu`` scenario)."""


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


def case_model(grade: str | None, spec: str | None) -> ErrorModel:
    """The error model of a case: the spec file when given, else the grade preset.

    Parameters
    ----------
    grade : str or None
        Grade preset, one of :data:`~schuler.imu.spec.GRADES` (None: the default, tactical).
    spec : str or None
        Path of a TOML spec file (figures in spec-sheet units); when set it wins over ``grade``.

    Returns
    -------
    ErrorModel
        The IMU's error terms, SI.
    """
    return load_spec_file(spec) if spec else preset(grade or PARAMETERS["grade"].default)


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
    require(samples * BYTES_PER_SAMPLE, "this record", "--duration or --imu-rate")
    return samples


def _round_trip(case: Case, seed: int, member: int, models: dict) -> tuple[ErrorModel, RoundTripResult]:
    key = (case["grade"], case["spec"])
    if key not in models:
        models[key] = case_model(*key)
    model = models[key]
    dt = sample_interval(case["imu_rate"], case["output_step"])
    samples = record_samples(case["duration"], dt)
    trip = round_trip(model, duration_s=samples * dt, sample_interval_s=dt, seed=seed, member=member,
                      latitude_rad=case["latitude"], heading_rad=case["azimuth"])
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


def evaluate(cases: Cases) -> dict[str, np.ndarray]:
    """Every output of :data:`OUTPUTS` for a batch of cases: one simulated record per case (see the module notes).

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values); the record's random numbers from ``cases.random`` (seed
        :data:`NOMINAL_SEED` when None) at ``cases.members``.

    Returns
    -------
    dict of str to ndarray
        Output name -> values of shape (number of cases,), SI.
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    seed = NOMINAL_SEED if cases.random is None else cases.random.seed
    models: dict = {}
    for i in range(n):
        _, trip = _round_trip(cases.case(i), seed, int(cases.members[i]), models)
        for name, value in outputs_of(trip).items():
            out[name][i] = value
    return out


def run_case(case: Case, fidelity: str | None = None) -> ImuRunResult:
    """One case in full: the round trip of the nominal record (seed 0, member 0) with its Allan curves.

    Parameters
    ----------
    case : Case
        Every parameter of :data:`PARAMETERS`, SI.
    fidelity : str or None
        The contract's evaluation fidelity; this system has a single way of evaluating, so it is not used.

    Returns
    -------
    ImuRunResult
        The model, the round trip with its curves, the outputs (SI) and the true terms per channel.

    Examples
    --------
    >>> r = run_case(PARAMETERS.case(grade="consumer", duration=600.0))
    >>> round(float(r.outputs["noise_gyro_x_N"] / r.true_terms["gyro_x"]["N"]), 2)
    1.0
    """
    model, trip = _round_trip(case, NOMINAL_SEED, 0, {})
    truth = {}
    for channel in CHANNELS:
        errors = model.gyro if sensor_of(channel) == "gyro" else model.accel
        terms = true_terms(errors, "xyz".index(channel[-1]))
        truth[channel] = {term: float(terms[term]) for term in OUTPUT_TERMS}
    return ImuRunResult(model=model, round_trip=trip, outputs=outputs_of(trip), true_terms=truth,
                        latitude_rad=case["latitude"], azimuth_rad=case["azimuth"])


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


__all__ = ["NOMINAL_SEED", "OUTPUTS", "PARAMETERS", "case_model", "evaluate", "member_bytes", "outputs_of",
           "run_case"]
