"""The web application's Progress panel: a trainee's learning curves from the records.

Without a browser: the chart's geometry against hand-computed pixels, and the
panel's state from a seeded database and from one that cannot be reached.
In Chromium: the application started with ``--records`` on a seeded SQLite
file; the panel opened, a trainee chosen, and the points of the drawn curves
read back from the page.
"""

import os
from pathlib import Path

import pytest
from test_records import closed_loopback_port, make_assessment
from trame.app import get_server

from VolumeCuttingLib.records import database
from VolumeCuttingLib.webapp import progress
from VolumeCuttingLib.webapp.browser import AppPage, AppServer

# Ann's sessions in time order (added out of order below): score, Dice, facial-nerve contacts (None: not measured).
ANN = [("2026-10-01T09:00:00Z", 31.0, 0.42, 4), ("2026-10-08T09:00:00Z", 48.5, 0.61, 2),
       ("2026-10-15T09:00:00Z", 44.0, 0.66, None), ("2026-10-22T09:00:00Z", 72.25, 0.83, 0)]


@pytest.fixture(scope="module")
def seeded(tmp_path_factory):
    path = tmp_path_factory.mktemp("records") / "records.sqlite"
    with database.open(str(path)) as records:
        for i in (2, 0, 3, 1):
            started, score, dice, contacts = ANN[i]
            metrics = {"final.dice": dice, "efficiency.path_length_mm": 900.0 - 100 * i}
            if contacts is not None:
                metrics["safety.contacts.FacialNerve"] = contacts
            records.add_assessment("Ann Resident", make_assessment(f"ann{i}", started, score, metrics))
        records.add_assessment("Bob Resident", make_assessment("bob0", "2026-10-02T09:00:00Z", 55.0))
    return path


def test_chart_points_are_the_values_on_the_charts_axes():
    # Plot area: x from 44 to 330 (width 340 minus margins 44 and 10), y from 18 (largest) to 98 (smallest).
    points = progress.chart_points([(1, 10.0), (2, None), (3, 30.0), (5, 20.0)])
    assert points == [(1, 10.0, 44.0, 98.0), (3, 30.0, 187.0, 18.0), (5, 20.0, 330.0, 58.0)]
    # One session, or one value for all: in the middle, not a division by zero.
    assert progress.chart_points([(1, 7.0)]) == [(1, 7.0, 187.0, 58.0)]
    assert progress.chart_points([(1, None), (2, float("nan"))]) == []
    assert "not measured" in progress.chart_svg("final.dice", [(1, None)], {})
    assert progress.default_metrics(["a.b", "final.dice", "z"]) == ["final.dice"]
    assert progress.default_metrics(["a.b", "c.d", "e.f"]) == ["a.b", "c.d"]


def test_the_panel_reads_the_records_and_says_when_it_cannot(seeded):
    server = get_server("progress-seeded", client_type="vue3")
    panel = progress.ProgressPanel(server, str(seeded))
    panel.refresh()
    state = server.state
    assert state.vc_pg_error == "" and state.vc_pg_trainees == ["Ann Resident", "Bob Resident"]
    state.vc_pg_trainee = "Ann Resident"
    panel._trainee_changed()
    assert state.vc_pg_metrics == ["final.dice", "safety.contacts.FacialNerve"]
    assert [c["name"] for c in state.vc_pg_charts] == ["score", "final.dice", "safety.contacts.FacialNerve"]
    assert state.vc_pg_charts[0]["svg"].count("<circle") == 4
    assert state.vc_pg_charts[2]["svg"].count("<circle") == 3  # the third session measured no contacts

    unreachable = get_server("progress-unreachable", client_type="vue3")
    panel = progress.ProgressPanel(unreachable, f"postgresql+psycopg://u:pw@127.0.0.1:{closed_loopback_port()}/r")
    panel.refresh()
    assert unreachable.state.vc_pg_error.startswith("The trainee records cannot be read: cannot open the records database")
    assert unreachable.state.vc_pg_trainees == [] and ":pw@" not in unreachable.state.vc_pg_error


@pytest.mark.browser
def test_the_progress_panel_draws_a_trainees_learning_curves_in_the_browser(seeded, browser, tmp_path):
    with AppServer("--phantom", "--records", seeded, log_path=tmp_path / "server.log") as server:
        context = browser.new_context(viewport={"width": 1440, "height": 900}, device_scale_factor=1)
        page = context.new_page()
        page.set_default_timeout(60000)
        app = AppPage(page)
        app.open(server.url)
        app.wait_ready(300)
        app.testid("progress-panel").click()
        app.wait_for("() => (window.trame.state.get('vc_pg_trainees') || []).length === 2", 30, "the trainees")
        app.testid("progress-trainee").click()
        page.locator(".v-list-item", has_text="Ann Resident").click()
        page.wait_for_function("() => document.querySelectorAll('[data-chart] circle').length === 11", timeout=30000)

        def drawn(curve):
            return page.eval_on_selector_all(
                f'[data-chart="{curve}"] circle',
                "cs => cs.map(c => [+c.dataset.number, +c.dataset.value, +c.getAttribute('cx'), +c.getAttribute('cy')])")

        score = drawn("score")
        assert [(n, v) for n, v, _, _ in score] == [(1, 31.0), (2, 48.5), (3, 44.0), (4, 72.25)]
        assert [(x, y) for _, _, x, y in score] == [(x, y) for _, _, x, y in progress.chart_points(
            [(i + 1, s[1]) for i, s in enumerate(ANN)])]
        # Better sessions are drawn higher: the 72.25 at the top, the 31 at the bottom of the plot.
        assert score[3][3] == progress.MARGIN_TOP and score[0][3] == progress.CHART_HEIGHT - progress.MARGIN_BOTTOM
        assert [(n, v) for n, v, _, _ in drawn("final.dice")] == [(1, 0.42), (2, 0.61), (3, 0.66), (4, 0.83)]
        assert [(n, v) for n, v, _, _ in drawn("safety.contacts.FacialNerve")] == [(1, 4.0), (2, 2.0), (4, 0.0)]
        assert app.testid("progress-sessions").inner_text() == "4 sessions, oldest on the left"
        folder = Path(os.environ.get("VOLUMECUTTING_SCREENSHOTS") or tmp_path)
        page.locator(".v-expansion-panel", has=app.testid("progress-panel")).screenshot(path=str(folder / "12-progress.png"))
        context.close()
