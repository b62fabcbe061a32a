"""Whole journeys through the web application, as a person takes them: each step in sequence on one page.

A part that passes alone can fail in sequence: drilling worked until the camera had been turned, and an own scan
opened as a close-up (issue 28). Each journey here opens a scan, checks that it opens whole in the view, sets roles,
turns the head, drills, zooms in, turns again, drills, undoes and redoes, exports the scene and reads the bundle back
with Slicer Core. Journeys: the phantom (shipped, the application's start), the example head CT (chosen in the Data
panel), a scan of one's own whose tissue fills its box, given by its server path with a labelmap whose segments
start without a role, and the high-resolution temporal bone (288^3 at 0.15 mm, 14 structures drawn slice by slice,
``data.temporalbone``) as a user brings it: CT, labelmap and colour table, roles by name on the command line and
one more by hand in the Segments panel.

Screenshots of every step go to ``$VOLUMECUTTING_SCREENSHOTS/journeys`` (Docs/webapp/journeys holds the committed
ones), else into pytest's temporary folder.
"""

import os
import time
from pathlib import Path

import numpy as np
import pytest

from VolumeCuttingLib.webapp.browser import AppPage, AppServer

pytestmark = pytest.mark.browser

VIEWPORT = {"width": 1440, "height": 900}
HINT_ROWS = 40  # the mode hint along the view's bottom edge


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    folder = os.environ.get("VOLUMECUTTING_SCREENSHOTS")
    path = Path(folder) / "journeys" if folder else tmp_path_factory.mktemp("journey-screenshots")
    path.mkdir(parents=True, exist_ok=True)
    return path


def write_nrrd(path: Path, array_kji: np.ndarray, spacing_mm: float, type_name: str) -> Path:
    k, j, i = array_kji.shape
    header = (f"NRRD0004\ntype: {type_name}\ndimension: 3\nspace: left-posterior-superior\nsizes: {i} {j} {k}\n"
              f"space directions: ({spacing_mm},0,0) (0,{spacing_mm},0) (0,0,{spacing_mm})\nkinds: domain domain domain\n"
              "endian: little\nencoding: raw\nspace origin: (0,0,0)\n\n")
    path.write_bytes(header.encode() + np.ascontiguousarray(array_kji).tobytes())
    return path


def write_bone_block(folder: Path) -> tuple[Path, Path]:
    """A 24 mm block of bone to its faces at 0.3 mm, a nerve and a sinus inside; a labelmap and its colour table."""
    n, spacing = 80, 0.3
    k, j, i = np.mgrid[0:n, 0:n, 0:n]
    labels = np.ones((n, n, n), np.uint8)  # Mastoid everywhere: the block is bone to its faces
    nerve = (i - 40) ** 2 + (j - 52) ** 2 <= 4 ** 2
    sinus = (i - 40) ** 2 + (j - 20) ** 2 + (k - 40) ** 2 <= 9 ** 2
    labels[nerve], labels[sinus] = 2, 3
    rng = np.random.default_rng(7)
    ct = np.choose(labels, [-1000, 1300, 40, 60]).astype(np.int16) + rng.normal(0, 20, labels.shape).astype(np.int16)
    ct_path = write_nrrd(folder / "block-ct.nrrd", ct, spacing, "short")
    labels_path = write_nrrd(folder / "block-labels.nrrd", labels, spacing, "unsigned char")
    (folder / "block-labels.ctbl").write_text("1 Mastoid 230 220 170 255\n2 FacialNerve 240 240 40 255\n3 Sinus 40 80 200 255\n")
    return ct_path, labels_path


def view_point(app, fx, fy):
    box = app.three_d_box()
    return box["x"] + fx * box["width"], box["y"] + fy * box["height"]


def border_tissue_share(app) -> float:
    """The share of the 3D view's border pixels that show tissue (bright) rather than the dark background."""
    pixels = app.three_d_pixels()[:-HINT_ROWS].astype(int)  # the bottom ring lies just above the hint
    ring = np.concatenate([pixels[:6].reshape(-1, 3), pixels[-6:].reshape(-1, 3),
                           pixels[:, :6].reshape(-1, 3), pixels[:, -6:].reshape(-1, 3)])
    return float((ring.mean(axis=1) > 110).mean())


def settle(app):
    box = app.three_d_box()
    app.page.mouse.move(box["x"] + 8, box["y"] + box["height"] - 8)
    app.wait_refined(1000, 300)


def set_role(app, segment_id, role, timeout_s=30):
    app.page.locator(f'[data-role-of="{segment_id}"]').click()
    app.page.locator(".v-overlay--active .v-list-item", has_text=role).first.click()
    app.wait_for(f"""() => [...document.querySelectorAll('[data-role-of="{segment_id}"]')]
                     .some(e => e.textContent.includes('{role}'))""", timeout_s, f"the role of {segment_id} to read {role}")


