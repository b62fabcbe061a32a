"""Whole jobs run without the Slicer GUI, and the self-tests that check them.

``mainjob`` is the README's main job (``python -m VolumeCuttingLib.jobs.mainjob``);
``hapticsjob`` and ``softcutjob`` are its haptic and SoftCut parts;
``selftests`` holds the Slicer self-tests that desktop Slicer and pytest both
run. Builds on every subpackage above it (``scene``, ``data``, ``config``,
``cutting``), which never import from here.
"""
