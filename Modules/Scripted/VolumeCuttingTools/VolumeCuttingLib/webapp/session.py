"""One user's drilling session: data, roles, tool, strokes, tables and exports, without a web server.

The web application (``webapp.app``) draws this session; everything it does
apart from drawing and routing events is here, on the product's own layers,
so that it is tested without a browser:

* data: the example head CT (``headct``), the temporal-bone phantom
  (``phantom``) or the user's own CT and segmentation (``owndata``), with the
  automatic bone segmentation of the module logic when there is no
  segmentation; loading new data replaces the old, and a load that fails
  leaves the previous data as it was;
* roles: cuttable, protected or none, per segment (``vtkMRMLVolumeCutNode``);
* the tool: a ``vtkMRMLVolumeCutToolNode`` configured through
  ``toolconfig`` (presets, shape, sizes, power), the cut node's active tool;
* strokes: ``begin_stroke`` / ``move_tool`` / ``end_stroke`` through
  ``vtkSlicerVolumeCuttingLogic.BeginStroke`` / ``MoveActiveTool`` /
  ``EndStroke``, with the pose of the tool from a point of the surface and
  the viewing direction (``tool_pose``); undo and redo;
* tables: the removed volume per segment (the logic's table) and the
  deepest contact with a structure the tool may not cut;
* exports: the removed region as STL and as a segmentation, the drilled CT,
  and the scene as a Slicer bundle (.mrb);
* SoftCut (``SoftCutSession``): a soft-tissue resection outlined on the skin,
  previewed at a depth, carved as one undo step, measured and exported as
  STL through ``vtkSlicerVolumeCuttingSoftCutLogic``.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import slicer
import vtk

from ..config import toolconfig
from ..cutting import softcut
from ..data import headct, owndata, phantom
from ..jobs import softcutjob
from ..scene.application import configure_scene_io

ROLES = (toolconfig.ROLE_CUTTABLE, toolconfig.ROLE_PROTECTED, toolconfig.ROLE_NONE)

# The phantom as the main job builds it: a temporal bone at 0.4 x 0.4 x 0.5 mm.
PHANTOM_DIMENSIONS = (128, 128, 96)
PHANTOM_SPACING = (0.4, 0.4, 0.5)

# Bone segmentation thresholds (HU) and smoothing (mm) of the main job.
CORTICAL_HU, TRABECULAR_HU, BONE_SMOOTHING_MM = 700.0, 200.0, 0.5
# The bone surface the 3D view shows, and thin bone in red below 1 mm, as in the main job.
SURFACE_ISO_HU = 300.0
THIN_BONE_MM = 1.0
# Window and level (HU) of the CT in slice views.
BONE_WINDOW_HU = (3000.0, 500.0)

DEFAULT_TOOL = "Burr"


class SessionError(ValueError):
    """Something the user asked for that cannot be done; the message says what and what to do."""


@dataclass(frozen=True)
class SegmentRow:
    """One line of the segments table."""

    segment_id: str
    name: str
    color: str  # "#rrggbb"
    role: str
    removed_mm3: float


@dataclass(frozen=True)
class Contact:
    """The deepest contact of the last stroke with a segment the tool may not cut."""

    segment_id: str
    name: str
    depth_mm: float
    position: tuple[float, float, float]


def _hex_color(rgb) -> str:
    return "#" + "".join(f"{max(0, min(255, round(255 * c))):02x}" for c in rgb[:3])


def half_length_along_shaft(tool_node) -> float:
    """How far (mm) the cutting part reaches from its centre along the shaft (the tool's z axis)."""
    shape = slicer.vtkMRMLVolumeCutToolNode.GetShapeAsString(tool_node.GetShape())
    if shape == "Sphere":
        return tool_node.GetDiameter() / 2.0
    if shape in ("Cylinder", "Blade"):
        return tool_node.GetLength() / 2.0
    if shape == "DiskSaw":
        return tool_node.GetThickness() / 2.0
    mesh = tool_node.GetMeshModelNode()
    if mesh is not None and mesh.GetPolyData() is not None:
        bounds = mesh.GetPolyData().GetBounds()
        return max(abs(bounds[4]), abs(bounds[5]))
    return 0.0


def tool_pose(surface_point, view_direction, depth_mm: float, reach_mm: float, view_up=(0.0, 0.0, 1.0)) -> vtk.vtkMatrix4x4:
    """Tool-to-RAS pose of a tool entering the surface along the viewing direction.

    The shaft (tool z axis) points back along ``view_direction`` (from the
    surface towards the eye, where the surgeon holds the handpiece) and the
    cutting part's tip lies ``depth_mm`` beyond ``surface_point``: its centre
    is at ``surface_point + (depth_mm - reach_mm) * view_direction``, where
    ``reach_mm`` is how far the cutting part reaches from its centre along
    the shaft. ``depth_mm`` 0 rests the tool on the surface.
    """
    direction = np.asarray(view_direction, dtype=float)
    norm = np.linalg.norm(direction)
    if not np.isfinite(norm) or norm == 0.0:
        raise ValueError(f"tool_pose: viewing direction {tuple(view_direction)} has no length")
    direction /= norm
    z_axis = -direction
    up = np.asarray(view_up, dtype=float)
    x_axis = np.cross(up, z_axis)
    if np.linalg.norm(x_axis) < 1e-6:
        x_axis = np.cross((1.0, 0.0, 0.0) if abs(z_axis[0]) < 0.9 else (0.0, 1.0, 0.0), z_axis)
    x_axis /= np.linalg.norm(x_axis)
    y_axis = np.cross(z_axis, x_axis)
    center = np.asarray(surface_point, dtype=float) + (depth_mm - reach_mm) * direction
    pose = vtk.vtkMatrix4x4()
    for row in range(3):
        pose.SetElement(row, 0, x_axis[row])
        pose.SetElement(row, 1, y_axis[row])
        pose.SetElement(row, 2, z_axis[row])
        pose.SetElement(row, 3, center[row])
    return pose


class DrillSession:
    """The scene content of one user: CT, segmentation, cut node, tool node.

    ``scene`` is a scene whose application logic has the VolumeCutting module
    logic (``logic``); the session configures the scene for saving bundles.
    ``work_directory`` receives exports (a temporary folder by default).
    """

    def __init__(self, scene, logic, work_directory: str | Path | None = None):
        self.scene = scene
        self.logic = logic
        self._temporary = None
        if work_directory is None:
            self._temporary = tempfile.TemporaryDirectory(prefix="volumecutting-webapp-")
            work_directory = self._temporary.name
        self.work_directory = Path(work_directory)
        self.work_directory.mkdir(parents=True, exist_ok=True)
        configure_scene_io(scene, self.work_directory / "cache")
        self.volume = None
        self.segmentation = None
        self.bone_segmentation = None
        self.cut_node = None
        self.tool_node = None
        self.description = ""
        self.source = ""
        self.inputs = {}
        self.warnings: list[str] = []
        self._data_nodes: list = []
        self.action = None  # slicer.vtkSlicerVolumeCuttingLogic.ToolCut or ToolRestore inside a stroke
        self.stroke_listener = None  # told of strokes, their poses, undo and redo (sessionrecording records them)
        self._presets = {preset.name: preset for preset in toolconfig.load_presets()}

    # ------------------------------------------------------------------ data

    @property
    def has_data(self) -> bool:
        return self.cut_node is not None

    SOURCES = ("headct", "phantom", "own")

    def load(self, source: str, **options) -> None:
        """Load data at once (see ``loading``)."""
        for _ in self.loading(source, **options):
            pass

    def loading(self, source: str, ct_path=None, segmentation_path=None, color_table=None, seed: int = 0,
                cuttable_names="", protected_names=""):
        """Load new data step by step, yielding (fraction done, what comes next) between steps.

        ``source``: "headct" (the example head CT, its bone segmented
        automatically, both bone segments cuttable), "phantom" (the
        temporal-bone phantom with its own segments and the main job's roles)
        or "own" (the user's CT at ``ct_path``: a DICOM series, NRRD, NIfTI
        or MetaImage; with ``segmentation_path`` every segment starts
        without a role, without it the bone is segmented automatically and
        made cuttable; ``cuttable_names`` and ``protected_names`` give roles
        to segments of the user's segmentation by name, as the main job's
        options do). The new data is built beside the old and replaces it
        only when all of it is ready: input that cannot be used raises
        ``owndata.InputError`` or ``SessionError`` and leaves the previous
        data as it was.
        """
        if source not in self.SOURCES:
            raise SessionError(f"Unknown data source {source!r}; choose one of {', '.join(self.SOURCES)}")
        warnings: list[str] = []
        roles = None
        if source == "phantom":
            roles = (phantom.CUTTABLE_SEGMENTS, phantom.PROTECTED_SEGMENTS)
        elif source == "own":
            if ct_path is None:
                raise SessionError("Give the CT: upload it or name its path on the server")
            if segmentation_path is not None:
                roles = ((), ())
            elif cuttable_names or protected_names:
                raise SessionError("Roles by name need the segmentation they name: give it with the CT")
        created = []
        try:
            yield 0.05, "Reading the CT"
            if source == "headct":
                volume = headct.load_volume_node(self.scene, name="HeadCT")
                segmentation = None
                description = "Example head CT (InVesalius)"
            elif source == "phantom":
                # As a scanner writes it: int16 HU.
                generated = phantom.generate_phantom(dimensions=PHANTOM_DIMENSIONS, spacing=PHANTOM_SPACING, seed=seed,
                                                     ct_dtype="int16")
                volume, segmentation = phantom.create_phantom_nodes(self.scene, generated)
                description = "Temporal-bone phantom"
            else:
                # A CD or PACS export holds several series: take the CT and say so in the warnings.
                volume = owndata.load_ct(self.scene, ct_path, messages=warnings, choose_series=True)
                created.append(volume)
                segmentation = None
                if segmentation_path is not None:
                    yield 0.3, "Reading the segmentation"
                    segmentation = owndata.load_segmentation(self.scene, segmentation_path, volume,
                                                             color_table=color_table, messages=warnings)
                description = Path(ct_path).name
            created += [volume, segmentation]
            dims = volume.GetImageData().GetDimensions()
            spacing = volume.GetSpacing()
            description += f" {dims[0]}x{dims[1]}x{dims[2]} at " + "x".join(f"{s:.2f}" for s in spacing) + " mm"
            bone = None
            if segmentation is None:
                yield 0.45, "Segmenting bone automatically"
                bone = self.logic.CreateBoneSegmentation(volume, CORTICAL_HU, TRABECULAR_HU, BONE_SMOOTHING_MM)
                if bone is None:
                    raise SessionError(f"{description}: the automatic bone segmentation failed (see the log); "
                                       "load a segmentation of your own with the CT")
                created.append(bone)
            yield 0.75, "Preparing the cut"
            roles_segmentation = segmentation if segmentation is not None else bone
            cut_node = self.logic.AddVolumeCutNode(volume, roles_segmentation)
            created.append(cut_node)
            if roles is None:
                cuttable = [self.logic.GetCorticalBoneSegmentID(), self.logic.GetTrabecularBoneSegmentID()]
                protected = []
            elif source == "own":
                cuttable, protected = owndata.resolve_roles(roles_segmentation, cuttable_names, protected_names)
            else:
                present = set(roles_segmentation.GetSegmentation().GetSegmentIDs())
                cuttable = [s for s in roles[0] if s in present]
                protected = [s for s in roles[1] if s in present]
            cut_node.SetProtectedSegmentIDs(protected)
            cut_node.SetCuttableSegmentIDs(cuttable)
            self._show_ct(volume)
            cut_node.SetSurfaceIsoValue(SURFACE_ISO_HU)
            cut_node.SetThinBoneShading(True)
            cut_node.SetThinBoneThickness(THIN_BONE_MM)
            shown = set(phantom.PROTECTED_SEGMENTS + phantom.BONE_SEGMENTS) if source == "phantom" else None
            self._show_segments(roles_segmentation, cut_node, shown)
            tool = toolconfig.create_tool_node(self.scene, self._initial_tool_parameters(), DEFAULT_TOOL)
            created += [tool, self.scene.GetNodeByID(tool.GetTransformNodeID())]
            cut_node.SetAndObserveActiveToolNodeID(tool.GetID())
            created.append(self.logic.GetRemovedVolumeTableNode(cut_node))
            created.append(self.logic.GetContactTableNode(cut_node))
            if self.logic.GetCutField(cut_node) is None:
                raise SessionError(f"{description}: no cut can be made on this volume (see the log)")
            self.logic.UpdateRemovedVolumeTable(cut_node)
        except BaseException:
            owndata.remove_nodes(self.scene, *reversed([n for n in created if n is not None]))
            raise
        # Everything is ready: the old data goes.
        self.end_stroke()
        owndata.remove_nodes(self.scene, *reversed(self._data_nodes))
        self._data_nodes = list(dict.fromkeys(n for n in created if n is not None))
        self.volume, self.segmentation, self.bone_segmentation = volume, roles_segmentation, bone
        self.cut_node, self.tool_node, self.description = cut_node, tool, description
        self.source = source
        # The user's files, for a recording that names its scan by them (sessionrecording.scan_descriptor).
        self.inputs = {"ct": ct_path, "segmentation": segmentation_path, "color_table": color_table} if source == "own" else {}
        self.warnings = warnings
        yield 1.0, "Ready"

    def _initial_tool_parameters(self) -> toolconfig.ToolParameters:
        if self.tool_node is not None:
            return toolconfig.from_tool_node(self.tool_node).replace(cuttable_segment_ids=(), use_cut_node_roles=True,
                                                                      mesh_model_node_id=None)
        return toolconfig.ToolParameters(shape="Sphere", diameter=4.0)

    @staticmethod
    def _show_ct(volume) -> None:
        """Slice views show the CT in a bone window (W 3000, L 500 HU): drilling happens in bone."""
        if volume.GetDisplayNode() is None:
            volume.CreateDefaultDisplayNodes()
        display = volume.GetDisplayNode()
        display.AutoWindowLevelOff()
        display.SetWindowLevel(BONE_WINDOW_HU[0], BONE_WINDOW_HU[1])

    @staticmethod
    def _show_segments(segmentation, cut_node, shown=None) -> None:
        """The cut anatomy shows through the volume-cut view; the segmentation's own surfaces stay hidden.

        Only ``shown`` segments colour the view (by default those with a role:
        soft tissue and air without one would hide the bone).
        """
        display = segmentation.GetDisplayNode()
        if display is None:
            segmentation.CreateDefaultDisplayNodes()
            display = segmentation.GetDisplayNode()
        display.SetVisibility3D(False)
        # Slice views: outlines over the CT (trame-slicer's slice views draw the CT black under a fill).
        display.SetVisibility2DFill(False)
        segments = segmentation.GetSegmentation()
        if shown is None:
            shown = set(cut_node.GetCuttableSegmentIDs()) | set(cut_node.GetProtectedSegmentIDs())
        for segment_id in segments.GetSegmentIDs():
            display.SetSegmentVisibility3D(segment_id, segment_id in shown or not shown)

    def volume_bounds(self):
        bounds = [0.0] * 6
        self.volume.GetRASBounds(bounds)
        return bounds

    # ------------------------------------------------------------------ roles

    def segment_rows(self) -> list[SegmentRow]:
        """Every segment with its colour, role and removed volume (mm3), in segmentation order."""
        if not self.has_data:
            return []
        removed = self.removed_volumes()
        rows = []
        for row in toolconfig.sensibility_rows(self.cut_node):
            segment = self.segmentation.GetSegmentation().GetSegment(row.segment_id)
            rows.append(SegmentRow(row.segment_id, row.name, _hex_color(segment.GetColor()), row.role,
                                   removed.get(row.segment_id, 0.0)))
        return rows

    def set_role(self, segment_id: str, role: str) -> None:
        """Make a segment cuttable, protected or neither ("")."""
        self._require_data()
        if role not in ROLES:
            raise SessionError(f"Role {role!r} of segment '{segment_id}' is not one of 'cuttable', 'protected' "
                               "or '' (none)")
        if self.segmentation.GetSegmentation().GetSegment(segment_id) is None:
            raise SessionError(f"There is no segment '{segment_id}' in {self.segmentation.GetName()}")
        cuttable = [s for s in self.cut_node.GetCuttableSegmentIDs() if s != segment_id]
        protected = [s for s in self.cut_node.GetProtectedSegmentIDs() if s != segment_id]
        if role == toolconfig.ROLE_CUTTABLE:
            cuttable.append(segment_id)
        elif role == toolconfig.ROLE_PROTECTED:
            protected.append(segment_id)
        was_modifying = self.cut_node.StartModify()
        self.cut_node.SetProtectedSegmentIDs(protected)
        self.cut_node.SetCuttableSegmentIDs(cuttable)
        self.cut_node.EndModify(was_modifying)
        display = self.segmentation.GetDisplayNode()
        if display is not None and role:
            display.SetSegmentVisibility3D(segment_id, True)
        self.logic.UpdateRemovedVolumeTable(self.cut_node)

    # ------------------------------------------------------------------ tool

    def preset_names(self) -> list[str]:
        return list(self._presets)

    def tool_parameters(self) -> toolconfig.ToolParameters:
        self._require_data()
        return toolconfig.from_tool_node(self.tool_node)

    def apply_preset(self, name: str) -> toolconfig.ToolParameters:
        self._require_data()
        if name not in self._presets:
            raise SessionError(f"There is no tool preset named '{name}'; choose one of {', '.join(self._presets)}")
        current = toolconfig.from_tool_node(self.tool_node)
        params = toolconfig.from_preset(self._presets[name], use_cut_node_roles=current.use_cut_node_roles,
                                        cuttable_segment_ids=current.cuttable_segment_ids)
        toolconfig.apply_to_tool_node(params, self.tool_node)
        return params

    def set_tool(self, **changes) -> toolconfig.ToolParameters:
        """Change tool parameters (``ToolParameters`` names); raises ``toolconfig.ToolConfigError`` naming the field."""
        self._require_data()
        params = toolconfig.from_tool_node(self.tool_node).replace(**changes)
        toolconfig.apply_to_tool_node(params, self.tool_node)
        return params

    # ------------------------------------------------------------------ strokes

    def begin_stroke(self, restore: bool = False) -> bool:
        """Open a stroke (one undo step) that cuts, or restores when ``restore``."""
        self._require_data()
        if self.action is not None:
            self.end_stroke()
        if not self.logic.BeginStroke(self.cut_node):
            return False
        self.action = slicer.vtkSlicerVolumeCuttingLogic.ToolRestore if restore else slicer.vtkSlicerVolumeCuttingLogic.ToolCut
        if self.stroke_listener is not None:
            self.stroke_listener.stroke_began(restore)
        return True

    def move_tool(self, pose: vtk.vtkMatrix4x4) -> bool:
        """Move the tool to ``pose``; inside a stroke it cuts (or restores) along the way."""
        self._require_data()
        action = self.action if self.action is not None else slicer.vtkSlicerVolumeCuttingLogic.ToolMove
        moved = bool(self.logic.MoveActiveTool(self.cut_node, pose, action))
        # After the move: the listener reads what the pose did (the nerve monitor's readings there).
        if self.action is not None and self.stroke_listener is not None:
            self.stroke_listener.tool_moved(pose)
        return moved

    def end_stroke(self) -> bool:
        """Close the open stroke (nothing happens without one); the tables are updated."""
        if self.action is None or not self.has_data:
            self.action = None
            return False
        self.action = None
        ended = bool(self.logic.EndStroke(self.cut_node))
        if self.stroke_listener is not None:
            self.stroke_listener.stroke_ended()
        return ended

    @property
    def in_stroke(self) -> bool:
        return self.action is not None

    def undo(self) -> bool:
        self._require_data()
        self.end_stroke()
        return self._edited("undo", self.logic.UndoStroke(self.cut_node))

    def redo(self) -> bool:
        self._require_data()
        self.end_stroke()
        return self._edited("redo", self.logic.RedoStroke(self.cut_node))

    def _edited(self, kind: str, done) -> bool:
        if done and self.stroke_listener is not None:
            self.stroke_listener.edited(kind)
        return bool(done)

    def undo_redo_counts(self) -> tuple[int, int]:
        field = self.cut_node.GetCutField() if self.has_data else None
        if field is None:
            return 0, 0
        return field.GetNumberOfUndoSteps(), field.GetNumberOfRedoSteps()

    def tool_reach(self) -> float:
        return half_length_along_shaft(self.tool_node)

    def contact(self) -> Contact | None:
        """The deepest contact since the stroke began with a segment the tool may not cut, or None."""
        if not self.has_data:
            return None
        segment_id = self.logic.GetContactSegmentID(self.cut_node)
        field = self.cut_node.GetCutField()
        if not segment_id or field is None or field.GetMaximumContactDepth() <= 0.0:
            return None
        segment = self.segmentation.GetSegmentation().GetSegment(segment_id)
        name = segment.GetName() if segment is not None else segment_id
        return Contact(segment_id, name, field.GetMaximumContactDepth(), tuple(field.GetContactPosition()))

    # ------------------------------------------------------------------ tables

    def update_removed_volumes(self) -> None:
        """Refill the logic's removed-volume table now (it does so itself at the end of each stroke)."""
        if self.has_data:
            self.logic.UpdateRemovedVolumeTable(self.cut_node)

    def removed_volumes(self) -> dict[str, float]:
        """Removed volume (mm3) per segment ID, from the logic's removed-volume table."""
        table = self.logic.GetRemovedVolumeTableNode(self.cut_node).GetTable()
        segments = table.GetColumnByName("Segment")
        volumes = table.GetColumnByName("Removed volume")
        if segments is None or volumes is None:
            return {}
        return {segments.GetValue(row): float(volumes.GetValue(row)) for row in range(table.GetNumberOfRows())}

    def total_removed_volume(self) -> float:
        return float(self.logic.GetRemovedVolume(self.cut_node)) if self.has_data else 0.0

    # ------------------------------------------------------------------ exports

    EXPORTS = {
        "stl": "removed region as a closed surface (.stl)",
        "segmentation": "removed region as a segmentation (.seg.nrrd)",
        "drilled_ct": "drilled CT (.nrrd)",
        "scene": "scene as a Slicer bundle (.mrb)",
    }

    def export(self, kind: str) -> Path:
        """Write one export into the work folder and return its path; the scene keeps no extra nodes."""
        self._require_data()
        self.end_stroke()
        folder = self.work_directory / "exports"
        folder.mkdir(parents=True, exist_ok=True)
        base = "".join(c if c.isalnum() or c in "-_" else "_" for c in self.volume.GetName()) or "volume"
        if kind == "scene":
            path = (folder / f"{base}-drilled.mrb").resolve()
            if not self.scene.WriteToMRB(str(path)):
                raise SessionError(f"Saving the scene to {path.name} failed (see the log)")
            return path
        if kind not in self.EXPORTS:
            raise SessionError(f"Unknown export {kind!r}; choose one of {', '.join(self.EXPORTS)}")
        if self.total_removed_volume() <= 0.0 and kind in ("stl", "segmentation"):
            raise SessionError("Nothing has been removed yet: drill first, then export the removed region")
        if kind == "stl":
            node = self.logic.ExportRemovedSurfaceToModel(self.cut_node, None)
            path = folder / f"{base}-removed.stl"
        elif kind == "segmentation":
            node = self.logic.ExportRemovedRegionToSegmentation(self.cut_node, None)
            path = folder / f"{base}-removed.seg.nrrd"
        else:
            node = self.logic.ExportDrilledVolume(self.cut_node, -1000.0, None)
            path = folder / f"{base}-drilled.nrrd"
        if node is None:
            raise SessionError(f"The {self.EXPORTS[kind]} could not be made (see the log)")
        try:
            storage = node.CreateDefaultStorageNode()
            storage.SetFileName(str(path))
            if kind != "stl":
                storage.SetUseCompression(True)
            if not storage.WriteData(node):
                raise SessionError(f"Writing {path.name} failed (see the log)")
        finally:
            owndata.remove_nodes(self.scene, node)
        return path

    # ------------------------------------------------------------------ helpers

    def _require_data(self) -> None:
        if not self.has_data:
            raise SessionError("Load a CT first (Data panel)")

    def close(self) -> None:
        self.end_stroke()
        if self._temporary is not None:
            self._temporary.cleanup()



# --------------------------------------------------------------------------- SoftCut

NORMAL_MODES = {"local": slicer.vtkVolumeCutResectionPlanner.LocalNormal,
                "average": slicer.vtkVolumeCutResectionPlanner.AverageNormal}
# Depth of cut (mm): the slider's range and step; the plan reaches as deep as the slider.
SOFTCUT_DEPTH_RANGE_MM = (0.5, 20.0)
SOFTCUT_DEPTH_STEP_MM = 0.5
SOFTCUT_DEFAULT_DEPTH_MM = softcutjob.DEPTH_MM
# The panel's measurements, in the logic's table's names.
SOFTCUT_MEASUREMENTS = ("Resected volume", "Surface area", "Length", "Width", "Thickness")


class SoftCutSession:
    """SoftCut on a drilling session's data: outline, normal mode, depth preview, carve, measurements, STL.

    The outline is a closed markups curve whose control points the user
    places on the skin (``add_point``, from a pick on the 3D view's
    surface) or the main job's cheek outline on the example head CT
    (``use_example_outline``). The plan is made when it is first needed
    (preview, carve, measurements, STL) and again after the outline or the
    normal mode changed. Bad input raises ``SessionError`` with the
    logic's message and changes nothing already planned or carved.

    While SoftCut is shown (``show_skin``) the cut node's surface is the skin
    (-500 HU), so that the view shows and picks what the outline lies on.
    """

    def __init__(self, session: DrillSession):
        self.session = session
        self.logic = softcut.create_logic(_ApplicationLogics(session))
        self.logic.SetSkinIsoValue(softcutjob.SKIN_ISO_HU)
        self.logic.SetMaximumDepth(SOFTCUT_DEPTH_RANGE_MM[1])
        self.normal_mode = "local"
        self.depth_mm = SOFTCUT_DEFAULT_DEPTH_MM
        self.outline = None
        self.measurements: dict[str, tuple[float, str]] = {}
        self._cut_node = None
        self._planned = None  # (outline points, normal mode) of the plan the logic holds
        self.previewing = False

    # -- outline

    def _sync(self) -> None:
        """New data: the outline and plan of the old data go with it."""
        if self.session.cut_node is self._cut_node:
            return
        if self.outline is not None and self.outline.GetScene() is not None:
            owndata.remove_nodes(self.session.scene, self.outline)
        self.outline, self._planned, self.measurements, self.previewing = None, None, {}, False
        self._cut_node = self.session.cut_node

    def outline_points(self) -> list[tuple[float, float, float]]:
        self._sync()
        if self.outline is None:
            return []
        points = []
        for index in range(self.outline.GetNumberOfControlPoints()):
            position = [0.0, 0.0, 0.0]
            self.outline.GetNthControlPointPositionWorld(index, position)
            points.append(tuple(position))
        return points

    def add_point(self, ras) -> int:
        """Append a control point (RAS, picked on the skin); returns how many the outline has."""
        self.session._require_data()
        self._sync()
        point = np.asarray(ras, dtype=float)
        if point.shape != (3,) or not np.all(np.isfinite(point)):
            raise SessionError(f"SoftCut outline point {ras!r} is not a point (three numbers, RAS mm)")
        if self.outline is None:
            self.outline = softcut.add_outline(self.session.scene, [point], name="SoftCut outline")
            if self.outline.GetDisplayNode() is not None:
                self.outline.GetDisplayNode().SetVisibility(False)  # the page draws its own outline
            self.session._data_nodes.append(self.outline)
        else:
            self.outline.AddControlPointWorld(vtk.vtkVector3d(*point))
        self._outline_changed()
        return self.outline.GetNumberOfControlPoints()

    def remove_last_point(self) -> int:
        self._sync()
        if self.outline is not None and self.outline.GetNumberOfControlPoints():
            self.outline.RemoveNthControlPoint(self.outline.GetNumberOfControlPoints() - 1)
            self._outline_changed()
        return len(self.outline_points())

    def clear_outline(self) -> None:
        self._sync()
        if self.outline is not None:
            self.outline.RemoveAllControlPoints()
            self._outline_changed()

    def has_example_outline(self) -> bool:
        return self.session.has_data and self.session.source == "headct"

    def use_example_outline(self) -> int:
        """The main job's right-cheek outline (softcutjob), picked on the head CT's skin; average normal."""
        self.session._require_data()
        if not self.has_example_outline():
            raise SessionError("The example cheek outline is drawn on the example head CT: load it in the Data panel, "
                               "or click the outline on the skin in SoftCut outline mode")
        points = softcut.picked_points(self.session.volume, softcutjob.CHEEK_CENTER, -np.asarray(softcutjob.VIEW_DIRECTION),
                                       softcutjob.CHEEK_RADII, count=softcutjob.CONTROL_POINTS, iso=softcutjob.SKIN_ISO_HU)
        self.clear_outline()
        for point in points:
            self.add_point(point)
        self.set_normal_mode("average")
        return len(points)

    def set_normal_mode(self, mode: str) -> None:
        if mode not in NORMAL_MODES:
            raise SessionError(f"SoftCut normal mode {mode!r} is not one of {', '.join(NORMAL_MODES)}")
        if mode != self.normal_mode:
            self.normal_mode = mode
            self._outline_changed()

    def _outline_changed(self) -> None:
        # A plan of another outline must neither be previewed nor carved.
        if self.previewing and self.session.has_data:
            self.logic.ClearPreview(self.session.cut_node)
        self.previewing = False
        self.measurements = {}

    # -- plan, preview, carve

    def set_depth(self, depth_mm) -> float:
        depth = float(depth_mm)
        if not np.isfinite(depth) or not SOFTCUT_DEPTH_RANGE_MM[0] <= depth <= SOFTCUT_DEPTH_RANGE_MM[1]:
            raise SessionError(f"SoftCut depth of cut {depth_mm!r} mm: give a depth between "
                               f"{SOFTCUT_DEPTH_RANGE_MM[0]:g} and {SOFTCUT_DEPTH_RANGE_MM[1]:g} mm")
        self.depth_mm = depth
        return depth

    def plan(self) -> None:
        """Plan the resection of the current outline (again only when the outline or the normal mode changed)."""
        self.session._require_data()
        self._sync()
        key = (tuple(self.outline_points()), self.normal_mode)
        if self._planned == key and self.logic.GetPlanner(self.session.cut_node) is not None:
            return
        if self.outline is None or self.outline.GetNumberOfControlPoints() == 0:
            raise SessionError("There is no SoftCut outline yet: click at least 3 points on the skin in SoftCut outline "
                               "mode, or use the example cheek outline")
        self.logic.SetNormalMode(NORMAL_MODES[self.normal_mode])
        if not self.logic.PlanResection(self.session.cut_node, self.outline):
            self._planned = None
            raise SessionError(self.logic.GetErrorMessage())
        self._planned = key

    def preview(self, depth_mm=None) -> None:
        """Show what a carve at the depth (mm; default the current one) would remove, in the 3D view."""
        if depth_mm is not None:
            self.set_depth(depth_mm)
        self.plan()
        if not self.logic.PreviewDepth(self.session.cut_node, self.depth_mm):
            raise SessionError(self.logic.GetErrorMessage())
        self.previewing = True

    def clear_preview(self) -> None:
        if self.session.has_data and self.previewing:
            self.logic.ClearPreview(self.session.cut_node)
        self.previewing = False

    def carve(self, depth_mm=None) -> dict[str, tuple[float, str]]:
        """Carve the resection at the depth into the cut (one undo step) and measure it; the measurements."""
        if depth_mm is not None:
            self.set_depth(depth_mm)
        self.plan()
        self.session.end_stroke()
        if not self.logic.CarveResection(self.session.cut_node, self.depth_mm):
            raise SessionError(self.logic.GetErrorMessage())
        self.previewing = False
        return self.measure()

    def measure(self) -> dict[str, tuple[float, str]]:
        """Volume, area and extents of the resected tissue at the current depth, {name: (value, unit)}."""
        self.plan()
        table = self.logic.MeasureResection(self.session.cut_node, self.depth_mm)
        if table is None:
            raise SessionError(self.logic.GetErrorMessage())
        self.measurements = softcut.table_rows(table)
        return self.measurements

    def export_stl(self) -> Path:
        """The resected tissue at the current depth as an STL (a harvesting guide), in the work folder."""
        self.plan()
        folder = self.session.work_directory / "exports"
        folder.mkdir(parents=True, exist_ok=True)
        base = "".join(c if c.isalnum() or c in "-_" else "_" for c in self.session.volume.GetName()) or "volume"
        path = folder / f"{base}-resection.stl"
        if not self.logic.ExportResectionToSTL(self.session.cut_node, self.depth_mm, str(path)):
            raise SessionError(self.logic.GetErrorMessage())
        return path

    # -- view

    SOFT_TISSUE_SEGMENT_ID = "SoftCutSoftTissue"

    def show_skin(self, shown: bool) -> None:
        """The 3D view's surface: the skin while SoftCut is used, the bone (and thin-bone shading) for drilling.

        The view draws segments only: the skin shows through a cuttable
        segment of the soft tissue (``softcutjob.soft_tissue_segment``),
        added on first use, first in order so that bone wins where they
        overlap, and hidden (still cuttable) for drilling.
        """
        if not self.session.has_data:
            return
        self._sync()
        cut_node = self.session.cut_node
        segmentation = self.session.segmentation
        segment_id = self.SOFT_TISSUE_SEGMENT_ID
        if shown and segmentation.GetSegmentation().GetSegment(segment_id) is None:
            segmentation.GetSegmentation().AddSegment(
                softcutjob.soft_tissue_segment(self.session.volume, "Skin and soft tissue (SoftCut)"), segment_id)
            segmentation.GetSegmentation().SetSegmentIndex(segment_id, 0)
            cut_node.SetCuttableSegmentIDs(list(cut_node.GetCuttableSegmentIDs()) + [segment_id])
        was_modifying = cut_node.StartModify()
        cut_node.SetSurfaceIsoValue(softcutjob.SKIN_ISO_HU if shown else SURFACE_ISO_HU)
        cut_node.SetThinBoneShading(not shown)
        cut_node.EndModify(was_modifying)
        display = segmentation.GetDisplayNode()
        if display is not None and segmentation.GetSegmentation().GetSegment(segment_id) is not None:
            display.SetSegmentVisibility3D(segment_id, bool(shown))

    def outline_polydata(self) -> vtk.vtkPolyData:
        """The outline as the page draws it: a ball at each point and a tube through them (closed from 3 points)."""
        points = self.outline_points()
        return balls_and_tube(points, ball_radius=1.2, tube_radius=0.6, closed=len(points) >= 3)


def balls_and_tube(points, ball_radius: float, tube_radius: float, closed: bool = False) -> vtk.vtkPolyData:
    """Marks drawn in the scene (an outline, the instructor's marker and guide axis): a ball at each point
    (RAS, mm) and, from two points, a tube through them (back to the first when ``closed``)."""
    append = vtk.vtkAppendPolyData()
    append.AddInputData(vtk.vtkPolyData())
    for point in points:
        ball = vtk.vtkSphereSource()
        ball.SetCenter(*point)
        ball.SetRadius(ball_radius)
        ball.SetThetaResolution(16)
        ball.SetPhiResolution(12)
        ball.Update()
        append.AddInputData(ball.GetOutput())
    if len(points) >= 2:
        line = vtk.vtkPolyData()
        vtk_points = vtk.vtkPoints()
        for point in points:
            vtk_points.InsertNextPoint(*point)
        ids = list(range(len(points))) + ([0] if closed else [])
        cells = vtk.vtkCellArray()
        cells.InsertNextCell(len(ids))
        for index in ids:
            cells.InsertCellPoint(index)
        line.SetPoints(vtk_points)
        line.SetLines(cells)
        tube = vtk.vtkTubeFilter()
        tube.SetInputData(line)
        tube.SetRadius(tube_radius)
        tube.SetNumberOfSides(10)
        tube.Update()
        append.AddInputData(tube.GetOutput())
    append.Update()
    return append.GetOutput()


class _ApplicationLogics:
    """What ``softcut.create_logic`` reads of an application: the scene and the volume-cutting logic."""

    def __init__(self, session: DrillSession):
        self.scene = session.scene
        self.volume_cutting_logic = session.logic
