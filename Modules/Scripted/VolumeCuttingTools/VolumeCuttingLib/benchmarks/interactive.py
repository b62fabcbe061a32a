"""Benchmark area ``interactive``: the CPU path's progressive refinement in a 3D view.

The product's 3D view (vtkMRMLVolumeCutDisplayableManager, the mapper on its
CPU path) at 1024 x 768 on the real head CT (drilled mastoid, cortical and
trabecular bone, ambient occlusion, thin-bone shading) and on the
patient-scale 512 x 512 x 133 CT (``patientscale``). The camera orbits 1
degree a frame:

* baseline: every frame at full resolution (the window's still rate), as
  before progressive refinement;
* interacting: the window's DesiredUpdateRate at 20 frames per second, as an
  interactor style sets it while the camera moves (50 ms a frame);
* refinement: the rate back at the still rate, the first frame after the
  last motion, which is the full image. Its baseline is a full frame of the
  same view drawn again from scratch right after it: the orbit has turned
  the camera 20 to 60 degrees further round by then, and a full frame's
  cost depends on the view (the baseline orbit covers its first degrees
  only).

On the head CT a burr stroke is also drawn with the camera still (the rate
at 20 frames per second while the stroke lasts, as the view's owner sets
it), a frame after each pose. Times are wall-clock seconds of
``vtkRenderWindow::Render`` with the frame read back, first call, median and
maximum.
"""

from __future__ import annotations

import statistics
import time

import vtk

from ..cutting import drilling
from ..data import headct, patientscale
from ..jobs import mainjob
from ..scene.application import HeadlessSlicer, opengl_renderer_name
from .harness import machine_description, measurement

SIZE = (1024, 768)
INTERACTIVE_RATE = 20.0  # frames per second while interacting: 50 ms a frame
STILL_RATE = 0.0001  # vtkRenderWindowInteractor's StillUpdateRate
ORBIT_FRAMES = 20
STROKE_BASELINE_POSES = 8


def _frame(view):
    start = time.perf_counter()
    view.render()
    # Reading a pixel waits for the frame to be drawn.
    view.render_window.GetRGBACharPixelData(0, 0, 0, 0, 1, vtk.vtkUnsignedCharArray())
    return time.perf_counter() - start


def _summary(times_s):
    return {"first_s": times_s[0], "median_s": statistics.median(times_s), "max_s": max(times_s), "frames": len(times_s)}


def _orbit(view, mapper, rate, frames):
    view.render_window.SetDesiredUpdateRate(rate)
    camera = view.renderer.GetActiveCamera()
    times, distances, in_mapper = [], [], []
    for _ in range(frames):
        camera.Azimuth(1.0)
        view.renderer.ResetCameraClippingRange()
        times.append(_frame(view))
        distances.append(mapper.GetLastImageSampleDistance())
        in_mapper.append(mapper.GetLastFrameTime())
    return times, distances, in_mapper


def _head_ct_view():
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    volume = headct.load_volume_node(application.scene, name="HeadCT")
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.5)
    cut_node = logic.AddVolumeCutNode(volume, bone)
    bone_segments = [logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()]
    cut_node.SetCuttableSegmentIDs(bone_segments)
    cut_node.SetMaterialSegmentIDs(bone_segments)
    bone.GetDisplayNode().SetVisibility3D(False)
    cut_node.SetSurfaceIsoValue(300.0)
    cut_node.SetThinBoneShading(True)
    cut_node.SetThinBoneThickness(1.0)
    plan = drilling.MastoidectomyPlan(entry=drilling.lateral_entry(volume, *headct.RIGHT_MASTOID_YZ))
    drilling.drill(logic, cut_node, plan)
    view = application.create_3d_view(*SIZE)
    mainjob.cavity_camera(view, plan)
    dims = volume.GetImageData().GetDimensions()
    return application, cut_node, view, plan, f"real head CT {dims[0]}x{dims[1]}x{dims[2]}, drilled mastoid, cavity view"


def _patient_scale_view():
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    case = patientscale.generate()
    volume, segmentation = patientscale.create_nodes(application.scene, case)
    cut_node = logic.AddVolumeCutNode(volume, segmentation)
    names = {segmentation.GetSegmentation().GetSegment(s).GetName(): s for s in segmentation.GetSegmentation().GetSegmentIDs()}
    cut_node.SetCuttableSegmentIDs([names[n] for n in patientscale.CUTTABLE if n in names])
    cut_node.SetProtectedSegmentIDs([names[n] for n in patientscale.PROTECTED if n in names])
    segmentation.GetDisplayNode().SetVisibility3D(False)
    view = application.create_3d_view(*SIZE)
    bounds = [0.0] * 6
    volume.GetRASBounds(bounds)
    center = [(bounds[2 * a] + bounds[2 * a + 1]) / 2.0 for a in range(3)]
    extent = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4])
    view.look_at(center, direction=(0.6, -0.8, 0.0), distance=2.0 * extent)
    dims = volume.GetImageData().GetDimensions()
    return application, cut_node, view, None, f"patient-scale CT {dims[0]}x{dims[1]}x{dims[2]} (0.7 x 0.7 x 2.5 mm), 5 segments"


