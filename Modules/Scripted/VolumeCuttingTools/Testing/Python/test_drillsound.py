"""The drill sound without speakers (issue 25): seconds rendered to a buffer and read in their spectrum.

Ground truth is analytic: the partials sit at k * rpm / 60, load scales that by
(1 - load_pitch_drop * load), bone thinner than thin_bone_mm by
(1 + thin_pitch_rise * (1 - t / thin_bone_mm)), the motor follows one-pole
spin-up and spin-down, the monitor's clock fires at its rate.
"""

import math

import numpy as np
import pytest

from VolumeCuttingLib.feedback import drillsound, soundanalysis
from VolumeCuttingLib.feedback.drillsound import SoundConfig, SoundParameterError, SoundParameters

RATE = drillsound.SAMPLE_RATE
CONFIG = SoundConfig()
ENGAGED = SoundParameters(drill_on=True, contact=True)


@pytest.mark.parametrize("burr", drillsound.BURR_TYPES)
@pytest.mark.parametrize("rpm", [20000.0, 45000.0, 80000.0, 100000.0])
def test_peaks_at_harmonics_of_the_burr_speed(burr, rpm):
    parameters = ENGAGED.replace(rpm=rpm, burr=burr)
    samples = drillsound.synthesize(parameters, 1.0)
    errors = soundanalysis.harmonic_errors(samples, rpm / 60.0, drillsound.SPECTRA[burr]["partials"])
    assert len(errors) >= 3
    for k, (error, prominence) in errors.items():
        assert abs(error) < 0.02, f"partial {k}: {error:+.3%} from {k * rpm / 60:.0f} Hz"
        assert prominence > 10.0, f"partial {k} is no peak (prominence {prominence:.1f})"
    # The loudest thing in the spectrum is one of the partials.
    strongest = soundanalysis.strongest_frequency(samples)
    k = round(strongest / (rpm / 60.0))
    assert k >= 1 and abs(strongest / (k * rpm / 60.0) - 1.0) < 0.02


def test_cutting_rings_at_its_flutes_and_diamond_is_smoother():
    cutting = drillsound.synthesize(ENGAGED.replace(burr="cutting"), 1.0)
    diamond = drillsound.synthesize(ENGAGED.replace(burr="diamond"), 1.0)
    f0 = 1000.0
    cutting_errors = soundanalysis.harmonic_errors(cutting, f0, [6, 12])
    diamond_errors = soundanalysis.harmonic_errors(diamond, f0, [1])
    assert cutting_errors[6][1] > 100 and cutting_errors[12][1] > 100
    # The diamond's partials are smeared into bands: far less prominent than the cutting burr's.
    assert diamond_errors[1][1] < 0.5 * soundanalysis.harmonic_errors(cutting, f0, [1])[1][1]
    # Its energy above 5 kHz is a smaller share than the cutting burr's (sharper, brighter).
    def high_share(samples):
        frequencies, magnitude = soundanalysis.spectrum(samples)
        power = magnitude ** 2
        return power[frequencies > 5000].sum() / power.sum()
    assert high_share(diamond) < 0.5 * high_share(cutting)


@pytest.mark.parametrize("load", [0.25, 0.5, 1.0])
def test_load_lowers_the_pitch_by_the_configured_ratio(load):
    config = SoundConfig(load_pitch_drop=0.2)
    free = drillsound.synthesize(ENGAGED, 2.0, config)
    loaded = drillsound.synthesize(ENGAGED.replace(load=load), 2.0, config)
    f_free = soundanalysis.fundamental(free, 1000.0)
    f_loaded = soundanalysis.fundamental(loaded, 1000.0 * (1 - 0.2 * load))
    assert f_loaded / f_free == pytest.approx(1.0 - 0.2 * load, abs=0.002)


def test_load_without_contact_does_not_change_the_pitch():
    idle = drillsound.synthesize(SoundParameters(drill_on=True, load=1.0), 1.0)
    assert soundanalysis.fundamental(idle, 1000.0) == pytest.approx(1000.0, rel=0.002)


