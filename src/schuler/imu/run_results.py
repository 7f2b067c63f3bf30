"""What ``schuler imu run`` and ``simulate`` return: :class:`ImuRun` (how a run renders) and :class:`SimulationResult`.

JSON of a run (``to_dict``): the flat outputs of ``evaluate`` (``noise_gyro_x_N``
... SI, null where not resolved), then the extras: the record, the nested
``noise.<channel>.<term>`` with ``tau_s`` and ``adev`` per channel (the issue's
keys), the true terms, the round-trip checks and the grade the record's gyro
curves belong to (:mod:`~schuler.imu.evaluation`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from schuler.imu.results import checks_table, terms_table
from schuler.results import Result, SystemResult


class ImuRun(SystemResult):
    """One IMU case as ``imu run`` gives it: the identified terms beside the true ones, the checks, the grade.

    ``extras`` hold the record (``model``, ``seed``, ``member``, ``samples`` ...), ``true_terms``, ``checks``
    and ``noise`` (JSON-safe, SI); ``histories["imu_allan"]`` the Allan curves over ``tau_s``.
    """

    def render(self):
        from rich.console import Group
        from rich.text import Text

        extras = self.extras
        checks = extras["checks"]
        within = sum(check["within"] for check in checks)
        lines = [f"{extras['model']}: {extras['model_source']}" if extras["model_source"] else extras["model"],
                 f"{within} of {len(checks)} resolved terms within their tolerance (3 sigma + method bias); "
                 f"the gyro curves belong to the {extras['grade'] or 'no preset'} grade",
                 f"record: seed {extras['seed']}, member {extras['member']}, latitude "
                 f"{math.degrees(extras['latitude_rad']):g} deg, heading {math.degrees(extras['azimuth_rad']):g} deg"]
        duration, dt = extras["duration_s"], extras["sample_interval_s"]
        parts = [Text("\n".join(lines)),
                 checks_table(checks, f"Round trip: {extras['model']}, {duration / 3600:.3g} h at {1 / dt:.6g} Hz, "
                                      f"seed {extras['seed']}"),
                 terms_table(extras["noise"], f"Allan analysis of simulated {extras['model']}, seed {extras['seed']}, "
                                              f"member {extras['member']}: {extras['samples']:,} samples, "
                                              f"{duration / 60:.4g} min at {1 / dt:.6g} Hz", extras["grade"])]
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
