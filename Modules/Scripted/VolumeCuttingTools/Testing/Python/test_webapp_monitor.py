"""The nerve monitor in the web application, in Chromium on the temporal-bone phantom.

The Drill panel's meter has a row per monitored structure (the phantom's
protected segments); hovering the bone in Drill mode fills it; then the burr
is brought to the facial nerve along the normal of its arc (analytic ground
truth: the phantom's torus arc, so the burr's surface is a known distance
from the nerve's), and the FacialNerve row's distance falls with the
analytic one and its level rises; above silent the segment takes the level's
colour in the server's scene (the colour the 3D view draws it in) and gets its
own back when the burr leaves.
"""

import numpy as np
import pytest

from VolumeCuttingLib.data import phantom
from VolumeCuttingLib.feedback import nervemonitor
from VolumeCuttingLib.webapp import monitormeter
from VolumeCuttingLib.webapp.browser import AppServer, opened_app_page, screenshot_folder
from VolumeCuttingLib.webapp.session import PHANTOM_DIMENSIONS, PHANTOM_SPACING

pytestmark = pytest.mark.browser

NERVE = "FacialNerve"
# Burr surface to nerve surface (mm), far to near; the monitor's smoothed surface and the voxels (0.4-0.5 mm) make
# its distance differ from the analytic one by up to about a voxel.
APPROACH_MM = (9.0, 6.0, 4.0, 3.0, 2.0, 1.5, 1.0, 0.6)
TOLERANCE_MM = 0.6


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    return screenshot_folder(tmp_path_factory, "webapp-monitor-screenshots")


@pytest.fixture(scope="module")
def app(browser, tmp_path_factory):
    log = tmp_path_factory.mktemp("webapp-monitor") / "server.log"
    with AppServer("--phantom", log_path=log) as server, opened_app_page(browser, server.url) as application:
        yield application


def nerve_arc():
    """The facial nerve's arc in RAS as the application's phantom places it: (arc point at mid-sweep, normal, radius)."""
    scale = phantom._auto_scale(np.asarray(PHANTOM_DIMENSIONS), np.asarray(PHANTOM_SPACING, dtype=float), np.eye(3))
    anatomy = phantom.TemporalBoneAnatomy(center_ras=(0.0, 0.0, 0.0), scale=scale)
    arcs = [p for p in anatomy.segment(NERVE).primitives if isinstance(p, phantom.TorusArc)]
    assert arcs, "the phantom's facial nerve is a torus arc"
    arc = arcs[0]
    return arc.arc_point(arc.sweep_angle / 2.0), np.asarray(arc.normal, dtype=float), arc.minor_radius


def meter_row(app, name):
    return app.page.evaluate("""(name) => { const row = document.querySelector(`[data-monitor-of="${name}"]`);
        return row && {mm: row.dataset.mm === '' ? null : Number(row.dataset.mm), level: row.dataset.level,
                       text: row.textContent}; }""", name)


def diagnostics(app):
    return app.server_timing()["monitor"]


def test_hovering_the_bone_fills_the_meter(app):
    meter = app.testid("monitor-meter")
    assert meter.is_visible()
    app.wait_for(f"() => document.querySelector('[data-monitor-of=\"{NERVE}\"]')", 60, "the meter's rows")
    # Before the burr is over the bone (its glyph hidden, at a pose nobody chose) nothing is tinted.
    assert diagnostics(app)["tinted"] == []
    names = app.page.evaluate("() => [...document.querySelectorAll('[data-monitor-of]')].map(e => e.dataset.monitorOf)")
    assert set(names) == set(phantom.PROTECTED_SEGMENTS)  # the monitored structures: the protected segments
    app.set_mode("drill")
    box = app.three_d_box()
    for i in range(6):
        app.page.mouse.move(box["x"] + (0.40 + 0.03 * i) * box["width"], box["y"] + 0.45 * box["height"])
        app.page.wait_for_timeout(60)
    app.wait_for(f"() => document.querySelector('[data-monitor-of=\"{NERVE}\"]').dataset.mm !== ''", 120,
                 "the distance fields to be built and a distance shown")
    row = meter_row(app, NERVE)
    assert row["mm"] > 0.0 and "mm" in row["text"]


def test_approaching_the_facial_nerve_lowers_its_distance_raises_its_level_and_tints_it(app, shots):
    centre, normal, nerve_radius = nerve_arc()
    burr_radius = app.page.evaluate("() => window.trame.state.get('vc_tool').diameter") / 2.0
    own = diagnostics(app)["colours"][NERVE]
    readings = []
    previous = "''"
    for gap in APPROACH_MM:
        point = centre + normal * (nerve_radius + burr_radius + gap)
        assert app.page.evaluate("(p) => window.trame.trigger('vc_place_tool', [p])", point.tolist()) is True
        # The meter's reading for this pose, not the last pose's still shown (within the tolerance of both).
        app.wait_for(f"""() => {{ const r = document.querySelector('[data-monitor-of="{NERVE}"]');
                         return r && r.dataset.mm !== '' && r.dataset.mm !== {previous}
                           && Math.abs(Number(r.dataset.mm) - {gap}) < {TOLERANCE_MM}; }}""",
                     20, f"the meter to read about {gap} mm")
        readings.append((gap, meter_row(app, NERVE), diagnostics(app)))
        previous = repr(app.page.evaluate(f"() => document.querySelector('[data-monitor-of=\"{NERVE}\"]').dataset.mm"))
    distances = [row["mm"] for _, row, _ in readings]
    assert all(b < a for a, b in zip(distances, distances[1:])), f"the distance does not fall: {distances}"
    levels = [nervemonitor.LEVEL_NAMES.index(row["level"]) for _, row, _ in readings]
    assert levels[0] == 0 and levels[-1] >= 2 and levels == sorted(levels), f"levels along the approach: {levels}"
    for _, row, monitor in readings:
        colour = monitor["colours"][NERVE]
        if row["level"] == "silent":
            assert colour == pytest.approx(own, abs=1e-3)
            assert NERVE not in monitor["tinted"]
        else:
            assert colour == pytest.approx(monitormeter.hex_to_rgb(nervemonitor.LEVEL_COLOURS[row["level"]]), abs=1e-3)
            assert NERVE in monitor["tinted"]
    # The segments table keeps the nerve's own colour while the 3D view shows the tint.
    segments = app.page.evaluate("() => window.trame.state.get('vc_segments')")
    table_colour = next(s["color"] for s in segments if s["name"] == NERVE)
    assert table_colour == monitormeter.rgb_to_hex(own)
    app.testid("monitor-meter").scroll_into_view_if_needed()
    app.settle(1000, 30)
    app.screenshot(shots / "14-nerve-monitor.png")
    # Away again: silent, in its own colour.
    point = centre + normal * (nerve_radius + burr_radius + APPROACH_MM[0])
    assert app.page.evaluate("(p) => window.trame.trigger('vc_place_tool', [p])", point.tolist()) is True
    app.wait_for(f"() => document.querySelector('[data-monitor-of=\"{NERVE}\"]').dataset.level === 'silent'", 20,
                 "the nerve to be silent again")
    assert diagnostics(app)["colours"][NERVE] == pytest.approx(own, abs=1e-3)
    print("approach (gap mm, meter mm, level):", [(gap, row["mm"], row["level"]) for gap, row, _ in readings])
