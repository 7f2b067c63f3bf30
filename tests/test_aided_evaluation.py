"""The aided run on simulated data (``schuler.aided.evaluation``): ideal sensors give the truth, outputs follow
the histories, each member runs its own filter, and the filter's outage 1-sigma describes the members' drift."""

from __future__ import annotations

import math

import numpy as np
import pytest

from schuler.aided import evaluation
from schuler.aided.plots import figures
from schuler.contract import Cases, System
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter

SHORT = {"duration": 300.0, "outage_start": 120.0}

AIDED = System(name="aided", title="Aided INS", reference="spec 07", parameters=evaluation.PARAMETERS,
               outputs=evaluation.OUTPUTS, evaluate=evaluation.evaluate, reproduce=lambda: None,
               report=lambda folder: None, figures=figures, random_terms=True, realisation=True,
               member_bytes=evaluation.member_bytes)
"""The evaluation on the contract, as the system will assemble it."""


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
    assert sorted(result.figures()) == ["aided_errors", "aided_outage_drift"]


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
    from schuler.aided.evaluation import _group

    run, errors, outages = _group(AIDED.case(**SHORT), np.arange(64), RandomStreams(2))
    (drift,) = analysis.outage_drift(run, errors, outages)
    assert drift.horizontal_error_sigma_m == pytest.approx(predicted, rel=0.02)
    assert drift.horizontal_error_end_m == pytest.approx(drift.horizontal_error_sigma_m, rel=0.15)


def test_unknown_aiding_is_refused_with_a_suggestion():
    with pytest.raises(InvalidParameter, match="did you mean 'gnss-velocity'"):
        AIDED.run(aiding="gnss-position,gnss-velocty", **SHORT)
    with pytest.raises(InvalidParameter, match="gnss-position is needed"):
        AIDED.run(aiding="gnss-velocity", **SHORT)
