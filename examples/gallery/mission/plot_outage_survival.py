"""
Mission: how long a GNSS outage each IMU grade survives
=======================================================

The question asked before buying an IMU: once GNSS drops out, how long until the
horizontal position error (1-sigma) passes 1 m, 10 m, 100 m? The aided mission
(``examples/mission_navigation_gnss.toml``: pulse calibration, 15-min Kalman
alignment, a 2-h flight aided by GNSS positions, here every second, and one
outage after an hour) is swept over the outage's duration for each grade,
as on the command line::

    schuler mission sweep examples/mission_navigation_gnss.toml \\
        --param imu=navigation,tactical,industrial,consumer --param gnss_rate=1 --param covariance_interval=1 \\
        --param outage_duration=1,3,10,30,100,300,1000,3000 --out sweep-outage-survival

Each case is the covariance analysis of the filter's closed loop
(:mod:`schuler.mission.aiding`); the longest outage within each bound is
interpolated in log-log between the sweep's points (:mod:`schuler.mission.survival`).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd

from schuler.mission.survival import survival_figure, survival_table
from schuler.study.scenario import load_scenario
from schuler.study.sweep import run_sweep

name = Path("examples", "mission_navigation_gnss.toml")  # found from the repository or its gallery folder
scenario = load_scenario(next(folder / name for folder in (Path.cwd(), *Path.cwd().parents)
                              if (folder / name).is_file()))
grid = ["imu=navigation,tactical,industrial,consumer", "gnss_rate=1", "covariance_interval=1",
        "outage_duration=1,3,10,30,100,300,1000,3000"]
with tempfile.TemporaryDirectory() as folder:
    run_sweep(scenario, folder, grid, progress=False, plots=False)
    frame = pd.read_parquet(Path(folder) / "results.parquet")

survival_figure(frame)
plt.show()

# %%
# The longest outage within each horizontal 1-sigma bound, s ("inf": the longest swept, 3000 s, stays within):
print(survival_table(frame).round(0))
