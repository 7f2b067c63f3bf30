"""The report opens in headless Chromium with no console error and no broken image.

Uses the system's Chromium (Debian package ``chromium``) through Playwright;
nothing is installed at run time. Skipped only where no Chromium binary exists.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import test_study_fake_system as fake
from schuler.study.report import build_report
from test_study_report import full_report, landed_systems

MIN_FONT_PX = 9.0
"""Smallest legible figure text as displayed in a 1280-px wide window, px."""

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
]


def chromium_binary() -> str | None:
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    return None


def open_in_browser(index: Path, screenshot: Path) -> dict:
    """Load the page; return console errors, page errors, failed requests and broken images."""
    playwright = pytest.importorskip("playwright.sync_api")
    binary = chromium_binary()
    if binary is None:
        pytest.skip(f"no Chromium binary on PATH (looked for {', '.join(CHROMIUM_NAMES)}); install Debian's chromium")
    problems = {"console": [], "page": [], "requests": []}
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=binary, args=CHROMIUM_ARGS, headless=True)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.on("console", lambda m: problems["console"].append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: problems["page"].append(str(e)))
            page.on("requestfailed", lambda r: problems["requests"].append(r.url))
            page.goto(index.resolve().as_uri(), wait_until="load")
            # lazy images: scroll through the page so that every one is fetched
            page.evaluate("document.querySelectorAll('img').forEach(img => img.loading = 'eager')")
            page.wait_for_function("Array.from(document.images).every(img => img.complete)", timeout=15_000)
            problems["images"] = page.evaluate(
                "Array.from(document.images).filter(img => img.naturalWidth === 0).map(img => img.src)"
            )
            problems["image_count"] = page.evaluate("document.images.length")
            # the smallest text of each figure as shown: its size in the image times the displayed scale
            problems["fonts"] = page.evaluate(
                "Array.from(document.images).map(img => [img.src.split('/').pop(), "
                "parseFloat(img.dataset.minFontPx || 'NaN') * img.clientWidth / img.naturalWidth])"
            )
            problems["title"] = page.title()
            page.screenshot(path=str(screenshot), full_page=True)
        finally:
            browser.close()
    print(f"screenshot: {screenshot}")
    return problems


def assert_clean(problems: dict, screenshot: Path) -> None:
    assert problems["console"] == []
    assert problems["page"] == []
    assert problems["requests"] == []
    assert problems["images"] == [], "broken images"
    assert problems["image_count"] > 0
    small = [(name, round(px, 1)) for name, px in problems["fonts"] if not px >= MIN_FONT_PX]
    assert not small, f"figure text smaller than {MIN_FONT_PX} px as displayed: {small}"
    assert problems["title"].startswith("schuler")
    assert screenshot.stat().st_size > 10_000


def test_report_of_the_fake_system_renders_cleanly(tmp_path, request):
    modules = {"fake": fake.__name__, "ghost": "schuler.no_such_system.api"}
    fake.only_systems(request, modules)
    index = build_report(tmp_path / "report")
    screenshot = tmp_path / "fake-report.png"
    assert_clean(open_in_browser(index, screenshot), screenshot)


@pytest.mark.slow
def test_the_full_report_renders_cleanly(tmp_path_factory):
    if not landed_systems():
        pytest.skip("no system is installed yet")
    if chromium_binary() is None:
        pytest.skip(f"no Chromium binary on PATH (looked for {', '.join(CHROMIUM_NAMES)}); install Debian's chromium")
    index = full_report(tmp_path_factory)
    screenshot = index.parent / "report-screenshot.png"
    problems = open_in_browser(index, screenshot)
    assert_clean(problems, screenshot)
