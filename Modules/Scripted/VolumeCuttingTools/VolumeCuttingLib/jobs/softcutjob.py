"""The main job's SoftCut part: a soft-tissue resection planned on the real head CT.

A surgeon planning the excision of a tumour of the right cheek, and the free
flap that will fill the defect (Blache et al., SoftCut): the outline is drawn
on the skin (a closed markups curve, picked in two sittings from the view of
the patient's right front, as clicks in a 3D view), the depth of cut is
previewed at two depths in the product's 3D view, the resection is carved
into the cut field at the chosen depth (one undo step, undone and redone
once to show it), measured (volume, surface area, length, width and
thickness in the resection's own frame) and exported as an STL guide for
harvesting the flap.

Renders (through vtkMRMLVolumeCutDisplayableManager and the adaptive
multivolume mapper; the CT's skin at -500 HU, soft tissue in skin colour,
bone from the bone segmentation in bone colour): the outline on the skin,
the two previews, the carved cheek, a close view of the defect, and the
resection's mesh on its own, from outside and from the deep side. Everything goes into the main job's output
folder with the prefix ``softcut_``; ``run`` returns the summary's
``softcut`` section.
"""

from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np
import slicer
import vtk

from ..cutting import softcut
from ..data import headct
from ..scene import nodes
from ..scene.application import HeadlessSlicer, _write_screenshot

# The outline: an ellipse of 34 x 24 mm centred on the right cheek (RAS, mm),
# below the eye and lateral to the nose, seen from the patient's right front.
CHEEK_CENTER = (42.0, 62.0, -40.0)
CHEEK_RADII = (17.0, 12.0)
VIEW_DIRECTION = tuple(np.array([1.0, 1.0, 0.15]) / np.linalg.norm([1.0, 1.0, 0.15]))  # from the face towards the camera
CONTROL_POINTS = 20
SKIN_ISO_HU = -500.0
PREVIEW_DEPTHS_MM = (4.0, 8.0)
DEPTH_MM = 8.0
MAXIMUM_DEPTH_MM = 25.0
SOFT_TISSUE_COLOR = (0.91, 0.72, 0.64)
BONE_COLOR = (0.96, 0.94, 0.86)


def _colour_segments(application, volume):
    """A segmentation that colours the view: the bone (region growing) and the soft tissue above the skin's iso-value."""
    logic = application.volume_cutting_logic
    segmentation = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.5)
    if segmentation is None:
        raise RuntimeError("SoftCut: the bone segmentation failed (see the log)")
    segmentation.SetName("SoftCut anatomy")
    segmentation.GetSegmentation().AddSegment(soft_tissue_segment(volume), "SoftTissue")
    colours = {"SoftTissue": SOFT_TISSUE_COLOR, logic.GetCorticalBoneSegmentID(): BONE_COLOR,
               logic.GetTrabecularBoneSegmentID(): BONE_COLOR}
    display = segmentation.GetDisplayNode()
    display.SetVisibility3D(False)  # Slicer's own surfaces: the cut view draws the segments
    # The soft tissue first: later segments win where they overlap, so bone shows as bone.
    ordered = ["SoftTissue", logic.GetTrabecularBoneSegmentID(), logic.GetCorticalBoneSegmentID()]
    for segment_id in ordered:
        segmentation.GetSegmentation().GetSegment(segment_id).SetColor(*colours[segment_id])
        display.SetSegmentVisibility3D(segment_id, True)
    for index, segment_id in enumerate(ordered):
        segmentation.GetSegmentation().SetSegmentIndex(segment_id, index)
    return segmentation, ordered


def soft_tissue_segment(volume, name="Soft tissue"):
    """A segment of everything above the skin's iso-value, grown two voxels into the air.

    The cut view draws only segments: with it the skin shows, and the skin's
    iso-surface lies inside the segment everywhere.
    """
    grown = nodes.array_from_volume_node(volume) > SKIN_ISO_HU
    for _ in range(2):
        step = grown.copy()
        for axis in range(3):
            step |= np.roll(grown, 1, axis) | np.roll(grown, -1, axis)
        grown = step
    image = slicer.vtkOrientedImageData()
    image.ShallowCopy(nodes.image_data_from_array(grown.astype(np.uint8)))
    image.SetImageToWorldMatrix(nodes.numpy_to_vtk_matrix(nodes.volume_node_ijk_to_ras(volume)))
    segment = slicer.vtkSegment()
    segment.SetName(name)
    segment.SetColor(*SOFT_TISSUE_COLOR)
    segment.AddRepresentation("Binary labelmap", image)
    return segment


def _outline_model(scene, planner, name):
    """The outline on the skin as a red tube (a model node), as the curve is drawn in Slicer."""
    polyline = vtk.vtkPolyData()
    planner.GetOutlineOnSkin(polyline)
    tube = vtk.vtkTubeFilter()
    tube.SetInputData(polyline)
    tube.SetRadius(0.6)
    tube.SetNumberOfSides(12)
    tube.Update()
    model = scene.AddNewNodeByClass("vtkMRMLModelNode", name)
    model.SetAndObservePolyData(tube.GetOutput())
    model.CreateDefaultDisplayNodes()
    model.GetDisplayNode().SetColor(0.85, 0.1, 0.1)
    return model


