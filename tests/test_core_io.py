"""Atomic output: a failure while writing leaves neither a partial file nor debris; a run's files come as a set."""

from __future__ import annotations

import json
import os
import signal
import stat
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

from schuler.core.lti import StateSpace, simulate
from schuler.io import (
    FILE_SET_RECORD,
    atomic_path,
    remove_stale_parts,
    save_figure_formats,
    signals_deferred,
    write_dataframe_csv,
    write_file_set,
    write_json,
    write_text,
)


def test_failed_write_leaves_no_file(tmp_path):
    target = tmp_path / "result.json"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text('{"half": ')
            raise RuntimeError("crash mid-write")
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []


def test_failed_write_keeps_the_previous_file(tmp_path):
    target = write_json(tmp_path / "result.json", {"run": 1})
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("garbage")
            raise RuntimeError("crash")
    assert target.read_text() == '{\n  "run": 1\n}\n'


def test_figures_in_two_formats(tmp_path):
    t = np.linspace(0, 100, 11)
    response = simulate(StateSpace([[0.0, 1.0], [-0.01, 0.0]], states=("x", "v")), t, initial_state=[1.0, 0.0])
    fig = response.plot()
    assert [ax.get_ylabel() for ax in fig.axes] == ["x", "v"]
    paths = save_figure_formats(fig, tmp_path / "oscillator")
    assert [p.name for p in paths] == ["oscillator.png", "oscillator.svg"]
    assert paths[0].read_bytes()[:4] == b"\x89PNG" and b"<svg" in paths[1].read_bytes()[:500]
    assert fig.number not in plt.get_fignums()  # closed after saving


# ------------------------------------------------------------------ a run's set of files
def _writer(contents: dict[str, str], fail_after: int | None = None):
    """A ``write(folder)`` writing ``contents`` (name -> text), interrupted after ``fail_after`` files."""

    def write(folder: Path) -> list[Path]:
        paths = []
        for count, (name, text) in enumerate(contents.items()):
            if count == fail_after:
                raise KeyboardInterrupt
            paths.append(write_text(folder / name, text))
        return paths

    return write


