"""The main job: a segmentation-then-drill session without the Slicer GUI.

    python -m VolumeCuttingLib.jobs.mainjob [--phantom] [--out DIR]
    python -m VolumeCuttingLib.jobs.mainjob --ct PATH [--segmentation PATH] [--color-table PATH]
                                            [--cuttable NAMES] [--protected NAMES] [--out DIR]
    ... [--openigtlink PORT [--openigtlink-host HOST]]

On the real head CT (Debian's invesalius-examples, fetched at setup), on the
procedural temporal-bone phantom, or on the user's own CT (a DICOM series,
NRRD, NIfTI or MetaImage) with their own segmentation and segment names
(``owndata``), it builds what a user builds in Slicer before
drilling: the CT as a scalar volume, a bone segmentation (region growing into
cortical and trabecular bone), and a volume-cut node that says which segments a
tool may cut and which are protected. It renders the 3D view offscreen through
Slicer's displayable managers to a PNG and saves the scene as a bundle (.mrb).

Later stages of the product (drilling, exact cut rendering, haptics) extend
this job; ``summary.json`` records what each stage produced and how long it took.
With ``--openigtlink PORT`` the drilling streams over OpenIGTLink as it goes
(``collaboration.igtlbridge``: desktop Slicer with SlicerOpenIGTLink mirrors the
tool, the nerve monitor, the contacts and the removed region).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import slicer

from . import hapticsjob, selftests, softcutjob
from ..assessment import metrics as assessment_metrics
from ..assessment import report as assessment_report
from ..assessment import scans as assessment_scans
from ..collaboration import igtloptions
from ..config import toolconfig
from ..cutting import drilling, recording
from ..data import headct, owndata, phantom
from ..scene.application import HeadlessSlicer
from ..scene.nodes import array_from_volume_node, by_segment_name, segment_display_names, volume_node_ijk_to_ras

PHANTOM_CUTTABLE_SEGMENTS = phantom.CUTTABLE_SEGMENTS
PHANTOM_BONE_SEGMENTS = phantom.BONE_SEGMENTS
PHANTOM_PROTECTED_SEGMENTS = phantom.PROTECTED_SEGMENTS

PHANTOM_DIMENSIONS, PHANTOM_SPACING = (128, 128, 96), (0.4, 0.4, 0.5)

# On the user's own CT: a short path into the cuttable bone with a 3.5 mm burr.
OWN_DATA_PLAN = {"surface_radius": 4.0, "depth": 4.0, "burr_radius": 1.75}


@dataclass
class OwnData:
    """The user's own input, as given on the command line (names as the user wrote them)."""

    ct: Path
    segmentation: Path | None = None
    color_table: Path | None = None
    cuttable: list = field(default_factory=list)
    protected: list = field(default_factory=list)
    warnings: list = field(default_factory=list)


class Stopwatch:
    def __init__(self):
        self.seconds = {}

    def measure(self, name):
        stopwatch = self

        class _Timer:
            def __enter__(self):
                self.start = time.perf_counter()

            def __exit__(self, *exc):
                stopwatch.seconds[name] = round(time.perf_counter() - self.start, 4)

        return _Timer()


