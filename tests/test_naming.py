"""Naming rules of ``docs/conventions.md`` held over the whole package (one name per thing)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from collections import defaultdict
from pathlib import Path

import pytest
from click.testing import CliRunner

import schuler
from schuler.cli import cli
from schuler.registry import SYSTEM_MODULES, get_system

PACKAGE = Path(schuler.__file__).parent
MODULES = sorted(info.name for info in pkgutil.walk_packages(schuler.__path__, "schuler."))
NUMBERED = re.compile(r"\b[Ss]ystems? [1-9]\b|\b[Ii]ssue [0-9]+")
"""The project's internal numbering: users know systems by name and never see our issue tracker."""


def defined_twice(namespaces) -> dict[str, list[str]]:
    """Public class names defined in more than one of ``namespaces`` ((module name, namespace) pairs)."""
    owners = defaultdict(list)
    for module, namespace in namespaces:
        for name, value in namespace.items():
            if inspect.isclass(value) and value.__module__ == module and not name.startswith("_"):
                owners[name].append(module)
    return {name: places for name, places in owners.items() if len(places) > 1}


def test_every_public_class_is_defined_once():
    assert len(MODULES) > 100
    assert not defined_twice((name, vars(importlib.import_module(name))) for name in MODULES)


def test_the_rule_finds_a_class_defined_twice():
    made = {module: {"SensorErrors": type("SensorErrors", (), {"__module__": module})} for module in ("a", "b")}
    assert defined_twice(made.items()) == {"SensorErrors": ["a", "b"]}


def test_no_system_or_issue_numbers_in_the_package_text():
    found = []
    for path in sorted(PACKAGE.rglob("*")):
        if path.suffix not in (".py", ".toml", ".html", ".js", ".css", ".md") or "__pycache__" in path.parts:
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if NUMBERED.search(line):
                found.append(f"{path.relative_to(PACKAGE)}:{number}: {line.strip()}")
    assert not found, "\n".join(found)
    assert NUMBERED.search("the ground gyrocompass (system 5)") and NUMBERED.search("issue 18: shares")


@pytest.mark.parametrize("name", sorted(SYSTEM_MODULES))
def test_no_system_or_issue_numbers_in_the_help(name):
    system = get_system(name)
    commands = ["run", "reproduce", *(action.name for action in system.actions)]
    runner = CliRunner()
    for command in commands:
        out = runner.invoke(cli, [name, command, "--help"])
        assert out.exit_code == 0, out.output
        assert not NUMBERED.search(out.output), (command, NUMBERED.search(out.output))
