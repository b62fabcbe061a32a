"""Real Slicer without its Qt application: scene, logics and offscreen 3D and slice views.

Desktop Slicer wires a scene to an application logic, the module logics and, for
each view, a group of displayable managers. This module does the same with
the Qt-free libraries of slicer-core, so that the main job, the benchmarks and the
tests use real MRML nodes, real logics and Slicer's own 3D and 2D rendering.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import slicer
import vtk
from vtkmodules.util import numpy_support

# Displayable managers of a desktop 3D view that this product's scenes use.
THREE_D_DISPLAYABLE_MANAGERS = (
    "vtkMRMLCameraDisplayableManager",
    "vtkMRMLViewDisplayableManager",
    "vtkMRMLModelDisplayableManager",
    "vtkMRMLSegmentationsDisplayableManager3D",
    "vtkMRMLVolumeRenderingDisplayableManager",
)

# Displayable managers of a desktop slice view that this product's scenes use.
SLICE_DISPLAYABLE_MANAGERS = (
    "vtkMRMLCrosshairDisplayableManager",
    "vtkMRMLModelSliceDisplayableManager",
    "vtkMRMLSegmentationsDisplayableManager2D",
    "vtkMRMLVolumeGlyphSliceDisplayableManager",
)


def _write_screenshot(render_window, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    grabber = vtk.vtkWindowToImageFilter()
    grabber.SetInput(render_window)
    grabber.ReadFrontBufferOff()
    # The caller has just rendered: reading the buffer must not draw a frame again.
    grabber.ShouldRerenderOff()
    grabber.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(str(path))
    writer.SetInputConnection(grabber.GetOutputPort())
    writer.Write()
    return path


def _nodes_of_class(scene, class_name: str) -> list:
    return [scene.GetNthNodeByClass(index, class_name) for index in range(scene.GetNumberOfNodesByClass(class_name))]


def opengl_renderer_name(render_window) -> str:
    """The OpenGL renderer of a window that has rendered (llvmpipe, or a GPU's name)."""
    capabilities = render_window.ReportCapabilities() or ""
    for line in capabilities.splitlines():
        if "OpenGL renderer string" in line:
            return line.split(":", 1)[1].strip()
    return "unknown"


def configure_scene_io(scene, cache_directory: str | Path | None = None):
    """Give a scene the data I/O and cache managers that scene bundles (.mrb) need, as desktop Slicer does.

    Reading a bundle unpacks it into the cache manager's folder: ``cache_directory``,
    or a temporary folder, whose ``TemporaryDirectory`` is returned (keep it
    alive as long as the scene; None when a folder was given).
    """
    temporary = None
    if cache_directory is None:
        temporary = tempfile.TemporaryDirectory(prefix="volumecutting-cache-")
        cache_directory = temporary.name
    Path(cache_directory).mkdir(parents=True, exist_ok=True)
    cache_manager = slicer.vtkCacheManager()
    cache_manager.SetRemoteCacheDirectory(str(cache_directory))
    data_io_manager = slicer.vtkDataIOManager()
    data_io_manager.SetCacheManager(cache_manager)
    scene.SetCacheManager(cache_manager)
    scene.SetDataIOManager(data_io_manager)
    return temporary


class HeadlessSlicer:
    """A scene with the application and module logics that VolumeCutting relies on.

    Attributes: ``scene``, ``application_logic`` and ``volume_cutting_logic``
    (plus the Segmentations and VolumeRendering logics the displayable managers
    look up by module name).
    """

    def __init__(self, cache_directory: str | Path | None = None):
        self.scene = slicer.vtkMRMLScene()
        self._temporary = configure_scene_io(self.scene, cache_directory)

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

    def create_slice_view(self, orientation: str = "Axial", width: int = 512, height: int = 512, name: str = "Red") -> SliceView:
        """An offscreen slice view (``orientation``: Axial, Sagittal or Coronal) named like Slicer's (Red, Yellow, Green)."""
        return SliceView(self, orientation, width, height, name)

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
        # The cut volume is ray cast once per pixel, so multisampling only
        # smooths polygon edges (tool glyph, markups); on llvmpipe it costs
        # 23 ms of a 1024 x 768 frame, half an interactive frame's budget.
        # The web application's views do the same.
        self.render_window.SetMultiSamples(0)
        self.render_window.AddRenderer(self.renderer)
        # Displayable managers install their interaction observers on it.
        self.interactor = vtk.vtkRenderWindowInteractor()
        self.interactor.SetRenderWindow(self.render_window)
        self.displayable_managers = factory.InstantiateDisplayableManagers(self.renderer)
        # Desktop Slicer creates ours by name through its object factory; here
        # it is added to the view's group directly.
        self.volume_cut_displayable_manager = slicer.vtkMRMLVolumeCutDisplayableManager()
        self.displayable_managers.AddDisplayableManager(self.volume_cut_displayable_manager)
        self.tool_displayable_manager = slicer.vtkMRMLVolumeCutToolDisplayableManager()
        self.displayable_managers.AddDisplayableManager(self.tool_displayable_manager)
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
        if not self.render_window.GetNeverRendered():
            return opengl_renderer_name(self.render_window)
        self.render()
        return opengl_renderer_name(self.render_window)

    def screenshot(self, path: str | Path) -> Path:
        self.render()
        return _write_screenshot(self.render_window, path)

    def close(self) -> None:
        self.displayable_managers.SetMRMLDisplayableNode(None)
        self.render_window.Finalize()


class SliceView:
    """An offscreen slice view: Slicer's slice logic and slice displayable managers, and ours.

    As in desktop Slicer, a ``vtkMRMLSliceLogic`` owns the slice node (and its
    composite node) and reslices the background and foreground volumes into one
    RGBA image of the view's size, drawn here as the background; the
    displayable managers draw over it in the slice node's XY (pixel)
    coordinates. Attributes: ``slice_node``, ``slice_logic``, ``renderer``,
    ``render_window``, ``displayable_managers`` and
    ``volume_cut_displayable_manager`` (vtkMRMLVolumeCutSliceDisplayableManager).
    """

    def __init__(self, application: HeadlessSlicer, orientation: str, width: int, height: int, name: str):
        if orientation not in ("Axial", "Sagittal", "Coronal"):
            raise ValueError(f"Slice view '{name}': orientation {orientation!r} is not Axial, Sagittal or Coronal")
        scene = application.scene
        self._application_logic = application.application_logic
        self.slice_logic = slicer.vtkMRMLSliceLogic()
        self.slice_logic.SetMRMLApplicationLogic(application.application_logic)
        self.slice_logic.SetMRMLScene(scene)
        # A scene read from a file may hold this view's slice node already
        # (slice nodes are singletons per view name).
        existing = [node for node in _nodes_of_class(scene, "vtkMRMLSliceNode") if node.GetLayoutName() == name]
        if existing:
            self.slice_node = existing[0]
            self.slice_logic.SetSliceNode(self.slice_node)
        else:
            self.slice_node = self.slice_logic.AddSliceNode(name)
        # Desktop Slicer's layout manager keeps the views' slice logics here
        # (crosshair, slice intersections and the segmentations 2D DM look them up).
        if application.application_logic.GetSliceLogics() is None:
            application.application_logic.SetSliceLogics(vtk.vtkCollection())
        application.application_logic.GetSliceLogics().AddItem(self.slice_logic)
        self.slice_node.SetOrientation(orientation)

        self.renderer = vtk.vtkRenderer()
        self.renderer.GetActiveCamera().ParallelProjectionOn()
        self.render_window = vtk.vtkRenderWindow()
        self.render_window.SetOffScreenRendering(True)
        self.render_window.SetSize(width, height)
        # Slice views draw the resliced image pixel for pixel, without
        # multisampling (on llvmpipe 8x multisampling costs 65 ms a frame at 800^2).
        self.render_window.SetMultiSamples(0)
        self.render_window.AddRenderer(self.renderer)
        self.interactor = vtk.vtkRenderWindowInteractor()
        self.interactor.SetRenderWindow(self.render_window)
        # The slice logic's image: the reslice of the layers, already windowed to 8-bit RGBA.
        self.image_mapper = vtk.vtkImageMapper()
        self.image_mapper.SetColorWindow(255.0)
        self.image_mapper.SetColorLevel(127.5)
        self.image_actor = vtk.vtkActor2D()
        self.image_actor.SetMapper(self.image_mapper)
        self.image_actor.GetProperty().SetDisplayLocationToBackground()
        self.image_actor.SetVisibility(False)
        self.renderer.AddViewProp(self.image_actor)

        factory = slicer.vtkMRMLSliceViewDisplayableManagerFactory.GetInstance()
        factory.SetMRMLApplicationLogic(application.application_logic)
        for manager in SLICE_DISPLAYABLE_MANAGERS:
            if not factory.IsDisplayableManagerRegistered(manager):
                factory.RegisterDisplayableManager(manager)
        self.displayable_managers = factory.InstantiateDisplayableManagers(self.renderer)
        # Desktop Slicer creates ours by name through its object factory
        # (qSlicerVolumeCuttingModule::setup); here it joins the view's group directly.
        self.volume_cut_displayable_manager = slicer.vtkMRMLVolumeCutSliceDisplayableManager()
        self.displayable_managers.AddDisplayableManager(self.volume_cut_displayable_manager)
        self.displayable_managers.SetMRMLDisplayableNode(self.slice_node)
        self.slice_logic.ResizeSliceNode(width, height)

    def set_background_volume(self, volume_node) -> None:
        """Show a volume (the CT) as the background layer, windowed by its display node."""
        if volume_node is not None and volume_node.GetDisplayNode() is None:
            volume_node.CreateDefaultDisplayNodes()
        # Volume display nodes map through Slicer's default grey colour table,
        # which desktop Slicer's colour logic adds at startup.
        scene = self.slice_node.GetScene()
        if volume_node is not None and scene.GetNodeByID("vtkMRMLColorTableNodeGrey") is None:
            color_logic = self._application_logic.GetColorLogic()
            color_logic.SetMRMLScene(scene)
            color_logic.AddDefaultColorNodes()
        self.slice_logic.GetSliceCompositeNode().SetBackgroundVolumeID(volume_node.GetID() if volume_node else None)

    def fit(self) -> None:
        """Fit the field of view to the background volume."""
        width, height = self.render_window.GetSize()
        self.slice_logic.FitSliceToAll(width, height)

    def set_slice_offset(self, offset_mm: float) -> None:
        """Move the plane along its normal to ``offset_mm`` (for an axial view: S, mm)."""
        self.slice_logic.SetSliceOffset(offset_mm)

    def set_slice_to_ras(self, slice_to_ras) -> None:
        """Any plane (oblique too): a 4x4 slice-to-RAS matrix (numpy or vtkMatrix4x4)."""
        matrix = slice_to_ras
        if not isinstance(matrix, vtk.vtkMatrix4x4):
            matrix = vtk.vtkMatrix4x4()
            for row in range(4):
                for column in range(4):
                    matrix.SetElement(row, column, float(slice_to_ras[row][column]))
        self.slice_node.GetSliceToRAS().DeepCopy(matrix)
        self.slice_node.UpdateMatrices()

    def xy_to_ras(self, x: float, y: float) -> tuple[float, float, float]:
        """RAS (mm) of a point of the view given in its XY (pixel) coordinates."""
        ras = self.slice_node.GetXYToRAS().MultiplyPoint((x, y, 0.0, 1.0))
        return ras[0], ras[1], ras[2]

    def render(self) -> None:
        connection = self.slice_logic.GetImageDataConnection()
        if connection is not None:
            self.image_mapper.SetInputConnection(connection)
        self.image_actor.SetVisibility(connection is not None)
        self.render_window.Render()

    def screenshot(self, path: str | Path) -> Path:
        self.render()
        return _write_screenshot(self.render_window, path)

    def rgb(self):
        """The rendered view as a (height, width, 3) uint8 array, row 0 at the bottom (XY y = 0)."""
        self.render()
        grabber = vtk.vtkWindowToImageFilter()
        grabber.SetInput(self.render_window)
        grabber.SetInputBufferTypeToRGB()
        grabber.ReadFrontBufferOff()
        grabber.Update()
        image = grabber.GetOutput()
        width, height, _ = image.GetDimensions()
        pixels = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars())
        return np.asarray(pixels).reshape(height, width, 3)

    def close(self) -> None:
        self.displayable_managers.SetMRMLDisplayableNode(None)
        self.render_window.Finalize()
