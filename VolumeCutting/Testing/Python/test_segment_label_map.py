"""The label map the nerve monitor, bone-ahead and display read: exact for shared layers, cropped layers and other grids.

Segments of a labelmap loaded with its scan share one layer on the scan's grid,
each with its own label value, and Slicer crops layers to their voxels. The
logic reads such a layer in place (no mask of the whole grid extracted per
segment, which made every role change on a 24-million-voxel scan wait seconds);
a segment on another grid is resampled onto the scan's. Later segments of the
list are drawn over earlier ones.
"""

import numpy as np
import slicer
import vtk
from vtk.util import numpy_support

from VolumeCuttingLib.scene import nodes
from VolumeCuttingLib.scene.application import HeadlessSlicer

SHAPE = (12, 16, 20)  # k, j, i
SPACING = (0.5, 0.6, 0.7)


def oriented_image(array_kji, ijk_to_ras, first_index=(0, 0, 0)):
    """A vtkOrientedImageData of array_kji whose voxel [0, 0, 0] is IJK first_index of ijk_to_ras."""
    image = slicer.vtkOrientedImageData()
    image.ShallowCopy(nodes.image_data_from_array(np.ascontiguousarray(array_kji)))
    i0, j0, k0 = first_index
    image.SetExtent(i0, i0 + array_kji.shape[2] - 1, j0, j0 + array_kji.shape[1] - 1, k0, k0 + array_kji.shape[0] - 1)
    image.SetImageToWorldMatrix(nodes.numpy_to_vtk_matrix(ijk_to_ras))
    return image


def label_map(cut, segment_ids):
    labels = vtk.vtkImageData()
    missing = slicer.vtkSlicerVolumeCuttingLogic.CreateSegmentLabelMap(cut, segment_ids, labels)
    dims = labels.GetDimensions()
    array = numpy_support.vtk_to_numpy(labels.GetPointData().GetScalars()).reshape(dims[2], dims[1], dims[0])
    return array, list(missing)


def test_shared_cropped_layers_and_other_grids_give_the_exact_labels():
    application = HeadlessSlicer()
    scene = application.scene
    logic = application.volume_cutting_logic
    ijk_to_ras = np.array([[0.0, -SPACING[1], 0.0, 4.0],
                           [SPACING[0], 0.0, 0.0, -3.0],
                           [0.0, 0.0, SPACING[2], 7.5],
                           [0.0, 0.0, 0.0, 1.0]])  # rotated, anisotropic, off the origin
    ct = np.full(SHAPE, 300, np.int16)
    volume = nodes.create_scalar_volume_node(scene, ct, ijk_to_ras, "CT")
    segmentation_node = scene.AddNewNodeByClass("vtkMRMLSegmentationNode", "Anatomy")
    segmentation_node.SetReferenceImageGeometryParameterFromVolumeNode(volume)

    # One shared layer cropped to k 2..9, j 3..14, i 1..18, holding labels 2, 5 and 9.
    rng = np.random.default_rng(7)
    full = np.zeros(SHAPE, np.uint8)
    full[2:10, 3:15, 1:19] = rng.choice([0, 2, 5, 9], size=(8, 12, 18))
    layer = oriented_image(full[2:10, 3:15, 1:19].copy(), ijk_to_ras, (1, 3, 2))
    segmentation = segmentation_node.GetSegmentation()
    for name, value in (("Nerve", 2), ("Sinus", 5), ("Canal", 9)):
        segment = slicer.vtkSegment()
        segment.SetName(name)
        segment.AddRepresentation("Binary labelmap", layer)
        segment.SetLabelValue(value)
        segmentation.AddSegment(segment, name)
    assert segmentation.GetNumberOfLayers() == 1

    # A segment on a grid one voxel along i away: the anatomy's voxel i is its voxel i - 1.
    shifted = ijk_to_ras.copy()
    shifted[:3, 3] += ijk_to_ras[:3, 0]
    own = np.zeros(SHAPE, np.uint8)
    own[4:8, 5:9, 3:12] = 1
    segment = slicer.vtkSegment()
    segment.SetName("Shifted")
    segment.AddRepresentation("Binary labelmap", oriented_image(own, shifted))
    segmentation.AddSegment(segment, "Shifted")

    cut = logic.AddVolumeCutNode(volume, segmentation_node)
    labels, missing = label_map(cut, ["Canal", "Nerve", "Shifted", "Sinus", "NoSuchSegment"])
    assert missing == ["NoSuchSegment"]
    expected = np.zeros(SHAPE, np.uint16)
    expected[full == 9] = 1
    expected[full == 2] = 2
    expected[:, :, 1:][own[:, :, :-1] == 1] = 3  # drawn over the labels before it
    expected[full == 5] = 4
    assert labels.dtype == np.uint16 and labels.shape == SHAPE
    np.testing.assert_array_equal(labels, expected)
