"""No import cycles in the package, counting every import statement wherever it sits.

An import inside a function or under ``if TYPE_CHECKING:`` hides a cycle from the
interpreter but not from the design: the two modules still depend on each other.
So the graph here has an edge for every ``import`` and ``from ... import``
anywhere in a module's syntax tree (relative ones resolved), and the test fails
on any strongly connected component of more than one module, or a module
importing itself. ``from package import name`` is an edge to the submodule
``package.name`` when there is one, else to ``package`` (its ``__init__``). The
implicit import of parent packages (``import a.b`` runs ``a/__init__`` first)
makes no edge, as in import-linter: a package's ``__init__`` re-exporting its
modules is not a cycle. Imports by a string at run time (``importlib``) are not
statements and make no edge.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import schuler

PACKAGE = Path(schuler.__file__).parent


def module_files(package_dir: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` under ``package_dir`` (a package)."""
    modules = {}
    for path in sorted(package_dir.rglob("*.py")):
        parts = list(path.relative_to(package_dir.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        modules[".".join(parts)] = path
    return modules


def imported_names(module: str, path: Path) -> list[tuple[str, list[str], int]]:
    """(imported module, names taken from it, line) for every import statement in ``path``."""
    is_package = path.name == "__init__.py"
    package = module if is_package else module.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            found.extend((alias.name, [], node.lineno) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                if node.level > 1:
                    base = base[: -(node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            found.append((target, [alias.name for alias in node.names], node.lineno))
    return found


def import_graph(package_dir: Path) -> dict[str, dict[str, int]]:
    """module -> {module it imports: line of the (first) import}, inside the package only."""
    modules = module_files(package_dir)
    graph: dict[str, dict[str, int]] = {name: {} for name in modules}
    for module, path in modules.items():
        for target, names, line in imported_names(module, path):
            targets = [f"{target}.{name}" for name in names if f"{target}.{name}" in modules]
            if len(targets) < len(names) or not names:  # a name from the package itself, or ``import a.b``
                targets.append(target)
            for imported in targets:
                if imported in modules:
                    graph[module].setdefault(imported, line)
    return graph


def strongly_connected(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """Tarjan's strongly connected components of more than one module, or with a self-import (iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(graph[root]))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, successors = work[-1]
            for successor in successors:
                if successor not in index:
                    index[successor] = low[successor] = len(index)
                    stack.append(successor)
                    on_stack.add(successor)
                    work.append((successor, iter(graph[successor])))
                    break
                if successor in on_stack:
                    low[node] = min(low[node], index[successor])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1 or node in graph[node]:
                        components.append(sorted(component))
    return sorted(components)


def describe(component: list[str], graph: dict[str, dict[str, int]], package_dir: Path) -> str:
    """The imports that tie a component together, one per line with file and line number."""
    modules = module_files(package_dir)
    members = set(component)
    lines = [f"cycle among {', '.join(component)}:"]
    for module in component:
        for imported, line in sorted(graph[module].items()):
            if imported in members:
                lines.append(f"  {modules[module].relative_to(package_dir.parent)}:{line} imports {imported}")
    return "\n".join(lines)


def test_no_import_cycles():
    graph = import_graph(PACKAGE)
    cycles = strongly_connected(graph)
    assert not cycles, "\n".join(describe(component, graph, PACKAGE) for component in cycles)


def _write(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root / "pkg"


def test_detector_sees_every_kind_of_import(tmp_path):
    package = _write(tmp_path, {
        "pkg/__init__.py": "from pkg.clean import value\n",
        # a cycle through a function-level import
        "pkg/a.py": "import pkg.b\n",
        "pkg/b.py": "def late():\n    from pkg import a\n    return a\n",
        # a cycle through TYPE_CHECKING
        "pkg/c.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.d import D\n",
        "pkg/d.py": "from pkg.c import something\n",
        # relative imports, one and two levels up, through a subpackage
        "pkg/sub/__init__.py": "",
        "pkg/sub/e.py": "from . import f\n",
        "pkg/sub/f.py": "from ..g import x\n",
        "pkg/g.py": "from .sub.e import y\n",
        # a self-import and a plain chain without a cycle
        "pkg/selfish.py": "import pkg.selfish\n",
        "pkg/clean.py": "import os\nfrom pkg import leaf\nvalue = 1\n",
        "pkg/leaf.py": "import numpy\n",
    })
    cycles = strongly_connected(import_graph(package))
    assert cycles == [
        ["pkg.a", "pkg.b"],
        ["pkg.c", "pkg.d"],
        ["pkg.g", "pkg.sub.e", "pkg.sub.f"],
        ["pkg.selfish"],
    ]


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("from pkg import clean", {"pkg.clean"}),  # a submodule by name
        ("from pkg import value", {"pkg"}),  # a name from the package's __init__
        ("import pkg.clean as c", {"pkg.clean"}),
        ("from .clean import value", {"pkg.clean"}),
        ("from . import clean, value", {"pkg.clean", "pkg"}),
    ],
)
def test_edges(tmp_path, source, expected):
    package = _write(tmp_path, {"pkg/__init__.py": "value = 1\n", "pkg/clean.py": "", "pkg/user.py": source + "\n"})
    assert set(import_graph(package)["pkg.user"]) == expected