def _case(make_view, repeats):
    application, cut_node, view, plan, description = make_view()
    logic = application.volume_cutting_logic
    mapper = view.volume_cut_displayable_manager.GetVolumeActor(cut_node).GetMapper()
    window = view.render_window
    window.SetDesiredUpdateRate(STILL_RATE)
    first_frame = _frame(view)
    machine = machine_description(opengl_renderer_name(window))
    full_times, _, _ = _orbit(view, mapper, STILL_RATE, max(repeats, 3))
    full = _summary([first_frame] + full_times)
    full_median = statistics.median(full_times)
    interactive_times, refine_times, same_view_times, distances, mapper_times = [], [], [], [], []
    for _ in range(max(repeats, 2)):
        times, used, in_mapper = _orbit(view, mapper, INTERACTIVE_RATE, ORBIT_FRAMES)
        interactive_times += times
        distances += used
        mapper_times += in_mapper
        window.SetDesiredUpdateRate(STILL_RATE)
        refine_times.append(_frame(view))
        if mapper.GetLastImageSampleDistance() != 1:
            raise RuntimeError("the frame after the motion stopped is not the full image")
        # The same view at full resolution in a still scene, every ray cast
        # again (otherwise nothing changed and no ray would be).
        mapper.GetRayCaster().InvalidateImage()
        same_view_times.append(_frame(view))
    setting = f"{description}; {SIZE[0]}x{SIZE[1]}, CPU path ({mapper.GetLastRenderPathAsString()}), camera orbiting 1 degree a frame"
    baseline = f"full-resolution frame while the camera moves (no refinement), same view, same run"
    details = {
        "setting": setting,
        "full_frames": full,
        "interactive_frames": _summary(interactive_times),
        # The rest of a frame is the view's own work (clearing, other
        # displayable managers, llvmpipe's compositing at 1024 x 768).
        "interactive_frames_in_the_mapper": _summary(mapper_times),
        "image_sample_distances": {str(d): distances.count(d) for d in sorted(set(distances))},
        "refinement_frames": _summary(refine_times),
        "full_frames_of_the_refined_view": _summary(same_view_times),
    }
    label = description.split(",")[0]
    results = [
        measurement(f"{label}: frame while the camera moves (rate 20/s), median", statistics.median(interactive_times), "s",
                    baseline, full_median, len(interactive_times), machine) | {"details": details},
        measurement(f"{label}: frame while the camera moves (rate 20/s), max (first call {interactive_times[0]:.3f} s)",
                    max(interactive_times), "s", baseline + ", max", max(full_times), len(interactive_times), machine),
        measurement(f"{label}: full-resolution image after the last motion, max (first call {refine_times[0]:.3f} s)",
                    max(refine_times), "s", "full-resolution frame of the same view drawn again from scratch, same run, max",
                    max(same_view_times), len(refine_times), machine),
    ]
    if plan is not None:
        # One burr pass across the cavity's floor, a frame after each pose.
        poses = max(plan.strokes(), key=len)
        window.SetDesiredUpdateRate(INTERACTIVE_RATE)
        logic.BeginStroke(cut_node)
        stroke_times = []
        for p0, p1 in zip(poses[:-1], poses[1:]):
            logic.CutSphereSweep(cut_node, p0 + 0.5 * plan.direction, p1 + 0.5 * plan.direction, plan.burr_radius)
            stroke_times.append(_frame(view))
        logic.EndStroke(cut_node)
        window.SetDesiredUpdateRate(STILL_RATE)
        after_stroke = _frame(view)
        # The same without refinement: a full-resolution frame after each of
        # the first poses (each takes seconds here).
        logic.BeginStroke(cut_node)
        full_stroke_times = []
        for p0, p1 in list(zip(poses[:-1], poses[1:]))[:STROKE_BASELINE_POSES]:
            logic.CutSphereSweep(cut_node, p0 + 1.0 * plan.direction, p1 + 1.0 * plan.direction, plan.burr_radius)
            full_stroke_times.append(_frame(view))
        logic.EndStroke(cut_node)
        results += [
            measurement(f"{label}: frame while a stroke is drawn (rate 20/s, camera still), median", statistics.median(stroke_times), "s",
                        "full-resolution frame after each pose of the next stroke (localized update), same run",
                        statistics.median(full_stroke_times), len(stroke_times), machine)
            | {"details": {"interactive": _summary(stroke_times), "full_resolution": _summary(full_stroke_times),
                           "full_image_after_the_stroke_s": after_stroke}},
        ]
    return results


def interactive(repeats: int) -> list[dict]:
    results = []
    for make_view in (_head_ct_view, _patient_scale_view):
        results += _case(make_view, repeats)
    return results
