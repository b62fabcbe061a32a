"""Cutting-tool configuration without Qt: parameters, presets, sensibility, devices.

Everything a tool-configuration user interface does, apart from drawing
widgets, lives here so that desktop Slicer's scripted module and a web
application share it:

- ``ToolParameters``: every property of a ``vtkMRMLVolumeCutToolNode``,
  validated on creation with the node's own limits;
- ``load_presets()``: the shipped presets
  (``Resources/Presets/VolumeCuttingToolPresets.json``), validated, with
  errors that name the file, the preset and the field;
- ``apply_to_tool_node()``, ``from_tool_node()``, ``create_tool_node()``;
- ``sensibility_rows()`` and ``set_segment_cuttable_for_tool()``: the
  per-segment table of which segments a tool may cut;
- ``list_devices()``: the mouse and the known input devices plugged in
  (``inputdevices``).
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import slicer

from .inputdevices import InputDevice, list_devices  # noqa: F401  (part of this module's interface)
from ..scene.resources import find_resource

PRESETS_FILE_NAME = "VolumeCuttingToolPresets.json"
PRESETS_FORMAT = "VolumeCuttingToolPresets"
PRESETS_VERSION = 1

_Tool = slicer.vtkMRMLVolumeCutToolNode
SHAPES: tuple[str, ...] = tuple(_Tool.GetShapeAsString(shape) for shape in range(_Tool.Shape_Last))
BURR_TYPES: tuple[str, ...] = tuple(_Tool.GetBurrTypeAsString(burr) for burr in range(_Tool.BurrType_Last))

#: Sizes each shape uses besides power and speed (JSON field names).
SHAPE_FIELDS: dict[str, tuple[str, ...]] = {
    "Sphere": ("burrType", "diameter"),
    "Cylinder": ("burrType", "diameter", "length"),
    "DiskSaw": ("diameter", "thickness"),
    "Blade": ("width", "length", "thickness"),
    "Mesh": (),
}

# JSON field name -> ToolParameters attribute.
_PARAMETER_OF_FIELD = {
    "shape": "shape",
    "burrType": "burr_type",
    "diameter": "diameter",
    "length": "length",
    "thickness": "thickness",
    "width": "width",
    "power": "power",
    "speed": "speed",
}
_PRESET_TEXT_FIELDS = ("name", "category", "description")

_defaults = _Tool()


class ToolConfigError(ValueError):
    """A tool parameter, preset or sensibility change that cannot be accepted.

    ``field`` names the offending parameter (ToolParameters attribute or JSON
    field) when there is one.
    """

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message)
        self.field = field


class PresetError(ToolConfigError):
    """A preset file that cannot be used; the message names the file, the preset and the field."""


def diameter_range(shape: str) -> tuple[float, float]:
    """Valid diameters (mm) of a shape, as the tool node checks them."""
    index = _Tool.GetShapeFromString(shape)
    return _Tool.GetMinimumDiameter(index), _Tool.GetMaximumDiameter(index)


#: Valid ranges of the shape-independent sizes and drive settings.
RANGES: dict[str, tuple[float, float]] = {
    "length": (_Tool.GetMinimumLength(), _Tool.GetMaximumLength()),
    "thickness": (_Tool.GetMinimumThickness(), _Tool.GetMaximumThickness()),
    "width": (_Tool.GetMinimumWidth(), _Tool.GetMaximumWidth()),
    "power": (0.0, 1.0),
    "speed": (0.0, _Tool.GetMaximumSpeed()),
}
UNITS = {"diameter": "mm", "length": "mm", "thickness": "mm", "width": "mm", "power": "of the maximum", "speed": "per minute"}


@dataclass(frozen=True)
class ToolParameters:
    """Every property of a cutting tool; invalid values raise ToolConfigError on creation.

    Sizes in mm; ``power`` a fraction (0-1) of the handpiece's maximum;
    ``speed`` revolutions (burrs, disk saws) or oscillations (blades) per
    minute. Which segments the tool may cut: the cut node's roles when
    ``use_cut_node_roles``, else ``cuttable_segment_ids``. A Mesh tool cuts
    the closed surface of the model node ``mesh_model_node_id``.
    """

    shape: str = _Tool.GetShapeAsString(_defaults.GetShape())
    burr_type: str = _Tool.GetBurrTypeAsString(_defaults.GetBurrType())
    diameter: float = _defaults.GetDiameter()
    length: float = _defaults.GetLength()
    thickness: float = _defaults.GetThickness()
    width: float = _defaults.GetWidth()
    power: float = _defaults.GetPower()
    speed: float = _defaults.GetSpeed()
    use_cut_node_roles: bool = _defaults.GetUseCutNodeRoles()
    cuttable_segment_ids: tuple[str, ...] = ()
    mesh_model_node_id: str | None = None

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise ToolConfigError(f"shape: '{self.shape}' is not a tool shape; use one of {', '.join(SHAPES)}", "shape")
        if self.burr_type not in BURR_TYPES:
            raise ToolConfigError(f"burr_type: '{self.burr_type}' is not a burr type; use one of {', '.join(BURR_TYPES)}", "burr_type")
        ranges = dict(RANGES, diameter=diameter_range(self.shape))
        for name, (minimum, maximum) in ranges.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ToolConfigError(f"{name}: {value!r} is not a number", name)
            if not (math.isfinite(value) and minimum <= value <= maximum):
                raise ToolConfigError(
                    f"{name}: {value} is outside {minimum:g} to {maximum:g} {UNITS[name]}"
                    + (f" for a {self.shape} tool" if name == "diameter" else ""),
                    name,
                )
            object.__setattr__(self, name, float(value))
        if not isinstance(self.use_cut_node_roles, bool):
            raise ToolConfigError(f"use_cut_node_roles: {self.use_cut_node_roles!r} is not true or false", "use_cut_node_roles")
        if isinstance(self.cuttable_segment_ids, str):
            raise ToolConfigError("cuttable_segment_ids: give a list of segment IDs, not one string", "cuttable_segment_ids")
        ids = tuple(self.cuttable_segment_ids)
        if not all(isinstance(segment_id, str) and segment_id for segment_id in ids):
            raise ToolConfigError(f"cuttable_segment_ids: {ids!r} must be non-empty segment ID strings", "cuttable_segment_ids")
        # The node keeps each ID once, in first order: so do the parameters, so that they compare equal.
        object.__setattr__(self, "cuttable_segment_ids", tuple(dict.fromkeys(ids)))
        if self.mesh_model_node_id is not None and not (isinstance(self.mesh_model_node_id, str) and self.mesh_model_node_id):
            raise ToolConfigError(f"mesh_model_node_id: {self.mesh_model_node_id!r} is not a node ID", "mesh_model_node_id")

    def replace(self, **changes) -> ToolParameters:
        """A validated copy with some parameters changed."""
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class ToolPreset:
    """A named tool of the presets file."""

    name: str
    category: str
    description: str
    parameters: ToolParameters = field(default_factory=ToolParameters)


def from_preset(preset: ToolPreset, **overrides) -> ToolParameters:
    """The preset's parameters, optionally with some changed (validated)."""
    return preset.parameters.replace(**overrides) if overrides else preset.parameters


