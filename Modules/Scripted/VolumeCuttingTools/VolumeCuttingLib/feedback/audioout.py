"""The drill sound on the desktop, in real time: PortAudio (through ``sounddevice``) pulls blocks of
``drillsound.MAX_BLOCK`` frames at 48 kHz from a ``DrillSoundRenderer``.

The logic or the haptic loop calls ``set_parameters`` whenever the drill's
state changes (any thread: it swaps one immutable object); the audio callback
reads the latest parameters at the start of each block. A machine without
PortAudio (Debian ``libportaudio2``) or without an output device gets a clear
message and a silent session, never an exception: ``start`` returns False and
``message`` says why.

``simulate_latency`` drives the same callback with a simulated stream of
real-sized blocks to measure how long a parameter change takes to be heard.
"""

from __future__ import annotations

import logging
import threading

import numpy as np

from . import drillsound, soundanalysis
from .drillsound import DrillSoundRenderer, SoundConfig, SoundParameters

LOGGER = logging.getLogger(__name__)


class DrillSoundOutput:
    """A PortAudio output stream playing the drill sound; silent, with a message, where none can be opened."""

    def __init__(self, config: SoundConfig | None = None, block: int = drillsound.MAX_BLOCK, device=None):
        if isinstance(block, bool) or not isinstance(block, int) or not 0 < block <= drillsound.MAX_BLOCK:
            raise drillsound.SoundParameterError(f"block = {block!r}; expected 1..{drillsound.MAX_BLOCK} frames")
        self.config = config or SoundConfig()
        self.block = block
        self.device = device
        self.renderer = DrillSoundRenderer(self.config)
        self._latest = self.renderer.parameters
        self._stream = None
        self.message = ""
        self.callback_errors = 0
        self._lock = threading.Lock()

    @property
    def playing(self) -> bool:
        return self._stream is not None

    @property
    def output_latency_s(self) -> float | None:
        """What PortAudio reports for the open stream (None without one)."""
        return float(self._stream.latency) if self._stream is not None else None

    def set_parameters(self, parameters: SoundParameters) -> None:
        """The sound to make from the next block on (validated here, so the callback never meets bad values)."""
        if not isinstance(parameters, SoundParameters):
            raise drillsound.SoundParameterError(f"expected SoundParameters, got {type(parameters).__name__}")
        self._latest = parameters

    def start(self) -> bool:
        """Open and start the stream; False, with ``message`` set and logged, where there is no sound to be had."""
        if self._stream is not None:
            return True
        try:
            import sounddevice
        except OSError as error:  # sounddevice loads PortAudio at import
            return self._silent(f"PortAudio is not installed ({error}); install Debian's libportaudio2 "
                                "(Utilities/vc setup does)")
        except ImportError as error:
            return self._silent(f"the sounddevice package is missing ({error}); run Utilities/vc setup")
        try:
            stream = sounddevice.OutputStream(
                samplerate=self.config.sample_rate, blocksize=self.block, channels=1, dtype="float32",
                latency="low", device=self.device, callback=self.callback)
            stream.start()
        except Exception as error:  # PortAudioError, or ValueError for an unknown device: both mean no sound here
            return self._silent(f"no audio output device could be opened ({error})")
        self._stream = stream
        self.message = f"drill sound playing: {self.block} frames at {self.config.sample_rate} Hz, " \
                       f"output latency {stream.latency * 1e3:.1f} ms"
        LOGGER.info(self.message)
        return True

    def _silent(self, reason: str) -> bool:
        self.message = f"Drill sound off: {reason}. The session goes on without sound."
        LOGGER.warning(self.message)
        return False

    def stop(self) -> None:
        stream, self._stream = self._stream, None
        if stream is not None:
            try:
                stream.stop()
                stream.close()
            except Exception as error:  # a device that vanished: there is nothing left to stop
                LOGGER.warning("closing the drill sound stream: %s", error)

    def callback(self, outdata, frames, time_info, status) -> None:
        """PortAudio's callback: the next ``frames`` samples into ``outdata`` (frames x 1 float32)."""
        with self._lock:
            try:
                self.renderer.set_parameters(self._latest)
                done = 0
                while done < frames:
                    count = min(drillsound.MAX_BLOCK, frames - done)
                    outdata[done:done + count, 0] = self.renderer.render(count)
                    done += count
            except Exception as error:  # never let the audio thread die: play silence and say why once
                outdata[:] = 0
                self.callback_errors += 1
                if self.callback_errors == 1:
                    LOGGER.error("drill sound callback failed, playing silence: %s", error)

    def __enter__(self):
        self.start()
        return self

    def __exit__(self, *exc):
        self.stop()


def simulate_stream(before: SoundParameters, after: SoundParameters | None, change_at: int, frames: int,
                    block: int = drillsound.MAX_BLOCK, config: SoundConfig | None = None) -> np.ndarray:
    """What a stream with ``block``-frame callbacks plays when ``set_parameters(after)`` is called (as from
    another thread) once ``change_at`` samples have been asked for, from ``before`` held steady."""
    output = DrillSoundOutput(config, block)
    output.renderer.set_parameters(before)
    output.renderer.settle()
    output.set_parameters(before)
    out = np.zeros((frames, 1), dtype=np.float32)
    position = 0
    while position < frames:
        if after is not None and position >= change_at:
            output.set_parameters(after)
        count = min(block, frames - position)
        output.callback(out[position:position + count], count, None, None)
        position += count
    return out[:, 0].astype(float)


def simulate_latency(before: SoundParameters, after: SoundParameters, block: int = drillsound.MAX_BLOCK,
                     config: SoundConfig | None = None, positions: int = 8) -> list[float]:
    """Seconds from a parameter change to the changed sound in the stream's output, for changes made at
    ``positions`` points spread over one block (the wait for the next callback is part of it).

    "Changed" is ``soundanalysis.changed_at``: the difference from the unchanged stream reaches -20 dB of
    the sound over a 1 ms window. A device adds the output latency PortAudio reports for its stream.
    """
    config = config or SoundConfig()
    rate = config.sample_rate
    start = 20 * block
    frames = start + block + int(0.1 * rate)
    reference = simulate_stream(before, None, 0, frames, block, config)
    latencies = []
    for offset in np.linspace(0, block, positions, endpoint=False):
        change_at = start + int(offset)
        changed = simulate_stream(before, after, change_at, frames, block, config)
        heard = soundanalysis.changed_at(changed, reference, change_at - 1, rate)
        if heard is None:
            raise RuntimeError(f"the change from {before} to {after} was never heard")
        latencies.append((heard - change_at) / rate)
    return latencies


# The changes whose latency the desktop path is measured on: pitch under load, contact, the monitor, volume.
LATENCY_CHANGES = {
    "load": (SoundParameters(drill_on=True, contact=True), SoundParameters(drill_on=True, contact=True, load=1.0)),
    "contact": (SoundParameters(drill_on=True), SoundParameters(drill_on=True, contact=True)),
    "monitor": (SoundParameters(drill_on=True, contact=True),
                SoundParameters(drill_on=True, contact=True, monitor_level="continuous", monitor_rate_hz=100.0)),
    "thinning": (SoundParameters(drill_on=True, contact=True), SoundParameters(drill_on=True, contact=True, thickness_mm=0.5)),
}
