"""The HTML report: a section per system, every referenced image exists, missing systems listed."""

from __future__ import annotations

import importlib.util
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

import test_study_fake_system as fake
from schuler.registry import SYSTEM_MODULES
from schuler.study.report import build_report


class Page(HTMLParser):
    """Section ids, image sources and link targets of a page."""

    def __init__(self, text: str):
        super().__init__()
        self.sections: list[str] = []
        self.images: list[str] = []
        self.links: list[str] = []
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "section":
            self.sections.append(attrs["id"])
        elif tag == "img":
            self.images.append(attrs["src"])
        elif tag == "a":
            self.links.append(attrs["href"])


def landed_systems() -> list[str]:
    """Systems whose api module exists in this installation."""
    return [name for name, module in SYSTEM_MODULES.items() if importlib.util.find_spec(module.rsplit(".", 1)[0])
            and importlib.util.find_spec(module)]


def full_report(tmp_path_factory) -> Path:
    """The report of all systems, built once per test process (the browser test reuses it)."""
    folder = tmp_path_factory.getbasetemp() / "full-report"
    index = folder / "index.html"
    if not index.exists():
        assert build_report(folder, jobs=2) == index
    return index


def check_page(index: Path, expected_sections: list[str]) -> Page:
    page = Page(index.read_text(encoding="utf-8"))
    assert page.sections == [f"system-{name}" for name in expected_sections]
    assert page.images, "the report shows no figure"
    for src in page.images + [link for link in page.links if not link.startswith("#")]:
        assert (index.parent / src).is_file() and (index.parent / src).stat().st_size > 0, src
    return page


def test_report_of_a_system_and_of_missing_ones(tmp_path, request):
    fake.only_systems(request, {
        "fake": fake.__name__,
        "ghost": "schuler.no_such_system.api",          # package missing
        "shadow": "schuler.study.no_such_module",      # module missing in an existing package
    })  # fmt: skip
    index = build_report(tmp_path / "report")
    assert index == tmp_path / "report" / "index.html"
    text = index.read_text(encoding="utf-8")
    page = check_page(index, ["fake", "ghost", "shadow"])
    assert page.images == ["figures/fake_azimuth.png"]
    assert 'href="figures/fake_azimuth.svg"' in text
    assert "Test fixture &lt;not a real source&gt; &amp; co" in text  # escaped
    assert text.count("Not yet available in this installation") == 2
    assert ('<h3>Reproduction (<span class="verdict agrees">1 agrees</span>, '
            '<span class="verdict erratum">1 erratum</span>)</h3>') in text
    assert '<td class="verdict erratum">erratum</td><td>the source drops a factor</td>' in text
    assert "schuler fake run --latitude 50" in text and "An erratum, explained." in text
    assert "<code>--drift-east</code>" in text  # parameters table


class Verdicts(HTMLParser):
    """The verdict cells of a page (class, text), its legend's kinds and its style sheet."""

    def __init__(self, text: str):
        super().__init__()
        self.cells: list[tuple[str, str]] = []
        self.legend: list[str] = []
        self.css = ""
        self._in: str | None = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        classes = (dict(attrs).get("class") or "").split()
        if tag == "td" and "verdict" in classes:
            self._in = "cell"
            self.cells.append((classes[1], ""))
        elif tag == "span" and "verdict" in classes and self._in == "legend":
            self.legend.append(classes[1])
        elif tag == "div" and "legend" in classes:
            self._in = "legend"
        elif tag == "style":
            self._in = "style"

    def handle_endtag(self, tag):
        if tag in ("td", "div", "style"):
            self._in = None

    def handle_data(self, data):
        if self._in == "cell":
            self.cells[-1] = (self.cells[-1][0], self.cells[-1][1] + data)
        elif self._in == "style":
            self.css += data


def test_each_kind_of_verdict_has_its_own_colour_and_a_legend():
    from schuler.contract import ReportSection
    from schuler.reproduction import Tolerance, compare
    from schuler.study.report import SystemEntry, render_html

    rows = [compare("a", 1.0, "m", printed="1.0", where="p. 1"),
            compare("b", 1.0, "m", printed="1.0", where="p. 2", tuned="the gain was chosen"),
            compare("c", 2.0, "m", printed="1.0", where="p. 3", erratum="a factor 2 dropped"),
            compare("d", 2.0, "m"),
            compare("e", 3.0, "m", printed="1.0", where="p. 4", tolerance=Tolerance(relative=0.01))]
    section = ReportSection(system="fake", title="Fake", source="A source.", summary="Five verdicts.", rows=rows)
    page = Verdicts(render_html([SystemEntry("fake", fake.SYSTEM, section)], seconds=0.1))
    assert page.cells == [("agrees", "agrees within 0.5 %"), ("tuned", "tuned to match within 0.5 %"),
                          ("erratum", "erratum"), ("not-printed", "not printed in the source"),
                          ("differs", "differs by 200 %")]
    colours = dict(re.findall(r"\.verdict\.([a-z-]+) \{ color: (#[0-9a-f]{6});", page.css))
    assert sorted(colours) == sorted(kind for kind, _ in page.cells)  # every kind styled ...
    assert len(set(colours.values())) == 5  # ... in a colour of its own
    assert page.legend == ["agrees", "tuned", "erratum", "not-printed", "differs"]


def test_a_system_that_fails_to_import_is_an_error_not_a_missing_system(tmp_path, monkeypatch, request):
    (tmp_path / "broken_system_api.py").write_text("import a_dependency_that_is_not_installed\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    fake.only_systems(request, {"broken": "broken_system_api"})
    with pytest.raises(ModuleNotFoundError, match="a_dependency_that_is_not_installed"):
        build_report(tmp_path / "report")


def test_report_command_prints_the_path(tmp_path, request, run_cli):
    modules = {"fake": fake.__name__}
    fake.only_systems(request, modules)
    out = run_cli("report", "--out", tmp_path / "r", "--jobs", "1")
    assert out.code == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == str(tmp_path / "r" / "index.html")
    assert (tmp_path / "r" / "figures" / "fake_azimuth.svg").exists()


@pytest.mark.slow
def test_the_report_has_a_section_per_landed_system(tmp_path_factory):
    landed = landed_systems()
    if not landed:
        pytest.skip("no system is installed yet")
    index = full_report(tmp_path_factory)
    text = index.read_text(encoding="utf-8")
    check_page(index, ["errors", "vertical", "calibrate", "align", "north", "imu", "navigate", "mission", "aided"])
    for name in SYSTEM_MODULES:
        section = text.split(f'id="system-{name}"')[1].split("</section>")[0]
        if name in landed:
            assert "<h3>Reproduction" in section and "<h3>Reproduce</h3>" in section and "<img" in section, name
        else:
            assert "Not yet available" in section, name
