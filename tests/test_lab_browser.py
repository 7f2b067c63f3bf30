"""The lab bench in Debian's Chromium through Playwright, against ``schuler lab`` in a subprocess.

Every request the page makes is watched: any that would leave 127.0.0.1 is
aborted and fails the test, as do console errors, page errors and failed
requests. The page keeps its Content-Security-Policy during the tests (waits
poll from Python instead of evaluating strings in the page).

Set SCHULER_UPDATE_SCREENSHOT=1 to write docs/lab-screenshot.png (otherwise the
screenshot goes to the test's temporary folder).
"""

from __future__ import annotations

import math
import os
import statistics
import time
from pathlib import Path
from urllib.parse import urlsplit

import pytest

from schuler.registry import get_system
from test_lab import start_server
from test_report_browser import CHROMIUM_ARGS, CHROMIUM_NAMES, chromium_binary

playwright_api = pytest.importorskip("playwright.sync_api")

ROOT = Path(__file__).resolve().parents[1]
WAIT_S = 60.0
"""Longest wait for a page to follow a change (generous: the suite runs beside other work on 2 cores)."""


@pytest.fixture(scope="module")
def server():
    if chromium_binary() is None:
        pytest.skip(f"no Chromium binary on PATH (looked for {', '.join(CHROMIUM_NAMES)}); install Debian's chromium")
    process, url = start_server()
    yield url
    process.terminate()
    process.wait(timeout=30)


@pytest.fixture(scope="module")
def browser(server):
    with playwright_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_binary(), args=CHROMIUM_ARGS, headless=True)
        yield browser
        browser.close()


class Watched:
    """A page whose console errors, page errors, failed requests and requests leaving 127.0.0.1 are recorded."""

    def __init__(self, browser, url: str, downloads: bool = False):
        self.context = browser.new_context(viewport={"width": 1280, "height": 900}, accept_downloads=downloads)
        self.page = self.context.new_page()
        self.problems = {"console": [], "page": [], "failed": [], "outside": []}
        self.page.on("console", lambda m: self.problems["console"].append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.problems["page"].append(str(e)))
        self.page.on("requestfailed", lambda r: self.problems["failed"].append(f"{r.url} {r.failure}"))
        self.page.route("**/*", self._only_local)
        self.url = url

    def _only_local(self, route):
        if urlsplit(route.request.url).hostname != "127.0.0.1":
            self.problems["outside"].append(route.request.url)
            route.abort()
        else:
            route.continue_()

    def open(self, path: str) -> None:
        self.page.goto(self.url + path)

    def text(self, selector: str) -> str:
        return self.page.locator(selector).inner_text().strip()

    def wait_for(self, condition, what: str, timeout: float = WAIT_S) -> float:
        """Poll ``condition()`` until true; returns the seconds it took."""
        start = time.perf_counter()
        while not condition():
            if time.perf_counter() - start > timeout:
                numbers = self.page.locator("[data-result]").all_inner_texts()[:3]
                raise AssertionError(f"timed out waiting for {what}; the page shows {numbers}")
            self.page.wait_for_timeout(25)
        return time.perf_counter() - start

    def type_value(self, name: str, value: str, key: str = "Enter") -> None:
        field = self.page.locator(f"[data-param={name}] input")
        field.fill(value)
        field.press(key)

    def close(self) -> dict:
        self.context.close()
        return self.problems


def arcmin(text: str) -> float:
    number, unit = text.split()
    assert unit == "arcmin"
    return float(number)


def steady_line(watched: Watched) -> float:
    """The y of the dotted delta_y (1.21) line of the time-history figure, as plotted (arcmin)."""
    graph = watched.page.locator("[data-figure=align_time_history] .js-plotly-plot")
    return graph.evaluate("element => element.layout.shapes[0].y0")


def expected_align(latitude_deg: float, drift_east_deg_h: float):
    """What ``schuler align run --latitude L --drift-east D`` gives (its Python API, the same System)."""
    return get_system("align").run(latitude=math.radians(latitude_deg),
                                   drift_east=math.radians(drift_east_deg_h) / 3600)


def close_to(text: str, value_rad: float) -> bool:
    """The shown number equals the value to its 4 significant digits (half a unit in the 4th digit)."""
    try:
        shown = arcmin(text)
    except (ValueError, AssertionError):
        return False
    return math.isclose(shown, math.degrees(value_rad) * 60, rel_tol=5e-4, abs_tol=1e-12)


AZIMUTH = "[data-result=azimuth_error_rad]"


