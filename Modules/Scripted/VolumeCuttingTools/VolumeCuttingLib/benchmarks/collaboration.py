"""The area ``collaboration`` (issue 27): instructor and trainee together.

Its parts measure each bridge out of a drilling session: the OpenIGTLink
bridge to desktop Slicer (``collaborationigtl``), the forces forwarded
between two haptic loops (``collaborationcoupling``) and the instructor's
page behind the trainee's (``collaborationobserver``, two browser pages),
and several sessions at once through the launcher (``collaborationload``).
"""

from __future__ import annotations

from .collaborationcoupling import coupling_measurements
from .collaborationigtl import igtl_measurements
from .collaborationload import load_measurements
from .collaborationobserver import observer_measurements


def collaboration(repeats: int) -> list[dict]:
    return (igtl_measurements(repeats) + coupling_measurements(repeats) + observer_measurements(repeats)
            + load_measurements(repeats))
