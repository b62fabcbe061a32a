"""VolumeCutting's Qt-free libraries, Python-wrapped (Slicer Core build).

Importing this package imports slicer-core first, so that the Slicer classes our
classes derive from are registered before ours.
"""

import slicer_core  # noqa: F401  (loads VTK and Slicer's libraries our modules link to)

from .vtkVolumeCuttingCore import *  # noqa: F401,F403
from .vtkVolumeCuttingRendering import *  # noqa: F401,F403
from .vtkVolumeCuttingSoftCut import *  # noqa: F401,F403
from .vtkVolumeCuttingHaptics import *  # noqa: F401,F403
from .vtkSlicerVolumeCuttingModuleMRML import *  # noqa: F401,F403
from .vtkSlicerVolumeCuttingModuleLogic import *  # noqa: F401,F403
from .vtkSlicerVolumeCuttingModuleMRMLDisplayableManager import *  # noqa: F401,F403
