"""The nerve monitor's meter and the drill sound in desktop Slicer, without Qt.

The module widget (``VolumeCuttingTools.py``) only draws and plays what this
controller computes: it calls :meth:`DesktopFeedback.tick` from its display
timer (every 16 ms, 62.5 Hz: at least the 50 Hz the sound's parameters need)
with the drill switch, shows :attr:`rows` (the meter: a row per monitored
structure with its distance, bar and level colour, the same rows as the web
application's) when :attr:`rows_changed`, and gives the sound's parameters to
``audioout.DrillSoundOutput``, whose PortAudio callback reads the latest at
each block of 256 frames. The parameters are ``soundsource.DrillSoundSource``'s,
the same computation the web application's feed publishes.

Sampling. The monitor's readings and the bone ahead are read at every tick
(the logic measures the monitor at every pose; the bone ahead costs tens of
microseconds). The removed volume of bone, whose rate is the load, is
sampled every ``REMOVED_PERIOD_S`` only: it sums the cut's removed voxels
per segment, whose cost grows with the cut.

Without an audio device the meter still runs: :meth:`start` returns False
and :attr:`message` says why the session goes on silent.
"""

from __future__ import annotations

import math
import time

from . import audioout, drillsound, nervemonitor, soundsource

TICK_PERIOD_S = 0.016
REMOVED_PERIOD_S = 0.1


class DesktopFeedback:
    """Meter rows and drill-sound parameters for one cut node of ``logic`` (``vtkSlicerVolumeCuttingLogic``)."""

    def __init__(self, logic, output: audioout.DrillSoundOutput | None = None,
                 config: drillsound.SoundConfig | None = None):
        self.logic = logic
        self.source = soundsource.DrillSoundSource(logic, config)
        self.output = output if output is not None else audioout.DrillSoundOutput(self.source.config)
        self.cut_node = None
        self.rows: list[dict] = []
        self.rows_changed = False
        self.parameters = drillsound.SoundParameters()
        self.message = ""
        self.ticks = 0
        self.sound_errors = 0
        self._removed_at = -math.inf

    @property
    def playing(self) -> bool:
        return self.output.playing

    def start(self, cut_node, sound: bool = True) -> bool:
        """Follow ``cut_node``; with ``sound``, open the audio stream. Whether the drill sound plays."""
        self.cut_node = cut_node
        self.source.stroke_ended()
        self.source.prepare(cut_node)
        self.rows, self.rows_changed = [], True
        return self.set_sound(sound)

    def set_sound(self, on: bool) -> bool:
        """Switch the drill sound on or off (the meter goes on either way); whether it plays now."""
        if not on:
            self.output.stop()
            self.message = "Drill sound off."
            return False
        playing = self.output.start()
        self.message = self.output.message
        return playing

    def set_volume(self, volume: float) -> None:
        """The sound's master gain, 0..1."""
        volume = float(volume)
        if not (math.isfinite(volume) and 0.0 <= volume <= 1.0):
            raise drillsound.SoundParameterError(f"volume = {volume!r} is outside 0..1")
        self.source.volume = volume

    def stop(self) -> None:
        """Silence and close the stream; the meter is emptied."""
        self.source.stroke_ended()
        self.output.set_parameters(drillsound.SoundParameters())
        self.output.stop()
        self.cut_node = None
        self.rows, self.rows_changed = [], True

    def _removed_mm3(self) -> float:
        return self.source.removed_bone_mm3(self.cut_node)

    def tick(self, drill_on: bool, now_s: float | None = None) -> list[dict]:
        """One display tick: read the monitor, follow the drill switch, hand the sound its parameters; the rows."""
        now_s = time.monotonic() if now_s is None else now_s
        self.ticks += 1
        monitor = self.logic.GetNerveMonitor(self.cut_node) if self.cut_node is not None else None
        rows = nervemonitor.meter_rows(nervemonitor.readings(monitor)) if monitor is not None else []
        self.rows_changed = nervemonitor.rows_differ(self.rows, rows)
        if self.rows_changed:
            self.rows = rows
        if bool(drill_on) != self.source.drill_on:
            if drill_on:
                self.source.stroke_began(self._removed_mm3(), now_s)
                self._removed_at = now_s
            else:
                self.source.stroke_ended()
        elif drill_on and now_s - self._removed_at >= REMOVED_PERIOD_S:
            self.source.note_removed(self._removed_mm3(), now_s)
            self._removed_at = now_s
        tool_node = self.cut_node.GetActiveToolNode() if self.cut_node is not None else None
        try:
            self.parameters = self.source.parameters(self.cut_node, tool_node)
        except drillsound.SoundParameterError as error:  # a bad reading: the sound keeps its last parameters
            self.sound_errors += 1
            self.message = f"Drill sound kept its last parameters: {error}"
            return self.rows
        self.output.set_parameters(self.parameters)
        return self.rows
