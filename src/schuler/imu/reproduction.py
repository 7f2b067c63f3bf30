"""The IMU system's reproduction: the grade presets' published figures round-tripped, and the PSINS recording.

Two kinds of rows:

* **Grade figures.** Each preset cites a data sheet (:data:`~schuler.imu.spec.PRESET_SPECS`).
  A record of the grade at rest (100 Hz, :data:`GRADE_DURATIONS`, seed 0,
  member 0) is simulated and its terms identified; the identified value of the
  x channel stands beside the figure as printed. The tolerance is the round
  trip's: 3 standard uncertainties of the identified value plus the method's
  bias (:func:`~schuler.imu.characterise.round_trip`), rounded up to two digits.
  Figures the sheets do not print (the presets' assumed values) are listed in
  the notes, not in rows.
* **The PSINS recording** (``lasergyro.imu``, PSINS toolbox, BSD-2; not part of
  the project), when found: the ``recording`` option, else the file named by
  ``SCHULER_PSINS_IMU``. Its header prints the site latitude, the initial yaw
  and g; the latitude and heading from the record's mean rates
  (:func:`~schuler.imu.static.static_attitude`) and the magnitude of its mean
  specific force stand beside them. The identified noise terms and the grade
  the gyro curves belong to are in the details. Without the file, the rows are
  the grade figures only and a note says so.

Constants: Omega = 7.292115e-5 rad/s (WGS-84), the file's own g for its
accelerometer counts, g0 = 9.80665 m/s^2 for spec-sheet "g" units.
"""

from __future__ import annotations

import math
import os
from functools import cache
from pathlib import Path

import numpy as np

from schuler.contract import FigureRef, ReportSection
from schuler.core.earth import EARTH_RATE
from schuler.exceptions import InvalidParameter
from schuler.imu.characterise import analyse_record, round_trip
from schuler.imu.files import read_record
from schuler.imu.results import DISPLAY_UNITS, NOISE_UNITS, AllanResult, RoundTripResult, sensor_of, shown_unit
from schuler.imu.spec import GRADES, PRESET_SPECS, preset
from schuler.imu.static import static_attitude
from schuler.params import Parameter, ParameterSet
from schuler.reproduction import Reproduction, Tolerance, compare
from schuler.units import to_unit

PSINS_ENVIRONMENT = "SCHULER_PSINS_IMU"
"""Environment variable naming the PSINS ``lasergyro.imu`` file."""

SAMPLE_INTERVAL = 0.01
"""Sample interval of the grade records, s (100 Hz, the PSINS recording's rate)."""

GRADE_DURATIONS = {"navigation": 1800.0, "tactical": 7200.0, "industrial": 3600.0, "consumer": 1800.0}
"""Record length of each grade, s: long enough to resolve its printed terms (industrial B needs tau ~ 15-1000 s);
the tactical record is longer so that the report's figure shows where its bias instability begins."""

PRINTED_FIGURES = (
    ("navigation", "gyro", "N", "0.002 deg/√h", "deg/h^0.5", "Honeywell HG9900 brochure N61-1638-000-000"),
    ("tactical", "gyro", "N", "0.125 deg/√h", "deg/h^0.5", "Honeywell HG1700 brochure N61-1619-000-001"),
    ("tactical", "accel", "N", "0.065 ft/s/√h", "ft/s/h^0.5", "Honeywell HG1700 brochure N61-1619-000-001"),
    ("industrial", "gyro", "N", "0.007 °/s/√Hz", "deg/s/Hz^0.5", "Xsens MTi 1-series data sheet"),
    ("industrial", "gyro", "B", "10 °/h", "deg/h", "Xsens MTi 1-series data sheet (in-run bias stability)"),
    ("industrial", "accel", "N", "120 µg/√Hz", "ug/Hz^0.5", "Xsens MTi 1-series data sheet"),
    ("industrial", "accel", "B", "0.03 mg", "mg", "Xsens MTi 1-series data sheet (in-run bias stability)"),
    ("consumer", "gyro", "N", "0.005 °/s/√Hz", "deg/s/Hz^0.5", "InvenSense PS-MPU-6000A-00 rev. 3.4"),
    ("consumer", "accel", "N", "400 µg/√Hz", "ug/Hz^0.5", "InvenSense PS-MPU-6000A-00 rev. 3.4"),
)
"""(grade, sensor, term, figure as printed, its unit, where) of every noise figure the presets' sources print."""

