"""What ``schuler imu run`` and ``simulate`` return and write: the result types and :func:`write_files`.

JSON of a run (``to_dict``): the flat outputs of ``evaluate`` (``noise_gyro_x_N``
... SI, null where not resolved), then the nested ``noise.<channel>.<term>``
with ``tau_s`` and ``adev`` per channel (the issue's keys), the true terms,
the round-trip checks and the grade the record's gyro curves belong to.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from schuler.imu.error_model import ErrorModel
from schuler.imu.record import ImuInfo
from schuler.imu.results import (
    CHANNELS,
    CHECK_UNITS,
    GRADE_MARGIN_UNITS,
    NOISE_UNITS,
    TERM_UNITS,
    AllanResult,
    RoundTripResult,
    sensor_of,
)
from schuler.reproduction import Reproduction
from schuler.results import Result, RunResult, json_safe


def flat_unit(name: str) -> str:
    """SI unit of a flat output: ``noise_gyro_x_N`` -> rad/s^0.5; anything else "1".

    Parameters
    ----------
    name : str
        An output name of :data:`~schuler.imu.evaluation.OUTPUTS`.

    Returns
    -------
    str
        Its SI unit as :mod:`schuler.units` writes it (:data:`~schuler.imu.results.TERM_UNITS`), "1" for plain
        numbers.
    """
    parts = name.split("_")
    if len(parts) == 4 and parts[0] == "noise":
        return TERM_UNITS[parts[1]][parts[3]]
    return "1"


@dataclass(kw_only=True)
class ImuRunResult(RunResult):
    """One IMU case: the record's identified terms beside the true ones (the round trip), and its Allan curves.

    Attributes
    ----------
    model : ErrorModel
        The simulated IMU (not in ``to_dict`` beyond its name and source).
    round_trip : RoundTripResult
        Checks of each resolved term and the Allan analysis of the six channels.
    outputs : dict
        The outputs of ``evaluate`` for this case (SI, NaN where not resolved).
    true_terms : dict
        Channel -> the model's N, B, K, Q, R, SI.
    latitude_rad, azimuth_rad : float
        Site latitude and heading of the body x axis.
    """

    model: ErrorModel = field(repr=False)
    round_trip: RoundTripResult = field(repr=False)
    outputs: dict[str, float] = field(repr=False)
    true_terms: dict[str, dict[str, float]] = field(repr=False)
    latitude_rad: float = 0.0
    azimuth_rad: float = 0.0

    units: ClassVar[dict[str, str]] = {**NOISE_UNITS, **CHECK_UNITS, **GRADE_MARGIN_UNITS, "samples": "1", "seed": "1",
                                       "member": "1", "fraction_within_tolerance": "1"}

    @property
    def analysis(self) -> AllanResult:
        return self.round_trip.analysis

    def to_dict(self) -> dict:
        trip, analysis = self.round_trip, self.round_trip.analysis
        data = {**json_safe(self.outputs),
                "model": self.model.name, "model_source": self.model.source, "seed": trip.seed, "member": trip.member,
                "samples": analysis.samples, "duration_s": trip.duration_s, "sample_interval_s": trip.sample_interval_s,
                "latitude_rad": self.latitude_rad, "azimuth_rad": self.azimuth_rad, "all_within": trip.all_within,
                "grade": analysis.grade, "grade_margin": json_safe(analysis.grade_margin),
                "true_terms": json_safe(self.true_terms), "checks": json_safe(trip.checks),
                "noise": analysis.to_dict()["noise"],
                "monte_carlo": json_safe(self.monte_carlo)}
        data["units"] = {**{name: flat_unit(name) for name in self.outputs}, **self.units}
        return data

    def render(self):
        from rich.console import Group
        from rich.text import Text

        trip = self.round_trip
        within = sum(check.within for check in trip.checks)
        lines = [f"{self.model.name}: {self.model.source}" if self.model.source else self.model.name,
                 f"{within} of {len(trip.checks)} resolved terms within their tolerance (3 sigma + method bias); "
                 f"the gyro curves belong to the {self.analysis.grade or 'no preset'} grade",
                 f"record: seed {trip.seed}, member {trip.member}, latitude {math.degrees(self.latitude_rad):g} deg, "
                 f"heading {math.degrees(self.azimuth_rad):g} deg"]
        parts = [Text("\n".join(lines)), trip.render(), self.analysis.render()]
        if self.monte_carlo is not None:
            parts.append(self.monte_carlo.render())
        return Group(*parts)


@dataclass
class SimulationResult(Result):
    """A simulated record written to a file (``schuler imu simulate``)."""

    path: str
    model: str
    model_source: str
    samples: int
    duration_s: float
    sample_interval_s: float
    seed: int
    latitude_rad: float
    azimuth_rad: float
    file_size_bytes: int
    files: list[Path] = field(default_factory=list, repr=False)

    units: ClassVar[dict[str, str]] = {"samples": "1", "seed": "1", "file_size_bytes": "byte"}

    def render(self):
        from rich.table import Table

        table = Table(title=f"Simulated record {Path(self.path).name}", show_header=False)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        rows = [("model", self.model), ("samples", f"{self.samples:,}"),
                ("sample rate", f"{1 / self.sample_interval_s:.6g} Hz"),
                ("duration", f"{self.duration_s:.6g} s ({self.duration_s / 3600:.4g} h)"), ("seed", str(self.seed)),
                ("latitude, heading",
                 f"{math.degrees(self.latitude_rad):g} deg, {math.degrees(self.azimuth_rad):g} deg"),
                ("file size", f"{self.file_size_bytes / 1e6:.3g} MB")]
        for name, value in rows:
            table.add_row(name, value)
        return table


def curves_frame(result: AllanResult):
    """The six Allan curves as a table: tau_s, then adev, bounds and edf per channel (SI units in the names).

    Parameters
    ----------
    result : AllanResult
        The analysis; every channel's curve shares the first channel's averaging times.

    Returns
    -------
    pandas.DataFrame
        One row per averaging time: ``tau_s`` (s), ``<channel>_adev_rad_s`` / ``_m_s2`` with their lower and
        upper bounds (rad/s or m/s^2) and ``<channel>_edf`` (plain number).
    """
    import pandas as pd

    first = next(iter(result.noise.values())).curve
    columns = {"tau_s": first.tau_s}
    for name in CHANNELS:
        curve = result.noise[name].curve
        unit = "rad_s" if sensor_of(name) == "gyro" else "m_s2"
        columns.update({f"{name}_adev_{unit}": curve.adev, f"{name}_adev_lower_{unit}": curve.adev_lower,
                        f"{name}_adev_upper_{unit}": curve.adev_upper, f"{name}_edf": curve.edf})
    return pd.DataFrame(columns)


def write_analysis(result: AllanResult, out_dir: Path, stem: str, true_model: ErrorModel | None = None) -> list[Path]:
    """Allan figures of the gyros and accelerometers (PNG, SVG) and the curves as CSV.

    Parameters
    ----------
    result : AllanResult
        The analysis to draw and tabulate.
    out_dir : Path
        Folder to write into.
    stem : str
        File name stem: ``<stem>_gyro.png``, ``<stem>_accel.svg``, ``<stem>.csv`` ...
    true_model : ErrorModel, optional
        Draw the model's exact curves too (round trips).

    Returns
    -------
    list of Path
        The files written.
    """
    from schuler.imu.plots import allan_figure, write_figures
    from schuler.io import write_dataframe_csv

    figures = {f"{stem}_gyro": allan_figure(result, "gyro", true_model),
               f"{stem}_accel": allan_figure(result, "accel", true_model)}
    return write_figures(figures, out_dir) + [write_dataframe_csv(curves_frame(result), Path(out_dir) / f"{stem}.csv")]


def write_files(result: Result, out_dir: Path) -> list[Path]:
    """Figures and CSV of a run (with its Monte Carlo), an Allan analysis or the reproduction; nothing for the rest.

    Parameters
    ----------
    result : Result
        What an ``imu`` command returned: :class:`ImuRunResult`, :class:`~schuler.imu.results.AllanResult`,
        a :class:`~schuler.reproduction.Reproduction`, or an info or simulation result (no files).
    out_dir : Path
        Folder to write into.

    Returns
    -------
    list of Path
        The files written.
    """
    from schuler.imu.plots import monte_carlo_figure, write_figures

    out_dir = Path(out_dir)
    if isinstance(result, ImuRunResult):
        files = write_analysis(result.analysis, out_dir, "imu_allan", true_model=result.model)
        if result.monte_carlo is not None:
            files += write_figures({"imu_monte_carlo": monte_carlo_figure(result.monte_carlo, result.true_terms)},
                                   out_dir)
        return files
    if isinstance(result, AllanResult):
        return write_analysis(result, out_dir, "imu_allan")
    if isinstance(result, Reproduction):
        written: list[Path] = []
        for stem, analysis in (result.data or {}).items():
            written += write_analysis(analysis, out_dir, stem)
        return written
    if isinstance(result, (ImuInfo, SimulationResult)):
        return []
    raise TypeError(f"imu writes no files for {type(result).__name__}")
