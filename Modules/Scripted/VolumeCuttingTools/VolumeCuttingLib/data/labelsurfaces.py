"""How smooth segments drawn from binary labelmaps look: the 3D view against Slicer's closed surface.

An analytic ball and an analytic cylinder (its axis oblique to the slices)
are stored as binary labelmaps on a chest-CT grid (0.7 x 0.7 x 2.5 mm, so
the slices cut terraces into them) and shown in one 3D view twice, in the
same run and from the same camera: drawn by the product
(``vtkMRMLVolumeCutDisplayableManager``, the segment drawn by its own shape
with the cut node's ``LabelSmoothing``) and as Slicer's own closed-surface
representation of the same segment with its default conversion parameters
(``vtkMRMLSegmentationsDisplayableManager3D``). Each depth image is turned
into surface points, and the distance along each pixel's ray to the exact
shape gives the depth error: its root mean square over the pixels whose ray
meets the shape away from its silhouette.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import slicer
import vtk
from vtkmodules.util import numpy_support

from . import analyticscene
from ..scene import nodes
from ..scene.application import HeadlessSlicer

SPACING = (0.7, 0.7, 2.5)
DIMENSIONS = (72, 72, 22)  # x, y, z voxels: 50 x 50 x 52 mm


@dataclass
class Shape:
    """A ball (``axis`` None) or an infinite cylinder, in RAS mm."""

    name: str
    center: np.ndarray
    radius: float
    axis: np.ndarray | None = None

    def inside(self, points: np.ndarray) -> np.ndarray:
        offset = points - self.center
        if self.axis is not None:
            offset = offset - (offset @ self.axis)[..., None] * self.axis
        return np.einsum("...i,...i->...", offset, offset) <= self.radius**2

    def ray_hits(self, origins: np.ndarray, directions: np.ndarray):
        """Ray parameter of the first hit (NaN for none) and the cosine between ray and normal there."""
        offset = origins - self.center
        d = directions
        if self.axis is not None:
            offset = offset - np.outer(offset @ self.axis, self.axis)
            d = d - np.outer(d @ self.axis, self.axis)
        a = np.einsum("ij,ij->i", d, d)
        b = 2.0 * np.einsum("ij,ij->i", offset, d)
        c = np.einsum("ij,ij->i", offset, offset) - self.radius**2
        disc = b * b - 4.0 * a * c
        with np.errstate(invalid="ignore", divide="ignore"):
            t = (-b - np.sqrt(disc)) / (2.0 * a)
        t[disc < 0.0] = np.nan
        hit = origins + t[:, None] * directions
        normal = hit - self.center
        if self.axis is not None:
            normal = normal - np.outer(normal @ self.axis, self.axis)
        normal /= np.linalg.norm(normal, axis=1)[:, None]
        cosine = np.abs(np.einsum("ij,ij->i", normal, directions))
        return t, cosine


def shapes() -> list:
    size = np.array(DIMENSIONS) * np.array(SPACING)
    center = size / 2.0 + np.array([0.13, -0.21, 0.37])  # off the voxel centres
    axis = np.array([1.0, 0.3, 1.4])
    return [Shape("ball", center, 11.0), Shape("cylinder", center, 6.0, axis / np.linalg.norm(axis))]


def _binary_labelmap(shape: Shape) -> np.ndarray:
    """The labelmap (k, j, i) that holds the voxels whose centres lie inside the shape."""
    i, j, k = (np.arange(n) * s for n, s in zip(DIMENSIONS, SPACING))
    grid = np.stack(np.meshgrid(i, j, k, indexing="ij"), axis=-1)  # x, y, z
    return np.ascontiguousarray(shape.inside(grid).transpose(2, 1, 0)).astype(np.uint8)


def _depth(view) -> np.ndarray:
    width, height = view.render_window.GetSize()
    depth = vtk.vtkFloatArray()
    view.render_window.GetZbufferData(0, 0, width - 1, height - 1, depth)
    return numpy_support.vtk_to_numpy(depth).reshape(height, width).astype(float)


def _rms(shape: Shape, matrix, depth: np.ndarray) -> tuple[float, int]:
    height, width = depth.shape
    origins, directions = analyticscene.pixel_rays(matrix, width, height)
    t_exact, cosine = shape.ray_hits(origins, directions)
    points = analyticscene.depth_to_points(matrix, depth).reshape(-1, 3)
    # Away from the silhouette (rays that meet the surface at more than 30
    # degrees from grazing) and from the volume's faces, where the cylinder is cut off.
    hits = origins + np.nan_to_num(t_exact)[:, None] * directions
    box = np.array(DIMENSIONS) * np.array(SPACING)
    inside_box = np.all((hits > 2.0 * np.array(SPACING)) & (hits < box - 3.0 * np.array(SPACING)), axis=1)
    valid = np.isfinite(t_exact) & (cosine > 0.5) & np.isfinite(points[:, 0]) & inside_box
    t_rendered = np.einsum("ij,ij->i", points - origins, directions)
    errors = t_rendered[valid] - t_exact[valid]
    return float(np.sqrt(np.mean(errors**2))), int(valid.sum())


def measure(label_smoothing: float = 1.0, size: int = 256) -> dict:
    """Depth RMS (mm) of each shape drawn by the product and by Slicer's closed surface, same view."""
    results = {}
    for shape in shapes():
        application = HeadlessSlicer()
        ijk_to_ras = np.diag(list(SPACING) + [1.0])
        ct = np.zeros(DIMENSIONS[::-1], np.int16)
        volume = nodes.create_scalar_volume_node(application.scene, ct, ijk_to_ras, "CT")
        labels = nodes.create_scalar_volume_node(application.scene, _binary_labelmap(shape), ijk_to_ras, "Labels")
        segmentation = application.scene.AddNewNodeByClass("vtkMRMLSegmentationNode", shape.name)
        segmentation.CreateDefaultDisplayNodes()
        segmentation.SetReferenceImageGeometryParameterFromVolumeNode(volume)
        labelmap = application.scene.AddNewNodeByClass("vtkMRMLLabelMapVolumeNode")
        labelmap.SetAndObserveImageData(labels.GetImageData())
        labelmap.SetIJKToRASMatrix(nodes.numpy_to_vtk_matrix(ijk_to_ras))
        slicer.vtkSlicerSegmentationsModuleLogic.ImportLabelmapToSegmentationNode(labelmap, segmentation)
        segment_id = segmentation.GetSegmentation().GetNthSegmentID(0)
        cut_node = application.volume_cutting_logic.AddVolumeCutNode(volume, segmentation)
        cut_node.SetLabelSmoothing(label_smoothing)
        cut_node.SetAmbientOcclusion(False)
        display = segmentation.GetDisplayNode()
        display.SetVisibility3D(True)
        display.SetSegmentVisibility3D(segment_id, True)
        view = application.create_3d_view(size, size)
        camera = view.renderer.GetActiveCamera()
        camera.ParallelProjectionOn()
        camera.SetParallelScale(1.25 * shape.radius if shape.axis is None else 14.0)
        view.look_at(shape.center, direction=(0.45, -0.55, 0.7), distance=120.0, view_up=(0.0, 0.0, 1.0))
        camera.SetClippingRange(60.0, 180.0)
        matrix = analyticscene.world_to_ndc(camera, size, size)
        # The product's drawing (the closed surface hidden), then Slicer's closed surface alone.
        segmentation.RemoveClosedSurfaceRepresentation()
        display.SetVisibility3D(False)
        view.render()
        ours = _rms(shape, matrix, _depth(view))
        display.SetVisibility3D(True)
        segmentation.CreateClosedSurfaceRepresentation()
        view.volume_cut_displayable_manager.GetVolumeActor(cut_node).SetVisibility(False)
        view.render()
        slicers = _rms(shape, matrix, _depth(view))
        results[shape.name] = {
            "volume_cut_rms_mm": round(ours[0], 4),
            "slicer_closed_surface_rms_mm": round(slicers[0], 4),
            "pixels": ours[1],
            "label_smoothing_voxels": label_smoothing,
        }
        view.close()
    return results
