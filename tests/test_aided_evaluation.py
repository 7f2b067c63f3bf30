"""The aided run on simulated data (``schuler aided``): ideal sensors give the truth, outputs follow the
histories, each member runs its own filter, the filter's outage 1-sigma describes the members' drift; the command
line's files and JSON."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.contract import Cases
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.registry import get_system

SHORT = {"duration": 300.0, "outage_start": 120.0}

AIDED = get_system("aided")


def test_ideal_sensors_and_noiseless_gnss_return_the_truth():
    result = AIDED.run(nominal=True, **SHORT)
    assert result.position_error_horizontal_max_m < 1e-3
    assert result.heading_error_rms_rad < math.radians(1e-4)
    assert result.rejected_measurements == 0


def test_a_run_is_member_zero_of_its_seed_and_its_outputs_follow_its_histories():
    result = AIDED.run(seed=4, **SHORT)
    cases = Cases.from_case(AIDED.case(**SHORT), 1, members=np.array([0]), random=RandomStreams(4))
    assert result.outputs == {name: float(values[0]) for name, values in AIDED.evaluate(cases).items()}
    errors = result.histories["aided_errors"]
    horizontal = errors["horizontal_error_m"]
    assert result.position_error_horizontal_max_m == pytest.approx(horizontal.max(), rel=1e-12)
    assert result.position_error_horizontal_rms_m == pytest.approx(np.sqrt(np.mean(horizontal ** 2)), rel=1e-12)
    assert np.allclose(horizontal, np.hypot(errors["north_error_m"], errors["east_error_m"]), rtol=1e-12)
    (outage,) = result.outages
    assert (outage["start_s"], outage["duration_s"]) == (120.0, 60.0)
    inside = (errors.time > 120.0) & (errors.time <= 180.0)
    assert outage["horizontal_error_max_m"] == pytest.approx(horizontal[inside].max(), rel=1e-12)
    assert result.outage_horizontal_error_max_m == outage["horizontal_error_max_m"]
    assert set(result.nees) == {"position", "velocity", "attitude"}
    assert sorted(result.figures()) == ["aided_errors", "aided_innovations", "aided_outage_drift"]


def test_members_draw_their_own_errors_the_same_in_any_batch():
    cases = Cases.from_case(AIDED.case(**SHORT), 3, members=np.array([0, 1, 2]), random=RandomStreams(9))
    together = AIDED.evaluate(cases)["position_error_horizontal_rms_m"]
    alone = AIDED.evaluate(Cases.from_case(AIDED.case(**SHORT), 1, members=np.array([2]), random=RandomStreams(9)))
    assert alone["position_error_horizontal_rms_m"][0] == pytest.approx(together[2], rel=1e-12)
    assert len(set(np.round(together, 9))) == 3


@pytest.mark.slow
def test_the_outage_sigma_describes_the_members_drift():
    # the predicted 1-sigma at the outage's end against the RMS over 64 members of the error there: the horizontal
    # error's RMS is sqrt(E[n^2 + e^2]) = sqrt(P_NN + P_EE) when the filter is consistent; sampling band of a
    # chi-square with 128 degrees of freedom: +-15 % at about 2.5 sigma
    result = AIDED.run(monte_carlo=64, seed=2, **SHORT)
    stats = result.monte_carlo
    predicted = stats["outage_horizontal_error_sigma_m"].mean
    assert predicted > 1.0
    from schuler.aided import analysis
    from schuler.aided.evaluation import _simulated_group

    run, errors, outages = _simulated_group(AIDED.case(**SHORT), np.arange(64), RandomStreams(2))
    (drift,) = analysis.outage_drift(run, errors, outages)
    assert drift.horizontal_error_sigma_m == pytest.approx(predicted, rel=0.02)
    assert drift.horizontal_error_end_m == pytest.approx(drift.horizontal_error_sigma_m, rel=0.15)


def test_unknown_aiding_is_refused_with_a_suggestion():
    with pytest.raises(InvalidParameter, match="did you mean 'gnss-velocity'"):
        AIDED.run(aiding="gnss-position,gnss-velocty", **SHORT)
    with pytest.raises(InvalidParameter, match="gnss-position is needed"):
        AIDED.run(aiding="gnss-velocity", **SHORT)


def test_the_command_writes_the_histories_the_figures_and_the_json_names_scripts_rely_on(run_cli, tmp_path):
    out = run_cli("aided", "run", "--duration", "300", "--outage-start", "120", "--json", "--out", str(tmp_path))
    assert out.code == 0, out.stderr
    data = out.json()
    for key in ("position_error_horizontal_rms_m", "position_error_horizontal_max_m", "position_error_vertical_rms_m",
                "velocity_error_horizontal_rms_m_s", "heading_error_rms_rad", "rejected_measurements"):
        assert isinstance(data[key], float), key
    assert set(data["outages"][0]) == {"start_s", "duration_s", "horizontal_error_max_m", "vertical_error_max_m",
                                       "heading_error_max_rad", "horizontal_error_sigma_m"}
    assert set(data["nees"]) == {"position", "velocity", "attitude"} and "band" in data["nis"]
    files = sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith("."))
    assert files == ["aided_errors.csv", "aided_errors.png", "aided_errors.svg", "aided_innovations.csv",
                     "aided_innovations.png", "aided_innovations.svg", "aided_outage_drift.png",
                     "aided_outage_drift.svg", "navigation.csv", "navigation.nav"]
    python = AIDED.run(duration=300.0, outage_start="2 min")
    assert python.position_error_horizontal_rms_m == pytest.approx(data["position_error_horizontal_rms_m"], rel=1e-12)


def test_bad_input_is_one_line_and_exit_2(run_cli):
    out = run_cli("aided", "run", "--duration", "300", "--aiding", "gps")
    assert out.code == 2 and out.stderr.count("\n") == 1 and "aiding" in out.stderr
    out = run_cli("aided", "run", "--duration", "300", "--imu", "no-such-grade")
    assert out.code == 2 and "neither a grade" in out.stderr


def test_the_innovations_over_their_sigma_are_unit_normal_and_drawn():
    # a filter whose model matches the simulation: each normalised GNSS residual has variance 1 (270 epochs x 6
    # components; the sample variance of 1,620 unit normals is within +-10 % at 4 sigma, correlations aside)
    result = AIDED.run(**SHORT)
    innovations = result.histories["aided_innovations"]
    components = [name for name in innovations.channels if name.endswith("_normalised")]
    assert len(components) == 6 and innovations.time.size > 200
    values = np.concatenate([innovations[name] for name in components])
    assert np.var(values) == pytest.approx(1.0, rel=0.1)
    assert "aided_innovations" in result.figures()
