"""The drill sound in Chromium: the page's AudioWorklet rendered in an OfflineAudioContext passes the spectrum
checks of the Python synthesiser and gives its samples; a parameter change is heard within 50 ms; in the web
application the sound switch and volume play what the server publishes at 50 Hz while drilling.

The worklet checks open the application's own ``www`` folder from a plain HTTP server (``SoundPage``: the
same files the application serves); the last tests drive the application on the temporal-bone phantom.
"""

import dataclasses

import numpy as np
import pytest

from VolumeCuttingLib.feedback import drillsound, soundanalysis
from VolumeCuttingLib.feedback.drillsound import SoundParameters
from VolumeCuttingLib.webapp.browser import AppServer, SoundPage, opened_app_page

pytestmark = pytest.mark.browser

RATE = drillsound.SAMPLE_RATE
ENGAGED = SoundParameters(drill_on=True, contact=True)
# The browser's bound (issue 25): a parameter change is heard within 50 ms.
BROWSER_LATENCY_MS = 50.0


@pytest.fixture(scope="module")
def sound_page(browser):
    with SoundPage(browser) as page:
        yield page


def render_in_browser(sound_page, schedule, seconds, config=None):
    if isinstance(schedule, SoundParameters):
        schedule = [(0.0, schedule)]
    return sound_page.render([(t, p.as_dict()) for t, p in schedule], seconds,
                             None if config is None else dataclasses.asdict(config))


@pytest.mark.parametrize("parameters", [
    ENGAGED,
    ENGAGED.replace(burr="diamond", rpm=35000.0, load=0.6, thickness_mm=0.8),
    SoundParameters(drill_on=True, rpm=90000.0, monitor_level="bursts", monitor_rate_hz=60.0, volume=0.7),
], ids=["cutting", "diamond-loaded-thin", "idle-bursts"])
def test_the_worklet_renders_the_samples_of_the_python_model(sound_page, parameters):
    browser_samples = render_in_browser(sound_page, parameters, 0.5)
    # The worklet renders quanta of 128 frames: the Python model at that block size, to float32 precision.
    python_samples = drillsound.synthesize(parameters, 0.5, block=128)
    assert np.abs(browser_samples - python_samples).max() < 1e-5


def test_the_worklet_follows_a_schedule_as_the_python_model(sound_page):
    # Changes on 128-frame boundaries, from standstill: spin-up, contact, load, a burst of clicks, spin-down.
    schedule = [(0.0, SoundParameters()), (128 * 10 / RATE, SoundParameters(drill_on=True)),
                (128 * 100 / RATE, ENGAGED.replace(load=0.5)),
                (128 * 150 / RATE, ENGAGED.replace(load=0.5, monitor_level="bursts", monitor_rate_hz=80.0)),
                (128 * 250 / RATE, SoundParameters())]
    browser_samples = render_in_browser(sound_page, schedule, 1.0)
    python_samples = drillsound.synthesize(schedule, 1.0, block=128)
    python_samples_unsteady = drillsound.synthesize(schedule, 1.0, block=128, steady=False)
    assert np.abs(browser_samples - python_samples).max() < 1e-5
    assert np.abs(python_samples - python_samples_unsteady).max() == 0.0  # silence is its own steady state


@pytest.mark.parametrize("burr", drillsound.BURR_TYPES)
@pytest.mark.parametrize("rpm", [20000.0, 60000.0, 80000.0])
def test_the_worklet_peaks_at_harmonics_of_the_burr_speed(sound_page, burr, rpm):
    samples = render_in_browser(sound_page, ENGAGED.replace(rpm=rpm, burr=burr), 1.0)
    errors = soundanalysis.harmonic_errors(samples, rpm / 60.0, drillsound.SPECTRA[burr]["partials"])
    for k, (error, prominence) in errors.items():
        assert abs(error) < 0.02 and prominence > 10.0, (k, error, prominence)


def test_the_worklet_load_thinning_clipping_and_clicks(sound_page):
    config = drillsound.SoundConfig()
    free = soundanalysis.fundamental(render_in_browser(sound_page, ENGAGED, 1.0), 1000.0)
    loaded = soundanalysis.fundamental(render_in_browser(sound_page, ENGAGED.replace(load=1.0), 1.0), 850.0)
    assert loaded / free == pytest.approx(1.0 - config.load_pitch_drop, abs=0.002)
    thin = soundanalysis.fundamental(render_in_browser(sound_page, ENGAGED.replace(thickness_mm=0.5), 1.0), 1000.0)
    assert thin / free == pytest.approx(1.0 + config.thin_pitch_rise * 0.75, abs=0.003)
    loudest = render_in_browser(sound_page, ENGAGED.replace(rpm=150000.0, monitor_level="contact", monitor_rate_hz=1000.0), 1.0)
    assert np.abs(loudest).max() <= drillsound.HEADROOM
    clicks = render_in_browser(sound_page, SoundParameters(monitor_level="sparse", monitor_rate_hz=25.0), 2.0)
    assert abs(len(soundanalysis.click_onsets(clicks)) - 50) <= 1


