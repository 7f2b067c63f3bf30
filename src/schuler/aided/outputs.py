"""What an aided run writes beside the generic CSV and figures: its navigation in KF-GINS's layout and as CSV.

``--out DIR`` (:func:`data_files`, the system's ``data_files`` hook) writes, from the run's navigation solution
at every IMU epoch (:class:`AidedResult`'s ``navigation``):

* ``navigation.nav``: KF-GINS's result format (:func:`schuler.aided.kfgins.write_navigation`): no header, 11
  columns -- GPS week (0, as KF-GINS writes it), seconds (of week for files, from the start for a simulated
  drive), latitude, longitude (deg, 12 decimals), height (m), v_N, v_E, v_D (m/s), roll, pitch, yaw (deg);
* ``navigation.csv``: the same solution with the filter's 1-sigma of position (m), velocity (m/s) and psi
  (deg; north, east, down -- the heading's 1-sigma is psi_down's), the unit in each column's name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from schuler.aided.kfgins import NavigationRecord, write_navigation
from schuler.results import SystemResult

NAVIGATION_FILE = "navigation.nav"
NAVIGATION_CSV = "navigation.csv"


@dataclass(kw_only=True)
class AidedResult(SystemResult):
    """What ``schuler aided run`` returns: the outputs, the extras, the error histories and the navigation.

    ``navigation`` (:class:`~schuler.core.response.Histories`, SI) is the solution with the filter's 1-sigma at
    every IMU epoch; it is written in its own layouts (:func:`data_files`), not as a generic history CSV.
    """

    navigation: Any = field(default=None, repr=False)

    def __post_init__(self) -> None:
        # evaluate hands the navigation over with the histories; it leaves them to be written by data_files
        if self.navigation is None and "navigation" in self.histories:
            self.navigation = self.histories.pop("navigation")


def navigation_record(navigation) -> NavigationRecord:
    """The navigation histories as a KF-GINS navigation record (week 0, as KF-GINS writes its result).

    Parameters
    ----------
    navigation : Histories
        ``AidedResult.navigation`` (SI).
    """
    h = navigation
    return NavigationRecord(np.zeros(h.time.size, dtype=np.int64), h.time, h["latitude_rad"], h["longitude_rad"],
                            h["height_m"], np.column_stack([h["velocity_north_m_s"], h["velocity_east_m_s"],
                                                            h["velocity_down_m_s"]]),
                            np.column_stack([h["roll_rad"], h["pitch_rad"], h["yaw_rad"]]))


def write_navigation_csv(path, navigation) -> Path:
    """The navigation histories as CSV: angles in deg, the unit in each column's name (``latitude_deg``).

    Parameters
    ----------
    path : str or Path
        The file.
    navigation : Histories
        ``AidedResult.navigation`` (SI).
    """
    import pyarrow as pa
    import pyarrow.csv

    columns = {"t_s": np.asarray(navigation.time)}
    for name in navigation.names:
        values = np.asarray(navigation[name])
        if name.endswith("_rad"):
            columns[name[:-len("_rad")] + "_deg"] = np.degrees(values)
        else:
            columns[name] = values
    path = Path(path)
    with path.open("wb") as handle:
        handle.write((",".join(columns) + "\n").encode())
        # pyarrow writes the shortest exact decimal of each double, several times faster than pandas' writer
        pyarrow.csv.write_csv(pa.table(columns), handle, write_options=pyarrow.csv.WriteOptions(
            include_header=False, quoting_style="none"))
    return path


def data_files(result, out_dir: Path) -> list[Path]:
    """``navigation.nav`` and ``navigation.csv`` of an aided run (module docstring); none for other results.

    Parameters
    ----------
    result : Result
        What the system returned.
    out_dir : Path
        The folder (it exists).
    """
    navigation = getattr(result, "navigation", None)
    if navigation is None:
        return []
    out_dir = Path(out_dir)
    return [write_navigation(out_dir / NAVIGATION_FILE, navigation_record(navigation)),
            write_navigation_csv(out_dir / NAVIGATION_CSV, navigation)]


def write_simulated_files(case, folder, *, seed: int = 0, week_start: float = 0.0) -> dict[str, Path]:
    """A simulated case's member 0 in KF-GINS's files: what ``schuler aided run`` on files reads back.

    Writes ``imu.txt`` (the measured increments), ``gnss.txt`` (7 or 13 columns, outages removed),
    ``reference.nav`` (the truth from the start, week 0) and ``kf-gins.yaml`` (:func:`~schuler.aided.
    kfgins_configuration.example_configuration` with the drive's initial state, the IMU rate and the case's
    lever arm; its ``imunoise`` is the example's, not the case's IMU).

    Parameters
    ----------
    case : Case
        A validated simulated case of the aided system (SI).
    folder : str or Path
        Where to write (created if missing).
    seed : int
        Seed of member 0's IMU errors and GNSS noise (the ``nominal`` case has none).
    week_start : float
        Seconds of week of the drive's start, s: added to every time written.

    Returns
    -------
    dict of str to Path
        ``imu``, ``gnss``, ``reference``, ``configuration``.
    """
    import dataclasses
    import re

    from schuler.aided.evaluation import lever_arm, simulated_inputs
    from schuler.aided.kfgins import write_gnss, write_imu
    from schuler.aided.kfgins_configuration import example_configuration
    from schuler.core.attitude import euler_from_quaternion
    from schuler.core.random import RandomStreams
    from schuler.imu.record import ImuRecord

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    data = simulated_inputs(case, np.zeros(1, dtype=np.int64), RandomStreams(seed))
    truth, path = data.truth, data.path
    paths = {"imu": folder / "imu.txt", "gnss": folder / "gnss.txt", "reference": folder / "reference.nav",
             "configuration": folder / "kf-gins.yaml"}
    write_imu(paths["imu"], ImuRecord(time_s=week_start + truth.t_s, gyro=data.increments[0, :, :3],
                                      accel=data.increments[0, :, 3:], kind="increment",
                                      sample_interval_s=truth.interval_s))
    gnss = data.gnss[0]
    write_gnss(paths["gnss"], dataclasses.replace(gnss, t_s=gnss.t_s + week_start))
    v0, q0 = path.kinematics(np.array([0.0]))
    q = np.vstack([q0, truth.quaternion])
    write_navigation(paths["reference"], NavigationRecord(
        np.zeros(q.shape[0], dtype=np.int64), week_start + np.r_[0.0, truth.t_s],
        np.r_[path.latitude, truth.latitude_rad], np.r_[path.longitude, truth.longitude_rad],
        np.r_[path.height, truth.height_m], np.vstack([v0, truth.velocity_ned_m_s]), euler_from_quaternion(q)))
    attitude = np.degrees(euler_from_quaternion(q0[0]))
    text = example_configuration(paths["imu"].name, paths["gnss"].name, "kf-gins-results")
    replaced = {
        "imudatarate": f"{case['imu_rate']:.0f}", "starttime": f"{week_start:.9f}",
        "initpos": f"[{np.degrees(path.latitude):.12f}, {np.degrees(path.longitude):.12f}, {path.height:.9f}]",
        "initvel": "[" + ", ".join(f"{v:.9f}" for v in v0[0]) + "]",
        "initatt": "[" + ", ".join(f"{a:.12f}" for a in attitude) + "]",
        "antlever": "[" + ", ".join(f"{a:g}" for a in lever_arm(case)) + "]"}
    for key, value in replaced.items():
        text = re.sub(rf"^{key}: *[^#\n]*", f"{key}: {value}  ", text, flags=re.MULTILINE)
    paths["configuration"].write_text(text, encoding="utf-8")
    return paths
