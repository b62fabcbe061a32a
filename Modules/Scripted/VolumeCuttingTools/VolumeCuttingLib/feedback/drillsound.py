"""The drill sound, synthesised from spectral peaks (seed 003, section 3.4).

A burr sounds as a series of noisy harmonics of its rotation: partial k sits at
k * f0, f0 = rpm / 60 Hz. Contact with bone brings in the engaged spectrum of
the burr type (a fluted cutting burr rings at its flute harmonics; a diamond
burr grinds, its partials smeared into bands and its high ones weak), load
pulls the rotation down by a configured ratio (``load_pitch_drop``), and bone
thinner than ``thin_bone_mm`` ahead of the burr raises the pitch, as surgeons
hear it before they break through. The nerve monitor's firing is mixed in as
clicks, single, in bursts or as a dense train, as a NIM-type monitor makes
nerve irritation audible.

Everything is a function of the samples' index, so the output does not depend
on how it is cut into blocks: every smoothed value (motor speed, load and
thinning factors, gains) follows a one-pole glide evaluated in closed form per
sample; the partials share one phase accumulator (exact harmonics, no phase
jump at any change); the noise that smears the partials is drawn every
``CONTROL_PERIOD`` samples as an integer hash of the draw's index and ramped
linearly between draws. The browser's AudioWorklet (``webapp/www/drillsound-worklet.js``)
implements the same model with the same constants.

Bounded by construction: tones, noise and clicks each have a gain budget and
the budgets sum to ``HEADROOM`` < 1, so no volume setting can clip.

``synthesize`` is the pure function (parameters -> samples);
``DrillSoundRenderer`` renders a stream block by block for a real-time
callback; ``parameters_from_session`` maps a session's tool node, drill switch
and removal rate (as load) to ``SoundParameters``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

SAMPLE_RATE = 48000
# Samples between two draws of the partials' noise: the noise bandwidth (a few hundred Hz) smears each partial into a band.
CONTROL_PERIOD = 64
MAX_BLOCK = 256
HEADROOM = 0.9
MOTOR_STOPPED_HZ = 0.5

BURR_TYPES = ("cutting", "diamond")
MONITOR_LEVELS = ("silent", "sparse", "bursts", "continuous", "contact")


class SoundParameterError(ValueError):
    """A sound parameter or configuration value that cannot be rendered; names the parameter."""


# Relative amplitudes of the partials (k: amplitude) and how much noise smears them (0: pure tone, 1: fully noisy).
# Cutting burrs: six flutes, so harmonics 6 and 12 ring strongly and sharply. Diamond: smooth, low partials, broad bands.
SPECTRA = {
    "idle": {"partials": {1: 1.0, 2: 0.3, 3: 0.12}, "smear": 0.1, "hiss": 0.1},
    "cutting": {"partials": {1: 1.0, 2: 0.5, 3: 0.35, 4: 0.25, 6: 0.8, 8: 0.2, 12: 0.5}, "smear": 0.25, "hiss": 0.25},
    "diamond": {"partials": {1: 1.0, 2: 0.35, 3: 0.15, 4: 0.08}, "smear": 0.7, "hiss": 0.45},
}
HARMONICS = sorted({k for spectrum in SPECTRA.values() for k in spectrum["partials"]})

# Shares of HEADROOM: tonal partials, broadband hiss, monitor clicks.
TONE_BUDGET = 0.55
HISS_BUDGET = 0.1
CLICK_BUDGET = HEADROOM - TONE_BUDGET - HISS_BUDGET
IDLE_GAIN = 0.25  # the free-running motor is quieter than the burr on bone
CLICK_GAIN = {"silent": 0.0, "sparse": 0.6, "bursts": 0.75, "continuous": 0.85, "contact": 1.0}
CLICKS_PER_BURST = 4
BURST_SPACING_S = 0.005
CLICK_FREQUENCY = 1800.0
CLICK_DECAY_S = 0.0008
CLICK_LENGTH_S = 0.004
SMEAR_SEED = 0x2545F491
HISS_SEED = 0x9E3779B9


@dataclass(frozen=True)
class SoundConfig:
    """How the sound responds; the defaults are the trainer's. Times in seconds, thickness in mm."""

    sample_rate: int = SAMPLE_RATE
    load_pitch_drop: float = 0.15  # at full load the burr turns this fraction slower
    thin_bone_mm: float = 2.0  # bone thinner than this ahead of the burr raises the pitch
    thin_pitch_rise: float = 0.25  # pitch rise (fraction) when no bone is left ahead
    spin_up_s: float = 0.15  # motor time constants (one-pole): speed reaches 95 % in 3 of them
    spin_down_s: float = 0.35
    glide_s: float = 0.002  # time constant of load, thinning and gain changes: fast, yet no click
    full_load_removal_mm3_s: float = 20.0  # removal rate that counts as full load

    def __post_init__(self):
        checks = {
            "sample_rate": 8000 <= self.sample_rate <= 192000,
            "load_pitch_drop": 0.0 <= self.load_pitch_drop < 1.0,
            "thin_bone_mm": self.thin_bone_mm > 0.0,
            "thin_pitch_rise": 0.0 <= self.thin_pitch_rise <= 1.0,
            "spin_up_s": self.spin_up_s > 0.0,
            "spin_down_s": self.spin_down_s > 0.0,
            "glide_s": self.glide_s > 0.0,
            "full_load_removal_mm3_s": self.full_load_removal_mm3_s > 0.0,
        }
        for name, ok in checks.items():
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and ok):
                raise SoundParameterError(f"SoundConfig.{name} = {value!r} is out of range")


