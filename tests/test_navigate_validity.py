"""The nonlinear INS at the edges of its models: runs that cannot go on are refused, degraded ones warn."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from schuler.core.earth import STANDARD_GRAVITY, gravity_height_coefficient, somigliana_gravity
from schuler.exceptions import SimulationError
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors
from schuler.navigate.mechanization import navigate
from schuler.navigate.trajectory import Stationary
from schuler.navigate.validity import VALID_HEIGHTS, ModelValidityWarning

LATITUDE = math.radians(45.0)


def _one_line_error(out) -> str:
    assert out.code == 2, out.stderr
    assert out.stderr.startswith("schuler: error:") and out.stderr.count("\n") == 1, out.stderr
    return out.stderr


@pytest.mark.parametrize("args, when", [
    # a 1-g down bias on the free channel: the height falls half way to the Earth's centre in 739 s
    (("--accel-bias-z", "1 g", "--duration", "86400"), "t = 739 s"),
    # started at -10 km with an ideal IMU: rounding alone diverges, e-folding every 570 s
    (("--height", "-10000", "--duration", "864000"), "t = 2"),
])
def test_a_free_channel_that_leaves_the_domain_is_refused_in_one_line(run_cli, args, when):
    out = run_cli("navigate", "run", "--vertical-channel", "free", "--imu-rate", "1", "--output-step", "600", *args)
    message = _one_line_error(out)
    assert "the run cannot be continued: the computed height fell below -3,189 km" in message
    assert when in message and "Traceback" not in message and "vertical channel off" in message


def test_an_ideal_imu_free_channel_over_a_day_is_refused_not_reported_as_numbers(run_cli):
    # before: -5,752 km of height error and 50 deg of heading error, printed without a word
    out = run_cli("navigate", "run", "--vertical-channel", "free", "--duration", "86400", "--json")
    assert "the computed height fell below -3,189 km" in _one_line_error(out) and out.stdout == ""


def test_a_height_beyond_the_gravity_model_warns_and_stays_finite(run_cli):
    # 1e-5 g down on the free channel: h = -(b / w^2)(cosh w t - 1), w^2 = g0 k1, past -11 km at 3,725 s
    out = run_cli("navigate", "run", "--vertical-channel", "free", "--accel-bias-z", "1e-5 g", "--duration", "4800",
                  "--imu-rate", "10", "--output-step", "60", "--json")
    assert out.code == 0
    data = out.json()
    w = math.sqrt(float(somigliana_gravity(LATITUDE)) * float(gravity_height_coefficient(LATITUDE)))
    b = 1e-5 * STANDARD_GRAVITY
    assert data["final_height_error_m"] == pytest.approx(-b / w**2 * (math.cosh(w * 4800) - 1), rel=0.01)
    [message] = data["warnings"]
    assert message.startswith("the computed height left -11 km .. 120 km at t = 3,780 s")  # the next output
    assert out.stderr == f"schuler: warning: {message}\n"
    assert all(math.isfinite(v) for v in data["height_error_m"])


@pytest.mark.parametrize("heading, warned", [("10 deg", True), ("3 deg", False)])
def test_attitude_errors_beyond_small_angles_warn(run_cli, heading, warned):
    out = run_cli("navigate", "run", "--heading-error", heading, "--duration", "600", "--imu-rate", "10",
                  "--output-step", "60", "--json")
    assert out.code == 0
    data = out.json()
    if warned:
        [message] = data["warnings"]
        assert message.startswith("the attitude error passed 5.7 deg at t = 0 s and reached 10 deg")
        assert out.stderr == f"schuler: warning: {message}\n"
    else:
        assert data["warnings"] == [] and out.stderr == ""


def test_a_batch_names_the_member_that_left_the_domain():
    # three members, the middle one with a 1-g down bias: the run stops and says which
    accel = np.zeros((3, 3))
    accel[1, 2] = STANDARD_GRAVITY
    with pytest.raises(SimulationError, match=r"fell below -3,189 km .* at t = 739 s \(member 11\)"):
        navigate(Stationary(latitude=LATITUDE), 3600.0, imu_rate=1.0, output_step=60.0, vertical_channel="free",
                 sensor_errors=ConstantSensorErrors(accel_bias=accel), member_ids=[10, 11, 12])


def test_a_batch_counts_the_members_past_the_gravity_model():
    accel = np.zeros((3, 3))
    accel[1:, 2] = 1e-5 * STANDARD_GRAVITY
    with pytest.warns(ModelValidityWarning, match=r"\(2 of 3 members, member 1 first\)"):
        result = navigate(Stationary(latitude=LATITUDE), 4800.0, imu_rate=10.0, output_step=60.0,
                          vertical_channel="free", sensor_errors=ConstantSensorErrors(accel_bias=accel))
    assert len(result.warnings) == 1 and np.all(np.isfinite(result.height_error_m))
    assert result.height_error_m[0, -1] > VALID_HEIGHTS[0] > result.height_error_m[1, -1]


def test_the_platform_mechanization_stops_too():
    with pytest.raises(SimulationError, match="fell below -3,189 km"):
        navigate(Stationary(latitude=LATITUDE), 3600.0, imu_rate=1.0, output_step=60.0, mode="platform",
                 vertical_channel="free", sensor_errors=ConstantSensorErrors(accel_bias=[0.0, 0.0, STANDARD_GRAVITY]))


def test_a_run_inside_the_models_is_silent():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = navigate(Stationary(latitude=LATITUDE), 600.0, imu_rate=10.0, output_step=60.0,
                          vertical_channel="baro", initial_errors=InitialErrors(heading_error=math.radians(5.0)))
    assert result.warnings == []


def test_a_computed_position_past_the_pole_is_still_inside_the_domain(run_cli):
    # 200 km north of 89 deg is 90.8 deg: the other side's frame, turned half a turn; only the pole itself is refused
    out = run_cli("navigate", "run", "--latitude", "89", "--position-error-north", "200000", "--duration", "600",
                  "--imu-rate", "10", "--output-step", "60", "--json")
    assert out.code == 0 and out.stderr == "", out.stderr
    assert out.json()["final_position_error_north_m"] == pytest.approx(2e5, rel=1e-3)