PSINS_LATITUDE_TOLERANCE_DEG = 1.0
"""Latitude from the mean rates vs the header's, deg: the four quarter-record estimates scatter by about 1.5 deg
(the vehicle's disturbances move the mean rates), so the whole record's mean is good to about 0.7 deg."""

PSINS_HEADING_TOLERANCE_DEG = 3.0
"""Heading from the mean rates vs the header's yaw, deg: quarter-record estimates scatter by about 2.4 deg, and the
header calls its attitude "maybe inaccurate"."""

REPRODUCE_PARAMETERS = ParameterSet((
    Parameter("recording", "", None, f"The PSINS lasergyro.imu recording (not set: ${PSINS_ENVIRONMENT}, else only "
              "the grade figures are reproduced).", kind="text"),
), owner="imu reproduce")


@cache
def grade_round_trip(grade: str) -> RoundTripResult:
    """The round trip of a grade's record (seed 0, member 0, 100 Hz, :data:`GRADE_DURATIONS`); cached: it is pure."""
    return round_trip(preset(grade), duration=GRADE_DURATIONS[grade], sample_interval=SAMPLE_INTERVAL, seed=0)


def _round_up(value: float, digits: int = 2) -> float:
    if value <= 0 or not math.isfinite(value):
        return value
    scale = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.ceil(value / scale) * scale


def _grade_rows() -> list:
    rows = []
    for grade, sensor, term, printed, unit, where in PRINTED_FIGURES:
        trip = grade_round_trip(grade)
        check = next((c for c in trip.checks if c.channel == f"{sensor}_x" and c.term == term), None)
        terms = trip.analysis.noise[f"{sensor}_x"].terms
        identified = float(to_unit(terms.values[term], unit))
        relative = check.tolerance / check.true if check is not None else math.nan
        resolved = "" if terms.resolved[term] else "; NOT resolved by the record"
        rows.append(compare(
            f"{grade}: {sensor} {term} ({GRADE_DURATIONS[grade] / 3600:g} h record)", identified, unit,
            printed=printed, where=where, tolerance=Tolerance(_round_up(relative)),
            note=f"identified on the x channel of a simulated 100 Hz record; tolerance 3 sigma + method bias"
                 f"{resolved}"))
    return rows


def psins_path(recording: str | None) -> Path | None:
    """The PSINS file: ``recording`` (must exist), else ``$SCHULER_PSINS_IMU`` when that file exists, else None.

    Parameters
    ----------
    recording : str or None
        Path the user gave (``--recording``); None or empty: not given.

    Returns
    -------
    Path or None
        The file to reproduce, or None when there is none.
    """
    if recording:
        path = Path(recording)
        if not path.is_file():
            raise InvalidParameter("recording", f"{recording!r} is not a file")
        return path
    named = os.environ.get(PSINS_ENVIRONMENT, "")
    return Path(named) if named and Path(named).is_file() else None


def _quarters(record) -> list:
    n = record.samples // 4
    return [static_attitude(record.gyro_rate_rad_s[i * n:(i + 1) * n].mean(axis=0),
                            record.accel_m_s2[i * n:(i + 1) * n].mean(axis=0)) for i in range(4)]


