"""The area ``collaboration`` (issue 27): instructor and trainee together.

Its parts measure each bridge out of a drilling session; so far the
OpenIGTLink bridge to desktop Slicer (``collaborationigtl``).
"""

from __future__ import annotations

from .collaborationigtl import igtl_measurements


def collaboration(repeats: int) -> list[dict]:
    return igtl_measurements(repeats)
