"""Python helpers of the VolumeCutting extension, in subpackages by role.

Subpackages (each imports only those listed above it, never one below):
    scene: real Slicer without its Qt application (scene, logics, offscreen views, scene IO),
        numpy <-> MRML volume helpers, and where the shipped resources are.
    data: the data sets (real head CT, temporal-bone phantom, SoftCut sphere phantom,
        patient-scale case, analytic accuracy scenes) and the user's own CT and segmentation.
    config: cutting-tool parameters and presets, the input devices and drilling with them,
        without Qt (shared by the desktop module and the web application).
    cutting: scripted drilling paths, recorded sessions and their replay, SoftCut planning.
    jobs: the main job (``python -m VolumeCuttingLib.jobs.mainjob``), its haptic and SoftCut
        parts, and the Slicer self-tests.
    records: trainee records, the assessed sessions in SQLite or PostgreSQL, and learning curves
        (``python -m VolumeCuttingLib.records``).
    webapp: the web application (``python -m VolumeCuttingLib.webapp``).
    benchmarks: the benchmark harness and one module per area
        (``python -m VolumeCuttingLib.benchmarks --area AREA``).

Submodules are not imported here (nor by the subpackages' ``__init__``) so
that the numpy-only parts stay usable without VTK or Slicer.
"""