def test_an_interrupted_file_set_leaves_nothing_behind(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        write_file_set(tmp_path / "new", _writer({"a.csv": "1", "b.png": "2", "c.svg": "3"}, fail_after=2), "x run")
    assert not (tmp_path / "new").exists()  # the folder it created is gone again
    old = tmp_path / "old"
    write_file_set(old, _writer({"a.csv": "old a", "b.png": "old b"}), "x run")
    before = {path.name: path.read_text() for path in old.iterdir()}
    with pytest.raises(KeyboardInterrupt):
        write_file_set(old, _writer({"a.csv": "new a", "b.png": "new b", "c.svg": "new c"}, fail_after=2), "x run")
    assert {path.name: path.read_text() for path in old.iterdir()} == before  # the previous set, untouched


def test_a_file_set_replaces_the_previous_set_of_the_same_command_only(tmp_path):
    out = tmp_path / "out"
    write_file_set(out, _writer({"x_history.csv": "1", "x_monte_carlo.png": "1", "x_monte_carlo.svg": "1"}), "x run")
    write_file_set(out, _writer({"x_reproduction.csv": "r"}), "x reproduce")
    (out / "notes.txt").write_text("mine")
    paths = write_file_set(out, _writer({"x_history.csv": "2"}), "x run")
    assert paths == [out / "x_history.csv"]
    assert sorted(path.name for path in out.iterdir() if not path.name.startswith(".")) == [
        "notes.txt", "x_history.csv", "x_reproduction.csv"]  # the old figures went with their run
    assert (out / "x_history.csv").read_text() == "2" and (out / "notes.txt").read_text() == "mine"
    assert json.loads((out / FILE_SET_RECORD).read_text()) == {"x run": ["x_history.csv"],
                                                               "x reproduce": ["x_reproduction.csv"]}


def test_a_file_set_follows_links_and_keeps_modes(tmp_path):
    previous = os.umask(0o022)
    try:
        out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
        out.mkdir()
        elsewhere.mkdir()
        (elsewhere / "real.csv").write_text("old")
        (out / "linked.csv").symlink_to(elsewhere / "real.csv")
        (out / "kept.csv").write_text("old")
        (out / "kept.csv").chmod(0o640)
        write_file_set(out, _writer({"linked.csv": "new", "kept.csv": "new", "fresh.csv": "new"}), "x run")
        assert (out / "linked.csv").is_symlink() and (elsewhere / "real.csv").read_text() == "new"
        assert stat.S_IMODE((out / "kept.csv").stat().st_mode) == 0o640
        assert stat.S_IMODE((out / "fresh.csv").stat().st_mode) == 0o644
        assert not list(tmp_path.rglob("*.part"))
    finally:
        os.umask(previous)


def test_a_staging_folder_left_by_a_killed_run_is_removed(tmp_path):
    staging = tmp_path / ".files.abc.part"
    staging.mkdir()
    (staging / "a.csv").write_text("half")
    (tmp_path / "kept.csv").write_text("kept")
    assert remove_stale_parts(tmp_path) == [staging]
    assert [path.name for path in tmp_path.iterdir()] == ["kept.csv"]


def test_signals_wait_for_the_end_of_the_block():
    finished = []
    with pytest.raises(KeyboardInterrupt):
        with signals_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # the handler runs between bytecodes: it has had its chance here
            finished.append(True)
    assert finished == [True]
    with signals_deferred(deliver=False):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


@pytest.mark.slow
def test_an_align_run_writes_its_files_complete_or_not_at_all(tmp_path, run_cli, monkeypatch):
    from matplotlib.figure import Figure

    out = tmp_path / "out"
    quick = ("--duration", "600 s", "--output-step", "10 s")
    assert run_cli("align", "run", *quick, "--monte-carlo", "5", "--out", out).code == 0
    (out / "notes.txt").write_text("mine")
    before = {path.name: path.read_bytes() for path in out.iterdir()}
    assert {"align_monte_carlo.png", "align_time_history.csv"} <= set(before)
    saved = []
    real_savefig = Figure.savefig

    def interrupted_savefig(self, *args, **kwargs):  # Ctrl-C while the third figure file is written
        if len(saved) == 2:
            raise KeyboardInterrupt
        saved.append(args)
        return real_savefig(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", interrupted_savefig)
    stopped = run_cli("align", "run", *quick, "--latitude", "40 deg", "--out", out)
    assert stopped.code == 130 and "partial files were removed" in stopped.stderr
    assert {path.name: path.read_bytes() for path in out.iterdir()} == before  # not one new file
    monkeypatch.setattr(Figure, "savefig", real_savefig)
    assert run_cli("align", "run", *quick, "--out", out).code == 0
    names = {path.name for path in out.iterdir() if not path.name.startswith(".")}
    assert "align_monte_carlo.png" not in names and {"notes.txt", "align_time_history.csv"} <= names


@pytest.mark.parametrize("numeric", [True, False])
def test_dataframe_csv_reads_back_exactly(tmp_path, numeric):
    """Both writers (Arrow for all-numeric tables, pandas otherwise) give every value back to the bit."""
    import pandas as pd

    rng = np.random.default_rng(7)
    frame = pd.DataFrame({"t_s": rng.normal(size=50) * 1e3, "tiny, m": rng.normal(size=50) * 1e-300,
                          "count": rng.integers(-5, 5, 50), "small": rng.normal(size=50).astype(np.float32)})
    frame.loc[3, "t_s"] = np.nan
    if not numeric:
        frame["label"] = ["a,b"] * 50
    path = write_dataframe_csv(frame, tmp_path / "table.csv")
    back = pd.read_csv(path)
    assert list(back.columns) == list(frame.columns)
    assert open(path).readline().startswith('t_s,"tiny, m",count,small')
    for name in ("t_s", "tiny, m", "count"):
        np.testing.assert_array_equal(back[name].to_numpy(), frame[name].to_numpy())
    np.testing.assert_array_equal(back["small"].to_numpy(np.float32), frame["small"].to_numpy())
