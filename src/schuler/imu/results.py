"""Typed results of the IMU layer: Allan characterisation, round trip, the PSINS reproduction.

All fields SI; :meth:`render` shows display units (deg/sqrt(h), deg/h, ug ...).
JSON (``to_dict``): ``noise.<channel>.<term>`` with channel ``gyro_x`` ..
``accel_z`` and term N, B, K, Q, R in the units of :data:`TERM_UNITS`, plus
``tau_s``, ``adev``, ``adev_lower``, ``adev_upper``, ``edf`` per channel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from schuler.core.response import Histories
from schuler.imu.allan import AllanCurve
from schuler.imu.noise_terms import TERMS, NoiseTerms
from schuler.imu.record import ImuInfo
from schuler.imu.spec import GRADES
from schuler.results import Footnotes, Result, json_safe

SHOWN_TERMS = ("N", "B", "K", "Q", "R")
"""The IEEE 952 terms in the order of tables and outputs."""

CHANNELS = ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z")

TERM_UNITS = {
    "gyro": {"N": "rad/s^0.5", "B": "rad/s", "K": "rad/s^1.5", "Q": "rad", "R": "rad/s^2"},
    "accel": {"N": "m/s^1.5", "B": "m/s^2", "K": "m/s^2.5", "Q": "m/s", "R": "m/s^3"},
}
"""SI unit of each IEEE 952 term for gyros and accelerometers."""

DISPLAY_UNITS = {
    "gyro": {"N": "deg/h^0.5", "B": "deg/h", "K": "deg/h^1.5", "Q": "arcsec", "R": "deg/h^2"},
    "accel": {"N": "m/s/h^0.5", "B": "ug", "K": "ug/h^0.5", "Q": "mm/s", "R": "ug/h"},
}
"""Display unit of each term in tables and plots."""

NOISE_UNITS: dict[str, str] = {
    **{term: f"{TERM_UNITS['gyro'][term]} (gyro_*), {TERM_UNITS['accel'][term]} (accel_*)"
       for term in ("N", "B", "K", "Q", "R")},
    "noise.*.sigma.*": "the term's unit", "noise.*.upper_bound.*": "the term's unit",
    "noise.*.dominant_tau_s.*": "s (first, last)",
    **{name: "rad/s (gyro_*), m/s^2 (accel_*)" for name in ("adev", "adev_lower", "adev_upper")},
    "edf": "1", "chi2_per_point": "1",
}
"""Units of the ``noise.<channel>`` JSON: each term by its key (N, B, K, Q, R wherever they appear), the curves."""

GRADE_MARGIN_UNITS = {"grade_margin": "1: largest ratio of the grade's Allan deviation to the record's upper bound",
                      **{grade: "1" for grade in GRADES}}
"""Units of the ``grade_margin`` JSON (one plain ratio per grade)."""

_SHOWN = {"deg/h^0.5": "deg/√h", "deg/h^1.5": "deg/h/√h", "m/s/h^0.5": "m/s/√h", "ug/h^0.5": "µg/√h", "ug": "µg",
          "ug/h": "µg/h"}


def shown_unit(unit: str) -> str:
    """A display unit as people write it (deg/h^0.5 -> deg/√h).

    Parameters
    ----------
    unit : str
        A display unit as :mod:`schuler.units` parses it (e.g. a value of :data:`DISPLAY_UNITS`).

    Returns
    -------
    str
        The unit with square roots and micro written as such (units without a special form unchanged).
    """
    return _SHOWN.get(unit, unit)


def sensor_of(channel: str) -> str:
    """'gyro' or 'accel'.

    Parameters
    ----------
    channel : str
        A channel name, ``gyro_x`` .. ``accel_z`` (:data:`CHANNELS`).

    Returns
    -------
    str
        The sensor part of the name, "gyro" or "accel".
    """
    return channel.split("_")[0]


@dataclass
class ChannelNoise:
    """The Allan curve of one channel and the terms identified on it."""

    curve: AllanCurve
    terms: NoiseTerms

    def to_dict(self) -> dict:
        t = self.terms
        return {**{term: t.values[term] for term in TERMS},
                "sigma": dict(t.sigma), "upper_bound": dict(t.upper_bound), "resolved": dict(t.resolved),
                "dominant_tau_s": dict(t.dominant_tau_s), "chi2_per_point": t.chi2_per_point,
                "tau_s": self.curve.tau_s, "adev": self.curve.adev, "adev_lower": self.curve.adev_lower,
                "adev_upper": self.curve.adev_upper, "edf": self.curve.edf}


def _number(value) -> float:
    """A term's number from a result or from its JSON (None there: not finite)."""
    return math.nan if value is None else float(value)


