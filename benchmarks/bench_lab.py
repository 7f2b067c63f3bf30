"""Benchmark: how long the gyrocompassing page of ``schuler lab`` takes to follow a change.

Starts ``schuler lab`` on a free port, opens ``/align`` in Debian's Chromium
(Playwright), sets an east drift of 0.02 deg/h and types a new latitude CHANGES times; each latency is the time
from Enter to the new azimuth-error number on the page (its figures are drawn
in the same update). The baseline measured in the same run is the computation
alone (``System.run`` of the same case plus building the figures, in process),
so the ratio shows what the web round trip adds. Target: median below 1 s.
The machine's load average is printed beside: the latency grows with it.
"""

from __future__ import annotations

import math
import os
import statistics
import subprocess
import sys
import time

from schuler.lab import figures, system_page
from schuler.registry import get_system

CHANGES = 12
TARGET_S = 1.0
LATITUDES = ("45", "30", "60", "20", "70", "50")


def start_server() -> tuple[subprocess.Popen, str]:
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONUNBUFFERED": "1"}
    process = subprocess.Popen([sys.executable, "-m", "schuler", "lab", "--port", "0", "--no-browser"],
                               stdout=subprocess.PIPE, text=True, env=env)
    return process, process.stdout.readline().split()[4]


def computation_only() -> float:
    """Median seconds of the run and its figures alone, in this process."""
    system = get_system("align")
    times = []
    for latitude in LATITUDES:
        start = time.perf_counter()
        result = system_page.run_typed(system, {"latitude": latitude})
        figures.interactive_figures(system, result)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> int:
    from playwright.sync_api import sync_playwright

    baseline = computation_only()
    process, url = start_server()
    latencies = []
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True,
                                        args=["--headless", "--no-sandbox", "--disable-gpu"])
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.goto(url + "align")
            number = page.locator("[data-result=azimuth_error_rad]")
            field = page.locator("[data-param=latitude] input")
            while number.inner_text().strip() == "-":
                page.wait_for_timeout(25)
            # a drift, so that the azimuth error depends on the latitude (without one it is 0 at every latitude)
            page.locator("[data-param=drift_east] input").fill("0.02")
            page.locator("[data-param=drift_east] input").press("Enter")
            while number.inner_text().strip() == "0 arcmin":
                page.wait_for_timeout(25)
            for change in range(CHANGES):
                shown = number.inner_text()
                field.fill(LATITUDES[change % len(LATITUDES)])
                start = time.perf_counter()
                field.press("Enter")
                while number.inner_text() == shown:
                    page.wait_for_timeout(10)
                latencies.append(time.perf_counter() - start)
                page.wait_for_timeout(300)
            browser.close()
    finally:
        process.terminate()
        process.wait(timeout=30)
    median = statistics.median(latencies)
    p90 = sorted(latencies)[math.ceil(0.9 * len(latencies)) - 1]
    print(f"load average (1 min): {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"computation alone (run + figures): {baseline * 1000:.0f} ms")
    print(f"page update, Enter to new number: median {median * 1000:.0f} ms, 90 % {p90 * 1000:.0f} ms, "
          f"max {max(latencies) * 1000:.0f} ms over {CHANGES} changes")
    print(f"ratio page / computation: {median / baseline:.1f}; target median < {TARGET_S:g} s: "
          f"{'met' if median < TARGET_S else 'NOT met'}")
    return 0 if median < TARGET_S else 1


if __name__ == "__main__":
    sys.exit(main())
