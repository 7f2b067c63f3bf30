"""The HTML report: a section per system, every referenced image exists, missing systems listed."""

from __future__ import annotations

import importlib.util
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
    assert "<h3>Reproduction (1 agrees, 1 erratum)</h3>" in text
    assert '<td class="erratum">erratum</td><td>the source drops a factor</td>' in text
    assert "schuler fake run --latitude 50" in text and "An erratum, explained." in text
    assert "<code>--drift-east</code>" in text  # parameters table


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
    check_page(index, ["errors", "vertical", "calibrate", "align", "north", "imu", "navigate", "mission"])
    for name in SYSTEM_MODULES:
        section = text.split(f'id="system-{name}"')[1].split("</section>")[0]
        if name in landed:
            assert "<h3>Reproduction" in section and "<h3>Reproduce</h3>" in section and "<img" in section, name
        else:
            assert "Not yet available" in section, name
