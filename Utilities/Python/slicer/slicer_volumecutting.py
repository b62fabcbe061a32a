# Jump pad of the `slicer` meta-package (see slicer/__init__.py of slicer-core):
# it makes VolumeCutting's classes available as slicer.<ClassName>, as desktop
# Slicer does for a loadable module's wrapped libraries.
from slicer_volumecutting import *  # noqa: F401,F403
