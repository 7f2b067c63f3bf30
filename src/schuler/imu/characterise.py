"""Characterise records: Allan curves and IEEE 952 terms of six channels, round trips, the PSINS recording.

These are the functions the command line calls (``schuler imu allan``,
``run``, ``reproduce``); each takes SI keyword arguments or records and
returns a typed result of :mod:`~schuler.imu.results`.

- :func:`analyse_record` / :func:`analyse_file`: Allan deviation with confidence
  intervals and identified terms per channel; a file is streamed chunk by chunk;
- :func:`classify_grade`: the grade preset nearest to the identified gyro terms;
- :func:`round_trip`: simulate from known terms, identify, compare within tolerances;
- :func:`reproduce_psins`: the real laser-gyro recording.
"""

from __future__ import annotations

import math

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.exceptions import InvalidParameter, renamed_keywords
from schuler.imu.allan import DEFAULT_MAX_FRACTION, AllanAccumulator, AllanCurve, allan_lags
from schuler.imu.error_model import ErrorModel, SensorErrors
from schuler.imu.files import open_record, read_record
from schuler.imu.noise_terms import TERMS, identify_terms, no_terms
from schuler.imu.readers import RecordSource
from schuler.imu.record import ImuRecord, record_info
from schuler.imu.results import (
    CHANNELS,
    AllanResult,
    ChannelNoise,
    PsinsReproduction,
    RoundTripResult,
    TermCheck,
    sensor_of,
)
from schuler.imu.simulate import simulate_record
from schuler.imu.spec import GRADES, preset

TOLERANCE_FACTORS = {"Q": 3.0, "N": 3.0, "B": 3.0, "K": 3.0, "R": 3.0}
"""Round-trip tolerance of each term in units of its standard uncertainty (3 sigma).

The sigma (:mod:`~schuler.imu.noise_terms`, inflated for the correlation of
overlapping estimates) is what makes N and Q tight (~0.1-1 %: many short-tau
points with huge edf) and B and K loose (10-50 %: the few long-tau points with
edf of a few)."""

GRADE_CONFIDENCE = 0.99
"""Confidence of the upper bound of a measured Allan deviation that a grade's model must stay below."""

GRADE_ALLOWANCE = 1.05
"""A grade's curve may exceed that bound by 5 %: its figures are typical, and at short tau (edf ~1e5)
the bound is within 1 % of the measured curve, closer than a model and its simulation agree."""


def classify_grade(noise: dict) -> tuple[str | None, dict[str, float]]:
    """The grade preset whose gyro Allan deviation stays below the measured one at every tau and comes closest.

    A record's Allan deviation is the sensor's plus whatever else moved it
    (vibration, sway), so a grade is consistent with the record when its model
    curve (:meth:`~schuler.imu.error_model.SensorErrors.allan_variance`: Q, N,
    flicker B, K) lies below the upper 99 % confidence bound of every gyro
    channel (with :data:`GRADE_ALLOWANCE`); of the consistent grades, the one
    whose curve comes closest to the record's (the largest margin) is the
    record's. The presets are not nested (the consumer part's noise density is
    below the industrial module's), so "closest" rather than "noisiest". A clean
    record of a grade therefore returns that grade, and a record dominated by
    motion still gets the grade its noise floor allows.

    Parameters
    ----------
    noise : dict
        Channel -> :class:`~schuler.imu.results.ChannelNoise`.

    Returns
    -------
    grade, margins : str or None, dict
        ``margins[grade]`` is the largest ratio model / upper bound (<= 1.05: consistent);
        the grade is None when no preset is consistent (a sensor noisier than consumer MEMS), and None with no
        margins when ``noise`` holds no gyro channel.
    """
    from scipy.stats import chi2

    if not any(sensor_of(name) == "gyro" for name in noise):
        return None, {}

    margins: dict[str, float] = {}
    for grade in GRADES:
        model = preset(grade).gyro
        worst = 0.0
        for name, channel in noise.items():
            if sensor_of(name) != "gyro":
                continue
            curve = channel.curve
            upper = curve.adev * np.sqrt(curve.edf / chi2.ppf((1.0 - GRADE_CONFIDENCE) / 2.0, curve.edf))
            expected = np.sqrt(model.allan_variance(curve.tau_s, "xyz".index(name[-1])))
            worst = max(worst, float(np.max(expected / upper)))
        margins[grade] = worst
    consistent = [grade for grade in GRADES if margins[grade] <= GRADE_ALLOWANCE]
    return (max(consistent, key=margins.__getitem__) if consistent else None), margins