@dataclass(frozen=True)
class SoundParameters:
    """What the sound is made of at one moment.

    ``rpm``: burr speed set on the handpiece (revolutions per minute, 0..150000);
    ``drill_on``: the motor runs; ``contact``: the burr is on bone (engaged sound);
    ``load``: 0..1, pulls the speed down by ``load_pitch_drop``;
    ``thickness_mm``: bone left ahead of the burr (``inf``: thick bone);
    ``monitor_level``/``monitor_rate_hz``: the nerve monitor's level name and firing rate;
    ``volume``: master gain 0..1.
    """

    rpm: float = 60000.0
    drill_on: bool = False
    burr: str = "cutting"
    contact: bool = False
    load: float = 0.0
    thickness_mm: float = math.inf
    monitor_level: str = "silent"
    monitor_rate_hz: float = 0.0
    volume: float = 1.0

    def __post_init__(self):
        def number(name, low, high, allow_inf=False):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise SoundParameterError(f"{name} must be a number, not {value!r}")
            value = float(value)
            if math.isnan(value) or (math.isinf(value) and not allow_inf) or not low <= value <= high:
                raise SoundParameterError(f"{name} = {value!r} is outside {low}..{high}")

        number("rpm", 0.0, 150000.0)
        number("load", 0.0, 1.0)
        number("thickness_mm", 0.0, math.inf, allow_inf=True)
        number("monitor_rate_hz", 0.0, 1000.0)
        number("volume", 0.0, 1.0)
        if self.burr not in BURR_TYPES:
            raise SoundParameterError(f"burr = {self.burr!r}; expected one of {', '.join(BURR_TYPES)}")
        if self.monitor_level not in MONITOR_LEVELS:
            raise SoundParameterError(f"monitor_level = {self.monitor_level!r}; expected one of {', '.join(MONITOR_LEVELS)}")

    def replace(self, **changes) -> "SoundParameters":
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict:
        """Plain values for JSON (the browser's state); an infinite thickness becomes -1."""
        values = dataclasses.asdict(self)
        if math.isinf(values["thickness_mm"]):
            values["thickness_mm"] = -1.0
        return values