def test_align_page_follows_latitude_and_drift_as_the_command_line_does(server, browser, tmp_path):
    watched = Watched(browser, server)
    watched.open("align")
    watched.wait_for(lambda: watched.text(AZIMUTH) != "-", "the first run")
    assert watched.text(AZIMUTH) == "0 arcmin"  # no drift: exactly 0, not the arithmetic's 1e-83 arcmin
    latencies = []

    watched.type_value("drift_east", "0.02", key="Tab")  # leaving the field applies it too
    latencies.append(watched.wait_for(lambda: close_to(watched.text(AZIMUTH), expected_align(50.0, 0.02)
                                                       .azimuth_error_rad), "the drift to apply"))
    watched.type_value("latitude", "45")
    result = expected_align(45.0, 0.02)
    latencies.append(watched.wait_for(lambda: close_to(watched.text(AZIMUTH), result.azimuth_error_rad),
                                      "the azimuth error of latitude 45 deg, drift 0.02 deg/h"))
    # (1.21): delta_y = Delta omega_dxi / (U cos phi) = 0.02 / (15.0411 cos 45 deg) rad = 6.465 arcmin
    assert arcmin(watched.text(AZIMUTH)) == pytest.approx(6.465, abs=0.001)
    assert close_to(watched.text("[data-result=azimuth_error_analytic_rad]"), result.azimuth_error_analytic_rad)
    watched.wait_for(lambda: math.isclose(steady_line(watched), math.degrees(result.azimuth_error_analytic_rad) * 60,
                                          rel_tol=1e-9), "the figure to follow")
    for value in ("30", "60", "45"):
        shown = watched.text(AZIMUTH)
        watched.type_value("latitude", value)
        latencies.append(watched.wait_for(lambda shown=shown: watched.text(AZIMUTH) != shown, f"latitude {value}"))
    print(f"update latency, Enter to new number: median {statistics.median(latencies):.2f} s, "
          f"max {max(latencies):.2f} s over {len(latencies)} changes")

    target = ROOT / "docs" / "lab-screenshot.png" if os.environ.get("SCHULER_UPDATE_SCREENSHOT") \
        else tmp_path / "lab-screenshot.png"
    watched.page.set_viewport_size({"width": 1280, "height": 1400})  # controls, numbers and the first figure
    watched.page.wait_for_timeout(500)
    watched.page.screenshot(path=str(target))
    assert target.stat().st_size > 20_000
    print(f"screenshot: {target}")

    shown, line = watched.text(AZIMUTH), steady_line(watched)
    watched.type_value("latitude", "95")
    error = watched.page.locator("[data-param=latitude] .error")
    watched.wait_for(lambda: error.inner_text().strip() != "", "the error message")
    assert error.inner_text().strip() == "--latitude: '95' is outside (-90, 90) deg"
    watched.page.wait_for_timeout(1500)  # nothing else changes, also not a moment later
    assert watched.text(AZIMUTH) == shown and steady_line(watched) == line
    assert watched.page.locator("[data-param] .error:not(:empty)").count() == 1

    problems = watched.close()
    assert problems == {"console": [], "page": [], "failed": [], "outside": []}


def test_the_reproduction_table_is_one_click_away(server, browser):
    watched = Watched(browser, server)
    watched.open("align")
    watched.page.locator("#reproduction-link").click()
    rows = watched.page.locator("table.reproduction tbody tr")
    watched.wait_for(lambda: rows.count() > 0, "the reproduction table")
    assert watched.page.url == server + "align/reproduction"
    reproduction = get_system("align").reproduce()
    assert rows.count() == len(reproduction.rows)
    verdicts = watched.page.locator("table.reproduction td.verdict").all_inner_texts()
    assert [v.strip() for v in verdicts] == [row.verdict for row in reproduction.rows]
    assert watched.close() == {"console": [], "page": [], "failed": [], "outside": []}


def test_two_sessions_do_not_disturb_each_other(server, browser):
    first, second = Watched(browser, server), Watched(browser, server)
    for watched in (first, second):
        watched.open("align")
        watched.wait_for(lambda watched=watched: watched.text(AZIMUTH) != "-", "the first run")
        watched.type_value("drift_east", "0.01")
    # different cases at the same moment: each page shows its own
    first.type_value("latitude", "30")
    second.type_value("latitude", "60")
    for watched, latitude in ((first, 30.0), (second, 60.0)):
        expected = expected_align(latitude, 0.01).azimuth_error_rad
        watched.wait_for(lambda watched=watched, expected=expected: close_to(watched.text(AZIMUTH), expected),
                         f"latitude {latitude}")
    # the same case at the same moment (the same job key if sessions were not kept apart): both get it
    first.type_value("latitude", "10")
    second.type_value("latitude", "10")
    expected = expected_align(10.0, 0.01).azimuth_error_rad
    for watched in (first, second):
        watched.wait_for(lambda watched=watched: close_to(watched.text(AZIMUTH), expected), "latitude 10 in both")
    assert first.close() == second.close() == {"console": [], "page": [], "failed": [], "outside": []}


