"""Sweeps and Monte Carlo: grids, identical results on every executor, resume, worker loss."""

from __future__ import annotations

import math
import os

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import test_study_fake_system as fake
from schuler.exceptions import ScenarioError
from schuler.study.plan import grid_values, parse_axis, plan_sweep
from schuler.study.scenario import parse_scenario
from schuler.study.store import chunk_path
from schuler.study.summary import histograms
from schuler.study.sweep import run_sweep

SCENARIO = """\
system = "fake"
[parameters]
latitude = "30 deg"
drift_east = "0.01 deg/h"
[monte_carlo]
seed = 11
[monte_carlo.normal]
drift_east = "0.002 deg/h"
[monte_carlo.uniform]
gain = [0.5, 1.5]
"""

GRID = ("latitude=0:60:10", "members=1,2")  # 7 x 2 grid points


@pytest.fixture(autouse=True)
def fake_system(monkeypatch):
    fake.register(monkeypatch)


@pytest.fixture
def scenario():
    return parse_scenario(SCENARIO, source="sweep.toml")


def results(path):
    return pd.read_parquet(path / "results.parquet")


# ------------------------------------------------------------------ grids
def test_grid_includes_stop_despite_float_rounding():
    values = grid_values(0.0, 1.0, 0.1)  # 10 * 0.1 = 0.9999999999999999 in floats
    assert len(values) == 11 and values[-1] == 1.0
    assert len(grid_values(0.1, 0.3, 0.1)) == 3  # (0.3 - 0.1) / 0.1 = 1.9999999999999998
    assert grid_values(0.0, 1.0, 0.3).tolist() == pytest.approx([0.0, 0.3, 0.6, 0.9])  # 1.0 is off the grid
    assert grid_values(5.0, 5.0, 1.0).tolist() == [5.0]
    assert grid_values(1.0, -1.0, -1.0).tolist() == [1.0, 0.0, -1.0]
    for start, stop, step in ((0.0, 1.0, 0.0), (0.0, 1.0, -0.1), (0.0, math.inf, 1.0)):
        with pytest.raises(ValueError):
            grid_values(start, stop, step)


@settings(max_examples=200, deadline=None)
@given(
    start=st.floats(-1e3, 1e3, allow_nan=False),
    step=st.floats(1e-6, 1e3, allow_nan=False),
    intervals=st.integers(0, 1000),
)
def test_grid_has_every_point_and_ends_on_stop(start, step, intervals):
    stop = start + intervals * step
    values = grid_values(start, stop, step)
    assert len(values) == intervals + 1
    assert values[0] == start and values[-1] == stop
    assert np.all(np.diff(values) > 0)


def test_axis_units_lists_and_errors():
    axis = parse_axis("drift_east=0.001:0.003:0.001 deg/h", fake.PARAMETERS)
    assert np.allclose(axis.values, np.radians([0.001, 0.002, 0.003]) / 3600, rtol=1e-12)
    axis = parse_axis("latitude=10 deg:20 deg:0.5 deg", fake.PARAMETERS)
    assert len(axis.values) == 21 and axis.values[-1] == pytest.approx(math.radians(20))
    assert parse_axis("duration=1 h,90 min", fake.PARAMETERS).values.tolist() == [3600.0, 5400.0]
    assert parse_axis("method=closed,table", fake.PARAMETERS).values.tolist() == ["closed", "table"]
    assert parse_axis("members=1:7:3", fake.PARAMETERS).values.tolist() == [1, 4, 7]
    for text, message in [
        ("colour=1:2:1", "`param` colour: unknown parameter"),
        ("latitude", "expected NAME=START:STOP:STEP"),
        ("latitude=0:100:10", "`param` latitude: 100.0 is outside [-89, 89] deg"),
        ("latitude=0:10", "is not START:STOP:STEP"),
        ("latitude=0:10:0", "the step must be a finite non-zero number"),
        ("latitude=0:10:-1", "the step goes away from the stop value"),
        ("drift_east=0:1:1 m", "is not an angular rate"),
        ("method=closed:table:1", "takes a list"),
    ]:
        with pytest.raises(ScenarioError, match=message.replace("[", r"\[").replace("(", r"\(")):
            parse_axis(text, fake.PARAMETERS)


