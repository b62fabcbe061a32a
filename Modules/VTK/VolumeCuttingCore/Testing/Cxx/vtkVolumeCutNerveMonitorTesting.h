// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Ground truth shared by the nerve monitor's tests: the exact distance to a
// structure's voxel cubes, the part of the shield that smoothing never removes.
#ifndef vtkVolumeCutNerveMonitorTesting_h
#define vtkVolumeCutNerveMonitorTesting_h

#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace vtkVolumeCutNerveMonitorTesting
{
/// A label image of dimensions voxels with value where inside(ras) holds at the voxel's centre.
inline vtkSmartPointer<vtkImageData> Rasterise(const int dimensions[3], vtkMatrix4x4* ijkToRAS, const std::function<bool(const double*)>& inside, int value)
{
  auto labels = vtkSmartPointer<vtkImageData>::New();
  labels->SetDimensions(dimensions[0], dimensions[1], dimensions[2]);
  labels->AllocateScalars(VTK_UNSIGNED_SHORT, 1);
  unsigned short* voxel = static_cast<unsigned short*>(labels->GetScalarPointer());
  for (int k = 0; k < dimensions[2]; ++k)
  {
    for (int j = 0; j < dimensions[1]; ++j)
    {
      for (int i = 0; i < dimensions[0]; ++i, ++voxel)
      {
        const double ijk[4] = { double(i), double(j), double(k), 1.0 };
        double ras[4];
        ijkToRAS->MultiplyPoint(ijk, ras);
        *voxel = inside(ras) ? static_cast<unsigned short>(value) : 0;
      }
    }
  }
  return labels;
}

/// i, j, k of the voxels of labels (unsigned short) holding value.
inline std::vector<int> VoxelsOf(vtkImageData* labels, int value)
{
  int dims[3];
  labels->GetDimensions(dims);
  const unsigned short* voxel = static_cast<const unsigned short*>(labels->GetScalarPointer());
  std::vector<int> voxels;
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i, ++voxel)
      {
        if (*voxel == value)
        {
          voxels.insert(voxels.end(), { i, j, k });
        }
      }
    }
  }
  return voxels;
}

/// Exact distance (mm) from a RAS point outside them to the union of the
/// voxels' cubes on the grid of ijkToRAS (axes at right angles, any direction).
inline double VoxelCubeDistance(vtkMatrix4x4* ijkToRAS, const std::vector<int>& voxels, const double ras[3])
{
  double spacing[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    spacing[axis] = std::sqrt(ijkToRAS->GetElement(0, axis) * ijkToRAS->GetElement(0, axis) +
      ijkToRAS->GetElement(1, axis) * ijkToRAS->GetElement(1, axis) + ijkToRAS->GetElement(2, axis) * ijkToRAS->GetElement(2, axis));
  }
  vtkNew<vtkMatrix4x4> rasToIJK;
  vtkMatrix4x4::Invert(ijkToRAS, rasToIJK);
  const double in[4] = { ras[0], ras[1], ras[2], 1.0 };
  double ijk[4];
  rasToIJK->MultiplyPoint(in, ijk);
  double best = 1e300;
  for (size_t n = 0; n < voxels.size(); n += 3)
  {
    double squared = 0.0;
    for (int axis = 0; axis < 3; ++axis)
    {
      const double gap = std::max(std::abs(ijk[axis] - voxels[n + axis]) - 0.5, 0.0) * spacing[axis];
      squared += gap * gap;
    }
    best = std::min(best, squared);
  }
  return std::sqrt(best);
}
}

#endif
