// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkBinaryVoxelCutter.h"

#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <limits>

vtkStandardNewMacro(vtkBinaryVoxelCutter);

//------------------------------------------------------------------------------
vtkBinaryVoxelCutter::vtkBinaryVoxelCutter()
{
  vtkMatrix4x4::Identity(&this->IJKToRAS[0][0]);
  vtkMatrix4x4::Identity(&this->RASToIJK[0][0]);
}

//------------------------------------------------------------------------------
vtkBinaryVoxelCutter::~vtkBinaryVoxelCutter() = default;

//------------------------------------------------------------------------------
bool vtkBinaryVoxelCutter::Initialize(const int dimensions[3], vtkMatrix4x4* ijkToRAS)
{
  if (!dimensions || dimensions[0] < 1 || dimensions[1] < 1 || dimensions[2] < 1 || !ijkToRAS || !(std::abs(ijkToRAS->Determinant()) > 1e-12))
  {
    vtkErrorMacro("Initialize: positive dimensions and an invertible IJK-to-RAS matrix are required");
    return false;
  }
  std::copy(dimensions, dimensions + 3, this->Dimensions);
  vtkMatrix4x4::DeepCopy(&this->IJKToRAS[0][0], ijkToRAS);
  vtkMatrix4x4::Invert(&this->IJKToRAS[0][0], &this->RASToIJK[0][0]);
  this->Mask.assign(static_cast<size_t>(dimensions[0]) * dimensions[1] * dimensions[2], 0);
  return true;
}

//------------------------------------------------------------------------------
bool vtkBinaryVoxelCutter::CutCapsule(const double p0[3], const double p1[3], double radius)
{
  if (this->Mask.empty() || !(radius > 0.0))
  {
    vtkErrorMacro("CutCapsule: not initialized, or radius not positive");
    return false;
  }
  int lower[3] = { std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), std::numeric_limits<int>::max() };
  int upper[3] = { std::numeric_limits<int>::min(), std::numeric_limits<int>::min(), std::numeric_limits<int>::min() };
  for (int corner = 0; corner < 8; ++corner)
  {
    double ras[4] = { 0, 0, 0, 1 };
    for (int axis = 0; axis < 3; ++axis)
    {
      ras[axis] = (corner >> axis) & 1 ? std::max(p0[axis], p1[axis]) + radius : std::min(p0[axis], p1[axis]) - radius;
    }
    double ijk[4];
    vtkMatrix4x4::MultiplyPoint(&this->RASToIJK[0][0], ras, ijk);
    for (int axis = 0; axis < 3; ++axis)
    {
      lower[axis] = std::min(lower[axis], static_cast<int>(std::floor(std::max(-1.0, std::min<double>(this->Dimensions[axis], ijk[axis])))));
      upper[axis] = std::max(upper[axis], static_cast<int>(std::ceil(std::max(-1.0, std::min<double>(this->Dimensions[axis], ijk[axis])))));
    }
  }
  const double ab[3] = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] };
  const double abLength2 = vtkMath::Dot(ab, ab);
  for (int k = std::max(lower[2], 0); k <= std::min(upper[2], this->Dimensions[2] - 1); ++k)
  {
    for (int j = std::max(lower[1], 0); j <= std::min(upper[1], this->Dimensions[1] - 1); ++j)
    {
      for (int i = std::max(lower[0], 0); i <= std::min(upper[0], this->Dimensions[0] - 1); ++i)
      {
        const double ijk[4] = { double(i), double(j), double(k), 1.0 };
        double p[4];
        vtkMatrix4x4::MultiplyPoint(&this->IJKToRAS[0][0], ijk, p);
        const double ap[3] = { p[0] - p0[0], p[1] - p0[1], p[2] - p0[2] };
        const double t = abLength2 > 0.0 ? std::min(1.0, std::max(0.0, vtkMath::Dot(ap, ab) / abLength2)) : 0.0;
        const double d[3] = { ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2] };
        if (vtkMath::Dot(d, d) <= radius * radius)
        {
          this->Mask[(static_cast<size_t>(k) * this->Dimensions[1] + j) * this->Dimensions[0] + i] = 1;
        }
      }
    }
  }
  return true;
}

//------------------------------------------------------------------------------
double vtkBinaryVoxelCutter::ComputeRemovedVolume() const
{
  const size_t removed = static_cast<size_t>(std::count(this->Mask.begin(), this->Mask.end(), 1));
  return removed * std::abs(vtkMatrix4x4::Determinant(&this->IJKToRAS[0][0]));
}

//------------------------------------------------------------------------------
bool vtkBinaryVoxelCutter::IsRemoved(const double ras[3]) const
{
  const double point[4] = { ras[0], ras[1], ras[2], 1.0 };
  double ijk[4];
  vtkMatrix4x4::MultiplyPoint(&this->RASToIJK[0][0], point, ijk);
  int index[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    index[axis] = static_cast<int>(std::lround(ijk[axis]));
    if (index[axis] < 0 || index[axis] >= this->Dimensions[axis])
    {
      return false;
    }
  }
  return this->Mask[(static_cast<size_t>(index[2]) * this->Dimensions[1] + index[1]) * this->Dimensions[0] + index[0]] != 0;
}

//------------------------------------------------------------------------------
void vtkBinaryVoxelCutter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " " << this->Dimensions[2] << "\n";
}
