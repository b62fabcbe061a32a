"""The drill sound's parameters from the module logic, for every output: the web page's AudioWorklet
(``webapp/soundfeed.py``, published in the trame state) and PortAudio on the desktop
(``desktopfeedback.py`` through ``audioout``).

One computation, so that both hear the same drill:

* the motor: the drill switch (a stroke is the foot pedal) and the tool
  node's speed times its power;
* load: the removal rate (mm3/s) of bone in the current stroke, from the
  removed volume the owner samples a few times a second (``note_removed``,
  e.g. ``removed_bone_mm3``; asking the logic for it at every tick would
  cost tens of ms while the field changes);
* the bone ahead: ``vtkSlicerVolumeCuttingLogic.MeasureBoneAhead``, the wall
  left ahead of the burr's tip along its axis, measured as the renderer's
  thin-bone tint measures walls (``vtkVolumeCutBoneAhead``);
* the nerve monitor's clicks: its loudest structure's level and firing rate.
"""

from __future__ import annotations

import math
import time

from . import drillsound, nervemonitor


class DrillSoundSource:
    """The drill sound's parameters for a cut node and its tool, from ``logic`` (``vtkSlicerVolumeCuttingLogic``)."""

    def __init__(self, logic, config: drillsound.SoundConfig | None = None, window_s: float = 0.25):
        self.logic = logic
        self.config = config or drillsound.SoundConfig()
        self.meter = drillsound.RemovalRateMeter(window_s=window_s)
        self.drill_on = False
        # Master gain 0..1: the desktop's volume slider (the page applies its own in the browser).
        self.volume = 1.0

    def stroke_began(self, removed_mm3: float, time_s: float | None = None) -> None:
        """The pedal pressed: the motor spins up; ``removed_mm3`` is the volume removed so far."""
        self.drill_on = True
        self.meter.reset()
        self.meter.update(removed_mm3, time.monotonic() if time_s is None else time_s)

    def stroke_ended(self) -> None:
        """The pedal released: the motor spins down."""
        self.drill_on = False

    def note_removed(self, removed_mm3: float, time_s: float | None = None) -> None:
        """The removed volume (mm3) just sampled: the removal rate follows from it while the drill is on."""
        if self.drill_on:
            self.meter.update(removed_mm3, time.monotonic() if time_s is None else time_s)

    def removed_bone_mm3(self, cut_node) -> float:
        """The volume (mm3) removed inside the cut node's cuttable segments: what loads the burr (air the burr
        sweeps through is removed from the cut field too, but costs it nothing)."""
        if cut_node is None:
            return 0.0
        volumes = (self.logic.GetRemovedVolumeInSegment(cut_node, segment_id) for segment_id in cut_node.GetCuttableSegmentIDs())
        return float(sum(volume for volume in volumes if volume > 0.0))

    def prepare(self, cut_node) -> None:
        """Make the bone-ahead query (the bone's mask from the cuttable segments: a pass over the scan) before
        the first stroke, so that the first tick of the sound does not wait for it."""
        if cut_node is not None:
            self.logic.GetBoneAhead(cut_node)

    def bone_ahead_mm(self, cut_node) -> float:
        """The bone left ahead of the tool's tip (mm; inf when none is ahead or nothing is known)."""
        if cut_node is None:
            return math.inf
        thickness = float(self.logic.MeasureBoneAhead(cut_node))
        return math.inf if math.isnan(thickness) else max(0.0, thickness)

    def monitor_input(self, cut_node) -> tuple[str, float]:
        """The nerve monitor's level and firing rate to mix in (silent without a monitor)."""
        return nervemonitor.sound_input(self.logic.GetNerveMonitor(cut_node) if cut_node is not None else None)

    def parameters(self, cut_node, tool_node) -> drillsound.SoundParameters:
        """The sound now (the defaults, silent, without a cut node and a tool); raises SoundParameterError."""
        if cut_node is None or tool_node is None:
            return drillsound.SoundParameters()
        rate = self.meter.rate if self.drill_on else 0.0
        level, monitor_rate = self.monitor_input(cut_node)
        return drillsound.parameters_from_session(
            tool_node, self.drill_on, rate, thickness_mm=self.bone_ahead_mm(cut_node),
            monitor_level=level, monitor_rate_hz=monitor_rate, volume=self.volume, config=self.config)
