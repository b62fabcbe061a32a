// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutEllipsoidTool.h"
#include "vtkVolumeCutKernels.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutEllipsoidTool);

//------------------------------------------------------------------------------
double vtkVolumeCutEllipsoidTool::EvaluateDistance(const double local[3])
{
  double k0 = 0.0;
  double k1 = 0.0;
  for (int axis = 0; axis < 3; ++axis)
  {
    const double scaled = local[axis] / this->Radii[axis];
    const double scaled2 = local[axis] / (this->Radii[axis] * this->Radii[axis]);
    k0 += scaled * scaled;
    k1 += scaled2 * scaled2;
  }
  k0 = std::sqrt(k0);
  k1 = std::sqrt(k1);
  if (k1 <= 0.0)
  {
    return -std::min({ this->Radii[0], this->Radii[1], this->Radii[2] }); // the centre
  }
  return k0 * (k0 - 1.0) / k1;
}

//------------------------------------------------------------------------------
void vtkVolumeCutEllipsoidTool::EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances)
{
  float inverse[3];
  float inverse2[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    inverse[axis] = static_cast<float>(1.0 / this->Radii[axis]);
    inverse2[axis] = static_cast<float>(1.0 / (this->Radii[axis] * this->Radii[axis]));
  }
  vtkVolumeCutKernels::Get().EllipsoidDistances(inverse, inverse2, static_cast<float>(-std::min({ this->Radii[0], this->Radii[1], this->Radii[2] })), x, y, z, count, distances);
}

//------------------------------------------------------------------------------
double vtkVolumeCutEllipsoidTool::GetBoundingRadius()
{
  return std::max({ this->Radii[0], this->Radii[1], this->Radii[2] });
}

//------------------------------------------------------------------------------
bool vtkVolumeCutEllipsoidTool::IsValid()
{
  for (double radius : this->Radii)
  {
    if (!(radius > 0.0) || !std::isfinite(radius))
    {
      vtkErrorMacro("IsValid: semi-axes must be positive numbers (got " << this->Radii[0] << ", " << this->Radii[1] << ", " << this->Radii[2] << ")");
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutEllipsoidTool::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Radii: " << this->Radii[0] << " " << this->Radii[1] << " " << this->Radii[2] << "\n";
}
