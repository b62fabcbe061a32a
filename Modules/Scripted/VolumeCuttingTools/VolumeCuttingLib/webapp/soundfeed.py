"""The drill sound's parameters for the page: published in the trame state (``vc_sound``) at 75 Hz while
drilling, played by the page's AudioWorklet (``www/drillsound.js``).

What the parameters are made of (the stroke as the foot pedal, the removal
rate as load, the bone left ahead of the burr, the nerve monitor's clicks) is
``feedback.soundsource.DrillSoundSource``, which the desktop plays too; this
feed keeps them in the state on a fixed clock while a stroke is held. The
application refreshes the removed volume a few times a second
(``note_removed``).
"""

from __future__ import annotations

import asyncio
import dataclasses
import time

from trame_server.utils.asynchronous import create_task

from ..feedback import drillsound, soundsource

PERIOD_S = 1.0 / 75.0  # 75 Hz: above the 50 Hz asked for, with room for ticks a busy event loop delays


class SoundFeed:
    """Keeps ``vc_sound`` in the state while drilling: {parameters, sent_at (ms since the epoch)}."""

    def __init__(self, session, state, config: drillsound.SoundConfig | None = None):
        self.session = session
        self.state = state
        self.source = soundsource.DrillSoundSource(session.logic, config)
        self._task = None
        self.published = 0

    @property
    def config(self) -> drillsound.SoundConfig:
        return self.source.config

    @property
    def drill_on(self) -> bool:
        return self.source.drill_on

    def initial_state(self) -> dict:
        return self._message(drillsound.SoundParameters())

    def _message(self, parameters: drillsound.SoundParameters) -> dict:
        return {"parameters": parameters.as_dict(), "sent_at": time.time() * 1000.0}

    def config_state(self) -> dict:
        """The sound's configuration for the page (``vc_sound_config``), sent once: not in every update."""
        return dataclasses.asdict(self.config)

    def prepare(self) -> None:
        """New data: the bone-ahead query is made now, not at the first stroke."""
        if self.session.has_data:
            self.source.prepare(self.session.cut_node)

    def parameters(self) -> drillsound.SoundParameters:
        if not self.session.has_data:
            return drillsound.SoundParameters()
        return self.source.parameters(self.session.cut_node, self.session.tool_node)

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
        self.source.note_removed(removed_mm3)

    def stroke_began(self, removed_mm3: float) -> None:
        self.source.stroke_began(removed_mm3)
        self.publish()
        if self._task is None or self._task.done():
            self._task = create_task(self._tick())

    def stroke_ended(self) -> None:
        self.source.stroke_ended()
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