def psins_rows(path: Path) -> tuple[list, dict, dict, AllanResult]:
    """Rows, details (SI), their units and the Allan analysis of the PSINS recording.

    Parameters
    ----------
    path : Path
        The PSINS ``lasergyro.imu`` file (its header must state the site latitude).

    Returns
    -------
    rows, details, units, analysis : list, dict, dict, AllanResult
        Comparison rows (latitude and heading in deg, specific force in m/s^2), details in SI, the units of
        the details, and the Allan analysis of the six channels.
    """
    record = read_record(path)
    if record.latitude_rad is None:
        raise InvalidParameter("recording", f"{path.name} states no site latitude; the PSINS reproduction reads a "
                                            "PSINS .imu file (its header gives the site)")
    gyro, accel = record.gyro_rate_rad_s.mean(axis=0), record.accel_m_s2.mean(axis=0)
    attitude = static_attitude(gyro, accel)
    quarters = _quarters(record)
    yaw = -math.degrees(record.initial_attitude_rad[2]) if record.initial_attitude_rad else math.nan
    heading = math.degrees(attitude.heading_rad)
    yaw_printed = f"{yaw:.1f}" if math.isfinite(yaw) else "-"
    where = f"{path.name}, header line 2"
    rows = [
        compare("PSINS: latitude from the mean rates, asin(omega . f / (|omega| |f|))",
                math.degrees(attitude.latitude_rad), "deg", printed=f"{math.degrees(record.latitude_rad):.6f}",
                where=where, tolerance=Tolerance(0.0, PSINS_LATITUDE_TOLERANCE_DEG),
                note="quarter-record estimates: " + ", ".join(f"{math.degrees(q.latitude_rad):.2f}" for q in quarters)
                     + " deg"),
        compare("PSINS: heading from the mean rates (double vector)", heading, "deg",
                printed=f"yaw0 = {yaw_printed}", value=-yaw, where=f"{path.name}, header line 1 ('maybe inaccurate')",
                tolerance=Tolerance(0.0, PSINS_HEADING_TOLERANCE_DEG),
                note="PSINS yaw is positive towards west: heading = -yaw; quarter-record estimates: "
                     + ", ".join(f"{math.degrees(q.heading_rad):.1f}" for q in quarters) + " deg"),
        compare("PSINS: magnitude of the mean specific force", float(np.linalg.norm(accel)), "m/s^2",
                printed=f"{record.gravity_m_s2}", where=where,
                note="the accelerometer counts are scaled with this g (ug*s per count times the file's g)"),
    ]
    analysis = analyse_record(record)
    details = {"psins_recording": path.name, "psins_samples": record.samples,
               "psins_mean_gyro_rad_s": gyro, "psins_mean_accel_m_s2": accel,
               "psins_earth_rate_ratio": float(np.linalg.norm(gyro) / EARTH_RATE),
               "psins_roll_rad": attitude.roll_rad, "psins_pitch_rad": attitude.pitch_rad,
               "psins_grade": analysis.grade,
               "psins_noise": {name: {term: channel.terms.values[term] if channel.terms.resolved[term] else None
                                      for term in ("N", "B", "K", "Q", "R")}
                               for name, channel in analysis.noise.items()}}
    units = {"psins_samples": "1", "psins_earth_rate_ratio": "1: |mean gyro| / Omega",
             **{term: NOISE_UNITS[term] for term in ("N", "B", "K", "Q", "R")}}
    return rows, details, units, analysis


def resolved_terms_text(analysis) -> str:
    """The resolved terms of each channel in display units, one line (channels with none left out).

    Parameters
    ----------
    analysis : AllanResult
        The analysis whose resolved terms (SI) are written in display units (gyro N in deg/sqrt(h), B in deg/h
        ..., :data:`~schuler.imu.results.DISPLAY_UNITS`).

    Returns
    -------
    str
        ``gyro_x N = ... deg/√h, ...; gyro_y ...``, or "none".
    """
    parts = []
    for name, channel in analysis.noise.items():
        units = DISPLAY_UNITS[sensor_of(name)]
        terms = [f"{term} = {to_unit(channel.terms.values[term], units[term]):.3g} {shown_unit(units[term])}"
                 for term in ("N", "B", "K", "Q", "R") if channel.terms.resolved[term]]
        if terms:
            parts.append(f"{name} " + ", ".join(terms))
    return "; ".join(parts) or "none"


def reproduce(recording: str | None = None) -> Reproduction:
    """The grade figures round-tripped and, when the file is found, the PSINS recording (see the module notes).

    Parameters
    ----------
    recording : str, optional
        Path of ``lasergyro.imu``; not set: ``$SCHULER_PSINS_IMU`` if that file exists.

    Returns
    -------
    Reproduction
        Rows of the printed figures beside the identified ones; ``data`` holds the
        Allan analyses of the tactical record and of the recording (for figures).
    """
    rows = _grade_rows()
    notes = [f"{grade}: {'; '.join(PRESET_SPECS[grade].get('notes', ()))}" for grade in GRADES]
    details: dict = {}
    details_units: dict = {}
    data = {"imu_reproduction_tactical": grade_round_trip("tactical").analysis}
    path = psins_path(recording)
    if path is None:
        notes.append(f"the PSINS recording lasergyro.imu is absent (set {PSINS_ENVIRONMENT} or --recording): "
                     "only the grade figures are reproduced")
    else:
        extra, details, details_units, analysis = psins_rows(path)
        rows += extra
        data["imu_reproduction_psins"] = analysis
        notes.append(f"PSINS {path.name}: the gyro curves belong to the {analysis.grade or 'no preset'} grade; "
                     "the vehicle's disturbances dominate the longer averaging times, so the identified terms "
                     "describe the curves, not the sensor's data sheet")
        notes.append(f"PSINS {path.name}, resolved terms: {resolved_terms_text(analysis)}")
    return Reproduction(
        system="imu",
        source="grade presets: Honeywell HG9900 and HG1700 brochures, Xsens MTi 1-series data sheet, InvenSense "
               "PS-MPU-6000A-00 rev. 3.4; recording: G. Yan, PSINS toolbox, lasergyro.imu (2014)",
        constants=f"Omega = {EARTH_RATE} rad/s (WGS-84); g0 = 9.80665 m/s^2 in spec-sheet units; "
                  "the PSINS file's own g for its counts",
        rows=rows, notes=notes, details=details, details_units=details_units, data=data)


