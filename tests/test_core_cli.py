"""The CLI's grammar and its one-line errors."""

from __future__ import annotations

import os
import subprocess
import sys

import click
import pytest

from schuler import __version__
from schuler.exceptions import InvalidParameter


def test_version_and_help(run_cli):
    out = run_cli("--version")
    assert out.code == 0 and __version__ in out.stdout
    out = run_cli("--help")
    assert out.code == 0
    for system in ("errors", "vertical", "calibrate", "align", "north", "run", "sweep", "report"):
        assert system in out.stdout


def test_unknown_command_is_one_line_exit_2(run_cli):
    out = run_cli("nosuch")
    assert out.code == 2
    assert out.stderr.strip().count("\n") == 0 and "No such command" in out.stderr


def test_unknown_option_is_one_line_exit_2(run_cli):
    out = run_cli("--bogus")
    assert out.code == 2 and out.stderr.startswith("schuler: error:") and "--bogus" in out.stderr


@pytest.fixture
def failing_command(monkeypatch):
    """Register a throwaway command that raises a library error."""
    import schuler.cli as cli_module

    @click.command()
    def fail():
        raise InvalidParameter("--latitude", "'95 deg' is outside [-90, 90] deg")

    sys.modules[__name__].fail = fail
    monkeypatch.setitem(cli_module.COMMANDS, "fail", (f"{__name__}:fail", "fails"))


def test_library_errors_become_one_line(run_cli, failing_command):
    out = run_cli("fail")
    assert out.code == 2
    assert out.stderr == "schuler: error: --latitude: '95 deg' is outside [-90, 90] deg\n"
    assert out.stdout == ""


def test_module_entry_point_runs():
    done = subprocess.run([sys.executable, "-m", "schuler", "--version"], capture_output=True, text=True, check=True)
    assert __version__ in done.stdout


def test_emit_uses_120_columns_when_stdout_is_not_a_terminal(capsys):
    from dataclasses import dataclass

    from schuler.cli.common import emit
    from schuler.results import Result

    @dataclass
    class Wide(Result):
        text: str

        def render(self):
            return self.text

    line = " ".join(["word"] * 23)  # 114 characters: rich's default 80 would wrap it
    emit(Wide(line), as_json=False)
    assert capsys.readouterr().out == line + "\n"
    emit(Wide(line + " overflow"), as_json=False)
    assert [row.rstrip() for row in capsys.readouterr().out.splitlines()] == [line, "overflow"]  # wraps at 120


def test_unwritable_output_folder_is_one_line(run_cli, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    out = run_cli("errors", "run", "--out", blocker / "figures")
    assert out.code == 2
    assert out.stderr.startswith("schuler: error: ") and out.stderr.count("\n") == 1


def test_the_command_runs_blas_on_one_thread_unless_told_otherwise():
    import subprocess
    import sys

    code = "import os, schuler.cli, numpy; print(os.environ['OPENBLAS_NUM_THREADS'])"
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    assert subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True).stdout.strip() == "1"
    env["OPENBLAS_NUM_THREADS"] = "2"
    assert subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True).stdout.strip() == "2"
