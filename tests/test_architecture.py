"""Meta-tests that keep the layering honest (the contract itself: test_contract.py; cycles: test_import_cycles.py)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import schuler
from schuler.registry import SYSTEM_MODULES, get_system

PACKAGE = Path(schuler.__file__).parent
BOUNDARY_LIBRARIES = {"pint", "click", "rich", "matplotlib", "pydantic", "pandas"}


def imported_modules(path: Path, top_level_only: bool = False) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = set()
    for node in tree.body if top_level_only else ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module.split(".")[0])
            if node.module.startswith("schuler."):
                names.add(node.module)
    return names


@pytest.mark.parametrize("path", sorted((PACKAGE / "core").glob("*.py")), ids=lambda p: p.name)
def test_core_is_pure_numerics(path):
    """The core works on SI floats and arrays: no units library, CLI, printing or plotting.

    The one allowance: result types may offer ``plot()`` and ``to_dataframe()``,
    importing matplotlib or pandas inside those methods only.
    """
    imports = imported_modules(path)
    forbidden = BOUNDARY_LIBRARIES - {"matplotlib", "pandas"}
    assert not imports & forbidden, f"{path.name} imports {imports & forbidden}"
    top_level = imported_modules(path, top_level_only=True)
    assert not top_level & BOUNDARY_LIBRARIES, f"{path.name} imports {top_level & BOUNDARY_LIBRARIES} at module level"
    allowed = ("schuler.core", "schuler.exceptions")
    assert not {m for m in imports if m.startswith("schuler.") and not m.startswith(allowed)}


@pytest.mark.parametrize("name", list(SYSTEM_MODULES))
def test_run_options_are_the_system_parameters(name, run_cli):
    out = run_cli(name, "run", "--help")
    assert out.code == 0
    for parameter in get_system(name).parameters:
        assert parameter.option in out.stdout


def test_no_module_is_longer_than_600_lines():
    long = {str(p.relative_to(PACKAGE)): n for p in PACKAGE.rglob("*.py")
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > 600}
    assert not long, f"split these along a seam: {long}"


def test_ci_runs_every_test():
    """CI runs the README's test command, then the tests it leaves out (marked slow), then the docs build."""
    root = Path(__file__).resolve().parents[1]
    commands = [line.strip() for line in (root / ".ci" / "run").read_text(encoding="utf-8").splitlines()
                if line.strip().startswith("make ")]
    assert commands == ["make test", "make test-slow", "make docs"]
    makefile = (root / "Makefile").read_text(encoding="utf-8")
    # the slow ones in two runs: beside each other, then those timed with the machine to themselves
    assert '$(PYTEST) -m "not slow"' in makefile and '$(PYTEST) -m "slow and not alone"' in makefile
    assert "$(PYTEST_ONE) -p no:xdist -m alone" in makefile