def default_presets_path() -> Path:
    """The shipped presets file, wherever this library is installed (see resources.find_resource).

    Raises PresetError naming the places tried.
    """
    try:
        return find_resource("Presets", PRESETS_FILE_NAME)
    except FileNotFoundError as error:
        raise PresetError(f"The tool presets file: {error}") from None


def load_presets(path: str | Path | None = None) -> list[ToolPreset]:
    """Read and validate a presets file (the shipped one by default).

    Raises PresetError, naming the file, the preset and the field, for a file
    that cannot be read, is not JSON, is not a presets file, or has a preset
    with a missing, unknown, mistyped or out-of-range field or a repeated name.
    """
    path = Path(path) if path is not None else default_presets_path()
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise PresetError(f"{path}: cannot read the tool presets file: {error}") from error
    try:
        document = json.loads(text)
    except json.JSONDecodeError as error:
        raise PresetError(f"{path}: not valid JSON at line {error.lineno}, column {error.colno}: {error.msg}") from error
    if not isinstance(document, dict) or document.get("format") != PRESETS_FORMAT:
        raise PresetError(f"{path}: not a tool presets file (expected an object with \"format\": \"{PRESETS_FORMAT}\")", "format")
    if document.get("version") != PRESETS_VERSION:
        raise PresetError(f"{path}: presets version {document.get('version')!r} is not supported (this version reads {PRESETS_VERSION})", "version")
    entries = document.get("presets")
    if not isinstance(entries, list) or not entries:
        raise PresetError(f"{path}: \"presets\" must be a non-empty list", "presets")
    presets = []
    names = set()
    for index, entry in enumerate(entries):
        preset = _parse_preset(path, index, entry)
        if preset.name in names:
            raise PresetError(f"{path}: preset #{index + 1} '{preset.name}': field 'name': the name is used by an earlier preset", "name")
        names.add(preset.name)
        presets.append(preset)
    return presets