def _term_text(channel: str, term: str, value, resolved: bool, upper) -> str:
    from schuler.units import to_unit

    unit = DISPLAY_UNITS[sensor_of(channel)][term]
    if resolved:
        return f"{to_unit(_number(value), unit):.3g}"
    upper = _number(upper)
    return f"< {to_unit(upper, unit):.2g}" if math.isfinite(upper) and upper > 0 else "-"


def terms_table(noise: dict, title: str, grade: str | None = None):
    """The terms of each channel in display units, unresolved ones as an upper bound (a rich Table).

    Parameters
    ----------
    noise : dict
        Channel -> its ``noise.<channel>`` JSON (:meth:`ChannelNoise.to_dict`): N, B, K, Q, R in the units of
        :data:`TERM_UNITS`, ``resolved``, ``upper_bound`` and ``chi2_per_point``.
    title : str
        Title of the table.
    grade : str, optional
        The grade the gyro curves belong to (shown in the caption).
    """
    from rich.table import Table

    table = Table(title=title)
    table.add_column("channel")
    for term in SHOWN_TERMS:
        table.add_column(term, justify="right")
    table.add_column("fit chi2/point", justify="right")
    for sensor in ("gyro", "accel"):
        units = DISPLAY_UNITS[sensor]
        names = [name for name in noise if sensor_of(name) == sensor]
        if names:
            table.add_row(f"[dim]{sensor} unit[/dim]", *(f"[dim]{shown_unit(units[t])}[/dim]" for t in SHOWN_TERMS),
                          "")
        for name in names:
            channel = noise[name]
            table.add_row(name, *(_term_text(name, term, channel[term], channel["resolved"][term],
                                             channel["upper_bound"][term]) for term in SHOWN_TERMS),
                          f"{_number(channel['chi2_per_point']):.3g}")
    if grade:
        table.caption = (f"grade: {grade} (the closest preset below the gyro curves); '< x': not resolved in this "
                         "record, about 2-sigma upper bound")
    return table


def curves_histories(noise: dict[str, ChannelNoise]) -> Histories:
    """The Allan curves as histories over the averaging time ``tau_s``: what ``imu_allan.csv`` holds.

    Parameters
    ----------
    noise : dict of str to ChannelNoise
        The analysed channels; every curve shares the first channel's averaging times (s).

    Returns
    -------
    Histories
        Indexed by ``tau_s`` (s): ``<channel>_adev_rad_s`` / ``_m_s2`` with their lower and upper 68 % bounds
        (rad/s or m/s^2) and ``<channel>_edf`` (plain number) per channel.
    """
    channels, units = {}, {}
    for name, channel in noise.items():
        curve = channel.curve
        unit, suffix = ("rad/s", "rad_s") if sensor_of(name) == "gyro" else ("m/s^2", "m_s2")
        for key, values in ((f"{name}_adev_{suffix}", curve.adev), (f"{name}_adev_lower_{suffix}", curve.adev_lower),
                            (f"{name}_adev_upper_{suffix}", curve.adev_upper), (f"{name}_edf", curve.edf)):
            channels[key], units[key] = values, "1" if key.endswith("_edf") else unit
    return Histories(next(iter(noise.values())).curve.tau_s, channels, units, time_name="tau_s")


