"""The drill sound's figures (issue 25): synthesis cost against real time, the spectrum checks' errors,
and the latency from a parameter change to the changed sound on the desktop and in Chromium.

Each figure is set against what it must stay within, as its baseline: a
256-frame block's duration for the synthesis cost (ratio: the share of real
time one core spends rendering), the 2 % bound for peak errors, the
configured ratios for load and thinning, 10 ms (desktop) and 50 ms (browser)
for latencies. ``sound_measurements`` is combined by the lead into area
``feedback``; it is not registered as an area of its own.
"""

from __future__ import annotations

import dataclasses
import statistics
import time

import numpy as np

from ..feedback import audioout, drillsound, soundanalysis
from ..feedback.drillsound import SoundParameters
from .harness import machine_description, measurement

BLOCK = drillsound.MAX_BLOCK
ENGAGED = SoundParameters(drill_on=True, contact=True)
PEAK_BOUND = 0.02
DESKTOP_BOUND_MS = 10.0
BROWSER_BOUND_MS = 50.0
RPMS = (20000.0, 45000.0, 60000.0, 80000.0, 100000.0)


def _block_cost(parameters: SoundParameters, blocks: int) -> float:
    """Median seconds to render one 256-frame block in a steady stream."""
    renderer = drillsound.DrillSoundRenderer(parameters=parameters)
    renderer.settle()
    for _ in range(20):
        renderer.render(BLOCK)
    times = []
    for _ in range(blocks):
        start = time.perf_counter()
        renderer.render(BLOCK)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def _peak_errors(render) -> list[float]:
    """|relative error| of every partial's peak over RPMS and both burrs, rendered by ``render(parameters)``."""
    errors = []
    for burr in drillsound.BURR_TYPES:
        for rpm in RPMS:
            samples = render(ENGAGED.replace(rpm=rpm, burr=burr))
            found = soundanalysis.harmonic_errors(samples, rpm / 60.0, drillsound.SPECTRA[burr]["partials"])
            errors.extend(abs(error) for error, _ in found.values())
    return errors


def _pitch_ratios(render, config: drillsound.SoundConfig) -> tuple[float, float]:
    """Measured drop at full load and rise at no bone left ahead (fractions of the free fundamental)."""
    free = soundanalysis.fundamental(render(ENGAGED), 1000.0)
    loaded = soundanalysis.fundamental(render(ENGAGED.replace(load=1.0)), 1000.0 * (1 - config.load_pitch_drop))
    thin = soundanalysis.fundamental(render(ENGAGED.replace(thickness_mm=0.0)), 1000.0 * (1 + config.thin_pitch_rise),
                                     relative_window=0.1)
    return 1.0 - loaded / free, thin / free - 1.0


def sound_measurements(repeats: int) -> list[dict]:
    machine = machine_description()
    config = drillsound.SoundConfig()
    block_s = BLOCK / config.sample_rate
    results = []

    for name, parameters in (("engaged cutting burr with monitor bursts", ENGAGED.replace(monitor_level="bursts", monitor_rate_hz=60.0)),
                             ("engaged diamond burr", ENGAGED.replace(burr="diamond")),
                             ("idle motor", SoundParameters(drill_on=True))):
        cost = statistics.median(_block_cost(parameters, 400) for _ in range(repeats))
        results.append(measurement(f"drill sound synthesis per {BLOCK}-frame block (Python, numpy), {name}",
                                   cost * 1e3, "ms", f"real time of a {BLOCK}-frame block at 48 kHz", block_s * 1e3,
                                   repeats, machine))

    def python_render(parameters):
        return drillsound.synthesize(parameters, 1.0)

    errors = _peak_errors(python_render)
    results.append(measurement(f"largest spectral peak error against k*rpm/60 (Python; {len(errors)} partials, "
                               f"rpm {', '.join(f'{r:.0f}' for r in RPMS)}, both burrs)", max(errors) * 100, "%",
                               "bound of issue 25", PEAK_BOUND * 100, 1, machine))
    drop, rise = _pitch_ratios(python_render, config)
    results.append(measurement("pitch drop at full load (Python)", drop, "fraction", "configured load_pitch_drop",
                               config.load_pitch_drop, 1, machine))
    results.append(measurement("pitch rise with no bone left ahead (Python)", rise, "fraction",
                               "configured thin_pitch_rise", config.thin_pitch_rise, 1, machine))

    latencies = []
    for before, after in audioout.LATENCY_CHANGES.values():
        latencies.extend(audioout.simulate_latency(before, after, block=BLOCK, config=config, positions=16))
    latencies_ms = np.array(latencies) * 1e3
    results.append(measurement(f"desktop: parameter change to changed sound, largest ({len(latencies)} changes "
                               f"over a {BLOCK}-frame callback stream; a device adds its output latency)",
                               float(latencies_ms.max()), "ms", "bound of issue 25", DESKTOP_BOUND_MS, 1, machine))
    results.append(measurement("desktop: parameter change to changed sound, median", float(np.median(latencies_ms)),
                               "ms", "bound of issue 25", DESKTOP_BOUND_MS, 1, machine))
    results.extend(_browser_measurements(config, machine))
    return results


