"""Every self-alignment method on the real recording: PSINS lasergyro.imu (ring-laser gyros, at rest with
disturbances, 100 Hz, 31 min, 34.25 deg N).

The file is not part of the project (PSINS toolbox, BSD-2): the tests read it from the path in
SCHULER_PSINS_IMU and skip when that is unset or missing. Windows: the first 300 s, the first 600 s,
the whole record. The methods that follow the body's turns with the gyros (inertial frame, Kalman filter,
gyrocompass loop) agree within their stated noise; coarse alignment does not, and the body's net turn over
the window, which it takes for Earth rate, explains by how much. The staged gyrocompass (the default design)
ends within twice the combined 1-sigma of the filter's and its own stated limit on every window; the KPI
design, torqued by the specific force, does not on the 300-s window.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import pytest

from schuler.alignment.commands import align_compare
from schuler.alignment.comparison import AGREEMENT_SIGMAS

PSINS = os.environ.get("SCHULER_PSINS_IMU", "")

pytestmark = pytest.mark.skipif(not PSINS or not Path(PSINS).is_file(),
                                reason="set SCHULER_PSINS_IMU to the PSINS lasergyro.imu file to run")

WINDOWS = (300.0, 600.0, None)
FOLLOWERS = ("inertial_frame", "gyrocompass")


@pytest.fixture(scope="module")
def results():
    return {window: align_compare(record=PSINS, duration=window) for window in WINDOWS}


def gyrocompass_offset(result) -> tuple[float, float]:
    """(|gyrocompass - Kalman heading|, twice the combined 1-sigma of the filter's and the loop's stated limit)."""
    kalman, loop = result.methods["kalman"], result.methods["gyrocompass"]
    difference = abs(math.remainder(loop["heading_rad"] - kalman["heading_rad"], math.tau))
    return difference, 2.0 * math.hypot(kalman["heading_sigma_rad"], loop["limit_heading_rad"])


@pytest.mark.parametrize("window", WINDOWS, ids=["300 s", "600 s", "whole"])
def test_staged_gyrocompass_agrees_with_the_filter(results, window):
    """Every window: the staged loop's heading within twice the combined 1-sigma of the filter's own and the
    loop's stated limit (measured: 1.8, 0.8 and 0.3 arcmin against 7.9, 5.4 and 3.8), and within 0.04 deg of the
    filter, as the compass alignment of a peer toolbox is of its Kalman alignment on this record."""
    result = results[window]
    assert result.gyrocompass_design == "staged"
    difference, bound = gyrocompass_offset(result)
    assert difference < bound
    assert difference < math.radians(0.04)


def test_kpi_design_lets_the_base_motion_into_the_heading():
    """The KPI design (T = 30 s, zeta = 0.8) on the first 300 s: 11.4 arcmin from the filter, beyond twice the
    combined 1-sigma (9.7 arcmin): the body's sway reaches the heading through c_a, and the result says so."""
    result = align_compare(record=PSINS, duration=300.0, gyrocompass_design="kpi")
    difference, bound = gyrocompass_offset(result)
    assert difference > bound
    assert difference == pytest.approx(math.radians(11.4 / 60.0), rel=0.05)


@pytest.mark.parametrize("window", WINDOWS, ids=["300 s", "600 s", "whole"])
def test_methods_that_follow_the_body_agree(results, window):
    """Heading within AGREEMENT_SIGMAS (3) combined noise limits of the Kalman filter's; the level within 3 of
    the combined limits (the bias part is common to all methods, so this is lenient)."""
    result = results[window]
    kalman = result.methods["kalman"]
    for name in FOLLOWERS:
        assert result.agreement[name]["agrees"], (name, result.agreement[name])
        assert result.agreement[name]["ratio"] <= AGREEMENT_SIGMAS
        row = result.methods[name]
        for axis in ("roll", "pitch"):
            combined = math.hypot(row[f"limit_{axis}_rad"], kalman[f"limit_{axis}_rad"])
            assert abs(row[f"{axis}_rad"] - kalman[f"{axis}_rad"]) < 3 * combined, (name, axis)
    # the filter's own 1-sigma is of the size of its limit (the record is a navigation-grade IMU)
    assert 0.5 < kalman["heading_sigma_rad"] / kalman["limit_heading_rad"] < 2.0


@pytest.mark.parametrize("window", WINDOWS, ids=["300 s", "600 s", "whole"])
def test_coarse_alignment_is_off_by_the_body_turn(results, window):
    """Coarse alignment reads the body's net east turn over the window as Earth rate: heading shift
    -turn_E / (T Omega cos L). That shift explains its difference from the filter to 15 %."""
    result = results[window]
    coarse = result.agreement["coarse"]
    assert not coarse["agrees"]
    assert coarse["difference_rad"] == pytest.approx(result.coarse_disturbance_rad, rel=0.15)


def test_headings_agree_across_windows(results):
    """The filter's heading of every window within 3 combined 1-sigma of the whole record's."""
    whole = results[None].methods["kalman"]
    for window in (300.0, 600.0):
        row = results[window].methods["kalman"]
        combined = math.hypot(row["heading_sigma_rad"], whole["heading_sigma_rad"])
        assert abs(row["heading_rad"] - whole["heading_rad"]) < 3 * combined, window