@renamed_keywords(sample_interval_s="sample_interval")
def analyse_chunks(chunks, *, sample_interval: float, expected_samples: int, kind: str = "rate",
                   source: str = "", per_octave: int = 2, max_fraction: float = DEFAULT_MAX_FRACTION,
                   channels: tuple[str, ...] = CHANNELS) -> AllanResult:
    """Allan analysis of streamed ``(time_s, gyro, accel)`` chunks (rates or increments, see ``kind``).

    ``expected_samples`` sets the lags (an estimate is fine: lags beyond
    ``max_fraction`` of the samples actually seen are dropped).

    Parameters
    ----------
    chunks : iterable of (ndarray, ndarray, ndarray)
        ``(time_s, gyro, accel)`` per chunk: times, s, shape (n,); gyro and accelerometer samples, arrays of
        shape (n, 3), body axes x forward, y right, z down: rad/s and m/s^2 (``kind="rate"``) or rad and m/s
        over each interval (``kind="increment"``). Only the sensor columns are used.
    sample_interval : float
        Sample interval dt, s.
    expected_samples : int
        Samples the record is expected to hold, number of (sets the lags; at least 4 used).
    kind : {"rate", "increment"}
        What the sensor columns hold; increments are divided by dt.
    source : str
        Name of the record shown in the result (e.g. the file name).
    per_octave : int
        Averaging times per octave of tau, number of.
    max_fraction : float
        Longest lag as a fraction of the samples seen, ratio (default 1/8).
    channels : tuple of str
        The channels to analyse, of :data:`~schuler.imu.results.CHANNELS` (default all six; the grade is
        judged on the gyro channels among them).

    Returns
    -------
    AllanResult
        Curves with confidence intervals, identified terms of the channels and the grade they match.
    """
    dt = float(sample_interval)
    lags = allan_lags(max(4, int(expected_samples)), per_octave=per_octave, max_fraction=max_fraction)
    # all six columns as they come (a copy's layout would move the offsets' rounding)
    columns = slice(None) if channels == CHANNELS else [CHANNELS.index(name) for name in channels]
    accumulator = AllanAccumulator(dt, lags, channels=len(channels))
    for _, gyro, accel in chunks:
        block = np.concatenate([gyro, accel], axis=1)[:, columns]
        accumulator.update(block / dt if kind == "increment" else block)
    if accumulator.samples < 16:
        raise InvalidParameter("samples", f"an Allan analysis needs at least 16 samples, got {accumulator.samples}")
    curves = accumulator.curves(max_lag=int(accumulator.samples * max_fraction))
    noise = {name: ChannelNoise(curve=curve, terms=identify_terms(curve) if np.any(curve.adev > 0) else no_terms())
             for name, curve in zip(channels, curves)}
    grade, margins = classify_grade(noise)
    return AllanResult(source=source, samples=accumulator.samples, sample_interval_s=dt,
                       duration_s=accumulator.samples * dt, noise=noise, grade=grade, grade_margin=margins)


def analyse_record(record: ImuRecord, per_octave: int = 2, max_fraction: float = DEFAULT_MAX_FRACTION,
                   channels: tuple[str, ...] = CHANNELS) -> AllanResult:
    """Allan curves with confidence intervals and IEEE 952 terms of the six channels of a record.

    Parameters
    ----------
    record : ImuRecord
        The samples (rates in SI, body axes).
    per_octave : int
        Averaging times per octave of tau, number of.
    max_fraction : float
        Longest lag as a fraction of the record's samples, ratio (default 1/8).
    channels : tuple of str
        The channels to analyse (default all six, :data:`~schuler.imu.results.CHANNELS`).

    Returns
    -------
    AllanResult
        Curves, terms and grade of the channels.

    Examples
    --------
    >>> from schuler.imu.spec import preset
    >>> record = simulate_record(preset("consumer"), duration=60.0, sample_interval=0.01, seed=2)
    >>> result = analyse_record(record)
    >>> round(float(result.noise["gyro_x"].terms.values["N"] / preset("consumer").gyro.random_walk[0]), 1)
    1.0
    """
    chunks = [(record.time_s, record.gyro_rate_rad_s, record.accel_m_s2)]
    return analyse_chunks(chunks, sample_interval=record.sample_interval_s, expected_samples=record.samples,
                          source=record.source, per_octave=per_octave, max_fraction=max_fraction, channels=channels)