@dataclass
class AllanResult(Result):
    """Allan deviation and IEEE 952 terms of the channels of a record (all six unless fewer were asked for).

    ``noise`` maps channel -> :class:`ChannelNoise`; ``grade`` is the preset
    whose gyro Allan deviation stays below the record's and comes closest
    (:func:`~schuler.imu.characterise.classify_grade`), ``grade_margin`` the
    largest ratio of each preset's curve to the record's upper bound.
    :meth:`to_dataframe` gives the curves indexed by the averaging time
    ``tau_s`` (the columns of ``imu_allan.csv``), :meth:`terms` the identified
    terms, ``plot()`` the Allan figures.
    """

    source: str
    samples: int
    sample_interval_s: float
    duration_s: float
    noise: dict[str, ChannelNoise] = field(repr=False)
    grade: str | None = None
    grade_margin: dict[str, float] = field(default_factory=dict)

    units = {**NOISE_UNITS, **GRADE_MARGIN_UNITS, "samples": "1"}

    def to_dict(self) -> dict:
        return {"source": self.source, "samples": self.samples, "sample_interval_s": self.sample_interval_s,
                "duration_s": self.duration_s, "grade": self.grade, "grade_margin": json_safe(self.grade_margin),
                "noise": {name: json_safe(channel.to_dict()) for name, channel in self.noise.items()},
                "units": dict(self.units)}

    @property
    def histories(self) -> dict[str, Histories]:
        """The curves as ``{"imu_allan": Histories}`` over ``tau_s``, as a run holds them (the CSV ``--out`` writes)."""
        return {"imu_allan": curves_histories(self.noise)}

    def to_dataframe(self):
        """The curves indexed by ``tau_s`` (s): adev and its 68 % bounds (rad/s, m/s^2) and edf per channel."""
        return self.histories["imu_allan"].to_dataframe()

    def terms(self) -> IdentifiedTerms:
        """The identified terms of each channel with their uncertainties (:class:`IdentifiedTerms`)."""
        return IdentifiedTerms(source=self.source, samples=self.samples, sample_interval_s=self.sample_interval_s,
                               duration_s=self.duration_s, grade=self.grade, terms={
                                   name: {**{t: channel.terms.values[t] for t in SHOWN_TERMS},
                                          **{key: dict(getattr(channel.terms, key))
                                             for key in ("sigma", "upper_bound", "resolved")},
                                          "chi2_per_point": channel.terms.chi2_per_point}
                                   for name, channel in self.noise.items()}, analysis=self)

    def render(self):
        """Terms per channel in display units; unresolved terms as an upper bound."""
        return terms_table({name: channel.to_dict() for name, channel in self.noise.items()},
                           f"Allan analysis of {self.source}: {self.samples:,} samples, "
                           f"{self.duration_s / 60:.4g} min at {1 / self.sample_interval_s:.6g} Hz", self.grade)


@dataclass
class IdentifiedTerms(Result):
    """The IEEE 952 terms identified on a record's Allan curves (:func:`schuler.imu.identify`).

    ``terms[channel]`` holds N, B, K, Q, R in the SI units of :data:`TERM_UNITS`
    (rad/s^0.5 ... for gyros, m/s^1.5 ... for accelerometers) and, per term,
    ``sigma`` (standard uncertainty, same unit), ``upper_bound`` (about 2 sigma,
    same unit) and ``resolved``, and the fit's ``chi2_per_point``; ``plot()``
    draws the Allan curves they were fitted to.
    """

    source: str
    samples: int
    sample_interval_s: float
    duration_s: float
    grade: str | None
    terms: dict[str, dict]
    analysis: AllanResult = field(repr=False)

    units = {**{term: NOISE_UNITS[term] for term in SHOWN_TERMS}, "sigma": "the term's unit",
             "upper_bound": "the term's unit", "chi2_per_point": "1", "samples": "1"}

    def to_dataframe(self):
        """One row per (channel, term): value, sigma, upper_bound (SI, the row's ``unit``) and resolved."""
        import pandas as pd

        rows = [{"channel": name, "term": term, "value": values[term], "sigma": values["sigma"][term],
                 "upper_bound": values["upper_bound"][term], "resolved": values["resolved"][term],
                 "unit": TERM_UNITS[sensor_of(name)][term]} for name, values in self.terms.items()
                for term in SHOWN_TERMS]
        return pd.DataFrame(rows).set_index(["channel", "term"])

    def render(self):
        return terms_table(self.terms, f"IEEE 952 terms of {self.source}", self.grade)


@dataclass
class TermCheck:
    """One identified term beside the value that went into the simulation."""

    channel: str
    term: str
    true: float
    identified: float
    sigma: float
    method_bias: float
    tolerance: float
    within: bool


CHECK_UNITS = {name: "the SI unit of the check's term (see N, B, K, Q, R)"
               for name in ("true", "identified", "sigma", "method_bias", "tolerance")}