def test_plan_counts_cases_and_refuses_inconsistent_requests(scenario):
    plan = plan_sweep(scenario, fake.FAKE, GRID, monte_carlo=5, chunk_size=8)
    assert plan.grid_shape == (7, 2) and plan.total == 70 and plan.chunks == 9
    assert plan.chunk_range(8) == (64, 70)
    with pytest.raises(ScenarioError, match="`param` latitude: given more than once"):
        plan_sweep(scenario, fake.FAKE, ("latitude=0:1:1", "latitude=2,3"))
    with pytest.raises(ScenarioError, match="`param` gain: already random"):
        plan_sweep(scenario, fake.FAKE, ("gain=1,2",), monte_carlo=3)
    plain = parse_scenario('system = "fake"\n')
    with pytest.raises(ScenarioError, match="`monte_carlo`: the scenario has no random parameters"):
        plan_sweep(plain, fake.FAKE, (), monte_carlo=3)


# ---------------------------------------------------------------- results
def test_sweep_results_are_the_closed_form_per_case(scenario, tmp_path):
    summary = run_sweep(scenario, tmp_path, GRID, monte_carlo=5, chunk_size=16, progress=False)
    frame = pd.read_csv(tmp_path / "results.csv")
    assert summary.cases == len(frame) == 70 and summary.chunks == 5
    assert list(frame.columns) == [
        "case", "latitude_deg", "drift_east_deg_per_h", "gain", "method", "members",
        "duration_s", "output_step_s", "sigma_drift_deg_per_h", "azimuth_error_rad", "settling_time_s",
    ]  # fmt: skip
    assert frame["case"].tolist() == list(range(70))
    # grid: case = (latitude index * 2 + members index) * 5 + draw
    assert np.allclose(frame["latitude_deg"], np.repeat(np.arange(0, 61, 10), 10))
    assert frame["members"].tolist() == np.tile(np.repeat([1, 2], 5), 7).tolist()
    horizontal_earth_rate = fake.EARTH_RATE * np.cos(np.radians(frame["latitude_deg"]))
    expected = np.radians(frame["drift_east_deg_per_h"]) / 3600 / horizontal_earth_rate
    assert np.allclose(frame["azimuth_error_rad"], expected, rtol=1e-12)
    assert np.allclose(frame["settling_time_s"], 3600.0 / frame["gain"] * frame["members"], rtol=1e-12)
    assert frame["gain"].between(0.5, 1.5).all() and frame["gain"].std() > 0.2
    assert frame["drift_east_deg_per_h"].std() == pytest.approx(0.002, rel=0.4)
    assert frame["method"].eq("closed").all()
    assert results(tmp_path).equals(pd.read_parquet(tmp_path / "results.parquet"))
    stats = summary.statistics["azimuth_error_rad"]
    assert stats["count"] == 70 and stats["nan_count"] == 0
    assert stats["mean"] == pytest.approx(frame["azimuth_error_rad"].mean(), rel=1e-12)
    assert stats["std"] == pytest.approx(frame["azimuth_error_rad"].std(), rel=1e-9)
    assert stats["p50"] == pytest.approx(frame["azimuth_error_rad"].median(), rel=1e-12)
    for name in ("sweep.json", "summary.json", "summary_azimuth_error_rad.png", "summary_settling_time_s.png"):
        assert (tmp_path / name).stat().st_size > 0
    # the streamed histogram is exact
    counts, edges = histograms(plan_sweep(scenario, fake.FAKE, GRID, 5, 16), tmp_path, summary.statistics)[
        "azimuth_error_rad"
    ]
    assert counts.tolist() == np.histogram(frame["azimuth_error_rad"], bins=edges)[0].tolist()


