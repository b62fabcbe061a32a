"""What every other subpackage builds on: a Slicer scene without the GUI.

``application`` gives real Slicer without its Qt application (the scene, the
module logics, scene IO and offscreen 3D and slice views with the product's
displayable managers); ``nodes`` moves numpy volumes in and out of MRML nodes;
``resources`` finds the files shipped with VolumeCutting (presets, recorded
sessions) however it is installed. Nothing here imports another subpackage.
"""
