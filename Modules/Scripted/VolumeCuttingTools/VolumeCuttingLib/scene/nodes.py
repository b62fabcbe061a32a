"""Small helpers that move numpy volumes in and out of MRML nodes.

Only VTK and the MRML classes of the Qt-free ``slicer`` package are used, so
these helpers work both inside the Slicer application and in plain Python with
Kitware's ``slicer-core`` wheels (where most of ``slicer.util`` is unavailable).

Conventions: numpy volumes are indexed ``[k, j, i]`` (slowest to fastest), which
is the memory order of ``vtkImageData``; geometry is a 4x4 IJK-to-RAS matrix.
As in Slicer, the geometry lives in the node (``SetIJKToRASMatrix``) and the
image data itself keeps the default origin (0, 0, 0) and spacing (1, 1, 1).
"""

import numpy as np


def numpy_to_vtk_matrix(matrix):
    """Return a ``vtkMatrix4x4`` holding the 4x4 numpy ``matrix``."""
    from vtkmodules.vtkCommonMath import vtkMatrix4x4

    matrix = np.asarray(matrix, dtype=float)
    if matrix.shape != (4, 4):
        raise ValueError(f"expected a 4x4 matrix, got shape {matrix.shape}")
    vtk_matrix = vtkMatrix4x4()
    for row in range(4):
        for column in range(4):
            vtk_matrix.SetElement(row, column, matrix[row, column])
    return vtk_matrix


def vtk_matrix_to_numpy(vtk_matrix):
    """Return the elements of a ``vtkMatrix4x4`` as a 4x4 numpy array."""
    return np.array([[vtk_matrix.GetElement(row, column) for column in range(4)] for row in range(4)])


def image_data_from_array(array_kji):
    """Return a ``vtkImageData`` with a deep copy of a 3D numpy array as its scalars.

    The array is indexed ``[k, j, i]``; the image gets dimensions ``(i, j, k)``,
    default origin and spacing, and the VTK scalar type matching the dtype.
    """
    from vtkmodules.util import numpy_support
    from vtkmodules.vtkCommonDataModel import vtkImageData

    array_kji = np.asarray(array_kji)
    if array_kji.ndim != 3:
        raise ValueError(f"expected a 3D array indexed [k, j, i], got shape {array_kji.shape}")
    image = vtkImageData()
    image.SetDimensions(array_kji.shape[2], array_kji.shape[1], array_kji.shape[0])
    scalars = numpy_support.numpy_to_vtk(np.ascontiguousarray(array_kji).ravel(), deep=True)
    scalars.SetName("ImageScalars")
    image.GetPointData().SetScalars(scalars)
    return image


def array_from_image_data(image):
    """Return a copy of the scalars of a ``vtkImageData`` as a numpy array indexed ``[k, j, i]``."""
    from vtkmodules.util import numpy_support

    dimensions = image.GetDimensions()
    scalars = image.GetPointData().GetScalars()
    if scalars is None:
        raise ValueError("image has no scalars")
    return numpy_support.vtk_to_numpy(scalars).reshape(dimensions[2], dimensions[1], dimensions[0]).copy()


def create_scalar_volume_node(scene, array_kji, ijk_to_ras, name):
    """Add a ``vtkMRMLScalarVolumeNode`` to ``scene`` showing ``array_kji`` at the given geometry.

    The IJK-to-RAS matrix (spacing, origin and possibly oblique directions) is
    set on the node exactly; the voxel values are deep-copied with their dtype
    preserved. A default display node is created so the volume can be shown
    when the scene is used in the Slicer application.
    """
    volume_node = scene.AddNewNodeByClass("vtkMRMLScalarVolumeNode", name)
    volume_node.SetAndObserveImageData(image_data_from_array(array_kji))
    volume_node.SetIJKToRASMatrix(numpy_to_vtk_matrix(ijk_to_ras))
    volume_node.CreateDefaultDisplayNodes()
    return volume_node


def volume_node_ijk_to_ras(volume_node):
    """Return the IJK-to-RAS matrix of a volume node as a 4x4 numpy array."""
    from vtkmodules.vtkCommonMath import vtkMatrix4x4

    vtk_matrix = vtkMatrix4x4()
    volume_node.GetIJKToRASMatrix(vtk_matrix)
    return vtk_matrix_to_numpy(vtk_matrix)


def array_from_volume_node(volume_node):
    """Return a copy of the voxels of a volume node as a numpy array indexed ``[k, j, i]``."""
    image = volume_node.GetImageData()
    if image is None:
        raise ValueError(f"volume node {volume_node.GetName()!r} has no image data")
    return array_from_image_data(image)


def create_segmentation_from_labels(scene, volume_node, labels_kji, names, name):
    """Add a ``vtkMRMLSegmentationNode`` on ``volume_node``'s grid with one segment per label.

    ``names`` maps label values of ``labels_kji`` (indexed ``[k, j, i]`` like the
    volume) to segment names, which are also the segment IDs; each segment
    gets its own binary labelmap of the voxels with that value.
    """
    import slicer

    segmentation_node = scene.AddNewNodeByClass("vtkMRMLSegmentationNode", name)
    segmentation_node.SetReferenceImageGeometryParameterFromVolumeNode(volume_node)
    image_to_world = numpy_to_vtk_matrix(volume_node_ijk_to_ras(volume_node))
    labels_kji = np.asarray(labels_kji)
    for value, segment_name in names.items():
        mask = slicer.vtkOrientedImageData()
        mask.ShallowCopy(image_data_from_array((labels_kji == value).astype(np.uint8)))
        mask.SetImageToWorldMatrix(image_to_world)
        segment = slicer.vtkSegment()
        segment.SetName(segment_name)
        segment.AddRepresentation("Binary labelmap", mask)
        segmentation_node.GetSegmentation().AddSegment(segment, segment_name)
    return segmentation_node


def segment_display_names(segmentation, segment_ids):
    """Each segment ID's name as a person reads it, unique among ``segment_ids``.

    Reports key their figures by these names. Slicer lets two segments share a
    name (two labelmaps imported with a default name, say), so a shared name
    gets its ID in brackets rather than one segment's figures overwriting the
    other's; a segment without a name shows its ID.
    """
    names = {}
    for segment_id in segment_ids:
        segment = segmentation.GetSegment(segment_id)
        if segment is None:
            raise ValueError(f"segment {segment_id!r} is not in the segmentation")
        names[segment_id] = segment.GetName() or segment_id
    shared = {name for name in names.values() if list(names.values()).count(name) > 1}
    return {segment_id: f"{name} ({segment_id})" if name in shared else name for segment_id, name in names.items()}


def by_segment_name(segmentation, figures_by_id):
    """``{name: {"segment_id": ID, **figures}}`` from ``{ID: {figure: value}}``, in the given order."""
    names = segment_display_names(segmentation, list(figures_by_id))
    return {names[segment_id]: {"segment_id": segment_id, **figures} for segment_id, figures in figures_by_id.items()}
