"""Grading recorded drilling sessions: metrics, score and report (``python -m VolumeCuttingLib.assessment``).

Between ``feedback`` and ``jobs``: it reads recordings (``cutting.recording``)
and the shipped scans (``data``) and needs neither Slicer nor Qt.
"""