def test_thinning_bone_raises_the_pitch():
    measured = []
    for thickness in (math.inf, 3.0, 2.0, 1.5, 1.0, 0.5, 0.0):
        parameters = ENGAGED.replace(thickness_mm=thickness)
        expected = drillsound.expected_fundamental(parameters, CONFIG)
        found = soundanalysis.fundamental(drillsound.synthesize(parameters, 1.0), expected, relative_window=0.1)
        assert found == pytest.approx(expected, rel=0.002), thickness
        measured.append(found)
    assert measured[0] == pytest.approx(measured[2], rel=0.002)  # 2 mm and more: no change
    assert all(b > a for a, b in zip(measured[2:], measured[3:]))
    assert measured[-1] / measured[0] == pytest.approx(1.0 + CONFIG.thin_pitch_rise, rel=0.003)


def random_schedule(seed, seconds, count):
    rng = np.random.default_rng(seed)
    schedule = []
    for i in range(count):
        schedule.append((i * seconds / count, SoundParameters(
            rpm=float(rng.uniform(0, 150000)), drill_on=bool(rng.random() < 0.8), burr=str(rng.choice(drillsound.BURR_TYPES)),
            contact=bool(rng.random() < 0.6), load=float(rng.random()), thickness_mm=float(rng.uniform(0, 4)),
            monitor_level=str(rng.choice(drillsound.MONITOR_LEVELS)), monitor_rate_hz=float(rng.uniform(0, 1000)),
            volume=1.0)))
    return schedule


def test_no_clipping_even_at_the_loudest():
    loudest = [
        ENGAGED.replace(rpm=150000, monitor_level="contact", monitor_rate_hz=1000.0),
        ENGAGED.replace(burr="diamond", monitor_level="bursts", monitor_rate_hz=400.0),
        ENGAGED.replace(rpm=20000, monitor_level="continuous", monitor_rate_hz=250.0, thickness_mm=0.0),
    ]
    for parameters in loudest:
        assert np.abs(drillsound.synthesize(parameters, 1.0)).max() <= drillsound.HEADROOM
    samples = drillsound.synthesize(random_schedule(7, 6.0, 60), 6.0, steady=False)
    assert np.isfinite(samples).all()
    assert np.abs(samples).max() <= drillsound.HEADROOM < 1.0


CHANGES = {
    "load": (ENGAGED, ENGAGED.replace(load=1.0)),
    "burr": (ENGAGED, ENGAGED.replace(burr="diamond")),
    "contact": (SoundParameters(drill_on=True), ENGAGED),
    "drill off": (ENGAGED, ENGAGED.replace(drill_on=False)),
    "rpm": (ENGAGED, ENGAGED.replace(rpm=30000.0)),
    "thinning": (ENGAGED, ENGAGED.replace(thickness_mm=0.2)),
    "volume": (ENGAGED, ENGAGED.replace(volume=0.0)),
}
# A change is heard as a glide, never as a step: within its first 4 samples (0.08 ms) the sound moves
# less than this (full scale 1) from the sound without the change. An abrupt switch moves it by about
# the sound's own amplitude (0.1-0.4); the 2 ms glide moves it by at most 4 % of the change.
STEP_BOUND = 0.02


@pytest.mark.parametrize("change", sorted(CHANGES))
def test_no_step_at_a_parameter_change(change):
    before, after = CHANGES[change]
    unchanged = drillsound.synthesize(before, 1.0)
    changed = drillsound.synthesize([(0.0, before), (0.5, after)], 1.0)
    first, jump = soundanalysis.onset_jump(changed, unchanged)
    assert first is not None and abs(first - 0.5 * RATE) <= drillsound.MAX_BLOCK  # at the next block
    assert jump <= STEP_BOUND, f"{change}: the sound jumped by {jump:.4f}"


def test_the_step_measure_sees_an_abrupt_switch():
    # The same changes spliced without glides (two steady renders cut together) break the bound above.
    for name in ("load", "burr", "contact", "rpm"):
        before, after = CHANGES[name]
        cut = int(0.5 * RATE)
        unchanged = drillsound.synthesize(before, 1.0)
        spliced = np.concatenate((unchanged[:cut], drillsound.synthesize(after, 1.0)[cut:]))
        assert soundanalysis.onset_jump(spliced, unchanged)[1] > 2 * STEP_BOUND, name


def test_the_monitor_clock_runs_on_through_a_rate_change():
    # The click clock keeps its phase: a new rate neither adds a click nor drops one at the change.
    schedule = [(0.0, SoundParameters(monitor_level="sparse", monitor_rate_hz=10.0)),
                (0.5, SoundParameters(monitor_level="sparse", monitor_rate_hz=40.0)),
                (1.0, SoundParameters(monitor_level="continuous", monitor_rate_hz=100.0))]
    onsets = soundanalysis.click_onsets(drillsound.synthesize(schedule, 1.5))
    assert abs(len(onsets) - (10 * 0.5 + 40 * 0.5 + 100 * 0.5)) <= 1