@pytest.mark.slow
def test_a_long_run_shows_progress_and_can_be_cancelled(server, browser):
    watched = Watched(browser, server)
    watched.open("align")
    watched.wait_for(lambda: watched.text(AZIMUTH) != "-", "the first run")
    shown = watched.text(AZIMUTH)
    status = watched.page.locator("#run-status")
    # about 2.5 min of work by the align estimate: long enough to watch, inside the 10-min time budget
    watched.type_value("monte_carlo", "500000")
    watched.wait_for(lambda: "running" in (status.get_attribute("class") or ""), "the running state")
    progress = watched.page.locator("#run-progress")
    watched.wait_for(lambda: (progress.get_attribute("value") or "0") not in ("0", ""), "the first progress")
    assert progress.get_attribute("max") == "500000"
    watched.page.locator("#run-cancel").click()
    watched.wait_for(lambda: "running" not in (status.get_attribute("class") or ""), "the cancellation")
    assert watched.text(AZIMUTH) == shown
    assert watched.page.locator("#monte-carlo").inner_text().strip() == ""
    assert watched.close() == {"console": [], "page": [], "failed": [], "outside": []}


def test_task1_marks_violated_constraints_and_exports_png_svg_csv(server, browser, tmp_path):
    watched = Watched(browser, server, downloads=True)
    watched.open("align/task1")
    panel = "[data-constraint=delta] td:last-child"
    watched.wait_for(lambda: watched.page.locator(panel).count() == 1, "the constraint panel")
    assert watched.text(panel) == "holds"
    field = watched.page.locator("[data-param=initial_azimuth_error] input")
    field.fill("30")
    field.press("Enter")
    watched.wait_for(lambda: watched.text(panel) == "VIOLATED", "the violated |delta| < 0.4 rad")
    assert "|delta| < 0.4 rad is violated at latitude (deg) = 0," in watched.text("#task-notes")
    saved = {}
    for fmt in ("png", "svg", "csv"):
        button = watched.page.locator(f"[data-figure=task1_sweep] button:text-is('{fmt.upper()}')")
        with watched.page.expect_download(timeout=WAIT_S * 1000) as download:
            button.click()
        saved[fmt] = tmp_path / download.value.suggested_filename
        download.value.save_as(saved[fmt])
    assert saved["png"].name == "task1_sweep.png" and saved["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert saved["svg"].read_text().lstrip().startswith("<svg")
    lines = saved["csv"].read_text().splitlines()
    assert lines[0].startswith("latitude (deg),azimuth_error_arcmin,") and len(lines) == 1 + 21
    assert watched.close() == {"console": [], "page": [], "failed": [], "outside": []}


@pytest.mark.slow  # its first job compiles the alignment kernels in a fresh process (about 20 s)
def test_the_alignment_comparison_runs_from_the_align_page_and_says_what_is_wrong(server, browser):
    from schuler.lab import compare_page

    watched = Watched(browser, server)
    watched.open("align")
    watched.page.locator("#compare-link").click()
    heading = watched.page.locator('[data-result="methods.kalman.heading_rad"]')
    # twice the usual wait: in a fresh checkout the job's process compiles the alignment kernels first (~20 s)
    watched.wait_for(lambda: heading.count() == 1 and heading.inner_text().endswith(" deg"), "the methods' table",
                     timeout=2 * WAIT_S)
    assert watched.page.url == server + "align/compare"
    expected = compare_page.run_typed(compare_page.STARTING_CASE).methods["kalman"]["heading_rad"]
    assert float(heading.inner_text().split()[0]) == pytest.approx(math.degrees(expected), rel=5e-4)
    image = watched.page.locator("[data-figure='align_compare_heading.png'] img")
    watched.wait_for(lambda: image.count() == 1, "the comparison's figure")
    watched.type_value("latitude", "95")
    error = watched.page.locator("[data-param=latitude] .error")
    watched.wait_for(lambda: error.inner_text().strip() != "", "the latitude's message")
    assert error.inner_text().strip() == "--latitude: '95' is outside [-89, 89] deg"
    assert watched.close() == {"console": [], "page": [], "failed": [], "outside": []}
