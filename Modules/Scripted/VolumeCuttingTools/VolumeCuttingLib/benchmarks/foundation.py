"""Benchmark area ``foundation``: scene building, closed surfaces and a first frame on the real head CT.

Slicer's path (volume node, region-growing bone segmentation, volume-cut node,
closed surfaces, a 3D view through the displayable managers) against plain VTK
doing the same work on the same voxels.
"""

from __future__ import annotations

import vtk
from vtkmodules.util import numpy_support

from ..data import headct
from ..scene.application import HeadlessSlicer
from .harness import machine_description, measurement, timed


def _scene_from_ct(path):
    application = HeadlessSlicer()
    logic = application.volume_cutting_logic
    volume = headct.load_volume_node(application.scene, name="HeadCT", path=path)
    bone = logic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
    cut = logic.AddVolumeCutNode(volume, bone)
    cut.SetCuttableSegmentIDs([logic.GetCorticalBoneSegmentID(), logic.GetTrabecularBoneSegmentID()])
    return application, volume, bone


def _plain_vtk_from_ct(path):
    """The same data with VTK alone: voxels into an image, two threshold label masks."""
    voxels, spacing, _ = headct.load_array(path=path)
    image = vtk.vtkImageData()
    image.SetDimensions(voxels.shape[2], voxels.shape[1], voxels.shape[0])
    image.SetSpacing(*spacing)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(voxels.ravel(), deep=True, array_type=vtk.VTK_SHORT))
    masks = []
    for lower, upper in ((700.0, 1e9), (200.0, 700.0)):
        threshold = vtk.vtkImageThreshold()
        threshold.SetInputData(image)
        threshold.ThresholdBetween(lower, upper)
        threshold.SetInValue(1)
        threshold.SetOutValue(0)
        threshold.SetOutputScalarTypeToUnsignedChar()
        threshold.Update()
        masks.append(threshold.GetOutput())
    return image, masks


def _offscreen_window(size):
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(True)
    window.SetSize(*size)
    return window


def foundation(repeats: int) -> list[dict]:
    path = headct.fetch()
    results = []

    scene_time, (application, volume, bone) = timed(lambda: _scene_from_ct(path), repeats)
    plain_time, (plain_image, plain_masks) = timed(lambda: _plain_vtk_from_ct(path), repeats)

    # Closed surfaces: Slicer's conversion (with its smoothing and decimation
    # defaults) against VTK's discrete flying edges on the same labels, unsmoothed.
    def slicer_surfaces():
        bone.RemoveClosedSurfaceRepresentation()
        bone.CreateClosedSurfaceRepresentation()

    def vtk_surfaces():
        polydata = []
        for mask in plain_masks:
            edges = vtk.vtkDiscreteFlyingEdges3D()
            edges.SetInputData(mask)
            edges.SetValue(0, 1)
            edges.Update()
            polydata.append(edges.GetOutput())
        return polydata

    surface_time, _ = timed(slicer_surfaces, repeats)
    flying_edges_time, surfaces = timed(vtk_surfaces, repeats)

    # First offscreen frame: a new 3D view of Slicer's displayable managers
    # against a bare VTK renderer showing the same surfaces.
    size = (800, 600)
    renderer_name = []

    def slicer_first_frame():
        view = application.create_3d_view(*size, name="BenchmarkView")
        view.fit()
        view.render()
        renderer_name.append(view.renderer_description())
        view.close()
        application.scene.RemoveNode(view.view_node)

    def vtk_first_frame():
        window = _offscreen_window(size)
        renderer = vtk.vtkRenderer()
        window.AddRenderer(renderer)
        for polydata in surfaces:
            mapper = vtk.vtkPolyDataMapper()
            mapper.SetInputData(polydata)
            actor = vtk.vtkActor()
            actor.SetMapper(mapper)
            renderer.AddActor(actor)
        renderer.ResetCamera()
        window.Render()
        window.Finalize()

    frame_time, _ = timed(slicer_first_frame, repeats)
    vtk_frame_time, _ = timed(vtk_first_frame, repeats)

    machine = machine_description(renderer_name[-1] if renderer_name else None)
    dims = volume.GetImageData().GetDimensions()
    data = f"real head CT {dims[0]}x{dims[1]}x{dims[2]}"
    results.append(measurement(
        f"MRML scene from the {data}: volume node, bone segmentation (region growing), volume-cut node",
        scene_time, "s", "plain VTK: the same voxels into vtkImageData and two vtkImageThreshold masks",
        plain_time, repeats, machine))
    results.append(measurement(
        f"closed-surface representation of the bone segmentation ({data}, Slicer defaults)",
        surface_time, "s", "vtkDiscreteFlyingEdges3D on the same two masks, no smoothing",
        flying_edges_time, repeats, machine))
    results.append(measurement(
        f"first offscreen frame of a new 3D view through Slicer's displayable managers, {size[0]}x{size[1]}",
        frame_time, "s", "first frame of a bare VTK render window with the same surfaces",
        vtk_frame_time, repeats, machine))
    return results