@pytest.mark.parametrize("block", [256, 128, 97, 1])
def test_the_sound_does_not_depend_on_the_block_size(block):
    schedule = random_schedule(3, 0.2, 1)
    reference = drillsound.synthesize(schedule, 0.2, steady=False)
    assert np.allclose(drillsound.synthesize(schedule, 0.2, block=block, steady=False), reference, atol=1e-9)


def short_time_fundamental(samples, start_s, guess_hz, window_s=0.04):
    segment = samples[int(start_s * RATE):int((start_s + window_s) * RATE)]
    return soundanalysis.fundamental(segment, guess_hz, relative_window=0.15)


def test_idle_spin_up_and_spin_down_envelopes():
    config = SoundConfig(spin_up_s=0.15, spin_down_s=0.35)
    on = SoundParameters(drill_on=True)
    samples = drillsound.synthesize([(0.0, SoundParameters()), (0.1, on), (1.6, on.replace(drill_on=False))], 4.0, config, steady=False)
    assert np.abs(samples[:int(0.1 * RATE)]).max() == 0.0  # silent until switched on
    f_set = 1000.0

    def motor(t_on, tau, rising):
        return f_set * (1 - math.exp(-t_on / tau)) if rising else f_set * math.exp(-t_on / tau)

    window = 0.04
    for t in (0.1, 0.15, 0.25, 0.4):  # spin-up: the window's centre, in s after switching on
        expected = motor(t, 0.15, True)
        found = short_time_fundamental(samples, 0.1 + t - window / 2, expected)
        assert found == pytest.approx(expected, rel=0.03), f"spin-up at {t} s"
    # Idle: the set speed, steady.
    assert short_time_fundamental(samples, 1.2, f_set, 0.3) == pytest.approx(f_set, rel=0.002)
    for t in (0.1, 0.35, 0.7):
        expected = motor(t, 0.35, False)
        found = short_time_fundamental(samples, 1.6 + t - window / 2, expected)
        assert found == pytest.approx(expected, rel=0.03), f"spin-down at {t} s"

    def rms(start_s, length_s=0.02):
        segment = samples[int(start_s * RATE):int((start_s + length_s) * RATE)]
        return float(np.sqrt(np.mean(segment ** 2)))

    rising = [rms(0.1 + t) for t in (0.0, 0.05, 0.1, 0.2, 0.4)]
    assert all(b > a for a, b in zip(rising, rising[1:]))
    falling = [rms(1.6 + t) for t in (0.05, 0.3, 0.6, 1.0, 1.5)]
    assert all(b < a for a, b in zip(falling, falling[1:]))
    assert rms(3.9, 0.1) < 0.01 * rms(1.2)  # spun down: below -40 dB of idle


def test_engaged_is_louder_than_idle():
    idle = drillsound.synthesize(SoundParameters(drill_on=True), 0.5)
    engaged = drillsound.synthesize(ENGAGED, 0.5)
    assert np.sqrt(np.mean(engaged ** 2)) > 2.0 * np.sqrt(np.mean(idle ** 2))  # +6 dB on bone


@pytest.mark.parametrize("level, rate", [("sparse", 8.0), ("sparse", 25.0), ("bursts", 40.0), ("continuous", 120.0), ("contact", 200.0)])
def test_monitor_clicks_at_the_given_rate(level, rate):
    seconds = 2.0
    samples = drillsound.synthesize(SoundParameters(monitor_level=level, monitor_rate_hz=rate), seconds)
    onsets = soundanalysis.click_onsets(samples)
    # The clock fires one period after it starts: whole periods fit, one more or less at the edges.
    per_trigger = drillsound.CLICKS_PER_BURST if level == "bursts" else 1
    assert abs(len(onsets) - rate * seconds) <= per_trigger, f"{len(onsets)} clicks in {seconds} s at {rate} Hz"
    intervals = np.diff(onsets) / RATE
    if level == "bursts":
        # Bursts of CLICKS_PER_BURST, 5 ms apart, starting rate / CLICKS_PER_BURST times a second.
        assert np.isclose(intervals, drillsound.BURST_SPACING_S, atol=2 / RATE).sum() >= 0.7 * len(intervals)
        assert np.median(intervals[intervals > 0.01]) == pytest.approx(drillsound.CLICKS_PER_BURST / rate - 3 * drillsound.BURST_SPACING_S, abs=2 / RATE)
    else:
        assert np.median(intervals) == pytest.approx(1.0 / rate, abs=2 / RATE)


