"""The area ``feedback`` (issue 25): what the trainee hears and is warned of.

The nerve monitor's accuracy and per-tick cost (``feedbackmonitor``), the
drill sound's spectrum checks, synthesis cost and latencies
(``feedbacksound``) and the bone-ahead query's accuracy and cost
(``feedbackboneahead``), written together to ``feedback.json``.
"""

from __future__ import annotations

from .feedbackboneahead import bone_ahead_measurements
from .feedbackmonitor import monitor_measurements
from .feedbacksound import sound_measurements


def feedback(repeats: int) -> list[dict]:
    return monitor_measurements(repeats) + sound_measurements(repeats) + bone_ahead_measurements(repeats)
