// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutKernels.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutBoxTool);

//------------------------------------------------------------------------------
double vtkVolumeCutBoxTool::EvaluateDistance(const double local[3])
{
  // Exact box distance: outside part from the clamped excess, inside part
  // from the largest (least negative) excess.
  double outside2 = 0.0;
  double largest = -1.0e300;
  for (int axis = 0; axis < 3; ++axis)
  {
    const double excess = std::abs(local[axis]) - 0.5 * this->Size[axis];
    outside2 += std::max(excess, 0.0) * std::max(excess, 0.0);
    largest = std::max(largest, excess);
  }
  return std::sqrt(outside2) + std::min(largest, 0.0);
}

//------------------------------------------------------------------------------
void vtkVolumeCutBoxTool::EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances)
{
  const float half[3] = { static_cast<float>(0.5 * this->Size[0]), static_cast<float>(0.5 * this->Size[1]), static_cast<float>(0.5 * this->Size[2]) };
  vtkVolumeCutKernels::Get().BoxDistances(half, x, y, z, count, distances);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutBoxTool::IsLeftBehind(const double center[3], double radius, const double motion[3])
{
  // Every (sub)gradient is a sum over the axes of the face normal sign(x_i)
  // e_i times a weight >= 0. Each axis the motion has must either see the
  // whole ball behind the motion, or have weight zero throughout the ball:
  // then the ball is deeper in that slab than another face is near.
  for (int axis = 0; axis < 3; ++axis)
  {
    if (motion[axis] == 0.0)
    {
      continue;
    }
    const bool behind = motion[axis] > 0.0 ? center[axis] + radius <= 0.0 : center[axis] - radius >= 0.0;
    double nearestOther = 1e300;
    for (int other = 0; other < 3; ++other)
    {
      if (other != axis)
      {
        nearestOther = std::min(nearestOther, 0.5 * this->Size[other]);
      }
    }
    const bool inactive = std::abs(center[axis]) + radius < 0.5 * this->Size[axis] - nearestOther;
    if (!behind && !inactive)
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
double vtkVolumeCutBoxTool::GetBoundingRadius()
{
  return 0.5 * std::sqrt(this->Size[0] * this->Size[0] + this->Size[1] * this->Size[1] + this->Size[2] * this->Size[2]);
}

//------------------------------------------------------------------------------
void vtkVolumeCutBoxTool::GetLocalHalfExtents(double halfExtents[3])
{
  for (int axis = 0; axis < 3; ++axis)
  {
    halfExtents[axis] = 0.5 * this->Size[axis];
  }
}

//------------------------------------------------------------------------------
bool vtkVolumeCutBoxTool::IsValid()
{
  for (double edge : this->Size)
  {
    if (!(edge > 0.0) || !std::isfinite(edge))
    {
      vtkErrorMacro("IsValid: edge lengths must be positive numbers (got " << this->Size[0] << ", " << this->Size[1] << ", " << this->Size[2] << ")");
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutBoxTool::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Size: " << this->Size[0] << " " << this->Size[1] << " " << this->Size[2] << "\n";
}
