"""What a careless user or a hostile file system does: modes, links, FIFOs, signals, stale partial files."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from schuler.io import atomic_path, remove_stale_parts, write_text

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture
def umask_022():
    previous = os.umask(0o022)
    yield
    os.umask(previous)


def test_new_files_get_the_mode_open_would_give(tmp_path, umask_022):
    path = write_text(tmp_path / "a.txt", "x")
    assert stat.S_IMODE(path.stat().st_mode) == 0o644
    os.umask(0o077)
    assert stat.S_IMODE(write_text(tmp_path / "b.txt", "x").stat().st_mode) == 0o600


def test_a_replaced_file_keeps_its_mode(tmp_path, umask_022):
    path = tmp_path / "kept.txt"
    path.write_text("old")
    path.chmod(0o664)
    write_text(path, "new")
    assert path.read_text() == "new" and stat.S_IMODE(path.stat().st_mode) == 0o664


def test_cli_output_files_are_world_readable(tmp_path, umask_022, run_cli):
    out = run_cli("align", "reproduce", "--out", tmp_path)
    assert out.code == 0, out.stderr
    files = list(tmp_path.iterdir())
    assert files and all(stat.S_IMODE(f.stat().st_mode) == 0o644 for f in files)


def test_a_symlink_is_followed_not_replaced(tmp_path):
    real = tmp_path / "data" / "real.csv"
    real.parent.mkdir()
    real.write_text("old")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    write_text(link, "new")
    assert link.is_symlink() and real.read_text() == "new"
    assert not list(tmp_path.rglob("*.part"))


def test_a_fifo_is_written_in_place(tmp_path):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()))
    reader.start()
    write_text(fifo, "through the pipe")
    reader.join(timeout=10)
    assert received == ["through the pipe"] and stat.S_ISFIFO(fifo.stat().st_mode)


def test_a_character_device_is_written_in_place():
    # /dev/null must stay the device even when the writer runs as root
    write_text(Path("/dev/null"), "discarded")
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_a_dash_writes_to_standard_output():
    script = "from schuler.io import write_text; write_text('-', 'to stdout')"
    completed = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert completed.stdout == "to stdout"


def test_errors_name_the_users_path_not_the_temporary_file(tmp_path, run_cli):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        if os.access(locked, os.W_OK):
            pytest.skip("running with permissions that ignore the folder's mode")
        with pytest.raises(OSError) as caught:
            with atomic_path(locked / "x.csv") as tmp:
                tmp.write_text("x")
        assert caught.value.filename == str(locked / "x.csv")
        out = run_cli("align", "reproduce", "--out", locked)
        assert out.code == 2 and ".part" not in out.stderr and str(locked) in out.stderr
    finally:
        locked.chmod(0o700)


@pytest.mark.skipif(not Path("/proc/self").exists(), reason="needs Linux's /proc, where nobody can create files")
def test_an_unwritable_place_is_named_as_given(run_cli):
    with pytest.raises(OSError) as caught:
        write_text("/proc/x.csv", "x")
    assert caught.value.filename == "/proc/x.csv"
    out = run_cli("align", "reproduce", "--out", "/proc/schuler-report")
    assert out.code == 2 and ".part" not in out.stderr and "/proc/schuler-report" in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


def test_stale_partial_files_are_removed(tmp_path):
    (tmp_path / "chunks").mkdir()
    stale = [tmp_path / ".results.csv.abc123.part", tmp_path / "chunks" / ".chunk-000001.parquet.x.part"]
    for path in stale:
        path.write_bytes(b"half")
    keep = tmp_path / "results.csv"
    keep.write_text("kept")
    assert sorted(remove_stale_parts(tmp_path)) == sorted(stale)
    assert keep.exists() and not any(p.exists() for p in stale)


def test_sigterm_ends_a_sweep_cleanly(tmp_path):
    out_dir = tmp_path / "sweep"
    command = [sys.executable, "-m", "schuler", "sweep", str(EXAMPLES / "align_gyrocompassing.toml"),
               "--param", "latitude=0:60:0.01", "--chunk-size", "500", "--out", str(out_dir), "--no-progress"]
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True)
    deadline = time.monotonic() + 120
    while not list(out_dir.glob("chunks/chunk-*.parquet")) and time.monotonic() < deadline:
        time.sleep(0.2)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 128 + signal.SIGTERM
    assert stderr.strip().splitlines()[-1].startswith("schuler: error: terminated (SIGTERM); partial files were")
    assert "Traceback" not in stderr
    assert not list(out_dir.rglob("*.part"))


@pytest.mark.parametrize(
    "command", [["align", "run"], ["report"], ["sweep", str(EXAMPLES / "align_gyrocompassing.toml")]]
)
def test_an_output_folder_named_like_an_option_is_refused(run_cli, tmp_path, command, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = run_cli(*command, "--out", "--help")
    assert result.code == 2 and "looks like an option" in result.stderr
    assert not (tmp_path / "--help").exists()