def test_the_worklet_glides_at_a_change(sound_page):
    before, after = ENGAGED, ENGAGED.replace(load=1.0, burr="diamond")
    at = 128 * 200 / RATE
    unchanged = render_in_browser(sound_page, before, 1.0)
    changed = render_in_browser(sound_page, [(0.0, before), (at, after)], 1.0)
    first, jump = soundanalysis.onset_jump(changed, unchanged)
    assert first == 128 * 200 and jump <= 0.02


def test_a_bad_value_keeps_the_previous_sound(sound_page):
    bad = dict(ENGAGED.as_dict(), rpm=-5.0)
    samples = sound_page.render([(0.0, ENGAGED.as_dict()), (0.1, bad)], 0.3)
    assert np.abs(np.array(samples) - drillsound.synthesize(ENGAGED, 0.3, block=128)).max() < 1e-5


def test_a_change_is_heard_within_50_ms_in_the_browser(sound_page):
    results = sound_page.measure_latency(ENGAGED.as_dict(), ENGAGED.replace(load=1.0).as_dict(), 20)
    latencies = [r["latencyMs"] for r in results]
    print(f"browser latency: median {np.median(latencies):.1f} ms, max {max(latencies):.1f} ms, output latency "
          f"{results[0]['outputLatencyMs']:.1f} ms, via the output timestamp: {results[0]['viaTimestamp']}")
    assert max(latencies) <= BROWSER_LATENCY_MS
    assert min(latencies) > 0.0


# ---------------------------------------------------------------- the application


@pytest.fixture(scope="module")
def app(browser, tmp_path_factory):
    log = tmp_path_factory.mktemp("webapp-sound") / "server.log"
    with AppServer("--phantom", log_path=log) as server, opened_app_page(browser, server.url, still_ms=1500) as application:
        yield application


def test_the_page_has_a_sound_switch_and_volume(app):
    switch = app.testid("sound-switch")
    assert switch.is_visible() and "Drill sound" in switch.inner_text()
    assert app.page.evaluate("() => window.trame.state.get('vc_sound_on')") is False
    assert app.page.evaluate("() => !window.vcDrillSound.context")  # silent until switched on
    switch.locator("input").click()
    app.wait_for("() => window.vcDrillSound.context && window.vcDrillSound.context.state === 'running'", 30,
                 "the audio context to run")
    slider = app.page.locator('[data-testid="sound-volume"] [role="slider"]')
    slider.focus()
    for _ in range(4):
        slider.press("ArrowLeft")
    app.wait_for("() => Math.abs(window.vcDrillSound.volume - 0.3) < 1e-6", 20, "the volume to read 0.3")


def test_drilling_feeds_the_worklet_at_50_hz(app):
    """While the pedal is down (a stroke held), the server publishes vc_sound at 75 Hz and the page passes it on.

    The rate is measured while the pointer rests in the stroke: each move also cuts and renders on the
    server's one event loop (hundreds of ms a move on this shared 2-core machine with llvmpipe), which
    delays the ticks behind it; that rate is printed, not bounded.
    """
    app.set_mode("drill")
    box = app.three_d_box()
    mouse = app.page.mouse
    path = [(box["x"] + (0.40 + 0.004 * i) * box["width"], box["y"] + (0.45 + 0.001 * i) * box["height"]) for i in range(8)]
    app.page.evaluate("() => { window.vcDrillSound.receivedAt.length = 0; window.vcDrillSound.transportMs.length = 0; }")
    mouse.move(*path[0])
    mouse.down()
    for x, y in path[1:]:
        app.page.wait_for_timeout(30)
        mouse.move(x, y)
    app.wait_for("() => window.trame.state.get('vc_sound').parameters.drill_on === true", 180, "the drill to start")
    # The server has taken the moves once the contact (removal) shows; then the pointer rests, pedal down.
    app.wait_for("() => window.trame.state.get('vc_sound').parameters.contact === true", 180, "the burr on bone")
    moving = app.page.evaluate("() => window.vcDrillSound.receivedAt.slice()")
    # The last 2 s of a 3 s rest: the first second still has the view's refinement render after the moves.
    app.page.wait_for_timeout(1000)
    held_from = app.page.evaluate("() => performance.now()")
    app.page.wait_for_timeout(2000)
    held = app.page.evaluate("(t) => window.vcDrillSound.receivedAt.filter((a) => a >= t)", held_from)
    transport = np.array(app.page.evaluate("() => window.vcDrillSound.transportMs"))
    rate_held = (len(held) - 1) / ((held[-1] - held[0]) / 1000.0) if len(held) > 1 else 0.0
    rate_moving = (len(moving) - 1) / ((moving[-1] - moving[0]) / 1000.0) if len(moving) > 1 else 0.0
    print(f"vc_sound at {rate_held:.1f} Hz with the stroke held, {rate_moving:.1f} Hz while the moves were cut; "
          f"server to page median {np.median(transport):.1f} ms, p95 {np.percentile(transport, 95):.1f} ms", flush=True)
    mouse.up()
    app.wait_for("() => window.trame.state.get('vc_sound').parameters.drill_on === false", 180, "the drill to stop")
    assert rate_held >= 50.0
    sound = app.page.evaluate("() => window.vcDrillSound.parameters")
    assert not sound["drill_on"] and sound["rpm"] > 0  # the pedal is up: the motor spins down
