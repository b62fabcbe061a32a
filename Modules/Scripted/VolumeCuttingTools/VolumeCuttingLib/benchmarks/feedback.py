"""The area ``feedback`` (issue 25): what the trainee hears and is warned of.

The nerve monitor's accuracy and per-tick cost (``feedbackmonitor``) and the
drill sound's spectrum checks, synthesis cost and latencies
(``feedbacksound``), written together to ``feedback.json``.
"""

from __future__ import annotations

from .feedbackmonitor import monitor_measurements
from .feedbacksound import sound_measurements


def feedback(repeats: int) -> list[dict]:
    return monitor_measurements(repeats) + sound_measurements(repeats)