def _parse_preset(path: Path, index: int, entry) -> ToolPreset:
    label = f"preset #{index + 1}"
    if isinstance(entry, dict) and isinstance(entry.get("name"), str) and entry["name"]:
        label += f" '{entry['name']}'"

    def fail(field_name: str, problem: str):
        raise PresetError(f"{path}: {label}: field '{field_name}': {problem}", field_name)

    if not isinstance(entry, dict):
        raise PresetError(f"{path}: {label}: a preset must be a JSON object, not {type(entry).__name__}")
    for name in (*_PRESET_TEXT_FIELDS, "shape", "power", "speed"):
        if name not in entry:
            fail(name, "missing")
    for name in _PRESET_TEXT_FIELDS:
        if not isinstance(entry[name], str) or not entry[name].strip():
            fail(name, f"{entry[name]!r} must be non-empty text")
    shape = entry["shape"]
    if shape not in SHAPES:
        fail("shape", f"{shape!r} is not a tool shape; use one of {', '.join(SHAPES)}")
    if shape == "Mesh":
        fail("shape", "a Mesh tool needs a model node and cannot be a preset")
    allowed = set(_PRESET_TEXT_FIELDS) | {"shape", "power", "speed"} | set(SHAPE_FIELDS[shape])
    for name in entry:
        if name not in allowed:
            reason = "is not used by a " + shape + " tool" if name in _PARAMETER_OF_FIELD else "is not a preset field"
            fail(name, f"{reason} (fields of a {shape}: {', '.join(sorted(allowed))})")
    for name in SHAPE_FIELDS[shape]:
        if name not in entry:
            fail(name, f"missing (a {shape} tool needs {', '.join(SHAPE_FIELDS[shape])})")
    values = {}
    for name, attribute in _PARAMETER_OF_FIELD.items():
        if name not in entry:
            continue
        value = entry[name]
        if attribute not in ("shape", "burr_type") and (isinstance(value, bool) or not isinstance(value, (int, float))):
            fail(name, f"{value!r} is not a number")
        values[attribute] = value
    try:
        return ToolPreset(entry["name"], entry["category"], entry["description"], ToolParameters(**values))
    except ToolConfigError as error:
        invalid = error
    json_name = next((name for name, attribute in _PARAMETER_OF_FIELD.items() if attribute == invalid.field), invalid.field)
    fail(json_name, str(invalid).split(": ", 1)[-1])


def apply_to_tool_node(params: ToolParameters, tool_node) -> None:
    """Set every property of a vtkMRMLVolumeCutToolNode, as one modification.

    Raises ToolConfigError if the node refused a value (it logs why), and
    RuntimeError if the mesh model node ID names no model node of its scene.
    """
    if not isinstance(params, ToolParameters):
        raise TypeError(f"apply_to_tool_node: expected ToolParameters, got {type(params).__name__}")
    if params.mesh_model_node_id is not None:
        scene = tool_node.GetScene()
        mesh = scene.GetNodeByID(params.mesh_model_node_id) if scene is not None else None
        if not isinstance(mesh, slicer.vtkMRMLModelNode):
            raise RuntimeError(f"Tool '{tool_node.GetName()}': mesh model node '{params.mesh_model_node_id}' is not a model node of its scene")
    was_modifying = tool_node.StartModify()
    try:
        # Shape first: the diameter's valid range depends on it.
        tool_node.SetShape(_Tool.GetShapeFromString(params.shape))
        tool_node.SetBurrType(_Tool.GetBurrTypeFromString(params.burr_type))
        tool_node.SetDiameter(params.diameter)
        tool_node.SetLength(params.length)
        tool_node.SetThickness(params.thickness)
        tool_node.SetWidth(params.width)
        tool_node.SetPower(params.power)
        tool_node.SetSpeed(params.speed)
        tool_node.SetUseCutNodeRoles(params.use_cut_node_roles)
        tool_node.SetCuttableSegmentIDs(list(params.cuttable_segment_ids))
        tool_node.SetAndObserveMeshModelNodeID(params.mesh_model_node_id)
    finally:
        tool_node.EndModify(was_modifying)
    applied = from_tool_node(tool_node)
    if applied != params:
        differing = [f.name for f in dataclasses.fields(params) if getattr(applied, f.name) != getattr(params, f.name)]
        raise ToolConfigError(f"Tool '{tool_node.GetName()}' did not accept {', '.join(differing)} (see the log)", differing[0])


def from_tool_node(tool_node) -> ToolParameters:
    """The parameters a vtkMRMLVolumeCutToolNode holds."""
    return ToolParameters(
        shape=_Tool.GetShapeAsString(tool_node.GetShape()),
        burr_type=_Tool.GetBurrTypeAsString(tool_node.GetBurrType()),
        diameter=tool_node.GetDiameter(),
        length=tool_node.GetLength(),
        thickness=tool_node.GetThickness(),
        width=tool_node.GetWidth(),
        power=tool_node.GetPower(),
        speed=tool_node.GetSpeed(),
        use_cut_node_roles=bool(tool_node.GetUseCutNodeRoles()),
        cuttable_segment_ids=tuple(tool_node.GetCuttableSegmentIDs()),
        mesh_model_node_id=tool_node.GetMeshModelNodeID() or None,
    )