def pitch_factor(parameters: SoundParameters, config: SoundConfig) -> float:
    """Ratio of the sounding rotation to the set speed: load lowers it, thin bone ahead raises it."""
    return load_factor(parameters, config) * thinning_factor(parameters.thickness_mm, config)


def load_factor(parameters: SoundParameters, config: SoundConfig) -> float:
    return 1.0 - config.load_pitch_drop * (parameters.load if parameters.contact else 0.0)


def thinning_factor(thickness_mm: float, config: SoundConfig) -> float:
    if not math.isfinite(thickness_mm) or thickness_mm >= config.thin_bone_mm:
        return 1.0
    return 1.0 + config.thin_pitch_rise * (1.0 - thickness_mm / config.thin_bone_mm)


def expected_fundamental(parameters: SoundParameters, config: SoundConfig | None = None) -> float:
    """The fundamental (Hz) the steady sound has: rpm / 60 times the pitch factor."""
    config = config or SoundConfig()
    return parameters.rpm / 60.0 * pitch_factor(parameters, config)


def hashed_uniform(seed: int, counters: np.ndarray) -> np.ndarray:
    """Noise in [0, 1) as a hash of a counter (the "lowbias32" integer hash), so blocks need no sequential state.

    The browser's worklet computes the same values with ``Math.imul``.
    """
    x = np.asarray(counters).astype(np.uint32) + np.uint32(seed)
    x ^= x >> np.uint32(16)
    x *= np.uint32(0x7FEB352D)
    x ^= x >> np.uint32(15)
    x *= np.uint32(0x846CA68B)
    x ^= x >> np.uint32(16)
    return x / 4294967296.0


def _glide(current: float, target: float, ratio: float, count: int) -> np.ndarray:
    """A one-pole glide from ``current`` towards ``target``, per sample: value[n] = target + (current - target) * ratio^(n+1)."""
    if current == target:
        return np.full(count, target)
    return target + (current - target) * ratio ** np.arange(1, count + 1)