def _mesh_image(mesh, normal, path, size):
    """The resection's mesh on its own (plain VTK), in flap colour: from outside (the skin) and from inside (the deep side)."""
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(True)
    window.SetSize(*size)
    edges = vtk.vtkFeatureEdges()
    edges.SetInputData(mesh)
    edges.BoundaryEdgesOff()
    edges.FeatureEdgesOn()
    edges.SetFeatureAngle(50.0)
    edges.ManifoldEdgesOff()
    edges.NonManifoldEdgesOff()
    for side, viewport in ((1.0, (0.0, 0.0, 0.5, 1.0)), (-1.0, (0.5, 0.0, 1.0, 1.0))):
        renderer = vtk.vtkRenderer()
        renderer.SetViewport(*viewport)
        renderer.SetBackground(0.32, 0.34, 0.43)
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputData(mesh)
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*SOFT_TISSUE_COLOR)
        actor.GetProperty().SetSpecular(0.2)
        renderer.AddActor(actor)
        edge_mapper = vtk.vtkPolyDataMapper()
        edge_mapper.SetInputConnection(edges.GetOutputPort())
        edge_mapper.ScalarVisibilityOff()
        edge_actor = vtk.vtkActor()
        edge_actor.SetMapper(edge_mapper)
        edge_actor.GetProperty().SetColor(0.4, 0.15, 0.1)
        renderer.AddActor(edge_actor)
        window.AddRenderer(renderer)
        renderer.ResetCamera()
        camera = renderer.GetActiveCamera()
        center = np.array(camera.GetFocalPoint())
        distance = camera.GetDistance()
        # Three quarters, a little from below, so the thickness shows.
        direction = side * np.asarray(normal) + np.array([0.0, 0.0, -0.45])
        direction /= np.linalg.norm(direction)
        camera.SetPosition(*(center + distance * direction))
        camera.SetViewUp(0.0, 0.0, 1.0)
        renderer.ResetCamera()
    window.Render()
    _write_screenshot(window, path)
    window.Finalize()
    return path


def _write_table(table_node, path):
    rows = softcut.table_rows(table_node)
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["Measurement", "Value", "Unit"])
        for name, (value, unit) in rows.items():
            writer.writerow([name, f"{value:.6g}", unit])
    return rows


def skipped(reason: str) -> dict:
    return {"planned": False, "reason": reason}


