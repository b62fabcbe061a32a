"""Real Slicer without its Qt application: scene, logics and an offscreen 3D view.

Desktop Slicer wires a scene to an application logic, the module logics and, for
each 3D view, a group of displayable managers. This module does the same with
the Qt-free libraries of slicer-core, so that the main job, the benchmarks and the
tests use real MRML nodes, real logics and Slicer's own 3D rendering.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import slicer
import vtk

# Displayable managers of a desktop 3D view that this product's scenes use.
THREE_D_DISPLAYABLE_MANAGERS = (
    "vtkMRMLCameraDisplayableManager",
    "vtkMRMLViewDisplayableManager",
    "vtkMRMLModelDisplayableManager",
    "vtkMRMLSegmentationsDisplayableManager3D",
    "vtkMRMLVolumeRenderingDisplayableManager",
)


def opengl_renderer_name(render_window) -> str:
    """The OpenGL renderer of a window that has rendered (llvmpipe, or a GPU's name)."""
    capabilities = render_window.ReportCapabilities() or ""
    for line in capabilities.splitlines():
        if "OpenGL renderer string" in line:
            return line.split(":", 1)[1].strip()
    return "unknown"


class HeadlessSlicer:
    """A scene with the application and module logics that VolumeCutting relies on.

    Attributes: ``scene``, ``application_logic`` and ``volume_cutting_logic``
    (plus the Segmentations and VolumeRendering logics the displayable managers
    look up by module name).
    """

    def __init__(self, cache_directory: str | Path | None = None):
        self.scene = slicer.vtkMRMLScene()
        # Reading a scene bundle (.mrb) unpacks it into the cache manager's folder.
        self._temporary = None
        if cache_directory is None:
            self._temporary = tempfile.TemporaryDirectory(prefix="volumecutting-cache-")
            cache_directory = self._temporary.name
        cache_manager = slicer.vtkCacheManager()
        cache_manager.SetRemoteCacheDirectory(str(cache_directory))
        data_io_manager = slicer.vtkDataIOManager()
        data_io_manager.SetCacheManager(cache_manager)
        self.scene.SetCacheManager(cache_manager)
        self.scene.SetDataIOManager(data_io_manager)

        self.application_logic = slicer.vtkSlicerApplicationLogic()
        self.application_logic.SetMRMLScene(self.scene)
        self._module_logics = {}
        for module_name, logic_class in (
            ("Segmentations", slicer.vtkSlicerSegmentationsModuleLogic),
            ("VolumeRendering", slicer.vtkSlicerVolumeRenderingLogic),
            ("VolumeCutting", slicer.vtkSlicerVolumeCuttingLogic),
        ):
            logic = logic_class()
            logic.SetMRMLApplicationLogic(self.application_logic)
            logic.SetMRMLScene(self.scene)
            self.application_logic.SetModuleLogic(module_name, logic)
            self._module_logics[module_name] = logic
        self.volume_cutting_logic = self._module_logics["VolumeCutting"]

    def module_logic(self, module_name: str):
        return self._module_logics[module_name]

    def create_3d_view(self, width: int = 800, height: int = 600, name: str = "View1") -> ThreeDView:
        return ThreeDView(self, width, height, name)

    def save_bundle(self, path: str | Path) -> Path:
        """Save the whole scene, with its data, as a Slicer scene bundle (.mrb)."""
        # Slicer resolves a bundle's files against the scene's root directory,
        # not the working directory: a relative path must be made absolute.
        path = Path(path).expanduser().resolve()
        path.parent.mkdir(parents=True, exist_ok=True)
        if not self.scene.WriteToMRB(str(path)):
            raise RuntimeError(f"Saving the scene to {path} failed (see the log)")
        return path

    def load_bundle(self, path: str | Path) -> None:
        """Replace the scene by a scene bundle (.mrb); a relative path is taken from the working directory."""
        path = Path(path).expanduser().resolve()
        if not path.is_file():
            raise FileNotFoundError(f"No scene bundle at {path}")
        if not self.scene.ReadFromMRB(str(path), True):
            raise RuntimeError(f"Reading the scene bundle {path} failed (see the log)")


class ThreeDView:
    """An offscreen 3D view rendered by Slicer's displayable managers."""

    def __init__(self, application: HeadlessSlicer, width: int, height: int, name: str):
        scene = application.scene
        self.view_node = scene.AddNewNodeByClass("vtkMRMLViewNode", name)
        self.view_node.SetBoxVisible(False)
        self.view_node.SetAxisLabelsVisible(False)
        factory = slicer.vtkMRMLThreeDViewDisplayableManagerFactory.GetInstance()
        factory.SetMRMLApplicationLogic(application.application_logic)
        for manager in THREE_D_DISPLAYABLE_MANAGERS:
            if not factory.IsDisplayableManagerRegistered(manager):
                factory.RegisterDisplayableManager(manager)
        self.renderer = vtk.vtkRenderer()
        self.render_window = vtk.vtkRenderWindow()
        self.render_window.SetOffScreenRendering(True)
        self.render_window.SetSize(width, height)
        self.render_window.AddRenderer(self.renderer)
        # Displayable managers install their interaction observers on it.
        self.interactor = vtk.vtkRenderWindowInteractor()
        self.interactor.SetRenderWindow(self.render_window)
        self.displayable_managers = factory.InstantiateDisplayableManagers(self.renderer)
        # Desktop Slicer creates ours by name through its object factory; here
        # it is added to the view's group directly.
        self.volume_cut_displayable_manager = slicer.vtkMRMLVolumeCutDisplayableManager()
        self.displayable_managers.AddDisplayableManager(self.volume_cut_displayable_manager)
        self.displayable_managers.SetMRMLDisplayableNode(self.view_node)

    def look_at(self, focal_point, direction, distance, view_up=(0.0, 0.0, 1.0)):
        """Place the camera at ``focal_point + distance * direction`` looking at the focal point."""
        camera = self.renderer.GetActiveCamera()
        camera.SetFocalPoint(*focal_point)
        camera.SetPosition(*(f + distance * d for f, d in zip(focal_point, direction)))
        camera.SetViewUp(*view_up)
        self.renderer.ResetCameraClippingRange()

    def fit(self, bounds=None):
        if bounds is None:
            self.renderer.ResetCamera()
        else:
            self.renderer.ResetCamera(bounds)

    def render(self) -> None:
        self.render_window.Render()

    def renderer_description(self) -> str:
        """The OpenGL renderer in use (for example llvmpipe, or a GPU's name)."""
        self.render()
        return opengl_renderer_name(self.render_window)

    def screenshot(self, path: str | Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.render()
        grabber = vtk.vtkWindowToImageFilter()
        grabber.SetInput(self.render_window)
        grabber.ReadFrontBufferOff()
        grabber.Update()
        writer = vtk.vtkPNGWriter()
        writer.SetFileName(str(path))
        writer.SetInputConnection(grabber.GetOutputPort())
        writer.Write()
        return path

    def close(self) -> None:
        self.displayable_managers.SetMRMLDisplayableNode(None)
        self.render_window.Finalize()