def test_draws_do_not_depend_on_chunking(scenario, tmp_path):
    run_sweep(scenario, tmp_path / "a", ("latitude=0,30",), monte_carlo=25, chunk_size=7, progress=False, plots=False)
    run_sweep(scenario, tmp_path / "b", ("latitude=0,30",), monte_carlo=25, chunk_size=50, progress=False, plots=False)
    pd.testing.assert_frame_equal(results(tmp_path / "a"), results(tmp_path / "b"))
    other = parse_scenario(SCENARIO.replace("seed = 11", "seed = 12"))
    run_sweep(other, tmp_path / "c", ("latitude=0,30",), monte_carlo=25, chunk_size=7, progress=False, plots=False)
    assert not np.allclose(results(tmp_path / "a")["gain"], results(tmp_path / "c")["gain"])


def test_system_random_terms_are_drawn_only_in_a_monte_carlo(scenario, tmp_path):
    # sigma_drift is a random term of the system itself: a plain grid is nominal, a Monte Carlo draws it
    noisy = parse_scenario(SCENARIO.replace('drift_east = "0.01 deg/h"',
                                            'drift_east = "0.01 deg/h"\nsigma_drift = "0.005 deg/h"'))
    plain = run_sweep(noisy, tmp_path / "grid", ("latitude=0,30",), progress=False, plots=False)
    assert plain.statistics["azimuth_error_rad"]["std"] > 0  # two latitudes
    grid = results(tmp_path / "grid")
    expected = np.radians(0.01) / 3600 / (fake.EARTH_RATE * np.cos(np.radians(grid["latitude_deg"])))
    assert np.allclose(grid["azimuth_error_rad"], expected, rtol=1e-12)
    run_sweep(noisy, tmp_path / "mc7", ("latitude=0,30",), monte_carlo=25, chunk_size=7, progress=False, plots=False)
    run_sweep(noisy, tmp_path / "mc50", ("latitude=0,30",), monte_carlo=25, chunk_size=50, progress=False, plots=False)
    pd.testing.assert_frame_equal(results(tmp_path / "mc7"), results(tmp_path / "mc50"), check_exact=True)
    drawn = results(tmp_path / "mc7")
    horizontal_earth_rate = fake.EARTH_RATE * np.cos(np.radians(drawn["latitude_deg"]))
    nominal = np.radians(drawn["drift_east_deg_per_h"]) / 3600 / horizontal_earth_rate
    assert not np.allclose(drawn["azimuth_error_rad"], nominal)


def test_monte_carlo_draws_outside_the_range_are_refused(tmp_path):
    wide = parse_scenario('system = "fake"\n[monte_carlo.normal]\nlatitude = "30 deg"\n')
    outside = r"\[monte_carlo.normal\] latitude: a draw of .* deg is outside \[-89, 89\] deg"
    with pytest.raises(ScenarioError, match=outside):
        run_sweep(wide, tmp_path, (), monte_carlo=1000, progress=False)


# ------------------------------------------------------------ executors
EXECUTOR_ARGS = dict(params=GRID, monte_carlo=5, chunk_size=9, progress=False, plots=False)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("options", "executor"),
    [({"workers": 2}, "processes"), ({"scheduler": "local", "workers": 2}, "dask")],
    ids=["local-processes", "dask-local-cluster"],
)
def test_every_executor_gives_identical_results(scenario, tmp_path, options, executor):
    reference = run_sweep(scenario, tmp_path / "inprocess", **EXECUTOR_ARGS)
    other = run_sweep(scenario, tmp_path / executor, **options, **EXECUTOR_ARGS)
    assert (reference.executor, other.executor) == ("in-process", executor)
    assert reference.chunks == other.chunks == 8
    pd.testing.assert_frame_equal(results(tmp_path / executor), results(tmp_path / "inprocess"), check_exact=True)
    assert (tmp_path / executor / "results.csv").read_text() == (tmp_path / "inprocess" / "results.csv").read_text()


