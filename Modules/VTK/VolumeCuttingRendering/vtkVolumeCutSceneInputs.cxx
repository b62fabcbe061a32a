// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutSceneInputs.h"

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutParallelFor.h"
#include "vtkVolumeCutRayMath.h"

#include <vtkColorTransferFunction.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>

#include <algorithm>
#include <cmath>

using vtkVolumeCutRayMath::TransformPoint;
using vtkVolumeCutRayMath::TransformVector;

namespace
{
template <typename T>
void CopyFirstComponent(const T* in, int stride, vtkIdType count, float* out)
{
  for (vtkIdType n = 0; n < count; ++n)
  {
    out[n] = static_cast<float>(in[n * stride]);
  }
}
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutSceneInputs::CopyAnatomy(
  vtkImageData* anatomy, vtkDataArray* scalars, vtkMatrix4x4* matrix, vtkVolumeCutRayScene& scene)
{
  int dims[3];
  anatomy->GetDimensions(dims);
  vtkNew<vtkMatrix4x4> ijkToWorld;
  if (matrix)
  {
    ijkToWorld->DeepCopy(matrix);
  }
  else
  {
    ijkToWorld->DeepCopy(anatomy->GetIndexToPhysicalMatrix());
  }
  if (!(std::abs(ijkToWorld->Determinant()) > 1e-12))
  {
    return "Render: the anatomy's IJK-to-world matrix is not invertible";
  }
  vtkNew<vtkMatrix4x4> worldToIJK;
  vtkMatrix4x4::Invert(ijkToWorld, worldToIJK);
  std::copy(&ijkToWorld->Element[0][0], &ijkToWorld->Element[0][0] + 16, scene.IJKToWorld);
  std::copy(&worldToIJK->Element[0][0], &worldToIJK->Element[0][0] + 16, scene.WorldToIJK);
  // Normals: the transpose of world-to-IJK's linear part maps IJK gradients to world.
  std::fill(scene.NormalMatrix, scene.NormalMatrix + 16, 0.0);
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      scene.NormalMatrix[4 * row + column] = worldToIJK->GetElement(column, row);
    }
  }
  scene.NormalMatrix[15] = 1.0;
  for (int axis = 0; axis < 3; ++axis)
  {
    const double* row = scene.WorldToIJK + 4 * axis;
    scene.MillimetresPerIndex[axis] = 1.0 / std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]);
  }
  const vtkIdType count = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  scene.Values.resize(count);
  const int stride = scalars->GetNumberOfComponents();
  switch (scalars->GetDataType())
  {
    vtkTemplateMacro(CopyFirstComponent(static_cast<const VTK_TT*>(scalars->GetVoidPointer(0)), stride, count, scene.Values.data()));
    default:
      return "Render: unsupported anatomy scalar type";
  }
  std::copy(dims, dims + 3, scene.Dimensions);
  return nullptr;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneInputs::CopyLabels(vtkDataArray* labels, std::vector<uint16_t>& copy)
{
  const vtkIdType count = labels->GetNumberOfTuples();
  copy.resize(count);
  bool outOfRange = false;
  for (vtkIdType n = 0; n < count; ++n)
  {
    const double label = labels->GetComponent(n, 0);
    outOfRange |= !(label >= 0.0 && label <= 65535.0);
    copy[n] = static_cast<uint16_t>(std::min(65535.0, std::max(0.0, std::isfinite(label) ? label : 0.0)));
  }
  return outOfRange;
}

