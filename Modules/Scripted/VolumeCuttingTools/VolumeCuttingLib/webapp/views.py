"""The web application's views: trame-slicer views with the product's displayable managers, and the drill.

* ``VolumeCutThreeDView``: trame-slicer's 3D view plus
  ``vtkMRMLVolumeCutDisplayableManager`` (the cut anatomy through the
  adaptive multivolume ray caster); it keeps the depth of the surface it
  drew (``SurfaceDepth``) so that the drill finds the surface under the mouse.
* ``VolumeCutSliceView``: trame-slicer's slice view plus
  ``vtkMRMLVolumeCutSliceDisplayableManager`` (outline and fill of the cut).
* ``DrillPipeline``: a slicer-layer-dm pipeline of the tool's display node
  in each 3D view. It draws the tool glyph at the tool's pose, over the
  anatomy (its own render layer, occluded by the bone in front of it), and,
  in the drill and restore modes, turns press-drag-release into a stroke of
  the active tool along the surface under the mouse; in the SoftCut outline
  mode a click places a point of the outline on the surface under the mouse.

Multisampling is off in every view: the images are the ray caster's and the
resliced CT, drawn pixel for pixel (on llvmpipe 8x multisampling made a
1024x768 frame of the 3D view 3.6 times slower: 96 against 27 ms).
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
import slicer
import vtk
from LayerDMLib import vtkMRMLLayerDMScriptedPipeline
from trame_slicer.views import SliceView, ThreeDView
from vtkmodules.util import numpy_support

from .session import tool_pose

# Window depth of pixels where no surface was drawn.
_BACKGROUND_DEPTH = 1.0 - 1e-6
# The surface under a burr is read from at most this many pixels either side of the pointer (a 25 x 25 window),
# and from at least this many pixels on the surface.
_FOOTPRINT_MAX_PIXELS = 12
_FOOTPRINT_MIN_PIXELS = 6


class SurfaceDepth:
    """The depth buffer of a renderer's last frame, read when that renderer finished drawing.

    Read before later render layers (the tool glyph) draw, so it holds the
    anatomy's surface alone. ``surface_point(fx, fy)`` gives the surface
    point (RAS) under a point of the view given as fractions of its width
    and height (0 at the left and bottom), and the direction of the ray
    from the eye, or None where the ray meets no surface.
    """

    def __init__(self, renderer):
        self._renderer = renderer
        self.depth = None  # (rows, columns) window depth, row 0 at the bottom
        self.captured_at = 0.0  # time.monotonic() of the frame
        self._ndc_to_world = None
        self._eye = None
        self._parallel_direction = None
        renderer.AddObserver(vtk.vtkCommand.EndEvent, self._capture)

    def _capture(self, *_):
        window = self._renderer.GetRenderWindow()
        width, height = window.GetSize()
        if width < 1 or height < 1:
            return
        values = vtk.vtkFloatArray()
        if not window.GetZbufferData(0, 0, width - 1, height - 1, values):
            return
        self.depth = numpy_support.vtk_to_numpy(values).reshape(height, width).copy()
        self.captured_at = time.monotonic()
        camera = self._renderer.GetActiveCamera()
        composite = camera.GetCompositeProjectionTransformMatrix(self._renderer.GetTiledAspectRatio(), -1.0, 1.0)
        inverse = vtk.vtkMatrix4x4()
        vtk.vtkMatrix4x4.Invert(composite, inverse)
        self._ndc_to_world = np.array([[inverse.GetElement(r, c) for c in range(4)] for r in range(4)])
        self._eye = np.array(camera.GetPosition())
        self._parallel_direction = np.array(camera.GetDirectionOfProjection()) if camera.GetParallelProjection() else None

    def snapshot(self) -> SurfaceDepth:
        """A copy that later frames do not change (a stroke follows the surface as it was when it began)."""
        copy = SurfaceDepth.__new__(SurfaceDepth)
        copy._renderer = None
        copy.depth = None if self.depth is None else self.depth.copy()
        copy.captured_at = self.captured_at
        copy._ndc_to_world = self._ndc_to_world
        copy._eye = self._eye
        copy._parallel_direction = self._parallel_direction
        return copy

    def surface_point(self, fx: float, fy: float, footprint_mm: float = 0.0):
        """With ``footprint_mm`` > 0 the point lies on the plane fitted to the surface within that radius of the
        pixel's point: a burr follows the surface under its whole footprint, not each pixel's noise, nor the
        4 x 4 blocks of a frame drawn while the camera moved (both printed bands across a drilled groove)."""
        if self.depth is None or not (0.0 <= fx <= 1.0 and 0.0 <= fy <= 1.0):
            return None
        rows, columns = self.depth.shape
        column = min(columns - 1, int(fx * columns))
        row = min(rows - 1, int(fy * rows))
        depth = float(self.depth[row, column])
        if depth >= _BACKGROUND_DEPTH:
            return None
        point = self._unproject(np.array([fx]), np.array([fy]), np.array([depth]))
        if point is None:
            return None
        point = point[0]
        direction = self._parallel_direction if self._parallel_direction is not None else point - self._eye
        norm = np.linalg.norm(direction)
        if not np.isfinite(norm) or norm == 0.0:
            return None
        direction = direction / norm
        if footprint_mm > 0.0:
            point = self._footprint_point(fx, fy, row, column, point, direction, footprint_mm)
        return point, direction

    def _unproject(self, fx, fy, depth):
        ndc = np.stack([2.0 * fx - 1.0, 2.0 * fy - 1.0, 2.0 * depth - 1.0, np.ones_like(fx)])
        world = self._ndc_to_world @ ndc
        if np.any(world[3] == 0.0):
            return None
        return (world[:3] / world[3]).T

    def _footprint_point(self, fx, fy, row, column, point, direction, footprint_mm):
        rows, columns = self.depth.shape
        beside = self._unproject(np.array([fx + 1.0 / columns]), np.array([fy]), np.array([self.depth[row, column]]))
        pixel_mm = float(np.linalg.norm(beside[0] - point)) if beside is not None else 0.0
        if not np.isfinite(pixel_mm) or pixel_mm <= 0.0:
            return point
        reach = int(min(_FOOTPRINT_MAX_PIXELS, np.ceil(footprint_mm / pixel_mm)))
        if reach < 1:
            return point
        r0, r1 = max(0, row - reach), min(rows, row + reach + 1)
        c0, c1 = max(0, column - reach), min(columns, column + reach + 1)
        window = self.depth[r0:r1, c0:c1]
        r, c = np.nonzero(window < _BACKGROUND_DEPTH)
        if len(r) < _FOOTPRINT_MIN_PIXELS:
            return point
        du = (c0 + c + 0.5) / columns - fx
        dv = (r0 + r + 0.5) / rows - fy
        points = self._unproject(fx + du, fy + dv, window[r, c].astype(float))
        if points is None:
            return point
        # Only the surface under the footprint: a silhouette's far side or another structure in front is left out.
        near = np.linalg.norm(points - point, axis=1) <= footprint_mm
        if near.sum() < _FOOTPRINT_MIN_PIXELS:
            return point
        along = (points[near] - point) @ direction
        design = np.stack([np.ones(int(near.sum())), du[near] * columns, dv[near] * rows], axis=1)
        solution, _, rank, _ = np.linalg.lstsq(design, along, rcond=None)
        if rank < 3 or not np.isfinite(solution[0]) or abs(solution[0]) > footprint_mm:
            return point
        return point + solution[0] * direction


def add_product_displayable_manager(view, manager):
    """Add the product's displayable manager to a trame-slicer view's group, multisampling off.

    Desktop Slicer creates it by name through its object factory; here it joins the group directly.
    """
    view.render_window().SetMultiSamples(0)
    view._displayable_manager_group.AddDisplayableManager(manager)
    return manager


def _box_center(bounds):
    return [(bounds[2 * axis] + bounds[2 * axis + 1]) / 2.0 for axis in range(3)]


def fitting_distance(bounds, direction, view_up, view_angle_deg: float, aspect: float, margin: float = 0.05) -> float:
    """The camera distance from the box's centre along ``direction`` at which the whole box is in a perspective view.

    ``view_angle_deg`` is the vertical view angle, ``aspect`` width / height. A corner at ``along`` towards
    the eye and ``across`` off the axis is inside when across / (distance - along) <= tan(half angle).
    """
    forward = np.asarray(direction, dtype=float)
    forward /= np.linalg.norm(forward)
    up = np.asarray(view_up, dtype=float) - np.dot(view_up, forward) * forward
    if np.linalg.norm(up) < 1e-9:  # looking along the up vector: any perpendicular will do
        up = np.cross(forward, [1.0, 0.0, 0.0] if abs(forward[0]) < 0.9 else [0.0, 1.0, 0.0])
    up /= np.linalg.norm(up)
    right = np.cross(forward, up)
    tan_vertical = math.tan(math.radians(view_angle_deg) / 2.0) * (1.0 - margin)
    tan_horizontal = tan_vertical * aspect
    center = np.array(_box_center(bounds))
    distance = 0.0
    for corner in itertools.product(*((bounds[2 * a], bounds[2 * a + 1]) for a in range(3))):
        offset = np.array(corner) - center
        along = float(np.dot(offset, forward))
        distance = max(distance, along + abs(float(np.dot(offset, up))) / tan_vertical,
                       along + abs(float(np.dot(offset, right))) / tan_horizontal)
    return max(distance, 1e-3)


class VolumeCutThreeDView(ThreeDView):
    """trame-slicer's 3D view with the product's volume-cut displayable manager."""

    def __init__(self, scene, app_logic, name, *args, **kwargs):
        super().__init__(scene, app_logic, name, *args, **kwargs)
        self.volume_cut_displayable_manager = add_product_displayable_manager(
            self, slicer.vtkMRMLVolumeCutDisplayableManager())
        self.surface_depth = SurfaceDepth(self.renderer())
        view_node = self.get_view_node()
        if view_node is not None:
            view_node.SetBoxVisible(False)
            view_node.SetAxisLabelsVisible(False)

    def look_from(self, bounds, direction, view_up=(0.0, 0.0, 1.0), margin=0.12) -> None:
        """Look at the centre of ``bounds`` (RAS) from ``direction`` (towards the eye), the whole box in view.

        The distance is the nearest at which every corner of the box projects inside the view, less
        ``margin`` of its half-size on each side (room for the mode hint along the bottom), at this view's aspect: a scan whose tissue fills its
        box (a temporal-bone block) opens whole, not as a close-up of its near face.
        """
        width, height = self.render_window().GetSize() if self.render_window() is not None else (1, 1)
        aspect = width / height if width > 0 and height > 0 else 1.0
        self.look_at(_box_center(bounds), direction, fitting_distance(bounds, direction, view_up, 30.0, aspect, margin),
                     view_up)

    def look_at(self, center, direction, distance, view_up=(0.0, 0.0, 1.0)) -> None:
        """Look at ``center`` (RAS) from ``distance`` mm along ``direction`` (towards the eye)."""
        camera_node = self.get_camera_node()
        camera = camera_node.GetCamera() if camera_node is not None else self.renderer().GetActiveCamera()
        camera.SetFocalPoint(*center)
        camera.SetPosition(*(c + distance * d for c, d in zip(center, direction)))
        camera.SetViewUp(*view_up)
        camera.SetViewAngle(30.0)
        self.renderer().ResetCameraClippingRange()
        if camera_node is not None:
            camera_node.ResetClippingRange()
        self.schedule_render()


class VolumeCutSliceView(SliceView):
    """trame-slicer's slice view with the cut region's outline and fill."""

    def __init__(self, scene, app_logic, name, *args, **kwargs):
        super().__init__(scene, app_logic, name, *args, **kwargs)
        self.volume_cut_displayable_manager = add_product_displayable_manager(
            self, slicer.vtkMRMLVolumeCutSliceDisplayableManager())


# --------------------------------------------------------------------------- the drill


def _updated(algorithm) -> vtk.vtkPolyData:
    algorithm.Update()
    return algorithm.GetOutput()


def _cylinder_along_z(radius: float, height: float, center_z: float, resolution: int) -> vtk.vtkPolyData:
    """A cylinder whose axis is the z axis (vtkCylinderSource's is y)."""
    source = vtk.vtkCylinderSource()
    source.SetRadius(radius)
    source.SetHeight(height)
    source.SetCenter(0.0, center_z, 0.0)
    source.SetResolution(resolution)
    rotate = vtk.vtkTransform()
    rotate.RotateX(90.0)  # y to z
    cylinder = vtk.vtkTransformPolyDataFilter()
    cylinder.SetTransform(rotate)
    cylinder.SetInputConnection(source.GetOutputPort())
    return _updated(cylinder)


def tool_glyph(tool_node) -> vtk.vtkPolyData:
    """The tool's cutting part in its local frame (centred, shaft along +z) and its shaft."""
    shape = slicer.vtkMRMLVolumeCutToolNode.GetShapeAsString(tool_node.GetShape())
    if shape == "Sphere":
        source = vtk.vtkSphereSource()
        source.SetRadius(tool_node.GetDiameter() / 2.0)
        source.SetThetaResolution(32)
        source.SetPhiResolution(24)
        part, top = _updated(source), tool_node.GetDiameter() / 2.0
    elif shape in ("Cylinder", "DiskSaw"):
        height = tool_node.GetLength() if shape == "Cylinder" else tool_node.GetThickness()
        part, top = _cylinder_along_z(tool_node.GetDiameter() / 2.0, height, 0.0, 32), height / 2.0
    elif shape == "Blade":
        source = vtk.vtkCubeSource()
        source.SetXLength(tool_node.GetWidth())
        source.SetYLength(tool_node.GetThickness())
        source.SetZLength(tool_node.GetLength())
        part, top = _updated(source), tool_node.GetLength() / 2.0
    else:
        mesh = tool_node.GetMeshModelNode()
        part = mesh.GetPolyData() if mesh is not None and mesh.GetPolyData() is not None else vtk.vtkPolyData()
        top = 0.0
    append = vtk.vtkAppendPolyData()
    append.AddInputData(part)
    display = tool_node.GetVolumeCutToolDisplayNode()
    if display is None or display.GetShowAxis():
        # The shaft towards the handpiece: thin, 25 mm.
        append.AddInputData(_cylinder_along_z(0.35, 25.0, top + 12.5, 12))
    normals = vtk.vtkPolyDataNormals()
    normals.SetInputConnection(append.GetOutputPort())
    return _updated(normals)


# Drill modes of the 3D view.
MODE_NAVIGATE = "navigate"
MODE_DRILL = "drill"
MODE_RESTORE = "restore"
MODE_OUTLINE = "outline"
MODES = (MODE_NAVIGATE, MODE_DRILL, MODE_RESTORE, MODE_OUTLINE)
# Events the SoftCut outline mode takes; the others (wheel, right and middle drags) move the camera.
_OUTLINE_EVENTS = (int(vtk.vtkCommand.LeftButtonPressEvent), int(vtk.vtkCommand.LeftButtonReleaseEvent))

# Depth of the tool's tip below the surface (mm): the wheel's step and the range.
DEPTH_STEP_MM = 0.25
DEPTH_RANGE_MM = (0.0, 10.0)
# Shift while drilling goes this many times deeper.
SHIFT_DEPTH_FACTOR = 2.0
# A pointer that jumps further than this many tool diameters lifts the tool:
# the drill does not cut a straight line across what lies between.
LIFT_JUMP_DIAMETERS = 3.0

CONTACT_COLOR = (1.0, 0.1, 0.1)


class DrillController:
    """What the drill pipelines of a session share: the mode, the depth, and callbacks to the application.

    ``on_stroke_begin()`` / ``on_stroke_end()`` / ``on_stroke_moved()`` and
    ``on_depth_changed(depth)`` let the application refine rendering and
    refresh its panels; ``on_outline_pick(point)`` receives the surface point
    (RAS) clicked in the SoftCut outline mode.
    """

    def __init__(self, session):
        self.session = session
        self.mode = MODE_NAVIGATE
        self.depth_mm = 1.0
        self.on_stroke_begin = lambda: None
        self.on_stroke_moved = lambda: None
        self.on_stroke_end = lambda: None
        self.on_hover = lambda: None
        self.on_depth_changed = lambda depth: None
        self.on_outline_pick = lambda point: None
        self.on_placed_changed = lambda: None  # the glyph shown or hidden: the tool is over the bone or not
        # Why a stroke may not begin now (a message: the instructor froze the drill), or None.
        self.stroke_refusal = lambda: None
        # The instructor's guide axis (collaboration.cosession.GuideAxis): strokes follow it, or None.
        self.guide = None
        # Where the surface under the mouse is read: the views' SurfaceDepth (the freshest is used).
        self.depth_sources = lambda: []
        # Whether the tool is over the surface (its glyph shows in every view) and touches a structure it may not cut.
        self.placed = False
        self.in_contact = False
        self.pipelines = []

    def set_mode(self, mode: str) -> None:
        if mode not in MODES:
            raise ValueError(f"Drill mode {mode!r} is not one of {', '.join(MODES)}")
        if mode != self.mode:
            self.end_stroke()
        self.mode = mode

    def set_depth(self, depth_mm: float) -> float:
        depth = float(depth_mm)
        if not math.isfinite(depth):
            raise ValueError(f"Drilling depth {depth_mm!r} is not a number")
        self.depth_mm = min(max(depth, DEPTH_RANGE_MM[0]), DEPTH_RANGE_MM[1])
        self.on_depth_changed(self.depth_mm)
        return self.depth_mm

    def set_glyph(self, placed: bool | None = None, in_contact: bool | None = None) -> None:
        """Show or hide the tool's glyph, in contact colour or not, in every view."""
        changed = False
        placed_changed = placed is not None and placed != self.placed
        if placed_changed:
            self.placed, changed = placed, True
        if in_contact is not None and in_contact != self.in_contact:
            self.in_contact, changed = in_contact, True
        if changed:
            for pipeline in self.pipelines:
                pipeline.UpdateFromMRML()
        if placed_changed:
            self.on_placed_changed()

    def place_tool_centre(self, point) -> bool:
        """Move the burr's centre to ``point`` (RAS, mm) in the tool's present orientation, without cutting."""
        centre = [float(v) for v in point] if isinstance(point, (list, tuple)) else []
        if len(centre) != 3 or not all(math.isfinite(v) for v in centre):
            raise ValueError(f"Tool position {point!r} is not three numbers (RAS, mm)")
        if self.session.in_stroke:
            return False
        pose = vtk.vtkMatrix4x4()
        transform = self.session.tool_node.GetParentTransformNode()
        if transform is not None:
            transform.GetMatrixTransformToWorld(pose)
        for row in range(3):
            pose.SetElement(row, 3, centre[row])
        moved = self.session.move_tool(pose)
        self.set_glyph(placed=True)
        return moved

    def end_stroke(self) -> bool:
        """End any open stroke (pointer released, lost, the page gone): what was cut stays."""
        ended = False
        for pipeline in list(self.pipelines):
            ended = pipeline.end_stroke() or ended
        if self.session.in_stroke:
            ended = self.session.end_stroke() or ended
        return ended

    def create_pipeline(self, view_node, display_node):
        """For the LayerDM pipeline factory: a drill pipeline for this session's tool in a 3D view."""
        if not isinstance(view_node, slicer.vtkMRMLViewNode) or not isinstance(display_node, slicer.vtkMRMLVolumeCutToolDisplayNode):
            return None
        if display_node.GetScene() is not self.session.scene:
            return None
        pipeline = DrillPipeline(self)
        self.pipelines = [p for p in self.pipelines if p.GetDisplayNode() is not None]
        self.pipelines.append(pipeline)
        return pipeline


class DrillPipeline(vtkMRMLLayerDMScriptedPipeline):
    """The tool glyph in one 3D view, and the mouse drill of that view."""

    def __init__(self, controller: DrillController):
        super().__init__()
        self.controller = controller
        self.view = None  # the VolumeCutThreeDView, set by the application
        self._tool_node = None
        self._transform_node = None
        self._mapper = vtk.vtkPolyDataMapper()
        self.actor = vtk.vtkActor()
        self.actor.SetMapper(self._mapper)
        self.actor.PickableOff()
        self.actor.SetVisibility(False)
        self._stroke_depth = None
        self._last_center = None
        self._lifted = False
        self._events = {
            int(vtk.vtkCommand.MouseMoveEvent): self._on_move,
            int(vtk.vtkCommand.LeftButtonPressEvent): self._on_press,
            int(vtk.vtkCommand.LeftButtonReleaseEvent): self._on_release,
            int(vtk.vtkCommand.MouseWheelForwardEvent): lambda data: self._on_wheel(+1),
            int(vtk.vtkCommand.MouseWheelBackwardEvent): lambda data: self._on_wheel(-1),
            int(vtk.vtkCommand.LeaveEvent): self._on_leave,
        }

    # -- render layer and MRML

    def GetRenderOrder(self) -> int:
        return 1

    def OnRendererAdded(self, renderer) -> None:
        if renderer is None:
            return
        # The glyph is hidden by the bone in front of it, like a real burr.
        renderer.SetPreserveDepthBuffer(True)
        renderer.AddViewProp(self.actor)

    def OnRendererRemoved(self, renderer) -> None:
        if renderer is not None:
            renderer.RemoveViewProp(self.actor)

    def SetDisplayNode(self, display_node) -> None:
        super().SetDisplayNode(display_node)
        tool = display_node.GetDisplayableNode() if display_node is not None else None
        self.UpdateObservation(self._tool_node, tool, [int(vtk.vtkCommand.ModifiedEvent),
                                                       int(slicer.vtkMRMLTransformableNode.TransformModifiedEvent)])
        self._tool_node = tool
        self.UpdateFromMRML()

    def OnUpdate(self, obj, event_id, call_data) -> None:
        self.UpdateFromMRML()

    def UpdateFromMRML(self) -> None:
        tool = self._tool_node
        display = self.GetDisplayNode()
        if tool is None or display is None:
            self.actor.SetVisibility(False)
            return
        self._mapper.SetInputData(tool_glyph(tool))
        pose = vtk.vtkMatrix4x4()
        transform = tool.GetParentTransformNode()
        if transform is not None:
            transform.GetMatrixTransformToWorld(pose)
        self.actor.SetUserMatrix(pose)
        cutting = self.controller.session.in_stroke
        color = CONTACT_COLOR if self.controller.in_contact else display.GetColor()
        self.actor.GetProperty().SetColor(*color)
        self.actor.GetProperty().SetOpacity(display.GetGlyphOpacityWhileCutting() if cutting else display.GetOpacity())
        self.actor.SetVisibility(bool(display.GetVisibility()) and transform is not None and self.controller.placed)
        self.RequestRender()

    # -- interaction

    def CanProcessInteractionEvent(self, event_data):
        if self.controller.mode == MODE_NAVIGATE or not self.controller.session.has_data:
            return False, 1e30
        if self.controller.mode == MODE_OUTLINE:
            return int(event_data.GetType()) in _OUTLINE_EVENTS, 0.0
        return int(event_data.GetType()) in self._events, 0.0

    def ProcessInteractionEvent(self, event_data) -> bool:
        if self.controller.mode == MODE_OUTLINE:
            return self._on_outline_event(event_data)
        handler = self._events.get(int(event_data.GetType()))
        return bool(handler(event_data)) if handler is not None else False

    def LoseFocus(self, event_data) -> None:
        self.end_stroke()

    def GetWidgetState(self) -> int:
        return slicer.vtkMRMLAbstractWidget.WidgetStateUser if self.controller.session.in_stroke else \
            slicer.vtkMRMLAbstractWidget.WidgetStateIdle

    def _fraction(self, event_data):
        renderer = self.view.renderer() if self.view is not None else self.GetRenderer()
        width, height = renderer.GetRenderWindow().GetSize()
        x, y = event_data.GetDisplayPosition()
        return (x + 0.5) / max(width, 1), (y + 0.5) / max(height, 1)

    def _depth_source(self):
        if self._stroke_depth is not None:
            return self._stroke_depth
        sources = [source for source in self.controller.depth_sources() if source.depth is not None]
        if not sources and self.view is not None:
            sources = [self.view.surface_depth]
        return max(sources, key=lambda source: source.captured_at) if sources else None

    def _pose_at(self, event_data, depth_mm):
        source = self._depth_source()
        if source is None:
            return None, None
        session = self.controller.session
        reach = session.tool_reach()
        hit = source.surface_point(*self._fraction(event_data), footprint_mm=reach)
        if hit is None:
            return None, None
        point, direction = hit
        camera = self.view.renderer().GetActiveCamera()
        pose = tool_pose(point, direction, depth_mm, reach, camera.GetViewUp())
        guide = self.controller.guide
        if guide is not None:
            # Guided drilling: the centre held on the planned path, the shaft along it; the mouse (and the
            # bone already removed under it) says how far along.
            centre = guide.constrain([pose.GetElement(r, 3) for r in range(3)])
            pose = tool_pose(centre + reach * guide.direction, guide.direction, 0.0, reach, camera.GetViewUp())
        return pose, np.array([pose.GetElement(r, 3) for r in range(3)])

    def _on_outline_event(self, event_data) -> bool:
        """SoftCut outline mode: a press on the surface places a point there (the release has nothing to do)."""
        if int(event_data.GetType()) != int(vtk.vtkCommand.LeftButtonPressEvent):
            return True
        source = self._depth_source()
        hit = source.surface_point(*self._fraction(event_data)) if source is not None else None
        if hit is not None:
            self.controller.on_outline_pick(hit[0])
        return True

    def _stroke_depth_mm(self, event_data) -> float:
        depth = self.controller.depth_mm
        if event_data.GetModifiers() & vtk.vtkEvent.ShiftModifier:
            depth *= SHIFT_DEPTH_FACTOR
        return min(depth, DEPTH_RANGE_MM[1])

    def _on_press(self, event_data) -> bool:
        session = self.controller.session
        source = self._depth_source()
        if source is None or source.depth is None:
            return True
        if self.controller.stroke_refusal() is not None:
            return True
        self._stroke_depth = source.snapshot()
        pose, center = self._pose_at(event_data, self._stroke_depth_mm(event_data))
        if pose is None:
            self._stroke_depth = None
            return True
        if not session.begin_stroke(restore=self.controller.mode == MODE_RESTORE):
            self._stroke_depth = None
            return True
        self._lifted = False
        self.controller.on_stroke_begin()
        session.move_tool(pose)
        self._last_center = center
        self.controller.set_glyph(placed=True)
        for pipeline in self.controller.pipelines:
            pipeline.UpdateFromMRML()  # the glyph turns translucent while it cuts
        self.controller.on_stroke_moved()
        return True

    def _on_move(self, event_data) -> bool:
        session = self.controller.session
        if not session.in_stroke:
            # Hovering: the tool rests on the surface under the pointer, and is hidden off the surface.
            pose, center = self._pose_at(event_data, 0.0)
            self.controller.on_hover()
            if pose is not None:
                session.move_tool(pose)
            self._last_center = center
            self.controller.set_glyph(placed=center is not None)
            return True
        pose, center = self._pose_at(event_data, self._stroke_depth_mm(event_data))
        if pose is None:
            # Off the surface: the tool is lifted until it is over the surface again.
            self._lifted = True
            return True
        jump = np.linalg.norm(center - self._last_center) if self._last_center is not None else 0.0
        if self._lifted or jump > LIFT_JUMP_DIAMETERS * max(2.0 * session.tool_reach(), 1.0):
            restore = self.controller.mode == MODE_RESTORE
            session.end_stroke()
            session.begin_stroke(restore=restore)
            self._lifted = False
        session.move_tool(pose)
        self._last_center = center
        self.controller.on_stroke_moved()
        return True

    def _on_leave(self, event_data) -> bool:
        """The pointer left the view: the stroke ends (what was cut stays) and the glyph hides."""
        self.controller.end_stroke()
        self._last_center = None
        self.controller.set_glyph(placed=False)
        return False

    def _on_release(self, event_data) -> bool:
        self.controller.end_stroke()
        return True

    def _on_wheel(self, steps: int) -> bool:
        self.controller.set_depth(self.controller.depth_mm + steps * DEPTH_STEP_MM)
        return True

    def end_stroke(self) -> bool:
        """Close this view's stroke, if one is open; returns whether one was."""
        was_open = self._stroke_depth is not None
        self._stroke_depth = None
        if self.controller.session.in_stroke:
            self.controller.session.end_stroke()
            was_open = True
        if was_open:
            for pipeline in self.controller.pipelines:
                pipeline.UpdateFromMRML()  # opaque again
            self.controller.on_stroke_end()
        return was_open