def analyse_source(source: RecordSource, per_octave: int = 2, max_fraction: float = DEFAULT_MAX_FRACTION,
                   channels: tuple[str, ...] = CHANNELS) -> AllanResult:
    """Allan analysis of an opened file, chunk by chunk (memory bounded by the longest lag, not the file).

    Parameters
    ----------
    source : RecordSource
        The opened file (:func:`~schuler.imu.files.open_record`); its chunks are consumed.
    per_octave : int
        Averaging times per octave of tau, number of.
    max_fraction : float
        Longest lag as a fraction of the samples read, ratio (default 1/8).
    channels : tuple of str
        The channels to analyse (default all six, :data:`~schuler.imu.results.CHANNELS`).

    Returns
    -------
    AllanResult
        Curves, terms and grade of the channels; ``source`` is the file's name.
    """
    chunks = source.chunks()
    first = next(chunks, None)
    if first is None:
        raise InvalidParameter("file", f"{source.path.name} holds no samples")

    def all_chunks():
        yield first
        yield from chunks

    return analyse_chunks(all_chunks(), sample_interval=source.interval_s(),
                          expected_samples=source.estimated_samples, kind=source.kind, source=source.path.name,
                          per_octave=per_octave, max_fraction=max_fraction, channels=channels)


def analyse_file(path, per_octave: int = 2, max_fraction: float = DEFAULT_MAX_FRACTION, **options) -> AllanResult:
    """Allan analysis of an IMU file (any format of :func:`~schuler.imu.files.open_record`), streamed.

    Parameters
    ----------
    path : str or Path
        The IMU file.
    per_octave : int
        Averaging times per octave of tau, number of.
    max_fraction : float
        Longest lag as a fraction of the samples read, ratio (default 1/8).
    **options
        Keywords of the reader (:func:`~schuler.imu.readers.open_csv` for CSV files).

    Returns
    -------
    AllanResult
        Curves, terms and grade of the six channels.
    """
    return analyse_source(open_record(path, **options), per_octave=per_octave, max_fraction=max_fraction)


def true_terms(errors: SensorErrors, axis: int) -> dict[str, float]:
    """The IEEE 952 terms a model puts on one axis, SI (B only for flicker: a Gauss-Markov bias has no single B).

    Parameters
    ----------
    errors : SensorErrors
        The triad's error model.
    axis : int
        Body axis index: 0 x forward, 1 y right, 2 z down.

    Returns
    -------
    dict of str to float
        Term -> value: Q (rad or m/s), N (rad/sqrt(s) or m/s/sqrt(s)), B (rad/s or m/s^2), K (rad/s/sqrt(s)
        or m/s^2/sqrt(s)), R (always 0: the model has no rate ramp), for a gyro or an accelerometer triad.
    """
    return {"Q": errors.quantization[axis], "N": errors.random_walk[axis],
            "B": errors.bias_instability[axis] if errors.gm_sigma[axis] == 0 else 0.0,
            "K": errors.rate_random_walk[axis], "R": 0.0}


def expected_terms(errors: SensorErrors, axis: int, curve: AllanCurve) -> dict[str, float]:
    """What the fit returns on the model's exact Allan curve (same tau and edf as ``curve``): the method's bias.

    The simulated flicker is a band-limited Gauss-Markov sum and IEEE 952's B is
    flat at every tau, so even a noise-free curve fits N, B slightly off the
    true values; a round trip allows for that difference.

    Parameters
    ----------
    errors : SensorErrors
        The triad's error model.
    axis : int
        Body axis index: 0 x forward, 1 y right, 2 z down.
    curve : AllanCurve
        A measured curve whose averaging times (s) and edf the exact curve takes.

    Returns
    -------
    dict of str to float
        Term -> value identified on the exact curve, SI (the units of :func:`true_terms`).
    """
    exact = np.sqrt(errors.allan_variance(curve.tau_s, axis))
    model_curve = AllanCurve(tau_s=curve.tau_s, adev=exact, adev_lower=exact, adev_upper=exact, edf=curve.edf,
                             alpha=curve.alpha, terms=curve.terms, samples=curve.samples,
                             sample_interval_s=curve.sample_interval_s)
    return identify_terms(model_curve).values


@renamed_keywords(duration_s="duration", sample_interval_s="sample_interval", latitude_rad="latitude",
                  heading_rad="heading")