class DrillSoundRenderer:
    """Renders the drill sound block by block, carrying every oscillator and glide across blocks.

    ``set_parameters`` may be called between blocks (a real-time callback reads
    the latest parameters at the start of each block); every change glides.
    The renderer starts silent, the motor stopped.
    """

    def __init__(self, config: SoundConfig | None = None, parameters: SoundParameters | None = None):
        self.config = config or SoundConfig()
        self.parameters = parameters or SoundParameters()
        rate = self.config.sample_rate
        self._ratio_up = math.exp(-1.0 / (self.config.spin_up_s * rate))
        self._ratio_down = math.exp(-1.0 / (self.config.spin_down_s * rate))
        self._ratio_glide = math.exp(-1.0 / (self.config.glide_s * rate))
        self.motor_hz = 0.0  # the motor's rotation (rev/s), slewing with spin-up and spin-down
        self._reference_hz = self.parameters.rpm / 60.0  # the last speed set: full loudness
        self.pitch = 1.0  # load and thinning factor, gliding
        self._gains = {"idle": 0.0, "cutting": 0.0, "diamond": 0.0, "click": 0.0, "volume": self.parameters.volume}
        self._phase = 0.0  # cycles of the fundamental, kept in [0, 1)
        self._click_phase = 0.0  # cycles of the click (or burst) clock
        self._clicks_active = False
        self._click_tail = np.zeros(0)  # click samples still to play
        self._harmonics = np.array(HARMONICS, dtype=float)
        # Per spectrum: partial amplitudes over HARMONICS, normalised to the tone budget.
        self._amplitudes = {}
        for name, spectrum in SPECTRA.items():
            amplitudes = np.array([spectrum["partials"].get(k, 0.0) for k in HARMONICS])
            self._amplitudes[name] = amplitudes * TONE_BUDGET / amplitudes.sum()
        length = int(CLICK_LENGTH_S * rate)
        t = np.arange(length) / rate
        self._click_shape = np.sin(2 * np.pi * CLICK_FREQUENCY * t) * np.exp(-t / CLICK_DECAY_S)
        self._click_shape /= np.abs(self._click_shape).max()
        self._burst_offsets = (np.arange(CLICKS_PER_BURST) * BURST_SPACING_S * rate).astype(int)
        self.samples_rendered = 0

    def set_parameters(self, parameters: SoundParameters) -> None:
        if not isinstance(parameters, SoundParameters):
            raise SoundParameterError(f"expected SoundParameters, got {type(parameters).__name__}")
        self.parameters = parameters

    def _targets(self) -> dict:
        p = self.parameters
        engaged = p.drill_on and p.contact
        return {
            # The free-running motor sounds while it turns, switched on or spinning down.
            "idle": IDLE_GAIN if not engaged and (p.drill_on or self.motor_hz > 0.0) else 0.0,
            "cutting": 1.0 if engaged and p.burr == "cutting" else 0.0,
            "diamond": 1.0 if engaged and p.burr == "diamond" else 0.0,
            "click": CLICK_GAIN[p.monitor_level] if p.monitor_rate_hz > 0.0 else 0.0,
            "volume": p.volume,
        }

    def settle(self) -> None:
        """Jump every glide to its target: the state after the parameters have held for a long time."""
        p = self.parameters
        self.motor_hz = p.rpm / 60.0 if p.drill_on else 0.0
        self._reference_hz = p.rpm / 60.0
        self.pitch = pitch_factor(p, self.config)
        self._gains.update(self._targets())

    def render(self, frames: int) -> np.ndarray:
        """The next ``frames`` samples (float64, mono, |x| <= HEADROOM)."""
        if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or not 0 < frames <= MAX_BLOCK:
            raise SoundParameterError(f"frames = {frames!r}; a block holds 1..{MAX_BLOCK} frames")
        config, p = self.config, self.parameters
        rate = config.sample_rate
        # Motor speed: spin-up and spin-down are one-pole slews of the rotation towards the set speed.
        motor_target = p.rpm / 60.0 if p.drill_on else 0.0
        ratio = self._ratio_up if motor_target > self.motor_hz else self._ratio_down
        motor = _glide(self.motor_hz, motor_target, ratio, frames)
        pitch = _glide(self.pitch, pitch_factor(p, config), self._ratio_glide, frames)
        self.motor_hz, self.pitch = float(motor[-1]), float(pitch[-1])
        if motor_target == 0.0 and self.motor_hz < MOTOR_STOPPED_HZ:
            self.motor_hz = 0.0  # an exponential never ends: call the motor stopped below an inaudible speed
        fundamental = motor * pitch
        # The motor's sound grows and fades with its speed (spin-up, spin-down).
        if p.rpm > 0.0:
            self._reference_hz = p.rpm / 60.0
        speed_fraction = np.clip(motor / self._reference_hz, 0.0, 1.0) if self._reference_hz > 0.0 else np.zeros(frames)
        # One phase for all partials: exact harmonics, continuous through every change of speed.
        phase = self._phase + np.cumsum(fundamental) / rate
        self._phase = float(phase[-1] % 1.0)
        gains = {}
        for name, target in self._targets().items():
            gains[name] = _glide(self._gains[name], target, self._ratio_glide, frames)
            self._gains[name] = float(gains[name][-1])
        samples = self.samples_rendered + np.arange(frames)
        self.samples_rendered += frames
        out = self._clicks(frames, gains["click"])
        active = [name for name in ("idle", "cutting", "diamond") if gains[name].any()]
        if active:
            smear = self._smear(samples)
            amplitude = np.zeros((len(HARMONICS), frames))
            hiss_gain = np.zeros(frames)
            for name in active:
                spectrum = SPECTRA[name]
                amplitude += gains[name] * self._amplitudes[name][:, None] * (1.0 - spectrum["smear"] * smear)
                hiss_gain += gains[name] * spectrum["hiss"]
            partial_hz = self._harmonics[:, None] * fundamental
            amplitude *= self._nyquist_fade(partial_hz) * speed_fraction
            hiss_gain *= speed_fraction
            out += (amplitude * np.sin(2.0 * np.pi * self._harmonics[:, None] * phase + self._harmonics[:, None])).sum(axis=0)
            out += self._hiss(samples, hiss_gain)
        return gains["volume"] * out

    def _nyquist_fade(self, frequency: np.ndarray) -> np.ndarray:
        """Partials fade out between 0.4 and 0.46 of the sample rate, so fast burrs never alias."""
        rate = self.config.sample_rate
        return np.clip((0.46 * rate - frequency) / (0.06 * rate), 0.0, 1.0)

    @staticmethod
    def _smear(samples: np.ndarray) -> np.ndarray:
        """Noise in [0, 1] per harmonic and sample, drawn every CONTROL_PERIOD samples and ramped between draws."""
        draw = samples // CONTROL_PERIOD
        fraction = (samples % CONTROL_PERIOD) / CONTROL_PERIOD
        count = len(HARMONICS)
        # Hash only the draws this block spans, then pick each sample's two.
        draws = np.arange(draw[0], draw[-1] + 2)
        values = hashed_uniform(SMEAR_SEED, draws[None, :] * count + np.arange(count)[:, None])
        before = values[:, draw - draw[0]]
        after = values[:, draw - draw[0] + 1]
        return before + (after - before) * fraction

    @staticmethod
    def _hiss(samples: np.ndarray, gain: np.ndarray) -> np.ndarray:
        """Broadband noise, high-passed by a first difference (the grinding), bounded by HISS_BUDGET."""
        white = hashed_uniform(HISS_SEED, samples)
        previous = hashed_uniform(HISS_SEED, samples - 1)
        return gain * HISS_BUDGET * (white - previous)

    def _clicks(self, frames: int, gain: np.ndarray) -> np.ndarray:
        """The monitor's clicks: a clock at the firing rate (per burst of CLICKS_PER_BURST at the bursts level)."""
        train = np.zeros(max(frames, len(self._click_tail)))
        train[:len(self._click_tail)] = self._click_tail
        p = self.parameters
        active = p.monitor_level != "silent" and p.monitor_rate_hz > 0.0
        if active and not self._clicks_active:
            # The monitor fires at once when it starts firing, not one period later.
            self._click_phase = math.nextafter(1.0, 0.0)
        self._clicks_active = active
        if active:
            bursts = p.monitor_level == "bursts"
            step = p.monitor_rate_hz / (CLICKS_PER_BURST if bursts else 1) / self.config.sample_rate
            clock = self._click_phase + step * np.arange(1, frames + 1)
            # A click (or burst) starts at each sample where the clock passes a whole cycle.
            starts = np.nonzero(np.floor(clock) > np.floor(np.concatenate(([self._click_phase], clock[:-1]))))[0]
            self._click_phase = float(clock[-1] % 1.0)
            offsets = self._burst_offsets if bursts else self._burst_offsets[:1]
            shape = self._click_shape
            # Dense trains overlap; scale each click so the sum stays within the budget.
            overlap = 1 if bursts else max(1, math.ceil(p.monitor_rate_hz * CLICK_LENGTH_S))
            for start in starts:
                for offset in offsets:
                    at = start + offset
                    if at + len(shape) > len(train):
                        train = np.concatenate((train, np.zeros(at + len(shape) - len(train))))
                    train[at:at + len(shape)] += shape / overlap
        self._click_tail = train[frames:]
        return np.clip(train[:frames], -1.0, 1.0) * gain * CLICK_BUDGET


