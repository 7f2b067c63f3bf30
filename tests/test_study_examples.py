"""Every example scenario runs, through ``schuler run`` and through a small sweep, and every command its
comments advertise runs as written within the time they state."""

from __future__ import annotations

import json
import re
import shlex
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest

from schuler.registry import SYSTEM_MODULES
from schuler.study.scenario import load_scenario
from schuler.study.systems import load_system

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FILES = sorted(EXAMPLES.glob("*.toml"))


@dataclass(frozen=True)
class CommentCommand:
    """A command written in an example's header comment, with the time the comment promises."""

    file: str
    text: str
    arguments: list[str]
    seconds: float | None


_STATED_TIME = re.compile(r"under (\d+(?:\.\d+)?) (s|min)\b")


def comment_commands(files=FILES) -> list[CommentCommand]:
    """Every ``schuler ...`` line of the examples' comments (continuations joined), its stated time in s."""
    commands = []
    for path in files:
        lines = [line.removeprefix("#").strip() for line in path.read_text().splitlines() if line.startswith("#")]
        joined: list[str] = []
        for line in lines:
            if joined and joined[-1].endswith("\\"):
                joined[-1] = joined[-1][:-1].rstrip() + " " + line
            else:
                joined.append(line)
        for line in joined:
            if not line.startswith("schuler "):
                continue
            text, _, note = line.partition("  (")
            stated = _STATED_TIME.search(note)
            seconds = None if stated is None else float(stated[1]) * (60.0 if stated[2] == "min" else 1.0)
            commands.append(CommentCommand(path.name, text.strip(), shlex.split(text)[1:], seconds))
    return commands


COMMANDS = comment_commands()
FAST_COMMAND = 30.0
"""Stated time (s) above which a comment's command runs with the slow tests."""


def system_of(path: Path) -> str:
    return tomllib.loads(path.read_text())["system"]


def require_system(path: Path):
    name = system_of(path)
    system = load_system(name)
    if system is None:
        pytest.skip(f"system {name!r} is not installed yet")
    return system


def test_there_is_an_example_per_system():
    names = {system_of(path) for path in FILES}
    assert names <= set(SYSTEM_MODULES)
    for path in FILES:
        assert system_of(path) in path.name  # file names contain the system name
    missing = [name for name in SYSTEM_MODULES if load_system(name) is not None and name not in names]
    assert missing == []


@pytest.mark.slow
@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_example_runs_like_the_system_command(path, run_cli, tmp_path):
    require_system(path)
    out = run_cli("run", path, "--json", "--out", tmp_path / "out")
    assert out.code == 0, out.stderr
    data = out.json()
    scenario = load_scenario(path)
    result = scenario.definition().run(fidelity=scenario.fidelity, **scenario.given())
    expected = json.loads(json.dumps(result.to_dict()))
    scalars = {k: v for k, v in expected.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    assert scalars, "the result has no scalar to compare"
    assert {k: data[k] for k in scalars} == pytest.approx(scalars, rel=1e-9)
    table = scenario.monte_carlo
    if table is not None and table.cases:  # the scenario's members: its distributions drawn per member
        assert data["monte_carlo"]["members"] == table.cases
    assert any((tmp_path / "out").iterdir())  # --out reaches the system's command


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_example_sweeps_with_its_monte_carlo_table(path, tmp_path):
    from schuler.study.sweep import run_sweep

    system = require_system(path)
    scenario = load_scenario(path)
    assert scenario.monte_carlo is not None
    # an aided mission draws no scenario value per member (its covariance and Monte Carlo describe one case)
    draws = 3 if scenario.monte_carlo.distributions else None
    assert draws or tomllib.loads(path.read_text())["parameters"].get("aiding")
    summary = run_sweep(scenario, tmp_path, (), monte_carlo=draws, progress=False, plots=False)
    frame = pd.read_parquet(tmp_path / "results.parquet")
    assert summary.cases == len(frame) == (draws or 1)
    assert len(frame.columns) > len(system.parameters) + 1  # parameters, case number and results
    assert summary.statistics and all(s["count"] + s["nan_count"] == (draws or 1) for s in summary.statistics.values())


def test_an_unregistered_system_name_is_refused_with_the_registered_names():
    from schuler.exceptions import InvalidParameter

    with pytest.raises(InvalidParameter, match=r"^system: 'allign' is not a system; did you mean 'align'\? "
                                               r"choose from errors, vertical, calibrate, align, north"):
        load_system("allign")
    with pytest.raises(InvalidParameter, match=r"'compass' is not a system; choose from errors, vertical"):
        load_system("compass")


def test_every_comment_command_states_its_time():
    assert len(COMMANDS) >= 2 * len(FILES)
    assert [c.text for c in COMMANDS if c.seconds is None] == []


def _marks(command: CommentCommand) -> list:
    """Slow above :data:`FAST_COMMAND`; timed alone when it spreads over the machine's cores (``--workers``),
    since beside other tests its processes share two cores with them (373 s for a 115-s command)."""
    if "--workers" in command.arguments:
        return [pytest.mark.slow, pytest.mark.alone]
    return [pytest.mark.slow] if command.seconds is None or command.seconds > FAST_COMMAND else []


@pytest.mark.parametrize("command", [
    pytest.param(c, id=f"{c.file}:{' '.join(c.arguments[:3])}:{i}", marks=_marks(c))
    for i, c in enumerate(COMMANDS)])
def test_a_comment_command_runs_as_written_within_its_stated_time(command, run_cli, tmp_path, monkeypatch):
    # as a user types it, from a folder holding the examples: relative paths resolve, --out folders land here
    (tmp_path / "examples").symlink_to(EXAMPLES)
    monkeypatch.chdir(tmp_path)
    started = time.perf_counter()
    out = run_cli(*command.arguments)
    elapsed = time.perf_counter() - started
    assert out.code == 0, out.stderr
    assert command.seconds is not None and elapsed <= command.seconds, f"{elapsed:.1f} s"
    if "--json" in command.arguments:
        json.loads(out.stdout)
    if "--out" in command.arguments:
        assert any((tmp_path / command.arguments[command.arguments.index("--out") + 1]).iterdir())
