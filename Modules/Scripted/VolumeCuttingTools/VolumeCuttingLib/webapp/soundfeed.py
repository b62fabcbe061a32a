"""The drill sound's parameters for the page: published in the trame state (``vc_sound``) at 50 Hz while
drilling, played by the page's AudioWorklet (``www/drillsound.js``).

A stroke is the foot pedal: the motor spins up when it begins and down when
it ends. Load is the removal rate (mm3/s) of the stroke, from the removed
volume the application refreshes a few times a second (``note_removed``):
asking the logic for it at 50 Hz would cost the server tens of ms a tick
while the field changes. The bone ahead of the burr: the renderer
measures wall thickness only inside its shader (vtkVolumeCutThinBoneShader,
private to the ray caster), with no per-stroke readout, so its stand-in here
is the nerve monitor's distance from the burr's surface to the nearest
monitored structure (the bone left between the burr and what it must spare),
from ``nearest_structure_mm`` (a callable; none until one is connected).
The nerve monitor's level and rate come from ``monitor`` (a callable giving
``(level, rate_hz)``), silent until one is connected.
"""

from __future__ import annotations

import asyncio
import dataclasses
import math
import time

from trame_server.utils.asynchronous import create_task

from ..feedback import drillsound

PERIOD_S = 1.0 / 75.0  # 75 Hz: above the 50 Hz asked for, with room for ticks a busy event loop delays


class SoundFeed:
    """Keeps ``vc_sound`` in the state while drilling: {parameters, sent_at (ms since the epoch)}."""

    def __init__(self, session, state, config: drillsound.SoundConfig | None = None):
        self.session = session
        self.state = state
        self.config = config or drillsound.SoundConfig()
        self.meter = drillsound.RemovalRateMeter(window_s=0.25)
        self.nearest_structure_mm = lambda: math.inf
        self.monitor = lambda: ("silent", 0.0)
        self.drill_on = False
        self._task = None
        self.published = 0

    def initial_state(self) -> dict:
        return self._message(drillsound.SoundParameters())

    def _message(self, parameters: drillsound.SoundParameters) -> dict:
        return {"parameters": parameters.as_dict(), "sent_at": time.time() * 1000.0}

    def config_state(self) -> dict:
        """The sound's configuration for the page (``vc_sound_config``), sent once: not in every update."""
        return dataclasses.asdict(self.config)

    def bone_ahead_mm(self) -> float:
        """The stand-in for the bone left ahead: the burr's surface to the nearest monitored structure (mm)."""
        if not self.session.has_data:
            return math.inf
        return max(0.0, self.nearest_structure_mm())

    def parameters(self) -> drillsound.SoundParameters:
        if not self.session.has_data:
            return drillsound.SoundParameters()
        rate = self.meter.rate if self.drill_on else 0.0
        level, monitor_rate = self.monitor()
        return drillsound.parameters_from_session(
            self.session.tool_node, self.drill_on, rate, thickness_mm=self.bone_ahead_mm(),
            monitor_level=level, monitor_rate_hz=monitor_rate, config=self.config)

    def publish(self) -> None:
        try:
            message = self._message(self.parameters())
        except (drillsound.SoundParameterError, ValueError) as error:  # a bad reading: keep the last sound
            print(f"[sound] {error}", flush=True)
            return
        with self.state:
            self.state.vc_sound = message
        self.published += 1

    def note_removed(self, removed_mm3: float) -> None:
        """The removed volume (mm3) just refreshed: the removal rate follows from it."""
        if self.drill_on:
            self.meter.update(removed_mm3, time.monotonic())

    def stroke_began(self, removed_mm3: float) -> None:
        self.drill_on = True
        self.meter.reset()
        self.meter.update(removed_mm3, time.monotonic())
        self.publish()
        if self._task is None or self._task.done():
            self._task = create_task(self._tick())

    def stroke_ended(self) -> None:
        self.drill_on = False
        self.publish()

    async def _tick(self) -> None:
        # On a fixed clock while the pedal is down. The server's event loop also cuts and renders: a frame that
        # holds it delays the next tick, which then comes at once (no catching up on the missed ones).
        loop = asyncio.get_running_loop()
        next_tick = loop.time()
        while self.drill_on:
            next_tick = max(next_tick + PERIOD_S, loop.time())
            await asyncio.sleep(next_tick - loop.time())
            if self.drill_on:
                self.publish()