def load_anatomy(application: HeadlessSlicer, use_phantom: bool, seed: int, own_data: OwnData | None = None):
    """Return (ct_volume_node, anatomy_segmentation_node or None, description)."""
    if own_data is not None:
        volume = owndata.load_ct(application.scene, own_data.ct, messages=own_data.warnings)
        segmentation = None
        if own_data.segmentation is not None:
            segmentation = owndata.load_segmentation(application.scene, own_data.segmentation, volume,
                                                     color_table=own_data.color_table, messages=own_data.warnings)
            own_roles(own_data, segmentation)  # wrong names fail here, before the bone segmentation's time
        dims = volume.GetImageData().GetDimensions()
        spacing = volume.GetSpacing()
        return volume, segmentation, f"user CT {own_data.ct} {dims[0]}x{dims[1]}x{dims[2]} at " + \
            "x".join(f"{s:.3f}" for s in spacing) + " mm"
    if use_phantom:
        generated = phantom.generate_phantom(dimensions=PHANTOM_DIMENSIONS, spacing=PHANTOM_SPACING, seed=seed)
        volume, segmentation = phantom.create_phantom_nodes(application.scene, generated)
        return volume, segmentation, "procedural temporal-bone phantom 128x128x96 at 0.4x0.4x0.5 mm"
    volume = headct.load_volume_node(application.scene, name="HeadCT")
    dims = volume.GetImageData().GetDimensions()
    spacing = volume.GetSpacing()
    return volume, None, f"Debian invesalius-examples Cranium head CT {dims[0]}x{dims[1]}x{dims[2]} at " + \
        "x".join(f"{s:.3f}" for s in spacing) + " mm"


def own_roles(own_data: OwnData, segmentation_node, default_cuttable=()):
    """The user's roles by name: (cuttable IDs, protected IDs); raises ``owndata.InputError``."""
    if own_data.segmentation is not None and not own_data.cuttable:
        segmentation = segmentation_node.GetSegmentation()
        names = ", ".join(f"'{segmentation.GetSegment(s).GetName()}'" for s in segmentation.GetSegmentIDs())
        raise owndata.InputError(own_data.segmentation, "no segment is named cuttable",
                                 f"Say which segments the drill may cut with --cuttable NAMES (its segments: {names}).")
    return owndata.resolve_roles(segmentation_node, own_data.cuttable or list(default_cuttable), own_data.protected)


def assign_roles(cut_node, segmentation_node, logic, use_phantom: bool, own_data: OwnData | None = None):
    segment_ids = set(segmentation_node.GetSegmentation().GetSegmentIDs())
    if own_data is not None:
        # Without a segmentation of the user's, names refer to the automatic bone segments.
        if own_data.segmentation is None:
            segmentation_node.SetAttribute(owndata.SOURCE_PATH_ATTRIBUTE, f"{own_data.ct} (automatic bone segmentation)")
        cuttable, protected = own_roles(
            own_data, segmentation_node, [logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()])
    elif use_phantom:
        cuttable = [s for s in PHANTOM_CUTTABLE_SEGMENTS if s in segment_ids]
        protected = [s for s in PHANTOM_PROTECTED_SEGMENTS if s in segment_ids]
    else:
        cuttable = [logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()]
        protected = []
    cut_node.SetProtectedSegmentIDs(protected)
    cut_node.SetCuttableSegmentIDs(cuttable)


def contacts_by_segment(contact_table) -> dict:
    """Per segment ID of the contact table: its contact events and the deepest one (mm)."""
    contacts = {}
    for row in range(contact_table.GetNumberOfRows()):
        segment_id = contact_table.GetCellText(row, 0)
        depth = float(contact_table.GetCellText(row, 3))
        entry = contacts.setdefault(segment_id, {"contact_events": 0, "deepest_mm": 0.0})
        entry["contact_events"] += 1
        entry["deepest_mm"] = round(max(entry["deepest_mm"], depth), 3)
    return contacts


# The slice view shows the removed region across the middle 40 % of its width,
# and at least this much (mm) around a small one.
SLICE_VIEW_MINIMUM_FIELD_MM = 30.0


