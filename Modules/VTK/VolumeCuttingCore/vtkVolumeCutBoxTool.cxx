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
double vtkVolumeCutBoxTool::GetBoundingRadius()
{
  return 0.5 * std::sqrt(this->Size[0] * this->Size[0] + this->Size[1] * this->Size[1] + this->Size[2] * this->Size[2]);
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
