"""The command line under careless input: every command and option, fuzzed.

Each example runs one command in-process with one option set to something a
careless user might type (numbers, NaN, inf, negatives, huge values, units of
the wrong dimension, garbage, an empty or binary file). Whatever it is, the run
ends with exit code 0 or 2, prints no traceback, stays within a time limit and
a small memory budget, and leaves no partial file behind.
"""

from __future__ import annotations

import signal
from contextlib import contextmanager

import click
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from schuler.cli import cli
from schuler.registry import SYSTEM_MODULES

SECONDS = 60
"""Longest a fuzzed command may run (a careless value must be refused, not computed for hours)."""

BUDGET = "512 MiB"
"""Memory budget of the fuzzed commands (``SCHULER_MEMORY_BUDGET``): big requests must be refused."""

QUICK = {
    "errors": ["--duration", "600"],
    "vertical": ["--duration", "600"],
    "align": ["--duration", "600"],
    "north": ["--duration", "600"],
    "calibrate": [],
    "imu": ["--duration", "120"],
    "navigate": ["--duration", "600", "--imu-rate", "10", "--output-step", "60"],
    "mission": ["--duration", "1200", "--output-step", "600"],
    "aided": ["--duration", "300", "--imu-rate", "20", "--outage-start", "120"],
}
"""Options that keep each system's base case short; the fuzzed option comes after them."""

QUICK_ACTIONS = {
    ("align", "compare"): ["--imu", "tactical", "--duration", "60"],
    ("north", "compare"): ["--monte-carlo", "4"],
    ("calibrate", "compare"): ["--monte-carlo", "2"],
}
"""The same for system actions whose defaults take long (Monte Carlo members of simulated records)."""

CARELESS = st.one_of(
    st.sampled_from(["nan", "NaN", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e9", "1e-300", "", " ",
                     "abc", "1,5", "12 parsecs", "5 kg", "0.01 Hz", "95 percent", "1e4 g", "-0", "0x10",
                     "1e9 s", "1e-9 s", "3 deg/h", "[1, 2]", "None", "true", "()", "f()", "10**10**10",
                     "10**400 deg", "1e400", "9" * 500]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(min_value=-10**12, max_value=10**12).map(str),
)


def _commands():
    """(system, command, option) for every option of every system command."""
    found = []
    group = cli
    with click.Context(group) as ctx:
        for name in SYSTEM_MODULES:
            try:
                system_group = group.get_command(ctx, name)
            except ImportError:
                continue
            for command_name, command in system_group.commands.items():
                for param in command.params:
                    if isinstance(param, click.Option) and param.name not in ("as_json", "out_dir", "help"):
                        if not param.is_flag and not param.hidden:
                            found.append((name, command_name, param.opts[0]))
    return found


COMMANDS = _commands()


@contextmanager
def time_limit(seconds: int):
    def expire(signum, frame):
        raise TimeoutError(f"took longer than {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


@pytest.fixture
def budget(monkeypatch):
    from schuler import memory

    monkeypatch.setenv(memory.ENVIRONMENT, BUDGET)
    memory._budget_from_environment.cache_clear()
    yield
    memory._budget_from_environment.cache_clear()


def run_careless(run_cli, system: str, command: str, option: str, value: str, workdir) -> None:
    """Run one command with one careless option value; check exit code, stderr and leftovers."""
    args = [system, command]
    if command == "run":
        args += QUICK[system]
    args += QUICK_ACTIONS.get((system, command), [])
    if command in ("identify", "info", "allan"):
        record = workdir / "record.csv"
        record.write_bytes(b"\x00\x01binary\xff\xfe")
        args.append(record)
    if option in ("--output", "-o"):
        args += [option, workdir / value.strip().replace("/", "_") if value.strip() else workdir / "x.csv"]
    else:
        args += [option, value]
    args += ["--out", workdir / "out"]
    with time_limit(SECONDS):
        out = run_cli(*args)
    assert out.code in (0, 2), (args, out.code, out.stderr[-500:])
    assert "Traceback" not in out.stderr, (args, out.stderr[-2000:])
    if out.code == 2:
        assert out.stderr.startswith("schuler: error:") and len(out.stderr.strip().splitlines()) == 1, out.stderr
    assert not list(workdir.rglob("*.part")), "a partial file was left behind"


COMMAND_NAMES = sorted({(system, command) for system, command, _ in COMMANDS})


@pytest.mark.parametrize(("system", "command"), COMMAND_NAMES, ids=lambda x: str(x))
@settings(max_examples=6, deadline=None, phases=[Phase.generate], derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_every_command_under_careless_input(system, command, data, run_cli, budget, tmp_path_factory):
    options = [option for s, c, option in COMMANDS if (s, c) == (system, command)]
    option = data.draw(st.sampled_from(options), label="option")
    value = data.draw(CARELESS, label="value")
    run_careless(run_cli, system, command, option, value, tmp_path_factory.mktemp("fuzz"))


@pytest.mark.slow
@pytest.mark.parametrize(("system", "command", "option"), COMMANDS, ids=lambda x: str(x))
@settings(max_examples=4, deadline=None, phases=[Phase.generate], derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(value=CARELESS)
def test_every_option_under_careless_input(system, command, option, value, run_cli, budget, tmp_path_factory):
    run_careless(run_cli, system, command, option, value, tmp_path_factory.mktemp("fuzz"))
