"""Benchmarks: one JSON file of measurements per product area.

``harness`` is what the areas share (machine description, measurements,
timing, grids, results files); every other module is one area, imported only
by ``__main__`` (``python -m VolumeCuttingLib.benchmarks --area AREA``) when
it runs. Areas import the harness and the rest of the library, never another
area, and nothing outside this package imports from here.
"""
