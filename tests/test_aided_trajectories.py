"""``schuler aided`` on every trajectory of ``schuler navigate``: their stops, the truth with ideal sensors, the
stops' updates at rest, and what each trajectory refuses."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from schuler.aided import evaluation
from schuler.exceptions import InvalidParameter
from schuler.navigate.drive import drive
from schuler.navigate.trajectory import GreatCircle, Stationary, WaypointProfile, stationary_intervals
from schuler.registry import get_system

AIDED = get_system("aided")
PROFILE = Path(__file__).resolve().parents[1] / "examples" / "profiles" / "manoeuvring_flight.toml"
COMMON = {"duration": 300.0, "outage_start": 120.0, "imu": "tactical"}


def test_each_trajectory_s_stationary_intervals():
    assert stationary_intervals(Stationary(latitude=0.5), 60.0) == [(0.0, 60.0)]
    assert stationary_intervals(GreatCircle(latitude=0.5, longitude=0.0, height=0.0, heading=0.0, speed=100.0,
                                            duration=60.0), 60.0) == []
    path = drive(duration=600.0, stops=3, stop_duration=20.0)
    assert stationary_intervals(path, 600.0) == path.stationary_intervals()
    assert [end - start for start, end in path.stationary_intervals()] == pytest.approx([20.0] * 3, rel=1e-12)
    # a profile at rest after its last waypoint stays at rest (its values hold); clipped to the time asked for
    parked = WaypointProfile(latitude=0.5, longitude=0.0, height=0.0, times=[0.0, 10.0, 30.0, 40.0],
                             speeds=[0.0, 0.0, 5.0, 0.0], headings=[0.0] * 4, flight_path_angles=[0.0] * 4)
    assert stationary_intervals(parked, 100.0) == [(0.0, 10.0), (40.0, 100.0)]
    assert stationary_intervals(parked, 5.0) == [(0.0, 5.0)]


def test_not_set_is_the_drive_and_its_options_shape_it():
    assert AIDED.run(**COMMON).outputs == AIDED.run(trajectory="drive", **COMMON).outputs
    case = AIDED.parameters.case(duration=600.0, stops=6, stop_duration=10.0)
    stops = stationary_intervals(evaluation.trajectory(case), 600.0)
    assert len(stops) == 6 and [end - start for start, end in stops] == pytest.approx([10.0] * 6, rel=1e-12)


@pytest.mark.parametrize("options", [{"trajectory": "stationary"},
                                     {"trajectory": "great-circle", "speed": 120.0, "heading": math.radians(45.0)},
                                     {"trajectory": str(PROFILE)},
                                     {"trajectory": "drive", "latitude": math.radians(60.0), "stops": 3}],
                         ids=["stationary", "great-circle", "profile", "drive-at-60-deg"])
def test_ideal_sensors_return_the_truth_on_every_trajectory(options):
    result = AIDED.run(nominal=True, **{**COMMON, **options})
    assert result.position_error_horizontal_max_m < 1e-3
    assert result.heading_error_rms_rad < math.radians(1e-4)
    assert result.outages[0]["start_s"] == 120.0 and result.outages[0]["horizontal_error_sigma_m"] > 1.0


def test_at_rest_the_stop_updates_hold_a_gnss_outage():
    # measured (member 0 of the default seed): 0.028 m with zupt and zaru (1-sigma 0.079 m), 11.4 m with GNSS
    # alone (1-sigma 6.5 m) at the end of a 60-s outage of a tactical IMU at rest
    alone = AIDED.run(trajectory="stationary", **COMMON).outages[0]
    held = AIDED.run(trajectory="stationary", aiding="gnss-position,gnss-velocity,zupt,zaru", **COMMON).outages[0]
    assert held["horizontal_error_max_m"] < 0.1 and held["horizontal_error_sigma_m"] < 0.1
    assert alone["horizontal_error_sigma_m"] > 50.0 * held["horizontal_error_sigma_m"]
    assert alone["horizontal_error_max_m"] > 1.0


def test_an_in_motion_start_on_a_flight_takes_no_rest():
    result = AIDED.run(trajectory="great-circle", initialisation="in-motion", nominal=True, **COMMON)
    assert result.position_error_horizontal_max_m < 0.05
    with pytest.raises(InvalidParameter, match="longer than the 25 s the data are at rest"):
        AIDED.run(initialisation="in-motion", alignment_duration=30.0, **COMMON)


@pytest.mark.parametrize(("arguments", "message"), [
    (("--trajectory", "great-circle", "--aiding", "gnss-position,nhc"), "--aiding: nhc: a ground vehicle's"),
    (("--trajectory", "great-circle", "--aiding", "gnss-position,odometer"), "--aiding: odometer: a ground vehicle"),
    (("--trajectory", "stationary", "--stops", "3"), "--stops: applies to the drive trajectory only"),
    (("--speed", "30"), "--speed: applies to the great-circle trajectory only"),
    (("--trajectory", str(PROFILE), "--latitude", "40"), "--latitude: is set by the profile"),
    (("--trajectory", "lawnmower"), "--trajectory: 'lawnmower' is neither stationary nor great-circle nor drive"),
    (("--record", "imu.txt", "--gnss-file", "gnss.txt", "--trajectory", "drive"),
     "--trajectory: applies to a simulated case"),
    (("--record", "imu.txt", "--gnss-file", "gnss.txt", "--stops", "3"), "--stops: applies to a simulated case"),
    (("--initialisation", "in-motion", "--alignment-duration", "30"), "--alignment-duration: 30 s is longer than"),
])
def test_a_trajectory_s_refusals_are_one_line(run_cli, arguments, message):
    out = run_cli("aided", "run", "--duration", "300", *arguments)
    assert out.code == 2 and out.stderr.count("\n") == 1 and message in out.stderr, out.stderr