def test_resume_after_interruption_skips_finished_chunks(scenario, tmp_path):
    args = dict(params=GRID, monte_carlo=5, chunk_size=10, progress=False, plots=False)

    def interrupt_after_three(index):
        if index == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(scenario, tmp_path / "sweep", on_chunk=interrupt_after_three, **args)
    stored = sorted(p.name for p in (tmp_path / "sweep" / "chunks").iterdir())
    assert stored == ["chunk-000000.parquet", "chunk-000001.parquet", "chunk-000002.parquet"]
    assert not (tmp_path / "sweep" / "results.parquet").exists()
    before = fake.CALLS["sweep"]
    resumed = run_sweep(scenario, tmp_path / "sweep", **args)
    assert (resumed.chunks_resumed, resumed.chunks_computed) == (3, 4)
    assert fake.CALLS["sweep"] - before == 4
    run_sweep(scenario, tmp_path / "straight", **args)
    pd.testing.assert_frame_equal(results(tmp_path / "sweep"), results(tmp_path / "straight"), check_exact=True)
    again = run_sweep(scenario, tmp_path / "sweep", **args)
    assert (again.chunks_resumed, again.chunks_computed) == (7, 0)
    with pytest.raises(ScenarioError, match="holds a different sweep"):
        run_sweep(scenario, tmp_path / "sweep", **{**args, "chunk_size": 11})


@pytest.mark.slow
def test_a_killed_dask_worker_loses_no_finished_chunk(scenario, tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    marker = tmp_path / "killed"
    # the worker that gets a chunk with latitude above 35 deg exits at once (os._exit), once;
    # workers are spawned after these are set, so they inherit them
    monkeypatch.setenv(fake.KILL_ABOVE, str(math.radians(35)))
    monkeypatch.setenv(fake.KILL_MARKER, str(marker))
    finished = []
    args = dict(params=GRID, monte_carlo=5, chunk_size=10, progress=False, plots=False)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=50
    ) as cluster:
        summary = run_sweep(scenario, tmp_path / "dask", scheduler=cluster.scheduler_address,
                            on_chunk=finished.append, **args)
    assert marker.exists() and int(marker.read_text()) != os.getpid()  # a worker process died
    assert summary.chunks_computed == summary.chunks == 7
    assert sorted(finished) == list(range(7))  # every chunk stored exactly once
    assert all(chunk_path(tmp_path / "dask", i).exists() for i in range(7))
    monkeypatch.delenv(fake.KILL_ABOVE)
    run_sweep(scenario, tmp_path / "inprocess", **args)
    pd.testing.assert_frame_equal(results(tmp_path / "dask"), results(tmp_path / "inprocess"), check_exact=True)


def test_sweep_command_line(tmp_path, run_cli):
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO)
    out = run_cli("sweep", path, "--param", "latitude=0:60:30", "--monte-carlo", "4", "--out", tmp_path / "o", "--json")
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["cases"] == 12 and data["chunks"] == 1 and data["executor"] == "in-process"
    assert data["statistics"]["settling_time_s"]["count"] == 12
    assert len(pd.read_csv(tmp_path / "o" / "results.csv")) == 12
    text = run_cli("sweep", path, "--param", "latitude=0:60:30", "--monte-carlo", "4", "--out", tmp_path / "o")
    assert text.code == 0 and "1 resumed" in text.stdout
    bad = run_cli("sweep", path, "--param", "latitude=0:95:5", "--out", tmp_path / "p")
    assert bad.code == 2 and bad.stderr.strip() == "schuler: error: --param latitude: 95.0 is outside [-89, 89] deg"
    bad = run_cli("sweep", path, "--fidelity", "rough", "--out", tmp_path / "r")
    assert bad.code == 2 and "--fidelity" in bad.stderr
    bad = run_cli("sweep", path, "--scheduler", "udp:x", "--out", tmp_path / "q")
    assert bad.code == 2 and "--scheduler: 'udp:x' is neither 'local' nor an address" in bad.stderr