def removed_region_view(removed_fraction_node):
    """Where an axial view of the cut looks (RAS, mm) and its field of view (mm).

    In the axial plane through the removed region's centroid (weighted by
    each voxel's removed fraction), centred on the region's box in that plane,
    which spans the middle 40 % of the view: the cavity with the bone around it.
    """
    fraction = array_from_volume_node(removed_fraction_node)
    removed = np.argwhere(fraction > 0.0)
    if len(removed) == 0:
        raise RuntimeError("the cut removed nothing: there is no cavity to show in the slice view")
    ijk_to_ras = volume_node_ijk_to_ras(removed_fraction_node)
    ras = removed[:, ::-1] @ ijk_to_ras[:3, :3].T + ijk_to_ras[:3, 3]
    weights = fraction[tuple(removed.T)].astype(float)
    centroid = weights @ ras / weights.sum()
    # The box of the voxels that are mostly removed, near the centroid's axial plane.
    slab = np.abs(ras[:, 2] - centroid[2]) <= max(1.0, float(np.ptp(ras[:, 2])) / 4.0)
    mostly = slab & (weights >= 0.5)
    inside = ras[mostly] if mostly.any() else ras
    low, high = inside[:, :2].min(axis=0), inside[:, :2].max(axis=0)
    center = np.array([(low[0] + high[0]) / 2.0, (low[1] + high[1]) / 2.0, centroid[2]])
    field = max(SLICE_VIEW_MINIMUM_FIELD_MM, 2.5 * float(np.max(high - low)))
    return center, field


def scan_descriptor(volume, use_phantom: bool, seed: int, own_data: OwnData | None, cut_node=None) -> dict:
    """What a recording says of the scan it was drilled on: the name the assessment rebuilds it by, and its grid.

    The user's own scan with their segmentation is named by its files and
    the roles of ``cut_node`` (``assessment.scans.own_descriptor``).
    """
    ijk_to_ras = volume_node_ijk_to_ras(volume)
    grid = {"dimensions": list(volume.GetImageData().GetDimensions()), "ijk_to_ras": [round(float(v), 6) for v in ijk_to_ras.ravel()]}
    if own_data is not None and own_data.segmentation is not None and cut_node is not None:
        return assessment_scans.own_descriptor(volume, cut_node.GetSegmentationNode(), list(cut_node.GetCuttableSegmentIDs()),
                                               list(cut_node.GetProtectedSegmentIDs()), own_data.ct, own_data.segmentation,
                                               own_data.color_table)
    if own_data is not None:
        return {"name": "own", "parameters": {"ct": str(own_data.ct)}, "grid": grid}
    if use_phantom:
        return {"name": "phantom", "parameters": {"dimensions": list(PHANTOM_DIMENSIONS), "spacing": list(PHANTOM_SPACING), "seed": seed},
                "grid": grid}
    return {"name": "headct", "parameters": {}, "grid": grid}


def cavity_camera(view, plan):
    """Look into the planned cavity along its approach, a view ten burr paths across, as a surgeon drilling sees it."""
    into = np.asarray(plan.direction, dtype=float) / np.linalg.norm(plan.direction)
    center = np.asarray(plan.entry, dtype=float) + 0.5 * plan.depth * into
    view.renderer.GetActiveCamera().SetViewAngle(30.0)
    height = 6.0 * plan.surface_radius
    view.look_at(center, direction=-into, distance=0.5 * height / np.tan(np.radians(15.0)), view_up=(0.0, 0.0, 1.0))


# The cutting burr matches the plan's; the last layers are polished with a 3 mm diamond burr.
FINISHING_BURR_RADIUS = 1.5


def session_tools(scene, plan) -> dict:
    """Tool nodes from the shipped presets: a cutting burr of the plan's size and a 3 mm diamond burr."""
    presets = {preset.name: preset for preset in toolconfig.load_presets()}
    diameter = 2.0 * plan.burr_radius
    cutting = presets.get(f"Cutting burr {diameter:g} mm")
    cutting_parameters = toolconfig.from_preset(cutting) if cutting else toolconfig.from_preset(presets["Cutting burr 5 mm"], diameter=diameter)
    return {
        "cutting": toolconfig.create_tool_node(scene, cutting_parameters, cutting.name if cutting else f"Cutting burr {diameter:g} mm"),
        "diamond": toolconfig.create_tool_node(scene, toolconfig.from_preset(presets["Diamond burr 3 mm"]), "Diamond burr 3 mm"),
    }