def rotate(app, degrees_of_view=0.25):
    """Navigate, then drag across the view as a person turns the head; then click Drill and press at once."""
    app.testid("mode-navigate").click()
    app.drag([view_point(app, 0.35 + degrees_of_view * t / 20, 0.5 + 0.05 * t / 20) for t in range(21)], 20)


def drill_now(app, fx, fy, what):
    """Click Drill and drag over the bone straight away, without waiting for the server: as a person does."""
    before = app.total_removed()
    app.testid("mode-drill").click()
    app.drag([view_point(app, fx + 0.003 * i, fy) for i in range(30)], 20)
    app.wait_for_total_removed(f"v > {before + 0.5}", 90)
    return settled_total(app, what)


def settled_total(app, what, timeout_s=180):
    """The removed volume once the server has taken the whole drag: the same figure a quiet second apart.

    On a loaded machine the strokes of one drag arrive for several seconds after the page is still.
    """
    deadline = time.monotonic() + timeout_s
    last = None
    while time.monotonic() < deadline:
        app.wait_still(1000, timeout_s)
        now = app.total_removed()
        if now == last:
            return now
        last = now
        app.page.wait_for_timeout(1000)
    raise AssertionError(f"the removed volume {what} did not settle in {timeout_s} s (last {last})")


def finish_journey(app, shots, prefix, tmp_path, fx, fy):
    """The steps every journey shares once roles are set: rotate, drill, zoom, rotate, drill, undo, redo, export, reload."""
    rotate(app)
    settle(app)
    app.screenshot(shots / f"{prefix}-03-rotated.png")
    first = drill_now(app, fx, fy, "after the first rotation")
    settle(app)
    app.screenshot(shots / f"{prefix}-04-drilled-after-rotation.png")
    app.testid("mode-navigate").click()
    box = app.three_d_box()
    app.page.mouse.move(*view_point(app, fx, fy))
    for _ in range(3):
        app.page.mouse.wheel(0, -240)  # zoom in towards the cavity
        app.page.wait_for_timeout(150)
    settle(app)
    app.screenshot(shots / f"{prefix}-05-zoomed.png")
    rotate(app, -0.15)
    settle(app)
    second = drill_now(app, fx, fy + 0.05, "after zooming and a second rotation")
    assert second > first
    settle(app)
    app.screenshot(shots / f"{prefix}-06-drilled-again.png")
    app.testid("undo").click()
    app.wait_for_total_removed(f"Math.abs(v - {first}) < 0.011", 180)
    app.testid("redo").click()
    app.wait_for_total_removed(f"Math.abs(v - {second}) < 0.011", 180)
    settle(app)
    app.screenshot(shots / f"{prefix}-07-undone-and-redone.png")
    app.page.locator('[data-testid="export-scene"]').scroll_into_view_if_needed()
    bundle_path = app.download("export-scene", tmp_path)
    app.screenshot(shots / f"{prefix}-08-exported.png")
    reload_and_compare(app, bundle_path, tmp_path)


def reload_and_compare(app, bundle_path, tmp_path):
    """The downloaded scene read back by Slicer Core: one cut node, each segment's removed volume as the page showed it."""
    from VolumeCuttingLib.scene.application import HeadlessSlicer

    shown = {element.get_attribute("data-removed-of"): float(element.inner_text())
             for element in app.page.locator("[data-removed-of]").all()}
    bundle = HeadlessSlicer(tmp_path / "bundle-cache")
    bundle.load_bundle(bundle_path)
    cut_nodes = [bundle.scene.GetNthNodeByClass(i, "vtkMRMLVolumeCutNode")
                 for i in range(bundle.scene.GetNumberOfNodesByClass("vtkMRMLVolumeCutNode"))]
    assert len(cut_nodes) == 1
    for segment_id, removed in shown.items():
        reloaded = bundle.volume_cutting_logic.GetRemovedVolumeInSegment(cut_nodes[0], segment_id)
        assert reloaded == pytest.approx(removed, abs=0.006), segment_id  # the page rounds to 0.01 mm3
    assert sum(shown.values()) > 1.0


def open_page(browser, server, timeout_s=300):
    context = browser.new_context(viewport=VIEWPORT, device_scale_factor=1, accept_downloads=True)
    page = context.new_page()
    page.set_default_timeout(60000)
    app = AppPage(page, timing=True)
    app.open(server.url, timeout_s)  # a large scan is read before the page is served
    app.wait_ready(timeout_s)
    app.wait_still(1500, timeout_s)
    return context, app


def test_phantom_journey(browser, tmp_path, shots):
    log = tmp_path / "server.log"
    with AppServer("--phantom", log_path=log) as server:
        context, app = open_page(browser, server)
        assert border_tissue_share(app) < 0.02
        app.screenshot(shots / "phantom-01-opened.png")
        set_role(app, "MastoidBone", "protected")
        app.screenshot(shots / "phantom-02-roles.png")
        finish_journey(app, shots, "phantom", tmp_path, 0.42, 0.45)
        assert app.removed_volume("MastoidBone") == 0.0
        context.close()