"""Units of a round trip's ``checks`` JSON."""


@dataclass
class RoundTripResult(Result):
    """A record simulated from known terms, characterised, and the identified terms beside the true ones.

    ``tolerance`` of a term is ``factor x sigma + method_bias``: the factor of
    :data:`~schuler.imu.characterise.TOLERANCE_FACTORS` (correlated overlapping
    estimates make the fit's sigma optimistic) and the difference between the
    true value and what the fit returns on the model's exact curve
    (:func:`~schuler.imu.characterise.expected_terms`).
    """

    model: str
    seed: int
    duration_s: float
    sample_interval_s: float
    checks: list[TermCheck] = field(repr=False)
    analysis: AllanResult = field(repr=False)
    all_within: bool = True
    member: int = 0

    def to_dict(self) -> dict:
        return {"model": self.model, "seed": self.seed, "duration_s": self.duration_s,
                "sample_interval_s": self.sample_interval_s, "all_within": self.all_within,
                "member": self.member, "checks": json_safe(self.checks), "noise": self.analysis.to_dict()["noise"],
                "units": {**NOISE_UNITS, **CHECK_UNITS, "seed": "1", "member": "1"}}

    def render(self):
        return checks_table(json_safe(self.checks), f"Round trip: {self.model}, {self.duration_s / 3600:.3g} h at "
                                                    f"{1 / self.sample_interval_s:.6g} Hz, seed {self.seed}")


def checks_table(checks: list[dict], title: str):
    """A round trip's checks, true beside identified in display units with the error and tolerance (a rich Table).

    Parameters
    ----------
    checks : list of dict
        The ``checks`` JSON (:class:`TermCheck` fields: ``true``, ``identified``, ``tolerance`` in the SI unit of
        the term, :data:`TERM_UNITS`).
    title : str
        Title of the table.
    """
    from rich.table import Table

    from schuler.units import to_unit

    table = Table(title=title)
    for column in ("channel", "term", "true", "identified", "error", "tolerance", "unit", "ok"):
        table.add_column(column, justify="left" if column in ("channel", "term", "unit") else "right")
    for check in checks:
        unit = DISPLAY_UNITS[sensor_of(check["channel"])][check["term"]]
        true, identified = _number(check["true"]), _number(check["identified"])
        error = (identified - true) / true if true else math.nan
        table.add_row(check["channel"], check["term"], f"{to_unit(true, unit):.4g}", f"{to_unit(identified, unit):.4g}",
                      f"{100 * error:+.2f} %", f"{100 * _number(check['tolerance']) / true:.2f} %" if true else "-",
                      shown_unit(unit), "yes" if check["within"] else "NO")
    return table


@dataclass
class PsinsReproduction(Result):
    """What the PSINS laser-gyro recording shows: means (Earth rate, gravity), noise terms, grade."""

    info: ImuInfo = field(repr=False)
    analysis: AllanResult = field(repr=False)
    horizontal_earth_rate_ratio: float = math.nan
    vertical_earth_rate_ratio: float = math.nan
    specific_force_z_m_s2: float = math.nan
    grade: str | None = None
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"info": self.info.to_dict(), "horizontal_earth_rate_ratio": self.horizontal_earth_rate_ratio,
                "vertical_earth_rate_ratio": self.vertical_earth_rate_ratio,
                "specific_force_z_m_s2": self.specific_force_z_m_s2, "grade": self.grade, "notes": self.notes,
                **{k: v for k, v in self.analysis.to_dict().items() if k in ("noise", "units")}}

    def render(self):
        from rich.console import Group
        from rich.text import Text

        notes = Footnotes()
        marks = [notes.reference(note) for note in self.notes]
        lines = [f"horizontal gyro mean / (Omega cos L): {self.horizontal_earth_rate_ratio:.4f}",
                 f"down gyro mean / (-Omega sin L): {self.vertical_earth_rate_ratio:.4f}",
                 f"specific force z (down): {self.specific_force_z_m_s2:.4f} m/s^2 (about -g)",
                 f"grade: {self.grade} {' '.join(marks)}".rstrip()]
        return Group(self.info.render(), Text("\n".join(lines)), self.analysis.render(),
                     Text("\n".join(notes.lines())))

