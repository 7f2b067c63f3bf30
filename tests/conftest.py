"""Shared fixtures: run the CLI in-process and capture its output."""

from __future__ import annotations

import json
from dataclasses import dataclass

import matplotlib
import pytest

matplotlib.use("Agg")


@dataclass
class CliOutcome:
    code: int
    stdout: str
    stderr: str

    def json(self):
        return json.loads(self.stdout)


@pytest.fixture
def run_cli(capsys):
    """Call ``schuler ARGS...`` in-process: returns exit code, stdout and stderr."""
    from schuler.cli import main

    def invoke(*args: str) -> CliOutcome:
        capsys.readouterr()
        try:
            main([str(a) for a in args])
            code = 0
        except SystemExit as exit_:
            code = exit_.code if isinstance(exit_.code, int) else 1
        captured = capsys.readouterr()
        return CliOutcome(code, captured.out, captured.err)

    return invoke