def create_tool_node(scene, params: ToolParameters, name: str = "Tool"):
    """A new tool node with these parameters, its display node, and a linear transform node for its pose.

    The node classes must be registered (the VolumeCutting module logic does
    it). On any failure nothing is left in the scene.
    """
    if not scene.IsNodeClassRegistered("vtkMRMLVolumeCutToolNode") or not scene.IsNodeClassRegistered("vtkMRMLVolumeCutToolDisplayNode"):
        raise RuntimeError("create_tool_node: the scene has no tool node classes; give it a vtkSlicerVolumeCuttingLogic first")
    created = []
    try:
        pose = scene.AddNewNodeByClass("vtkMRMLLinearTransformNode", scene.GenerateUniqueName(f"{name} pose"))
        created.append(pose)
        tool_node = scene.AddNewNodeByClass("vtkMRMLVolumeCutToolNode", name)
        created.append(tool_node)
        tool_node.SetAndObserveTransformNodeID(pose.GetID())
        tool_node.CreateDefaultDisplayNodes()
        if tool_node.GetDisplayNode() is not None:
            created.append(tool_node.GetDisplayNode())
        else:
            raise RuntimeError(f"create_tool_node: no display node could be made for tool '{name}' (see the log)")
        apply_to_tool_node(params, tool_node)
    except Exception:
        for node in reversed(created):
            scene.RemoveNode(node)
        raise
    return tool_node


ROLE_CUTTABLE = "cuttable"
ROLE_PROTECTED = "protected"
ROLE_NONE = ""


@dataclass(frozen=True)
class SensibilityRow:
    """One segment of the sensibility table.

    ``role`` is the cut node's role of the segment; ``may_cut`` whether the
    tool may remove it (protection always wins, so ``editable`` is false for
    protected segments); ``from_tool`` whether that comes from the tool's own
    list rather than the cut node's roles.
    """

    segment_id: str
    name: str
    color: tuple[float, float, float]
    role: str
    may_cut: bool
    from_tool: bool
    editable: bool


def _segmentation(cut_node):
    segmentation_node = cut_node.GetSegmentationNode() if cut_node is not None else None
    return segmentation_node.GetSegmentation() if segmentation_node is not None else None


def sensibility_rows(cut_node, tool_node=None) -> list[SensibilityRow]:
    """One row per segment of the cut node's segmentation, in its order.

    Without a tool node the rows show the cut node's roles alone. A cut node
    without a segmentation gives no rows.
    """
    segmentation = _segmentation(cut_node)
    if segmentation is None:
        return []
    rows = []
    for index in range(segmentation.GetNumberOfSegments()):
        segment_id = segmentation.GetNthSegmentID(index)
        segment = segmentation.GetSegment(segment_id)
        protected = bool(cut_node.IsSegmentProtected(segment_id))
        role = ROLE_PROTECTED if protected else ROLE_CUTTABLE if cut_node.IsSegmentCuttable(segment_id) else ROLE_NONE
        if tool_node is None:
            may_cut, from_tool = role == ROLE_CUTTABLE, False
        else:
            may_cut, from_tool = bool(tool_node.MayCutSegment(cut_node, segment_id)), not tool_node.GetUseCutNodeRoles()
        rows.append(SensibilityRow(segment_id, segment.GetName() or segment_id, tuple(segment.GetColor()), role, may_cut, from_tool, not protected))
    return rows


def set_segment_cuttable_for_tool(cut_node, tool_node, segment_id: str, cuttable: bool) -> None:
    """Let the tool cut a segment, or not: the setter of the sensibility table.

    A tool that followed the cut node's roles switches to its own list, which
    starts as what the roles allowed, so that one change in the table changes
    one segment. A protected segment cannot be given to a tool (unprotect it in
    the cut node first); an unknown segment is refused. Both raise
    ToolConfigError and change nothing.
    """
    segmentation = _segmentation(cut_node)
    if segmentation is None or segmentation.GetSegment(segment_id) is None:
        raise ToolConfigError(f"Segment '{segment_id}' is not in the segmentation of cut node "
                              f"'{cut_node.GetName() if cut_node is not None else None}'", "cuttable_segment_ids")
    if cuttable and cut_node.IsSegmentProtected(segment_id):
        raise ToolConfigError(f"Segment '{segmentation.GetSegment(segment_id).GetName()}' is protected: no tool may cut it; "
                              "remove its protected role in the cut node first", "cuttable_segment_ids")
    was_modifying = tool_node.StartModify()
    try:
        if tool_node.GetUseCutNodeRoles():
            tool_node.SetCuttableSegmentIDs(list(tool_node.GetEffectiveCuttableSegmentIDs(cut_node)))
            tool_node.SetUseCutNodeRoles(False)
        tool_node.SetSegmentCuttable(segment_id, cuttable)
    finally:
        tool_node.EndModify(was_modifying)