def run(use_phantom: bool, out_dir: Path, seed: int = 0, size=(1024, 768), own_data: OwnData | None = None,
        openigtlink: igtloptions.BridgeOptions | None = None) -> dict:
    """Run the job; ``own_data`` (the user's CT and segmentation) takes the place of the shipped data.

    ``openigtlink`` streams the session over OpenIGTLink while it runs (the bridge stops at the end).
    """
    bridge = None
    if openigtlink is not None:
        from ..collaboration import igtlbridge  # pyigtl only when asked for

        bridge = igtlbridge.IgtlBridge(openigtlink).start()
    try:
        return _run(use_phantom, out_dir, seed, size, own_data, bridge)
    finally:
        if bridge is not None:
            bridge.stop()


def _run(use_phantom: bool, out_dir: Path, seed: int, size, own_data: OwnData | None, bridge) -> dict:
    timer = Stopwatch()
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic

    with timer.measure("load_ct_s"):
        volume, anatomy_segmentation, description = load_anatomy(application, use_phantom, seed, own_data)
    out_dir.mkdir(parents=True, exist_ok=True)
    with timer.measure("bone_segmentation_s"):
        bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.5)
    if bone is None:
        raise RuntimeError("bone segmentation failed (see the log)")
    roles_segmentation = anatomy_segmentation if anatomy_segmentation is not None else bone
    cut_node = logic.AddVolumeCutNode(volume, roles_segmentation)
    assign_roles(cut_node, roles_segmentation, logic, use_phantom, own_data)
    # Bone is one material outside; a cut shows whether it exposes cortex or cancellous bone.
    bone_segments = PHANTOM_BONE_SEGMENTS if use_phantom else \
        [logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()] if roles_segmentation is bone else []
    cut_node.SetMaterialSegmentIDs(list(bone_segments))
    messages = slicer.vtkMRMLMessageCollection()
    inputs_ok = logic.CheckInputs(cut_node, messages)
    if bridge is not None:
        bridge.attach(logic, cut_node)

    # Drill a cortical mastoidectomy from the patient's right.
    if use_phantom:
        air_cells = anatomy_segmentation.GetSegmentation().GetSegment("MastoidAirCells")
        bounds = [0.0] * 6
        air_cells.GetBounds(bounds)
        target_yz = ((bounds[2] + bounds[3]) / 2.0, (bounds[4] + bounds[5]) / 2.0)
        plan = drilling.MastoidectomyPlan(entry=drilling.lateral_entry(volume, *target_yz),
                                          surface_radius=7.0, depth=8.0, burr_radius=2.0)
    elif own_data is not None:
        # From the patient's right into the cuttable segments, through the centre of their bounds.
        entry = drilling.lateral_entry_into_segments(roles_segmentation, list(cut_node.GetCuttableSegmentIDs()))
        plan = drilling.MastoidectomyPlan(entry=entry, **OWN_DATA_PLAN)
    else:
        plan = drilling.MastoidectomyPlan(entry=drilling.lateral_entry(volume, *headct.RIGHT_MASTOID_YZ))
    # The cut anatomy as the product shows it: through the adaptive multivolume
    # ray-cast mapper (vtkMRMLVolumeCutDisplayableManager), before and after.
    # The segmentation's own surfaces stay hidden; its segments colour the view.
    display = roles_segmentation.GetDisplayNode()
    display.SetVisibility3D(False)
    if anatomy_segmentation is not None:
        # Bone and the structures at risk; soft tissue and air stay hidden.
        shown = set(PHANTOM_PROTECTED_SEGMENTS + PHANTOM_BONE_SEGMENTS) if own_data is None else \
            set(cut_node.GetCuttableSegmentIDs()) | set(cut_node.GetProtectedSegmentIDs())
        for segment_id in anatomy_segmentation.GetSegmentation().GetSegmentIDs():
            display.SetSegmentVisibility3D(segment_id, segment_id in shown)
    # Bone surface at 300 HU; bone thinner than 1 mm over what lies behind it
    # shows red and translucent (Morris et al.), as a surgeon drilling sees it.
    cut_node.SetSurfaceIsoValue(300.0)
    cut_node.SetThinBoneShading(True)
    cut_node.SetThinBoneThickness(1.0)
    view = application.create_3d_view(*size)
    cavity_camera(view, plan)
    with timer.measure("first_frame_s"):
        view.render()
    before_path = view.screenshot(out_dir / "cut_before.png")

    # The surgeon's tools from the presets, and the drilling as a recorded
    # session replayed through the tool nodes (the shipped recording on the
    # head CT; elsewhere the plan, recorded on the fly). The removed volume
    # per segment and the contacts are kept in tables as it goes.
    tools = session_tools(application.scene, plan)
    if use_phantom or own_data is not None:
        session = recording.record_mastoidectomy(plan, finishing_radius=FINISHING_BURR_RADIUS)
    else:
        session = recording.load(recording.head_ct_mastoidectomy_path())
    volume_table = logic.GetRemovedVolumeTableNode(cut_node)
    # The drilling is recorded as a live session is (session.json): poses with
    # their times, the camera it was seen from, contacts and removed volumes.
    recorder = recording.SessionRecorder(
        {key: {"name": tool.GetName(), "burr_type": toolconfig.from_tool_node(tool).burr_type,
               "radius_mm": toolconfig.from_tool_node(tool).diameter / 2.0} for key, tool in tools.items()},
        scan=scan_descriptor(volume, use_phantom, seed, own_data, cut_node),
        description=f"The main job's mastoidectomy on the {description}")
    camera = view.renderer.GetActiveCamera()
    recorder.camera(camera.GetPosition(), camera.GetFocalPoint(), camera.GetViewUp(), camera.GetViewAngle())
    with timer.measure("drilling_s"):
        drilled = recording.replay(logic, cut_node, session, tools, recorder=recorder)
    session_path = recording.save(recorder.recording, out_dir / "session.json")
    drilled["tool_presets"] = {key: tool.GetName() for key, tool in tools.items()}
    contact_table = logic.GetContactTableNode(cut_node)
    drilled["contact_events"] = contact_table.GetNumberOfRows()
    roles = roles_segmentation.GetSegmentation()
    drilled["contacts_per_segment"] = by_segment_name(roles, contacts_by_segment(contact_table))
    drilled["removed_volume_table"] = by_segment_name(roles, {
        volume_table.GetCellText(row, 0): {"role": volume_table.GetCellText(row, 2),
                                           "removed_volume_mm3": float(volume_table.GetCellText(row, 3))}
        for row in range(volume_table.GetNumberOfRows())})
    # Then a session through the haptic path, beside the cavity: what it cuts
    # adds to the recorded mastoidectomy's volume in the tables that follow.
    with timer.measure("haptics_s"):
        haptics = hapticsjob.run(application, cut_node, plan, out_dir, frame=view.render,
                                 scan=scan_descriptor(volume, use_phantom, seed, own_data, cut_node))
    openigtlink = None
    if bridge is not None:
        # Clients get what is due before the bridge closes with the job.
        flushed = bridge.flush(timeout_s=5.0)
        openigtlink = {"address": bridge.address, "flushed": flushed, **bridge.stats()}
        bridge.detach()
    removed_per_segment = by_segment_name(roles, {
        segment_id: {"removed_volume_mm3": round(logic.GetRemovedVolumeInSegment(cut_node, segment_id), 2)}
        for segment_id in roles.GetSegmentIDs()
    })
    # Exports: the removed region as a segment (binary labelmap) and as a
    # fraction volume on the CT's grid, as a closed surface (STL), and the
    # drilled CT.
    removed = logic.ExportRemovedRegionToSegmentation(cut_node, None)
    removed.GetDisplayNode().SetVisibility3D(False)
    removed_fraction = logic.ExportRemovedFractionToVolume(cut_node, None)
    removed_model = logic.ExportRemovedSurfaceToModel(cut_node, None)
    # The view shows the cavity itself, not the model of what filled it.
    removed_model.GetDisplayNode().SetVisibility(False)
    storage = removed_model.CreateDefaultStorageNode()
    storage.SetFileName(str(out_dir / "removed.stl"))
    if not storage.WriteData(removed_model):
        raise RuntimeError("writing removed.stl failed (see the log)")
    drilled_ct = logic.ExportDrilledVolume(cut_node, -1000.0, None)

    # The stills show the bone: the drills are lifted out of the picture.
    tool_nodes = application.scene.GetNodesByClass("vtkMRMLVolumeCutToolNode")
    for index in range(tool_nodes.GetNumberOfItems()):
        tool_display = tool_nodes.GetItemAsObject(index).GetDisplayNode()
        if tool_display is not None:
            tool_display.SetVisibility(False)
    with timer.measure("cut_frame_s"):
        view.render()
    image_path = view.screenshot(out_dir / "3d.png")
    mapper = view.volume_cut_displayable_manager.GetVolumeActor(cut_node).GetMapper()
    rendering = {
        "displayable_manager": "vtkMRMLVolumeCutDisplayableManager",
        "mapper": mapper.GetClassName(),
        "path": mapper.GetLastRenderPathAsString(),
        "gpu_fallback_reason": mapper.GetGPUFallbackReason(),
        "frame_time_s": round(mapper.GetLastFrameTime(), 4),
    }
    # Zoom onto the rim of the cavity, where the cut meets the cortex: the
    # edge is drawn exactly, not as voxel stairs.
    entry = np.asarray(plan.entry, dtype=float)
    bounds = [0.0] * 6
    volume.GetRASBounds(bounds)
    lateral = 1.0 if entry[0] > (bounds[0] + bounds[1]) / 2.0 else -1.0
    # The lower rim, from outside the head and a little above, so that its
    # edge shows against the cavity's far wall (the bone above the upper rim
    # bulges out and would hide it).
    rim = entry - np.array([0.0, 0.0, 0.85 * plan.surface_radius])
    view.look_at(rim, direction=(lateral * 0.94, 0.0, 0.34), distance=45.0, view_up=(0.0, 0.0, 1.0))
    view.renderer.GetActiveCamera().SetViewAngle(12.0)
    view.renderer.ResetCameraClippingRange()
    cut_node.SetThinBoneShading(False)  # the edge itself, in the bone's colour
    view.render()
    # Taken before thin-bone shading comes back: the node's change would draw the view again.
    zoom_path = view.screenshot(out_dir / "cut_edge_zoom.png")
    cut_node.SetThinBoneShading(True)
    renderer = view.renderer_description()

    # A slice view across the cavity: the cut's outline and fill over the CT
    # show how deep it goes (seed 000, Fig. 5d).
    slice_center, field_of_view = removed_region_view(removed_fraction)
    slice_view = application.create_slice_view("Axial", 600, 600, "Red")
    slice_view.set_background_volume(volume)
    # Slicer's axial orientation: the patient's right on the view's left.
    slice_to_ras = np.diag([-1.0, 1.0, 1.0, 1.0])
    slice_to_ras[:3, 3] = slice_center
    slice_view.set_slice_to_ras(slice_to_ras)
    slice_view.slice_node.SetFieldOfView(field_of_view, field_of_view, 1.0)
    slice_path = slice_view.screenshot(out_dir / "cut_slice_axial.png")
    slice_view.close()

    with timer.measure("save_scene_s"):
        bundle = application.save_bundle(out_dir / "scene.mrb")
    # The saved session comes back whole: the same cut, sample for sample.
    with timer.measure("reload_check_s"):
        reloaded = HeadlessSlicer()
        reloaded.load_bundle(bundle)
        read = reloaded.scene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
        reload_check = {
            "cut_identical": selftests.same_cut(read.GetCutField(), logic.GetCutField(cut_node)),
            "removed_volume_mm3": round(reloaded.volume_cutting_logic.GetRemovedVolume(read), 2),
        }

    # Segments by the names a person gave them; their IDs beside, for scripts that look them up.
    bone_ids = list(bone.GetSegmentation().GetSegmentIDs())
    bone_names = segment_display_names(bone.GetSegmentation(), bone_ids)
    role_names = segment_display_names(roles, roles.GetSegmentIDs())
    cuttable_ids = list(cut_node.GetCuttableSegmentIDs())
    protected_ids = list(cut_node.GetProtectedSegmentIDs())
    contact_id = logic.GetContactSegmentID(cut_node)
    summary = {
        "anatomy": description,
        "ct_node": volume.GetName(),
        "bone_segments": [bone_names[s] for s in bone_ids],
        "bone_segment_ids": bone_ids,
        "volume_cut_node": cut_node.GetName(),
        "cuttable_segments": [role_names[s] for s in cuttable_ids],
        "cuttable_segment_ids": cuttable_ids,
        "protected_segments": [role_names[s] for s in protected_ids],
        "protected_segment_ids": protected_ids,
        "sub_voxel_factor": cut_node.GetSubVoxelFactor(),
        "inputs_ok": bool(inputs_ok),
        "input_messages": messages.GetAllMessagesAsString(),
        "drilling": {
            "plan": {
                "entry_ras_mm": [round(float(v), 2) for v in plan.entry],
                "surface_radius_mm": plan.surface_radius,
                "depth_mm": plan.depth,
                "burr_radius_mm": plan.burr_radius,
            },
            **drilled,
            "removed_volume_mm3": round(logic.GetRemovedVolume(cut_node), 2),
            "removed_volume_per_segment": removed_per_segment,
            "deepest_contact_with_protected": {
                "segment": role_names.get(contact_id, contact_id),
                "segment_id": contact_id,
                "depth_mm": round(logic.GetCutField(cut_node).GetMaximumContactDepth(), 3),
            },
        },
        "haptics": haptics,
        "openigtlink": openigtlink,
        "exports": {
            "removed_segmentation": removed.GetName(),
            "removed_fraction_volume": removed_fraction.GetName(),
            "removed_surface_stl": str(out_dir / "removed.stl"),
            "removed_surface_triangles": removed_model.GetPolyData().GetNumberOfCells(),
            "drilled_ct": drilled_ct.GetName(),
        },
        "renderer": renderer,
        "rendering": rendering,
        "image": str(image_path),
        "image_before_cutting": str(before_path),
        "image_cut_edge_zoom": str(zoom_path),
        "scene_bundle": str(bundle),
        "reload_check": reload_check,
        "image_slice_view": str(slice_path),
        "timings": timer.seconds,
    }
    # The recorded session graded (vc assess): on the shipped scans, which the assessment rebuilds, and on the
    # user's scan with their segmentation (read again from their files, the roles by their names).
    if own_data is None or own_data.segmentation is not None:
        with timer.measure("assessment_s"):
            graded = assessment_metrics.assess(recording.load(session_path), recording_path=session_path)
            written = assessment_report.write(graded, out_dir / "assessment")
        summary["assessment"] = {"session": str(session_path), "score": graded.score, "report": str(written["html"]),
                                 "metrics": str(written["json"])}
    else:
        summary["assessment"] = {"session": str(session_path), "score": None,
                                 "report": "not graded: without a segmentation of the user's there are no regions or "
                                           "structures at risk to grade against (give --segmentation)"}
    # Soft-tissue resection planning (SoftCut) on the head CT, in its own scene.
    summary["softcut"] = softcutjob.run(out_dir, size=size, head_ct=not use_phantom and own_data is None)
    if own_data is not None:
        summary["own_data"] = {
            "ct": str(own_data.ct),
            "segmentation": str(own_data.segmentation) if own_data.segmentation is not None else None,
            "segment_names": {segment_id: roles.GetSegment(segment_id).GetName() for segment_id in roles.GetSegmentIDs()},
            "warnings": list(own_data.warnings),
        }
    (out_dir / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    view.close()
    return summary


def _image_size(text: str):
    try:
        width, height = (int(value) for value in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels, got {text!r}") from None
    if width < 16 or height < 16:
        raise argparse.ArgumentTypeError(f"images of at least 16x16 pixels, got {text!r}")
    return width, height


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phantom", action="store_true", help="use the procedural temporal-bone phantom instead of the real head CT")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: out/headct or out/phantom)")
    parser.add_argument("--seed", type=int, default=0, help="noise seed of the phantom")
    parser.add_argument("--size", type=_image_size, default=(1024, 768), metavar="WxH",
                        help="size of the rendered images in pixels (default 1024x768)")
    own = parser.add_argument_group("own data", "drill the user's own CT instead of the shipped data")
    own.add_argument("--ct", type=Path, default=None,
                     help="the CT: a DICOM series folder (or one file of it), .nrrd, .nhdr, .nii, .nii.gz, .mha or .mhd")
    own.add_argument("--segmentation", type=Path, default=None,
                     help="its segmentation: a Slicer .seg.nrrd or a labelmap volume (default: automatic bone segmentation)")
    own.add_argument("--color-table", type=Path, default=None,
                     help="names of the labelmap's labels ('label name R G B A' a line; default: a .ctbl or .txt "
                          "beside the labelmap with its base name)")
    own.add_argument("--cuttable", default="", help="comma-separated names of the segments the drill may cut")
    own.add_argument("--protected", default="", help="comma-separated names of the segments the drill must not cut")
    igtloptions.add_arguments(parser)
    args = parser.parse_args(argv)
    try:
        openigtlink = igtloptions.options_from_arguments(args)
    except ValueError as error:
        parser.error(str(error))
    own_data = None
    if args.ct is not None:
        if args.phantom:
            parser.error("--phantom and --ct exclude each other")
        own_data = OwnData(ct=args.ct, segmentation=args.segmentation, color_table=args.color_table,
                           cuttable=owndata.split_names(args.cuttable), protected=owndata.split_names(args.protected))
    elif args.segmentation or args.color_table or args.cuttable or args.protected:
        parser.error("--segmentation, --color-table, --cuttable and --protected go with --ct")
    out_dir = args.out or Path("out") / ("phantom" if args.phantom else "owndata" if own_data else "headct")
    try:
        summary = run(args.phantom, out_dir, seed=args.seed, size=args.size, own_data=own_data, openigtlink=openigtlink)
    except owndata.InputError as error:
        print(f"main job: {error}", file=sys.stderr)
        return 1
    except (RuntimeError, ValueError, OSError) as error:
        print(f"main job failed: {error}", file=sys.stderr)
        return 1
    print(json.dumps(summary, indent=2))
    for warning in summary.get("own_data", {}).get("warnings", []):
        print(f"warning: {warning}", file=sys.stderr)
    haptics = summary.get("haptics", {})
    if haptics and not haptics.get("real_time_priority"):
        # The one line a user needs to read the haptic figures: the loop ran at normal priority, and why.
        print(f"note: the haptic loop ran at normal priority: {haptics.get('real_time_priority_status')}", file=sys.stderr)
    machine = haptics.get("machine_check") if haptics else None
    if machine and haptics.get("overruns"):
        # Overruns alone do not say whose they are: beside them, what the same work got on this machine without the product's code.
        profile = haptics["tick_profile"]
        print(f"note: the haptic loop overran {haptics['overruns']} times ({haptics['overruns_woken_late']} asleep: woken up "
              f"to {haptics['wake_up_lateness_us_max']:.0f} us late; {profile['slow_ticks']} ticks over "
              f"{profile['slow_tick_us']:.0f} us, {profile['slow_ticks_processor_bound']} processor-bound); a thread doing "
              f"the same work, tick by tick, without memory, beside the same views overran {machine['overruns']} "
              f"times ({machine['overruns_woken_late']} asleep; {machine['slow_ticks']} over, "
              f"{machine['slow_ticks_processor_bound']} processor-bound): what this machine does to that work alone",
              file=sys.stderr)
    return 0 if summary["inputs_ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
