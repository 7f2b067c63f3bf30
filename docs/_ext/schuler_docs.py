"""Sphinx directives that take the guide's tables and outputs from the package itself.

Nothing the package already knows is written twice: the bibliography comes from
:data:`schuler.references.BIBLIOGRAPHY`, a system's parameter table from its
:class:`~schuler.params.ParameterSet`, the reproduction of a source from
``SYSTEM.reproduce()``, the command-line outputs from running the commands at
build time (a command that fails fails the build), and ``api/index.rst`` from
the package's modules (:mod:`schuler_api`).

Directives:

``.. schuler-bibliography::``
    every reference, with the label ``ref-KEY`` (``:ref:`ref-bollay1966```).
``.. schuler-reproduction:: SYSTEM``
    the source's printed numbers beside the computed ones, with verdicts and notes.
``.. schuler-parameters:: SYSTEM [ACTION]``
    options of ``schuler SYSTEM run`` (or of an action, or ``reproduce``).
``.. schuler-command::``
    each content line is a command (``schuler align run ...``) run in a scratch
    folder beside a link to ``examples/``; shows the command and its output.
``.. schuler-help::``
    ``--help`` of every command, for the command-line reference.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import os
import re
import shlex
import tempfile
from pathlib import Path

import schuler_api
from docutils import nodes
from docutils.parsers.rst import Directive, directives
from docutils.statemachine import StringList
from sphinx.util import logging
from sphinx.util.fileutil import copy_asset

REPOSITORY = Path(__file__).resolve().parents[2]
logger = logging.getLogger(__name__)


def escape(text: str) -> str:
    """Text as reStructuredText shows it literally (inline markup characters escaped)."""
    for char in "\\*`_|[]":
        text = text.replace(char, "\\" + char)
    return text


class _Generated(Directive):
    """A directive whose output is reStructuredText generated from the package by its ``lines()``."""

    def run(self) -> list[nodes.Node]:
        container = nodes.container()
        text = StringList(self.lines(), source=f"<{self.name}>")  # type: ignore[attr-defined]
        self.state.nested_parse(text, self.content_offset, container)
        return container.children


def _table(header: list[str], rows: list[list[str]], widths: str = "auto") -> list[str]:
    lines = [".. list-table::", "   :header-rows: 1", f"   :widths: {widths}", "   :class: schuler-table", ""]
    for row in [header, *rows]:
        lines.append(f"   * - {row[0] or ' '}")
        lines.extend(f"     - {cell or ' '}" for cell in row[1:])
    return lines + [""]


class Bibliography(_Generated):
    def lines(self) -> list[str]:
        from schuler.references import BIBLIOGRAPHY

        out: list[str] = []
        for ref in BIBLIOGRAPHY:
            out += [f".. _ref-{ref.key}:", "", f"**{escape(ref.short)}**", ""]
            out.append(f"   {escape(ref.citation)}." + (f" {escape(ref.note)}." if ref.note else ""))
            out += [f"   (``schuler.references.{_constant_name(ref)}``)", ""]
        return out


def _constant_name(ref) -> str:
    import schuler.references as module

    return next(name for name, value in vars(module).items() if value is ref and name.isupper())


def _number(value) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:,.6g}" if 1e4 <= abs(value) < 1e9 else f"{value:.6g}"
    return str(value)


class ReproductionTable(_Generated):
    required_arguments = 1

    def lines(self) -> list[str]:
        from schuler.registry import get_system
        from schuler.reproduction import Reproduction

        reproduction = get_system(self.arguments[0]).reproduce()
        if not isinstance(reproduction, Reproduction):
            raise self.error(f"{self.arguments[0]}: reproduce() returned {type(reproduction).__name__}")
        rows = [[escape(r.quantity), escape(r.printed or "-"), escape(r.where), _number(r.computed), escape(r.unit),
                 escape(r.verdict), escape(r.note)] for r in reproduction.rows]
        out = [f"Constants: {escape(reproduction.constants)}.", ""]
        out += _table(["quantity", "printed", "where", "computed", "unit", "verdict", "note"], rows,
                      "22 9 11 9 6 10 33")
        out += [f"* {escape(note)}" for note in reproduction.notes]
        return out + [""]


class ParameterTable(_Generated):
    required_arguments = 1
    optional_arguments = 1

    def lines(self) -> list[str]:
        from schuler.registry import get_system

        system = get_system(self.arguments[0])
        command = self.arguments[1] if len(self.arguments) > 1 else "run"
        if command == "run":
            parameters = system.parameters
        elif command == "reproduce":
            parameters = system.reproduce_parameters
        else:
            actions = {action.name: action for action in system.actions}
            if command not in actions:
                raise self.error(f"{system.name} has no command {command!r}")
            parameters = actions[command].parameters
        rows = []
        for spec in parameters:
            unit = spec.unit if spec.kind == "quantity" else spec.kind
            allowed = spec.range_text() if spec.kind in ("quantity", "integer") else ", ".join(spec.choices or ())
            default = "not set" if spec.default is None else str(spec.default)
            rows.append([f"``{spec.option}``", escape(unit or "plain number"), escape(default), escape(allowed),
                         escape(spec.help)])
        if not rows:
            return ["This command has no options besides ``--json`` and ``--out``.", ""]
        return _table(["option", "unit", "default", "allowed", "meaning"], rows, "18 10 10 14 48")


def run_command(line: str, cwd: Path) -> tuple[int, str]:
    """Run ``schuler ...`` in-process in ``cwd``: exit code and what it printed (stdout, then stderr)."""
    from schuler.cli import main

    words = shlex.split(line)
    if words[0] != "schuler":
        raise ValueError(f"not a schuler command: {line}")
    stdout, stderr = io.StringIO(), io.StringIO()
    previous = Path.cwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
            try:
                main(words[1:])
                code = 0
            except SystemExit as exit_:
                code = exit_.code if isinstance(exit_.code, int) else 1
    finally:
        os.chdir(previous)
    return code, stdout.getvalue() + stderr.getvalue()


class Command(Directive):
    has_content = True
    option_spec = {"head": directives.positive_int}

    def run(self) -> list[nodes.Node]:
        shown = []
        with tempfile.TemporaryDirectory(prefix="schuler-docs-") as scratch:
            (Path(scratch) / "examples").symlink_to(REPOSITORY / "examples")
            for line in (entry.strip() for entry in self.content):
                if not line:
                    continue
                code, output = run_command(line, Path(scratch))
                if code != 0:
                    raise self.error(f"`{line}` exited with {code}: {output.strip()}")
                lines = output.rstrip().replace(scratch, ".").splitlines()
                head = self.options.get("head")
                if head and len(lines) > head:
                    lines = lines[:head] + [f"... ({len(lines) - head} more lines)"]
                shown.append("$ " + line + ("\n" + "\n".join(lines) if lines else ""))
        block = nodes.literal_block("\n\n".join(shown), "\n\n".join(shown))
        block["language"] = "text"
        block["classes"].append("schuler-console")
        return [block]


class Help(Directive):
    """``--help`` of ``schuler`` and of every command under it, each in its own section."""

    def run(self) -> list[nodes.Node]:
        from schuler.cli import COMMANDS
        from schuler.registry import SYSTEM_MODULES

        sections = []
        commands = [*((name, "system") for name in SYSTEM_MODULES), *((name, origin) for name, (origin, _) in
                                                                       COMMANDS.items())]
        for name, origin in [("", ""), *commands]:
            paths = [name] if origin != "system" else [name, *_subcommands(name)]
            for path in paths:
                line = f"schuler {path} --help".replace("  ", " ")
                code, output = run_command(line, REPOSITORY)
                if code != 0:
                    raise self.error(f"`{line}` exited with {code}: {output.strip()}")
                title = f"schuler {path}".strip()
                section = nodes.section(ids=[nodes.make_id(title)], names=[nodes.fully_normalize_name(title)])
                section += nodes.title(title, title)
                block = nodes.literal_block(output, output)
                block["language"] = "text"
                section += block
                self.state.document.note_implicit_target(section)
                sections.append(section)
        return sections


def _subcommands(name: str) -> list[str]:
    from schuler.registry import get_system

    system = get_system(name)
    return [f"{name} run", f"{name} reproduce", *(f"{name} {action.name}" for action in system.actions)]


_LITERALS = re.compile(r"(``.*?``|:?[\w:]*`[^`]*`_?)")


def escape_bars(app, what, name, obj, options, lines: list[str]) -> None:
    """Show the docstrings' plain-text absolute values ``|x|`` as written.

    The package's docstrings are read in terminals too, so they write an absolute
    value as ``|x|``, which reStructuredText takes for a substitution; they use no
    substitutions, line blocks or grid tables. Bars in prose are escaped; inline
    literals, roles, literal blocks and doctests (up to the blank line that ends
    them, their expected output included) are left alone.
    """
    literal_indent = None
    in_doctest = False
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal_indent is not None:
            if not stripped or indent > literal_indent:
                continue
            literal_indent = None
        in_doctest = bool(stripped) and (in_doctest or stripped.startswith(">>>"))
        if in_doctest:
            continue
        if "|" in line:
            parts = _LITERALS.split(line)
            lines[i] = "".join(part if k % 2 else part.replace("|", "\\|") for k, part in enumerate(parts))
        if stripped.endswith("::"):
            literal_indent = indent


def _mathjax_files() -> Path:
    """MathJax as the sphinx-mathjax-offline package ships it (its own extension is not parallel-safe)."""
    spec = importlib.util.find_spec("sphinx-mathjax-offline")
    if spec is None or spec.origin is None:
        raise RuntimeError("sphinx-mathjax-offline is not installed: pip install -e '.[docs]'")
    return Path(spec.origin).parent / "static" / "mathjax"


def _offline_mathjax(app, config) -> None:
    config.mathjax_path = "mathjax/tex-chtml.js"


def _copy_mathjax(app, exception) -> None:
    if exception is None and app.builder.format == "html":
        copy_asset(_mathjax_files(), Path(app.outdir) / "_static" / "mathjax")


def _check_site(app, exception) -> None:
    if exception is None and app.builder.name == "html":
        for problem in schuler_api.site_problems(Path(app.outdir)):
            logger.warning("site check: %s", problem)


def _write_api_index(app, config) -> None:
    schuler_api.write_index(Path(app.srcdir))


def setup(app):
    app.add_directive("schuler-bibliography", Bibliography)
    app.add_directive("schuler-reproduction", ReproductionTable)
    app.add_directive("schuler-parameters", ParameterTable)
    app.add_directive("schuler-command", Command)
    app.add_directive("schuler-help", Help)
    # before Sphinx lists the source files, so that autosummary finds api/index.rst and writes the module pages
    app.connect("config-inited", _write_api_index)
    # MathJax served from the build, not a CDN
    app.connect("config-inited", _offline_mathjax)
    app.connect("build-finished", _copy_mathjax)
    # what the issue asks the site to show, checked on the built pages (a warning fails the -W build)
    app.connect("build-finished", _check_site)
    # before numpydoc turns the sections into reStructuredText
    app.connect("autodoc-process-docstring", escape_bars, priority=400)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
