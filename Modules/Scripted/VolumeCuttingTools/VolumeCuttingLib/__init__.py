"""Python helpers of the VolumeCutting extension.

Modules:
    phantom: procedural temporal-bone CT phantom with analytic geometry.
    headct: loader for the real head CT shipped by Debian (invesalius-examples).
    nodes: numpy <-> MRML volume helpers shared by the two.

Submodules are not imported here so that the numpy-only parts stay usable
without VTK or Slicer.
"""