def test_silent_monitor_adds_nothing():
    plain = drillsound.synthesize(ENGAGED, 0.5)
    silent = drillsound.synthesize(ENGAGED.replace(monitor_level="silent", monitor_rate_hz=50.0), 0.5)
    assert np.array_equal(plain, silent)


@pytest.mark.parametrize("changes, message", [
    ({"rpm": -1.0}, "rpm"),
    ({"rpm": float("nan")}, "rpm"),
    ({"rpm": float("inf")}, "rpm"),
    ({"rpm": 200000.0}, "rpm"),
    ({"load": float("nan")}, "load"),
    ({"load": 1.5}, "load"),
    ({"thickness_mm": -0.1}, "thickness_mm"),
    ({"thickness_mm": float("nan")}, "thickness_mm"),
    ({"monitor_rate_hz": -5.0}, "monitor_rate_hz"),
    ({"volume": 2.0}, "volume"),
    ({"rpm": "fast"}, "rpm"),
    ({"burr": "steel"}, "burr"),
    ({"monitor_level": "loud"}, "monitor_level"),
])
def test_bad_parameters_are_refused_by_name(changes, message):
    with pytest.raises(SoundParameterError, match=message):
        SoundParameters(**changes)


def test_bad_configuration_and_calls_are_refused():
    with pytest.raises(SoundParameterError, match="load_pitch_drop"):
        SoundConfig(load_pitch_drop=1.0)
    with pytest.raises(SoundParameterError, match="spin_up_s"):
        SoundConfig(spin_up_s=float("nan"))
    renderer = drillsound.DrillSoundRenderer()
    with pytest.raises(SoundParameterError, match="frames"):
        renderer.render(257)
    with pytest.raises(SoundParameterError, match="frames"):
        renderer.render(0)
    with pytest.raises(SoundParameterError, match="SoundParameters"):
        renderer.set_parameters({"rpm": 1000})
    with pytest.raises(SoundParameterError, match="seconds"):
        drillsound.synthesize(ENGAGED, float("nan"))
    with pytest.raises(SoundParameterError, match="time 0"):
        drillsound.synthesize([(0.5, ENGAGED)], 1.0)
    # A refused change leaves the renderer as it was.
    renderer.set_parameters(ENGAGED)
    with pytest.raises(SoundParameterError):
        renderer.set_parameters(ENGAGED.replace(rpm=-1))
    assert renderer.parameters == ENGAGED


def test_parameters_from_the_session_tool_node():
    slicer = pytest.importorskip("slicer")
    tool = slicer.vtkMRMLVolumeCutToolNode()
    tool.SetSpeed(40000.0)
    tool.SetPower(0.5)
    tool.SetBurrType(tool.Diamond)
    parameters = drillsound.parameters_from_session(tool, True, removal_rate_mm3_s=5.0, thickness_mm=1.0,
                                                    monitor_level="bursts", monitor_rate_hz=30.0)
    assert parameters.rpm == 20000.0 and parameters.burr == "diamond"
    assert parameters.contact and parameters.load == pytest.approx(5.0 / CONFIG.full_load_removal_mm3_s)
    assert parameters.thickness_mm == 1.0 and parameters.monitor_level == "bursts"
    assert drillsound.parameters_from_session(tool, True, 1000.0).load == 1.0
    off = drillsound.parameters_from_session(tool, False, 5.0)
    assert not off.drill_on and not off.contact
    tool.SetBurrType(tool.Cutting)
    assert drillsound.parameters_from_session(tool, True, 0.0).burr == "cutting"
    assert not drillsound.parameters_from_session(tool, True, 0.0).contact
    with pytest.raises(SoundParameterError, match="removal_rate"):
        drillsound.parameters_from_session(tool, True, float("nan"))


def test_removal_rate_meter():
    meter = drillsound.RemovalRateMeter(window_s=0.05)
    assert meter.update(0.0, 0.0) == 0.0
    for i in range(1, 200):
        rate = meter.update(10.0 * i * 0.01, i * 0.01)  # 10 mm3/s
    assert rate == pytest.approx(10.0, rel=1e-3)
    for i in range(200, 260):
        rate = meter.update(19.9, i * 0.01)  # stopped removing
    assert rate < 0.01