//------------------------------------------------------------------------------
void vtkVolumeCutSceneInputs::CopyFraction(vtkDataArray* values, double valueAtZero, double valueAtOne, std::vector<float>& fractions)
{
  fractions.resize(values->GetNumberOfTuples());
  const double v0 = valueAtZero;
  const double scale = 1.0 / (valueAtOne - valueAtZero);
  for (vtkIdType n = 0; n < values->GetNumberOfTuples(); ++n)
  {
    const double f = (values->GetComponent(n, 0) - v0) * scale;
    fractions[n] = std::isfinite(f) ? static_cast<float>(std::min(1.0, std::max(0.0, f))) : 0.f;
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutSceneInputs::MarkNonZeroBlocks(const vtkVolumeCutRayScene& scene, vtkVolumeCutRayScene::FractionVolume& fraction, int maximumThreads)
{
  constexpr int size = vtkVolumeCutRayScene::FractionBlockSize;
  const int* dims = scene.Dimensions;
  int blocks[3];
  scene.GetFractionBlockDimensions(blocks);
  fraction.NonZeroBlocks.assign(static_cast<size_t>(blocks[0]) * blocks[1] * blocks[2], 0);
  if (fraction.Values.size() != static_cast<size_t>(dims[0]) * dims[1] * dims[2])
  {
    fraction.NonZeroBlocks.clear(); // not on the grid: every block is read
    return;
  }
  const vtkIdType sy = dims[0];
  const vtkIdType sz = static_cast<vtkIdType>(dims[0]) * dims[1];
  // Each voxel marks the blocks of the cells it is a corner of: its own
  // block, and the one before along an axis where it starts a block.
  vtkVolumeCutParallelFor(maximumThreads, blocks[2], [&](vtkIdType beginZ, vtkIdType endZ) {
    for (vtkIdType bz = beginZ; bz < endZ; ++bz)
    {
      // The voxels of this layer's cells, far corners included.
      const int k0 = static_cast<int>(bz) * size;
      const int k1 = std::min(k0 + size, dims[2] - 1);
      for (int by = 0; by < blocks[1]; ++by)
      {
        const int j0 = by * size;
        const int j1 = std::min(j0 + size, dims[1] - 1);
        for (int bx = 0; bx < blocks[0]; ++bx)
        {
          const int i0 = bx * size;
          const int i1 = std::min(i0 + size, dims[0] - 1);
          bool nonZero = false;
          for (int k = k0; k <= k1 && !nonZero; ++k)
          {
            for (int j = j0; j <= j1 && !nonZero; ++j)
            {
              const float* row = fraction.Values.data() + j * sy + k * sz;
              for (int i = i0; i <= i1; ++i)
              {
                // NaN counts, as interpolating it does.
                if (!(row[i] == 0.f))
                {
                  nonZero = true;
                  break;
                }
              }
            }
          }
          fraction.NonZeroBlocks[bx + static_cast<size_t>(blocks[0]) * (by + static_cast<size_t>(blocks[1]) * bz)] = nonZero ? 1 : 0;
        }
      }
    }
  });
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneInputs::SameDimensions(vtkImageData* a, vtkImageData* b)
{
  int da[3];
  int db[3];
  a->GetDimensions(da);
  b->GetDimensions(db);
  return da[0] == db[0] && da[1] == db[1] && da[2] == db[2];
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneInputs::OnAnatomyGrid(vtkVolumeCutField* field, const int dims[3], const double ijkToWorld[16])
{
  const int factor = field->GetSubVoxelFactor();
  bool usable = factor > 0;
  if (usable)
  {
    const int* fieldDims = field->GetDimensions();
    usable = fieldDims[0] == dims[0] * factor && fieldDims[1] == dims[1] * factor && fieldDims[2] == dims[2] * factor;
  }
  if (usable)
  {
    vtkNew<vtkMatrix4x4> subToWorld;
    field->GetSubVoxelIJKToRAS(subToWorld);
    // Sub-voxel s lies at anatomy index (s + 0.5) / f - 0.5.
    double tolerance = 0.0;
    for (int axis = 0; axis < 3; ++axis)
    {
      double column[3];
      const double unit[3] = { axis == 0 ? 1.0 : 0.0, axis == 1 ? 1.0 : 0.0, axis == 2 ? 1.0 : 0.0 };
      TransformVector(ijkToWorld, unit, column);
      tolerance = std::max(tolerance, 1e-4 * vtkMath::Norm(column));
    }
    for (int corner = 0; corner < 4 && usable; ++corner)
    {
      const double sub[3] = { corner == 1 ? 10.0 : 0.0, corner == 2 ? 10.0 : 0.0, corner == 3 ? 10.0 : 0.0 };
      double h[4] = { sub[0], sub[1], sub[2], 1.0 };
      double viaField[4];
      subToWorld->MultiplyPoint(h, viaField);
      double anatomyIndex[3];
      for (int axis = 0; axis < 3; ++axis)
      {
        anatomyIndex[axis] = (sub[axis] + 0.5) / factor - 0.5;
      }
      double viaAnatomy[3];
      TransformPoint(ijkToWorld, anatomyIndex, viaAnatomy);
      for (int axis = 0; axis < 3; ++axis)
      {
        usable &= std::abs(viaField[axis] - viaAnatomy[axis]) <= tolerance;
      }
    }
  }
  return usable;
}

//------------------------------------------------------------------------------
void vtkVolumeCutSceneInputs::CopyTransferFunctions(
  vtkColorTransferFunction* color, vtkPiecewiseFunction* opacity, vtkVolumeCutRayScene& scene)
{
  constexpr int size = vtkVolumeCutRayScene::TransferTableSize;
  double range[2];
  opacity->GetRange(range);
  double colorRange[2];
  color->GetRange(colorRange);
  scene.TableRange[0] = std::min(range[0], colorRange[0]);
  scene.TableRange[1] = std::max(range[1], colorRange[1]);
  scene.ColorTable.resize(3 * size);
  scene.OpacityTable.resize(size);
  color->GetTable(scene.TableRange[0], scene.TableRange[1], size, scene.ColorTable.data());
  opacity->GetTable(scene.TableRange[0], scene.TableRange[1], size, scene.OpacityTable.data());
}

//------------------------------------------------------------------------------
void vtkVolumeCutSceneInputs::CopyPlanes(vtkPlaneCollection* planes, std::vector<vtkVolumeCutRayScene::PlaneEquation>& equations)
{
  equations.clear();
  if (!planes)
  {
    return;
  }
  planes->InitTraversal();
  while (vtkPlane* plane = planes->GetNextItem())
  {
    vtkVolumeCutRayScene::PlaneEquation equation;
    plane->GetNormal(equation.Normal);
    if (vtkMath::Normalize(equation.Normal) <= 0.0)
    {
      continue;
    }
    double origin[3];
    plane->GetOrigin(origin);
    equation.Offset = -vtkMath::Dot(equation.Normal, origin);
    equations.push_back(equation);
  }
}
