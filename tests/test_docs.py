"""The documentation: docstrings state units, the guide's Python runs, the gallery runs, pages cross-link.

The API reference (``make docs``) documents the functions that
``docs/_ext/schuler_api.py`` calls public; every one of them that takes
parameters must have a numpydoc Parameters section naming each of them, and
each numeric entry must state its unit: an SI or display unit ("rad/s",
"deg/h", "m"), a unit word ("seconds"), "SI", "plain number",
"dimensionless", a count ("number of", "members", "index") or a choice
(``{"a", "b"}``). Entries whose type is not a number (str, bool, a path, a
callable, a class) and ``*args``/``**kwargs`` need no unit.
"""

from __future__ import annotations

import doctest
import importlib
import inspect
import re
import runpy
import sys
import warnings
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import pytest
from numpydoc.docscrape import FunctionDoc

from schuler.registry import SYSTEM_MODULES, get_system

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

import schuler_api  # noqa: E402

UNIT = re.compile(
    r"""(?ix)
    (?<![\w/^])
    (rad|mrad|urad|rad/s|rad/s\^?2|rad/s²|rad/sqrt\(s\)|m/s|m/s\^?2|m/s²|m\^?2|s\^?2|ms|hz|kg|
     deg|degrees?|deg/h|deg/s|arcmin|arcsec|ft|ft/s|mi|km|ppm|ug|mg|min|1/s|1/s\^?2|bytes?|gib|mib|%|percent|
     radians?|metres?|meters?|seconds?|hours?|minutes?|si|dpi|px|pixels?|kg\s?m\^?2|n\s?m(\s?s)?|v\s?s|v/rad|v/deg|n\s?m/a)
    (?![\w])
    | (?:^|\|\s*|,\s*|\bin\s+|\d\s?)(?-i:m|s|N|g|h)(?=[\s,.;:]|$) | \((?-i:m|s|N|V|A|g|h)\)
    | plain\ numbers? | dimensionless | unitless | \bunits?\b | \bratios?\b | \bfactor\b | \bcounts?\b
    | number\ of | \bindex\b | \bindices\b | \bseed\b | \bmembers?\b | \bsamples\b | \bpasses\b | \bsteps\b
    """
)
"""Evidence that an entry states its unit (or is a count or a plain ratio).

A one-letter unit (m, s, N, g, h; V and A only in parentheses) counts only where a unit stands:
opening the description, after a comma, "in" or a number, or in parentheses ("s.", "float, s", "in m",
"9.8 m", "T (s)"), so that the article "a" or the "n" of "shape (n,)" is no unit."""

NUMERIC = re.compile(r"(?i)\b(float|int|integer|array|array_like|ndarray|number|scalar|complex|real)\b")


def unit_problems(function) -> list[str]:
    """What is missing from ``function``'s docstring: undocumented parameters, numeric entries without units."""
    parameters = [p.name for p in inspect.signature(function).parameters.values() if p.name not in ("self", "cls")]
    if not parameters:
        return []
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an unknown section header is a broken docstring
        try:
            entries = FunctionDoc(function, config={})["Parameters"]
        except Warning as warning:
            return [str(warning)]
    if not entries:
        return ["no Parameters section"]
    problems, documented = [], set()
    for entry in entries:
        if entry.name.startswith(">>>"):
            problems.append("a doctest read as a parameter: put it under an Examples header")
            continue
        names = [name.strip().lstrip("*") for name in entry.name.split(",")]
        documented.update(names)
        numeric = bool(NUMERIC.search(entry.type)) or not (entry.type.strip() or entry.name.startswith("*"))
        choice = "{" in entry.type
        if numeric and not choice and not UNIT.search(entry.type + " | " + " ".join(entry.desc)):
            problems.append(f"{entry.name}: no unit")
    problems += [f"{name}: not documented" for name in parameters if name not in documented]
    return problems


FUNCTIONS = list(schuler_api.public_functions())
MODULES = sorted({name.rsplit(".", 2)[0] if name.split(".")[-2][0].isupper() else name.rsplit(".", 1)[0]
                  for name, _ in FUNCTIONS})


@pytest.mark.parametrize("module", MODULES)
def test_public_functions_document_parameters_with_units(module):
    problems = {}
    for name, function in FUNCTIONS:
        owner = name.rsplit(".", 2)[0] if name.split(".")[-2][0].isupper() else name.rsplit(".", 1)[0]
        if owner == module and (found := unit_problems(function)):
            problems[name] = found
    assert not problems, "\n".join(f"{name}: {'; '.join(found)}" for name, found in problems.items())


@pytest.mark.parametrize("module", schuler_api.public_modules())
def test_every_public_module_imports(module):
    importlib.import_module(module)


def test_the_unit_check_catches_what_it_should():
    def no_section(latitude):
        """Nothing about latitude."""

    def no_unit(latitude, name):
        """A function.

        Parameters
        ----------
        latitude : float
            The latitude.
        name : str
            A label.
        """

    def fine(latitude, count, mode):
        """A function.

        Parameters
        ----------
        latitude : float
            phi, rad.
        count : int
            Number of members.
        mode : {"a", "b"}
        """

    assert unit_problems(no_section) == ["no Parameters section"]
    assert unit_problems(no_unit) == ["latitude: no unit"]
    assert unit_problems(fine) == []

    def doctest_in_parameters(latitude):
        """A function.

        Parameters
        ----------
        latitude : float
            phi, rad.

        >>> doctest_in_parameters(0.5)
        """

    assert unit_problems(doctest_in_parameters) == ["a doctest read as a parameter: put it under an Examples header"]

    def letters_that_are_no_units(state, weight, step):
        """A function.

        Parameters
        ----------
        state : ndarray, shape (n,)
            A state.
        weight : float
            Weight of a member's sample in the mean, m.
        step : float
            Time step, s.
        """

    # the article "a" and the "n" of a shape are no units; "m" after a comma and "s" after one are
    assert unit_problems(letters_that_are_no_units) == ["state: no unit"]