@pytest.mark.realdata
def test_head_ct_journey(browser, tmp_path, shots):
    log = tmp_path / "server.log"
    with AppServer("--phantom", log_path=log) as server:
        context, app = open_page(browser, server)
        app.page.locator('[data-testid="source"]').click()
        app.page.locator(".v-overlay--active .v-list-item", has_text="Example head CT").click()
        app.testid("load").click()
        app.wait_for("() => (document.querySelector('[data-testid=status]')?.textContent || '').includes('Ready: Example head CT')",
                     180, "the head CT to be ready")
        app.wait_still(1500, 180)
        assert border_tissue_share(app) < 0.02
        app.screenshot(shots / "headct-01-opened.png")
        finish_journey(app, shots, "headct", tmp_path, 0.45, 0.40)
        context.close()


def test_own_block_journey(browser, tmp_path, shots):
    """A scan of one's own, by its server path: it opens whole, its role-less segments say how to go on."""
    data = tmp_path / "scans"
    data.mkdir()
    ct_path, labels_path = write_bone_block(data)
    log = tmp_path / "server.log"
    with AppServer("--ct", ct_path, "--segmentation", labels_path, "--data-dir", data, log_path=log) as server:
        context, app = open_page(browser, server)
        share = border_tissue_share(app)
        app.screenshot(shots / "own-01-opened.png")
        assert share < 0.02, f"{share:.0%} of the view's border shows the block: it opened as a close-up"
        # Every segment of a labelmap starts without a role: the burr stops and the warning says what to do.
        app.testid("mode-drill").click()
        app.drag([view_point(app, 0.45 + 0.003 * i, 0.55) for i in range(20)], 20)
        warning = app.testid("contact-warning")
        warning.wait_for(state="visible", timeout=60000)
        assert "not cuttable" in warning.inner_text() and "Segments panel" in warning.inner_text()
        assert app.total_removed() == 0.0
        app.screenshot(shots / "own-02-not-cuttable.png")
        app.testid("make-cuttable").click()
        app.wait_for("""() => [...document.querySelectorAll('[data-role-of]')]
                         .some(e => e.textContent.includes('cuttable'))""", 30, "the segment to become cuttable")
        set_role(app, app.page.locator("[data-removed-of]").nth(1).get_attribute("data-removed-of"), "protected")
        finish_journey(app, shots, "own", tmp_path, 0.45, 0.50)
        context.close()


def segment_id_named(app, name):
    return app.page.locator("tr[data-segment]", has_text=name).first.get_attribute("data-segment")


def test_temporal_bone_journey(browser, tmp_path, shots):
    """The anatomy the product exists for: mastoid made cuttable, nerve and sinus protected, drilled after turning.

    Roles come as a user with a labelmap of their own gives them: most by name on the command line (as the main
    job takes them), one by hand in the Segments panel. Each role change rebuilds the 24-million-voxel masks.
    """
    from VolumeCuttingLib.data import temporalbone

    paths = temporalbone.cached_case_files()
    log = tmp_path / "server.log"
    with AppServer("--ct", paths["ct"], "--segmentation", paths["labels"], "--data-dir", paths["ct"].parent,
                   "--cuttable", "Mastoid bone", "--protected", "Facial nerve,Sigmoid sinus", log_path=log) as server:
        context, app = open_page(browser, server)
        share = border_tissue_share(app)
        app.screenshot(shots / "temporalbone-01-opened.png")
        assert share < 0.02, f"{share:.0%} of the view's border shows bone: it opened as a close-up"
        cuttable = [segment_id_named(app, name) for name in ("Mastoid bone", "Mastoid air cells")]
        protected = [segment_id_named(app, name) for name in ("Facial nerve", "Sigmoid sinus")]
        roles = {segment_id: app.page.locator(f'[data-role-of="{segment_id}"]').inner_text()
                 for segment_id in cuttable + protected}
        assert "cuttable" in roles[cuttable[0]] and "cuttable" not in roles[cuttable[1]], roles
        assert all("protected" in roles[segment_id] for segment_id in protected), roles
        set_role(app, cuttable[1], "cuttable", 180)
        app.screenshot(shots / "temporalbone-02-roles.png")
        finish_journey(app, shots, "temporalbone", tmp_path, 0.45, 0.45)
        untouched = [element.get_attribute("data-removed-of") for element in app.page.locator("[data-removed-of]").all()]
        removed = {segment_id: app.removed_volume(segment_id) for segment_id in untouched}
        assert sum(removed[segment_id] for segment_id in cuttable) > 1.0
        assert all(volume == 0.0 for segment_id, volume in removed.items() if segment_id not in cuttable), removed
        context.close()
