"""The mission on the contract's one evaluation: the JSON keys, files and columns scripts rely on; the drive."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from schuler.contract import Cases
from schuler.exceptions import InvalidParameter
from schuler.mission.aided_monte_carlo import OUTAGE_SLOTS
from schuler.mission.api import SYSTEM
from schuler.mission.covariance import covariance_budget
from schuler.mission.evaluation import PARAMETERS, evaluate
from schuler.mission.results import MissionResult
from schuler.mission.setup import SOURCES, mission_setup
from schuler.navigate.drive import GroundVehicleProfile, drive
from test_contract import LIGHT

KEYS = ["position_error_sigma_m", "position_error_north_sigma_m", "position_error_east_sigma_m",
        "velocity_error_sigma_m_s", "heading_error_sigma_rad", "initial_heading_error_sigma_rad",
        "initial_tilt_sigma_rad", "dominant_share", "member_position_error_m", "budget", "dominant_source",
        "instrument", "monte_carlo", "units", "outage_horizontal_error_sigma_m",
        *(f"member_outage_{k}_horizontal_error_{kind}_m" for k in range(1, OUTAGE_SLOTS + 1)
          for kind in ("end", "max"))]
"""The top-level keys of ``mission run --json`` (with schuler_version, inputs and files), recorded before the
mission moved to the one evaluation (main at 58a5aa9, the light case), and the outputs of the aided mission
since."""

COLUMNS = ["t_s", "position_error_sigma_m", "velocity_error_sigma_m_s", "heading_error_sigma_rad",
           *(f"variance_{name}_m2" for name in SOURCES)]
"""The columns of ``mission_budget.csv``, recorded likewise."""

COMPARISON = ["position_error_sigma_m", "position_error_sigma_standard_error_m", "covariance_position_error_sigma_m",
              "nominal_covariance_position_error_sigma_m"]
"""What the mission adds to ``to_dict()["monte_carlo"]``: the covariance beside the members."""


def light_options() -> list[str]:
    return [part for name, value in LIGHT["mission"].items() for part in (PARAMETERS[name].option, str(value))]


def test_the_run_keeps_its_json_keys_files_and_columns(run_cli, tmp_path):
    out = run_cli("mission", "run", *light_options(), "--json", "--out", tmp_path)
    assert out.code == 0, out.stderr
    data = out.json()
    assert set(data) == {"schuler_version", "inputs", "files", *KEYS}
    written = sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith("."))
    assert written == ["mission_budget.csv", "mission_budget.png", "mission_budget.svg"]
    table = pd.read_csv(tmp_path / "mission_budget.csv")
    assert list(table.columns) == COLUMNS
    # the light case: 1200 s at 600-s steps; the last row is the JSON's final 1-sigma, the variances its square
    assert table["t_s"].tolist() == [0.0, 600.0, 1200.0]
    final = table.iloc[-1]
    assert final["position_error_sigma_m"] == pytest.approx(data["position_error_sigma_m"], rel=1e-12)
    variances = final[[f"variance_{name}_m2" for name in SOURCES]]
    assert variances.sum() == pytest.approx(data["position_error_sigma_m"] ** 2, rel=1e-12)
    assert dict(zip(SOURCES, variances / variances.sum())) == pytest.approx(data["budget"], rel=1e-9, abs=1e-15)
    assert sum(data["budget"].values()) == pytest.approx(1.0, abs=1e-12)
    assert data["units"]["budget"] == "1" and data["units"]["position_error_sigma_m"] == "m"
    assert data["monte_carlo"] is None and data["member_position_error_m"] == 0.0
    # the light case's number on main before the move (the covariance of a tactical 20-min cruise); 1e-9: the
    # linear-algebra libraries' rounding differs by machine (2.6e-11 seen), a change of the model moves it by far more
    assert data["position_error_sigma_m"] == pytest.approx(11125.796258358929, rel=1e-9)


def test_the_result_is_evaluate_in_full_and_compares_its_monte_carlo():
    result = SYSTEM.run(**LIGHT["mission"], monte_carlo=8, seed=2)
    assert type(result) is MissionResult
    direct = evaluate(Cases.from_case(SYSTEM.case(**LIGHT["mission"])), histories=True)
    assert result.budget == direct.extras["budget"] and result.instrument == direct.extras["instrument"]
    history = result.histories["mission_budget"]
    setup = mission_setup(dict(SYSTEM.case(**LIGHT["mission"])))
    np.testing.assert_array_equal(history["heading_error_sigma_rad"], covariance_budget(setup).sigma("heading"))
    compared = result.to_dict()["monte_carlo"]
    assert all(key in compared for key in COMPARISON)
    assert compared["position_error_sigma_m"] == pytest.approx(compared["statistics"]["member_position_error_m"]
                                                               ["rms"], rel=1e-12)
    assert compared["nominal_covariance_position_error_sigma_m"] == result.position_error_sigma_m
    # JSON keeps 15 significant digits
    assert json.loads(json.dumps(result.to_dict(), allow_nan=False))["budget"] == pytest.approx(result.budget,
                                                                                                rel=1e-14)
    assert "Monte Carlo (8 members, nonlinear INS)" in " ".join(str(result).split())


def test_the_drive_is_navigates_drive_and_its_covariance_agrees_with_the_nonlinear_members():
    case = {"trajectory": "drive", "duration": 900.0}
    setup = mission_setup(dict(SYSTEM.case(**case)))
    path = setup.trajectory()
    expected = drive(latitude=setup.latitude, longitude=setup.longitude, height=setup.height,
                     heading=setup.heading, duration=900.0)
    assert isinstance(path, GroundVehicleProfile) and path.name == "drive"
    np.testing.assert_array_equal(path.times, expected.times)
    np.testing.assert_array_equal(path.headings, expected.headings)
    # turns and speed changes: the accelerometer errors act, so the budget is not the stationary one
    result = SYSTEM.run(**case, monte_carlo=400, seed=3)
    still = SYSTEM.run(trajectory="stationary", duration=900.0)
    assert result.position_error_sigma_m > 1.4 * still.position_error_sigma_m
    # the members' RMS (nonlinear INS) within three of its sampling standard errors (about 3.5 % each at 400)
    compared = result.to_dict()["monte_carlo"]
    band = 3.0 * compared["position_error_sigma_standard_error_m"]
    assert 0.05 < band / compared["position_error_sigma_m"] < 0.2
    assert abs(compared["position_error_sigma_m"] - compared["covariance_position_error_sigma_m"]) <= band


def test_a_drive_too_short_for_its_stops_is_refused_by_duration():
    with pytest.raises(InvalidParameter, match="^duration: 120 s is too short: 4 stops of 25 s"):
        SYSTEM.run(trajectory="drive", duration=120.0)


def test_the_geodesic_is_navigates_great_circle_and_the_former_name_is_refused_naming_it(run_cli):
    """One trajectory vocabulary: mission's geodesic is navigate's ``great-circle``, the same path from one start."""
    from schuler.navigate.evaluation import DRIVE_OPTIONS, trajectory_of

    setup = mission_setup(PARAMETERS.case({"trajectory": "great-circle", "duration": 600.0, "speed": 200.0}))
    ours = setup.trajectory()
    theirs, _ = trajectory_of("great-circle", {"latitude": setup.latitude, "longitude": setup.longitude,
                                               "height": setup.height, "heading": setup.heading, "speed": 200.0,
                                               "duration": 600.0, **dict.fromkeys(DRIVE_OPTIONS)})
    times = np.linspace(0.0, 600.0, 7)
    for mine, navigates in zip(ours.kinematics(times), theirs.kinematics(times), strict=True):
        np.testing.assert_allclose(mine, navigates, rtol=0.0, atol=1e-12)  # velocity m/s, attitude quaternion
    with pytest.raises(InvalidParameter, match="^trajectory: 'cruise' is renamed to 'great-circle'"):
        SYSTEM.run(trajectory="cruise")
    out = run_cli("mission", "run", "--trajectory", "cruise", "--json")
    assert out.code == 2 and "renamed to 'great-circle'" in out.stderr