def run(out_dir: Path, size=(1024, 768), head_ct: bool = True) -> dict:
    """Plan, preview, carve, measure and export a cheek resection on the head CT; the summary's ``softcut`` section.

    ``head_ct`` False (the phantom or the user's own scan, where no cheek is
    known) records why nothing was planned.
    """
    if not head_ct:
        return skipped("SoftCut plans its cheek outline on the real head CT; run the main job without --phantom or --ct")
    out_dir = Path(out_dir)
    timings = {}
    start = time.perf_counter()
    application = HeadlessSlicer()
    volume = headct.load_volume_node(application.scene, name="HeadCT")
    segmentation, segment_ids = _colour_segments(application, volume)
    module = application.volume_cutting_logic
    cut = module.AddVolumeCutNode(volume, segmentation)
    cut.SetName("Cheek")
    cut.SetCuttableSegmentIDs(segment_ids)
    cut.SetSurfaceIsoValue(SKIN_ISO_HU)
    logic = softcut.create_logic(application)
    logic.SetNormalMode(slicer.vtkVolumeCutResectionPlanner.AverageNormal)  # a cheek: nearly flat
    logic.SetSkinIsoValue(SKIN_ISO_HU)
    logic.SetMaximumDepth(MAXIMUM_DEPTH_MM)
    timings["scene_s"] = time.perf_counter() - start

    # The outline, clicked on the skin in two sittings (the view turned in between).
    view_direction = -np.asarray(VIEW_DIRECTION)
    outline = softcut.outline_by_picking(application.scene, volume, CHEEK_CENTER, view_direction, CHEEK_RADII,
                                         count=CONTROL_POINTS, iso=SKIN_ISO_HU, name="Cheek resection outline", sittings=2)
    start = time.perf_counter()
    if not logic.PlanResection(cut, outline):
        raise RuntimeError(f"SoftCut planning failed: {logic.GetErrorMessage()}")
    timings["plan_s"] = time.perf_counter() - start
    planner = logic.GetPlanner(cut)
    outline_model = _outline_model(application.scene, planner, "Outline on the skin")

    view = application.create_3d_view(*size)
    view.look_at(CHEEK_CENTER, direction=VIEW_DIRECTION, distance=260.0)
    view.renderer.GetActiveCamera().SetViewAngle(30.0)
    view.renderer.ResetCameraClippingRange()
    images = {}
    start = time.perf_counter()
    view.render()
    timings["first_frame_s"] = time.perf_counter() - start
    images["outline"] = str(view.screenshot(out_dir / "softcut_outline.png"))
    outline_model.GetDisplayNode().SetVisibility(False)

    previews = []
    for depth in PREVIEW_DEPTHS_MM:
        start = time.perf_counter()
        if not logic.PreviewDepth(cut, depth):
            raise RuntimeError(f"SoftCut preview failed: {logic.GetErrorMessage()}")
        update = time.perf_counter() - start
        start = time.perf_counter()
        view.render()
        frame = time.perf_counter() - start
        images[f"preview_{depth:g}mm"] = str(view.screenshot(out_dir / f"softcut_preview_{depth:g}mm.png"))
        previews.append({"depth_mm": depth, "update_s": round(update, 4), "frame_s": round(frame, 4)})
    if module.GetRemovedVolume(cut) != 0.0:
        raise RuntimeError("SoftCut: the preview cut the field")

    start = time.perf_counter()
    table = logic.MeasureResection(cut, DEPTH_MM)
    if table is None:
        raise RuntimeError(f"SoftCut measurement failed: {logic.GetErrorMessage()}")
    timings["measure_s"] = time.perf_counter() - start
    rows = _write_table(table, out_dir / "softcut_measurements.csv")
    stl_path = out_dir / "softcut_resection.stl"
    if not logic.ExportResectionToSTL(cut, DEPTH_MM, str(stl_path)):
        raise RuntimeError(f"SoftCut STL export failed: {logic.GetErrorMessage()}")
    estimate = logic.GetEstimate(cut)

    start = time.perf_counter()
    if not logic.CarveResection(cut, DEPTH_MM):
        raise RuntimeError(f"SoftCut carving failed: {logic.GetErrorMessage()}")
    timings["carve_s"] = time.perf_counter() - start
    field = module.GetCutField(cut)
    removed = module.GetRemovedVolume(cut)
    per_segment = nodes.by_segment_name(segmentation.GetSegmentation(), {
        segment_id: {"removed_volume_mm3": round(module.GetRemovedVolumeInSegment(cut, segment_id), 2)}
        for segment_id in segment_ids})
    undo_steps = field.GetNumberOfUndoSteps()
    undone = module.UndoStroke(cut) and module.GetRemovedVolume(cut) == 0.0
    redone = module.RedoStroke(cut) and abs(module.GetRemovedVolume(cut) - removed) < 1e-6 * max(removed, 1.0)

    start = time.perf_counter()
    view.render()
    timings["carved_frame_s"] = time.perf_counter() - start
    mapper = view.volume_cut_displayable_manager.GetVolumeActor(cut).GetMapper()
    rendering = {"path": mapper.GetLastRenderPathAsString(), "mapper_frame_time_s": round(mapper.GetLastFrameTime(), 4),
                 "renderer": view.renderer_description(), "cut_fields_in_view_while_previewing": 2}
    images["carved"] = str(view.screenshot(out_dir / "softcut_carved.png"))
    # Close: into the defect, the wall's rim and the floor.
    view.look_at(CHEEK_CENTER, direction=VIEW_DIRECTION, distance=95.0)
    view.renderer.ResetCameraClippingRange()
    view.render()
    images["carved_zoom"] = str(view.screenshot(out_dir / "softcut_carved_zoom.png"))
    view.close()
    normal = [0.0] * 3
    planner.GetAverageNormal(normal)
    images["resection_mesh"] = str(_mesh_image(estimate.GetSurface(), normal, out_dir / "softcut_resection_mesh.png", size))

    extent = [0] * 6
    planner.GetBoxExtent(extent)
    return {
        "planned": True,
        "anatomy": "real head CT (invesalius-examples), skin at -500 HU",
        "outline": {
            "node": outline.GetName(),
            "control_points": outline.GetNumberOfControlPoints(),
            "sittings": 2,
            "length_mm": round(planner.GetOutlineLength(), 2),
            "projected_area_mm2": round(planner.GetProjectedArea(), 2),
            "normal_mode": "average normal",
            "average_normal_ras": [round(v, 4) for v in normal],
        },
        "box_extent_ijk": extent,
        "filled_soft_tissue_voxels": planner.GetNumberOfFilledVoxels(),
        "depth_mm": DEPTH_MM,
        "previews": previews,
        "measurements": {name: [round(value, 3), unit] for name, (value, unit) in rows.items()},
        "estimate_triangles": estimate.GetSurface().GetNumberOfPolys(),
        "carve": {
            "removed_volume_mm3": round(removed, 2),
            "removed_volume_per_segment": per_segment,
            "undo_steps": undo_steps,
            "undo_then_redo_restores": bool(undone and redone),
            "note": "the cut field also removes the air just above the skin (2 voxels) to open it cleanly; "
                    "the resected tissue is the measured volume",
        },
        "exports": {"stl": str(stl_path), "measurements_csv": str(out_dir / "softcut_measurements.csv"),
                    "table_node": table.GetName()},
        "rendering": rendering,
        "images": images,
        "timings": {name: round(value, 4) for name, value in timings.items()},
    }