def test_a_chunk_size_below_one_is_refused(tmp_path, run_cli):
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO)
    for size in ("0", "-5"):
        out = run_cli("sweep", path, "--chunk-size", size, "--out", tmp_path / "o")
        assert out.code == 2 and out.stderr == f"schuler: error: --chunk-size: {size} must be at least 1\n"
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------ local worker processes
def test_workers_share_the_cores():
    from schuler.study import executors

    assert executors.worker_environment(2, {}) == dict.fromkeys(
        executors.THREAD_VARIABLES, str(max(1, executors.available_cores() // 2)))
    assert "OMP_NUM_THREADS" not in executors.worker_environment(1, {"OMP_NUM_THREADS": "3"})  # the user's stays


def test_worker_processes_get_their_share_of_threads_and_ignore_ctrl_c(monkeypatch):
    import signal

    from schuler.study import executors

    for name in executors.THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("MKL_NUM_THREADS", "3")  # set by the user: kept
    monkeypatch.setattr(executors, "available_cores", lambda: 4)
    pool = executors.LocalProcesses(2)
    try:
        seen = sorted(pool.map(os.getenv, executors.THREAD_VARIABLES))
        handlers = list(pool.map(signal.getsignal, [signal.SIGINT] * 2))
    finally:
        pool.close()
    assert seen == ["2", "2", "2", "3"]  # 4 cores shared by 2 workers; MKL as the user set it
    assert handlers == [signal.SIG_IGN] * 2
    assert not {"OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "NUMBA_NUM_THREADS"} & set(os.environ)  # restored


STOP_SECONDS = 5.0
"""An interrupted sweep with worker processes ends within this, s (measured: 1.3-1.8 s on a loaded 2-core machine)."""


@pytest.mark.slow
@pytest.mark.parametrize(("signal_name", "to_group", "code", "said"),
                         [("SIGINT", True, 130, "interrupted"), ("SIGTERM", False, 143, "terminated (SIGTERM)")],
                         ids=["ctrl-c", "sigterm"])
def test_a_sweep_with_workers_stops_at_once_and_keeps_its_chunks(tmp_path, signal_name, to_group, code, said):
    import re
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "align_gyrocompassing.toml"
    out_dir = tmp_path / "sweep"
    command = [sys.executable, "-m", "schuler", "sweep", str(example), "--param", "latitude=0:80:1",
               "--monte-carlo", "2000", "--chunk-size", "1000", "--workers", "2", "--out", str(out_dir),
               "--no-progress"]
    # as a user runs it: no thread settings in the environment
    env = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                               start_new_session=True)
    try:
        deadline = time.monotonic() + 180
        while not list(out_dir.glob("chunks/chunk-*.parquet")) and time.monotonic() < deadline:
            assert process.poll() is None, process.communicate()
            time.sleep(0.1)
        sent = time.monotonic()
        # Ctrl-C at a terminal reaches the whole process group, workers included
        number = getattr(signal, signal_name)
        os.killpg(process.pid, number) if to_group else process.send_signal(number)
        _, stderr = process.communicate(timeout=60)
        took = time.monotonic() - sent
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.communicate()
    assert took < STOP_SECONDS, took
    assert process.returncode == code and "Traceback" not in stderr, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    kept = re.fullmatch(rf"schuler: error: {re.escape(said)}; partial files were removed; (\d+) of 162 chunks are "
                        rf"kept in {re.escape(str(out_dir))}, from which the same command resumes", lines[0])
    assert kept, lines[0]
    assert len(list(out_dir.glob("chunks/chunk-*.parquet"))) == int(kept.group(1)) >= 1
    assert not list(out_dir.rglob("*.part"))