def synthesize(parameters, seconds: float, config: SoundConfig | None = None, block: int = MAX_BLOCK,
               steady: bool = True) -> np.ndarray:
    """Samples of the drill sound: the pure function.

    ``parameters`` is one ``SoundParameters`` or a schedule, a list of
    ``(time_s, SoundParameters)`` sorted by time whose first entry is at 0;
    each takes effect at the first block boundary at or after its time.
    ``steady``: start as if the first parameters had held for ever (motor at
    speed, gains settled); otherwise start silent with the motor stopped.
    """
    config = config or SoundConfig()
    schedule = [(0.0, parameters)] if isinstance(parameters, SoundParameters) else list(parameters)
    if not schedule or schedule[0][0] != 0.0:
        raise SoundParameterError("a schedule starts with parameters at time 0")
    times = [t for t, _ in schedule]
    if any(not math.isfinite(t) for t in times) or times != sorted(times):
        raise SoundParameterError("a schedule's times must be finite and increasing")
    if not (isinstance(seconds, (int, float)) and math.isfinite(seconds) and 0.0 < seconds <= 600.0):
        raise SoundParameterError(f"seconds = {seconds!r}; expected 0 < seconds <= 600")
    renderer = DrillSoundRenderer(config, schedule[0][1])
    if steady:
        renderer.settle()
    total = int(round(seconds * config.sample_rate))
    out = np.empty(total)
    position, entry = 0, 0
    while position < total:
        while entry + 1 < len(schedule) and schedule[entry + 1][0] * config.sample_rate <= position:
            entry += 1
        renderer.set_parameters(schedule[entry][1])
        count = min(block, total - position)
        out[position:position + count] = renderer.render(count)
        position += count
    return out


