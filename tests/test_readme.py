"""The README's Python tour runs as written."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_has_a_python_tour():
    assert python_blocks()


@pytest.mark.parametrize("index", range(len(python_blocks())))
def test_readme_python_block_runs(index, capsys):
    exec(compile(python_blocks()[index], f"README.md block {index}", "exec"), {})
    printed = capsys.readouterr().out.split()
    assert float(printed[0]) == pytest.approx(2 * 1e-4 * 6_371_000.0, rel=1e-6)  # 2 k R, m
    assert float(printed[1]) == pytest.approx(3.556, abs=5e-4)  # arcmin


def tour_commands() -> list[str]:
    blocks = re.findall(r"```sh\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)
    lines = [line.split("  #")[0].strip() for block in blocks for line in block.splitlines()]
    return [line for line in lines if line.startswith(".venv/bin/schuler ")]


QUICK_TOUR = [pytest.param(c, marks=pytest.mark.slow) if "reproduce --out" in c or "--monte-carlo" in c else c
              for c in tour_commands() if " report " not in c + " " and " sweep " not in c]


def test_readme_study_commands_name_existing_options(run_cli):
    # the sweep and report lines are run by the study tests; here their options must exist
    for command in tour_commands():
        words = shlex.split(command)[1:]
        if words[0] in ("sweep", "report"):
            help_text = run_cli(words[0], "--help").stdout
            assert all(w in help_text for w in words if w.startswith("--")), command


@pytest.mark.parametrize("command", QUICK_TOUR)
def test_readme_tour_runs(command, run_cli, tmp_path):
    words = [w.replace("results/", f"{tmp_path}/") for w in shlex.split(command)[1:]]
    out = run_cli(*words)
    assert out.code == 0, (command, out.stderr)
