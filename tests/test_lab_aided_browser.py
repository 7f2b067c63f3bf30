"""The ``aided`` page in Chromium (skipped without it): typed values and ticked aiding names run the case, the
error figure shows the outage shaded on every row."""

from __future__ import annotations

import pytest

from test_lab_browser import Watched, browser, server  # noqa: F401  (the fixtures)

pytestmark = pytest.mark.slow

FIGURE = "[data-figure=aided_errors] .js-plotly-plot"
HORIZONTAL = "[data-result=position_error_horizontal_rms_m]"


def test_the_aided_page_runs_the_typed_case_and_shades_its_outage(server, browser, tmp_path):  # noqa: F811
    from schuler.registry import get_system

    watched = Watched(browser, server)
    watched.open("aided")
    watched.type_value("duration", "300")
    watched.type_value("outage_start", "120")
    expected = get_system("aided").run(duration=300.0, outage_start=120.0)
    shown = f"{expected.position_error_horizontal_rms_m:.4g} m"
    watched.wait_for(lambda: watched.text(HORIZONTAL) == shown, "the typed case")

    def shapes():
        return watched.page.locator(FIGURE).evaluate("element => (element.layout.shapes || []).length")

    watched.wait_for(lambda: shapes() == 4, "the outage on the four rows")
    watched.page.locator("[data-param=aiding] label", has_text="gnss-position").click()
    only_position = get_system("aided").run(duration=300.0, outage_start=120.0, aiding="gnss-position")
    watched.wait_for(lambda: watched.text(HORIZONTAL) == f"{only_position.position_error_horizontal_rms_m:.4g} m",
                     "the ticked aiding")
    watched.page.screenshot(path=str(tmp_path / "aided.png"), full_page=True)
    assert watched.close() == {"console": [], "page": [], "failed": [], "outside": []}