def parameters_from_session(tool_node, drill_on: bool, removal_rate_mm3_s: float, thickness_mm: float = math.inf,
                            monitor_level: str = "silent", monitor_rate_hz: float = 0.0, volume: float = 1.0,
                            config: SoundConfig | None = None) -> SoundParameters:
    """Sound parameters from a session: the tool node (``vtkMRMLVolumeCutToolNode``), the drill switch, the
    removal rate (mm3/s) of the current stroke as load, the bone left ahead and the nerve monitor's reading.

    The sounding speed is the node's speed times its power (the foot pedal); contact is any removal;
    load is the removal rate over ``full_load_removal_mm3_s``, at most 1.
    """
    config = config or SoundConfig()
    rate = float(removal_rate_mm3_s)
    if math.isnan(rate) or rate < 0.0:
        raise SoundParameterError(f"removal_rate_mm3_s = {removal_rate_mm3_s!r} must be a number >= 0")
    burr = "diamond" if tool_node.GetBurrType() == 1 else "cutting"  # vtkMRMLVolumeCutToolNode::Diamond
    return SoundParameters(
        rpm=float(tool_node.GetSpeed()) * float(tool_node.GetPower()),
        drill_on=bool(drill_on),
        burr=burr,
        contact=bool(drill_on) and rate > 0.0,
        load=min(1.0, rate / config.full_load_removal_mm3_s),
        thickness_mm=thickness_mm,
        monitor_level=monitor_level,
        monitor_rate_hz=monitor_rate_hz,
        volume=volume,
    )


class RemovalRateMeter:
    """The removal rate (mm3/s) from the removed volume sampled over time, smoothed over ``window_s``."""

    def __init__(self, window_s: float = 0.05):
        if not (math.isfinite(window_s) and window_s > 0.0):
            raise SoundParameterError(f"window_s = {window_s!r} must be > 0")
        self.window_s = window_s
        self.rate = 0.0
        self._last = None

    def update(self, removed_mm3: float, time_s: float) -> float:
        if self._last is not None:
            volume0, time0 = self._last
            dt = time_s - time0
            if dt > 0.0:
                instant = max(0.0, removed_mm3 - volume0) / dt
                weight = 1.0 - math.exp(-dt / self.window_s)
                self.rate += weight * (instant - self.rate)
        self._last = (removed_mm3, time_s)
        return self.rate

    def reset(self) -> None:
        self.rate = 0.0
        self._last = None