def _browser_measurements(config, machine) -> list[dict]:
    """The page's AudioWorklet in Chromium: the same spectrum checks, its samples against Python's, latency."""
    try:
        from playwright.sync_api import sync_playwright

        from ..webapp.browser import SoundPage, launch_chromium
    except ImportError as error:  # the web application's packages are not installed: no browser figures
        print(f"feedbacksound: no browser figures ({error})", flush=True)
        return []
    results = []
    with sync_playwright() as playwright:
        browser = launch_chromium(playwright)
        try:
            with SoundPage(browser) as page:
                def browser_render(parameters):
                    return page.render([(0.0, parameters.as_dict())], 1.0, dataclasses.asdict(config))

                errors = _peak_errors(browser_render)
                results.append(measurement(f"largest spectral peak error against k*rpm/60 (Chromium AudioWorklet, "
                                           f"OfflineAudioContext; {len(errors)} partials)", max(errors) * 100, "%",
                                           "bound of issue 25", PEAK_BOUND * 100, 1, machine))
                drop, rise = _pitch_ratios(browser_render, config)
                results.append(measurement("pitch drop at full load (Chromium)", drop, "fraction",
                                           "configured load_pitch_drop", config.load_pitch_drop, 1, machine))
                results.append(measurement("pitch rise with no bone left ahead (Chromium)", rise, "fraction",
                                           "configured thin_pitch_rise", config.thin_pitch_rise, 1, machine))
                parameters = ENGAGED.replace(load=0.4, monitor_level="bursts", monitor_rate_hz=60.0)
                difference = np.abs(browser_render(parameters) - drillsound.synthesize(parameters, 1.0, config, block=128)).max()
                results.append(measurement("largest sample difference, Chromium worklet against the Python model (1 s)",
                                           float(difference), "full scale", "float32 resolution at 1.0", 2.0 ** -24, 1, machine))
                latency = page.measure_latency(ENGAGED.as_dict(), ENGAGED.replace(load=1.0).as_dict(), 40)
                values = np.array([r["latencyMs"] for r in latency])
                via = "the output timestamp" if latency[0]["viaTimestamp"] else "the worklet's answer plus the output latency"
                results.append(measurement(f"browser: parameter change in the page to changed sound at the output, largest "
                                           f"(40 changes, live AudioContext, by {via}; output latency "
                                           f"{latency[0]['outputLatencyMs']:.1f} ms)", float(values.max()), "ms",
                                           "bound of issue 25", BROWSER_BOUND_MS, 1, machine))
                results.append(measurement("browser: parameter change in the page to changed sound, median",
                                           float(np.median(values)), "ms", "bound of issue 25", BROWSER_BOUND_MS, 1, machine))
        finally:
            browser.close()
    return results