def round_trip(model: ErrorModel | str, *, duration: float, sample_interval: float, seed: int = 0,
               member: int = 0, latitude: float = math.radians(45.0), heading: float = 0.0) -> RoundTripResult:
    """Simulate a record from known terms, identify them, and check each within its tolerance.

    Parameters
    ----------
    model : ErrorModel or str
        A model or a grade name.
    duration, sample_interval : float
        Record length and dt, s.
    seed, member : int
        Address of the record's random numbers: seed and member number.
    latitude, heading : float
        Site latitude and heading of the body x axis, rad.

    Returns
    -------
    RoundTripResult
        One check per channel and non-zero true term whose identified value is
        resolved; B is compared only where there is no Gauss-Markov term.
    """
    model = preset(model) if isinstance(model, str) else model
    record = simulate_record(model, duration=duration, sample_interval=sample_interval, seed=seed,
                             member=member, latitude=latitude, heading=heading)
    analysis = analyse_record(record)
    checks = []
    for name in CHANNELS:
        errors = model.gyro if sensor_of(name) == "gyro" else model.accel
        axis = "xyz".index(name[-1])
        truth = true_terms(errors, axis)
        terms = analysis.noise[name].terms
        expected = expected_terms(errors, axis, analysis.noise[name].curve)
        for term in TERMS:
            if truth[term] <= 0 or not terms.resolved[term]:
                continue
            method_bias = abs(expected[term] - truth[term])
            tolerance = TOLERANCE_FACTORS[term] * terms.sigma[term] + method_bias
            identified = terms.values[term]
            checks.append(TermCheck(channel=name, term=term, true=float(truth[term]), identified=identified,
                                    sigma=terms.sigma[term], method_bias=float(method_bias),
                                    tolerance=float(tolerance),
                                    within=bool(abs(identified - truth[term]) <= tolerance)))
    return RoundTripResult(model=model.name, seed=seed, member=member, duration_s=record.duration_s,
                           sample_interval_s=record.sample_interval_s, checks=checks, analysis=analysis,
                           all_within=all(c.within for c in checks))


def reproduce_psins(path) -> PsinsReproduction:
    """The PSINS laser-gyro recording: mean rates against the Earth rate and gravity, Allan terms, grade.

    Parameters
    ----------
    path : str or Path
        ``lasergyro.imu`` (PSINS toolbox, BSD-2; not part of this project).
    """
    record = read_record(path)
    if record.latitude_rad is None:
        raise InvalidParameter("file", f"{record.source} states no latitude; the Earth-rate check needs one")
    info = record_info(record)
    latitude = record.latitude_rad
    analysis = analyse_record(record)
    gyro = np.asarray(info.mean_gyro_rad_s)
    notes = ["the vehicle stood still with disturbances (PSINS demo notes): the long-tau Allan points carry them",
             "gyro output is quantised at 0.1 arcsec per count (10 deg/h per sample at 100 Hz): Q dominates short tau"]
    return PsinsReproduction(
        info=info, analysis=analysis,
        horizontal_earth_rate_ratio=float(math.hypot(gyro[0], gyro[1]) / (EARTH_RATE * math.cos(latitude))),
        vertical_earth_rate_ratio=float(gyro[2] / (-EARTH_RATE * math.sin(latitude))),
        specific_force_z_m_s2=float(info.mean_accel_m_s2[2]), grade=analysis.grade, notes=notes)


def model_from_analysis(result: AllanResult, name: str | None = None) -> ErrorModel:
    """An :class:`~schuler.imu.error_model.ErrorModel` of the identified noise terms (for simulation and mapping).

    N, K and Q become random walk, rate random walk and quantisation; B becomes
    flicker over the record's tau range (the Gauss-Markov sum of
    :func:`~schuler.imu.error_model.flicker_terms`). Unresolved terms are left at
    zero; R has no counterpart (a rate ramp is a trend, not noise). Constant
    biases, scale factors and misalignments cannot be seen in an Allan curve and
    stay zero.

    Parameters
    ----------
    result : AllanResult
        The analysis of the six channels.
    name : str, optional
        Name of the model (not set: "identified from" the analysed record).

    Returns
    -------
    ErrorModel
        Gyro and accelerometer triads, SI.
    """
    def triad(sensor: str) -> SensorErrors:
        values = {term: np.zeros(3) for term in ("Q", "N", "B", "K")}
        low, high = math.inf, 0.0
        for axis, letter in enumerate("xyz"):
            channel = result.noise[f"{sensor}_{letter}"]
            low, high = min(low, channel.curve.tau_s[0]), max(high, channel.curve.tau_s[-1])
            for term in values:
                if channel.terms.resolved[term]:
                    values[term][axis] = channel.terms.values[term]
        return SensorErrors(quantization=values["Q"], random_walk=values["N"], bias_instability=values["B"],
                            rate_random_walk=values["K"], flicker_tau_range_s=(low, high))

    return ErrorModel(gyro=triad("gyro"), accel=triad("accel"), name=name or f"identified from {result.source}",
                      source=f"Allan analysis of {result.source}")