def report(outdir: Path) -> ReportSection:
    """Write this system's figures into ``outdir`` and describe them (a few seconds, more with the PSINS file).

    Parameters
    ----------
    outdir : Path
        Folder the PNG figures are written into.

    Returns
    -------
    ReportSection
        The report's section: summary, comparison rows, figures with captions, commands and notes.
    """
    from schuler.imu.plots import channel_curves, write_figures

    outdir = Path(outdir)
    reproduction = reproduce()
    tactical = reproduction.data["imu_reproduction_tactical"]
    model = preset("tactical")
    hours = GRADE_DURATIONS["tactical"] / 3600
    figures = {"imu_tactical_gyro": channel_curves(tactical, "gyro", model, f"Simulated tactical IMU ({hours:g} h): "
                                                                             "gyros"),
               "imu_tactical_accel": channel_curves(tactical, "accel", model, f"Simulated tactical IMU ({hours:g} h): "
                                                                               "accelerometers")}
    captions = {
        "imu_tactical_gyro": "Overlapping Allan deviation of the three gyros of a simulated tactical-grade record "
                             "(HG1700 figures, 100 Hz) with 68 % bars, the IEEE 952 fit of each and the true model: "
                             "the -1/2 slope of the angle random walk bends towards the 0.3 deg/h bias instability.",
        "imu_tactical_accel": "The same for the accelerometers: velocity random walk, then the 50 ug bias-instability "
                              "floor.",
    }
    psins = reproduction.data.get("imu_reproduction_psins")
    if psins is not None:
        figures["imu_psins_gyro"] = channel_curves(psins, "gyro", title="PSINS lasergyro.imu: gyros")
        figures["imu_psins_accel"] = channel_curves(psins, "accel", title="PSINS lasergyro.imu: accelerometers")
        captions["imu_psins_gyro"] = (f"The real ring-laser-gyro recording (PSINS, 100 Hz, 31 min, vehicle at rest "
                                      f"with disturbances): gyro Allan deviation; its floor places it in the "
                                      f"{psins.grade or 'no preset'} grade. The vehicle's motion (the bump near "
                                      f"0.2 s) is not one of the five IEEE 952 terms: the fitted lines describe the "
                                      f"curves only roughly, not the sensor.")
        captions["imu_psins_accel"] = ("The recording's accelerometers: white noise and quantisation at short tau, "
                                       "the disturbances beyond (least on z, the vertical).")
    write_figures(figures, outdir, formats=("png",))
    return ReportSection(
        system="imu",
        title="IMU layer: recordings, spec-sheet error models, Allan variance",
        source=reproduction.source,
        summary=("Sensor error models from spec-sheet figures (grade presets with their data sheets, or TOML spec "
                 "files), simulated records, the overlapping Allan deviation with confidence intervals and the IEEE "
                 "Std 952 terms identified by weighted least squares. A grade's printed noise figures come back "
                 "from a simulated record within the identification's uncertainty; the PSINS ring-laser-gyro "
                 "recording shows the Earth rate and gravity of its site and a navigation-grade noise floor."),
        rows=reproduction.rows,
        figures=[FigureRef(f"{stem}.png", captions[stem]) for stem in figures],
        commands=["schuler imu reproduce", "schuler imu run --grade tactical --duration '2 h' --out imu",
                  "schuler imu simulate --grade industrial --duration '1 h' -o industrial.parquet",
                  "schuler imu allan industrial.parquet --out imu-allan",
                  "schuler align run --imu tactical"],
        notes=reproduction.notes,
    )