def test_the_api_reference_covers_every_package():
    text = schuler_api.index_text()
    packages = {module.split(".")[1] for module in SYSTEM_MODULES.values()} | {"core", "study", "imu", "contract"}
    for package in packages:
        assert f"   schuler.{package}\n" in text, package
    assert "schuler.cli" not in text
    assert not any(part.startswith("_") for name in schuler_api.public_modules() for part in name.split("."))


def _complete_site(root: Path) -> None:
    """A minimal built site holding everything :func:`schuler_api.site_problems` asks for."""
    (root / "api" / "generated").mkdir(parents=True)
    (root / "index.html").write_text('<html><script src="_static/a.js"></script></html>')
    for name in SYSTEM_MODULES:
        guide = get_system(name).guide
        (root / "gallery" / guide).mkdir(parents=True)
        (root / "guide").mkdir(exist_ok=True)
        (root / "guide" / f"{guide}.html").write_text("<html></html>")
        (root / "gallery" / guide / "plot_x.html").write_text(
            '<img src="../../_images/sphx_glr_plot_x_001.png" alt="x"/>')
    for top in {".".join(module.split(".")[:2]) for module in schuler_api.public_modules()}:
        (root / "api" / "generated" / f"{top}.html").write_text("<html></html>")


def test_the_site_check_catches_what_it_should(tmp_path):
    _complete_site(tmp_path)
    assert schuler_api.site_problems(tmp_path) == []
    (tmp_path / "gallery" / "north" / "plot_x.html").write_text("<p>no figure</p>")
    (tmp_path / "api" / "generated" / "schuler.core.html").unlink()
    (tmp_path / "guide" / "fonts.html").write_text('<link rel="stylesheet" href="https://fonts.example/a.css">')
    (tmp_path / "guide" / "cdn.html").write_text("<script src='//cdn.example/a.js'></script>")
    (tmp_path / "guide" / "link.html").write_text('<a href="https://example.org">a link is fine</a>')
    assert schuler_api.site_problems(tmp_path) == [
        "north: no gallery page with a figure under gallery/north/ (examples/gallery/north/plot_*.py)",
        "no API page for schuler.core",
        "guide/cdn.html: loads an asset from another site",
        "guide/fonts.html: loads an asset from another site",
    ]


GUIDE_PAGES = [DOCS / "getting-started.rst", *sorted((DOCS / "guide").glob("*.rst"))]


@pytest.mark.parametrize("page", GUIDE_PAGES, ids=lambda p: p.name)
def test_guide_python_runs(page):
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    result = doctest.testfile(str(page), module_relative=False, optionflags=flags, raise_on_error=False)
    assert result.failed == 0


GALLERY = sorted((ROOT / "examples" / "gallery").glob("*/plot_*.py"))


@pytest.mark.slow
@pytest.mark.parametrize("script", GALLERY, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_gallery_example_runs_and_draws(script, capsys):
    assert matplotlib.get_backend().lower() == "agg"
    plt.close("all")
    runpy.run_path(str(script), run_name="__main__")
    assert plt.get_fignums(), "the example drew no figure"
    assert capsys.readouterr().out.strip(), "the example printed nothing"
    plt.close("all")


def _documented(name: str) -> bool:
    guide = get_system(name).guide
    page = any((DOCS / "guide" / f"{guide}{suffix}").exists() for suffix in (".rst", ".md"))
    return page and bool(list((ROOT / "examples" / "gallery" / guide).glob("plot_*.py")))


def test_every_system_has_a_guide_page_and_a_gallery_section():
    missing = [name for name in SYSTEM_MODULES if name not in schuler_api.GUIDE_BACKLOG and not _documented(name)]
    assert not missing, f"write docs/guide/NAME.rst and examples/gallery/NAME/plot_*.py for {missing}"


def test_the_guide_backlog_only_shrinks():
    stale = [name for name in schuler_api.GUIDE_BACKLOG if name not in SYSTEM_MODULES or _documented(name)]
    assert not stale, f"remove from schuler_api.GUIDE_BACKLOG: {stale}"


@pytest.mark.parametrize("name", list(SYSTEM_MODULES))
def test_help_points_to_the_guide(name, run_cli):
    out = run_cli(name, "--help")
    assert f"Guide: docs/_build/html/guide/{get_system(name).guide}.html" in " ".join(out.stdout.split())


def test_report_links_the_guide(tmp_path, monkeypatch):
    from schuler.study import report

    system = get_system("align")
    figures = tmp_path / "results" / "figures"
    figures.mkdir(parents=True)
    monkeypatch.setattr(report, "GUIDE", tmp_path / "missing")
    assert "<code>guide/align.html</code>" in report._guide_link(system, figures)
    built = tmp_path / "docs" / "_build" / "html" / "guide"
    built.mkdir(parents=True)
    (built / "align.html").write_text("<html></html>")
    monkeypatch.setattr(report, "GUIDE", built)
    assert 'href="../docs/_build/html/guide/align.html"' in report._guide_link(system, figures)
