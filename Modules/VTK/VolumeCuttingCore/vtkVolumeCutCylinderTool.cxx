// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutKernels.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutCylinderTool);

//------------------------------------------------------------------------------
double vtkVolumeCutCylinderTool::EvaluateDistance(const double local[3])
{
  // Exact distance to a finite cylinder: a 2D box distance in (radial, axial).
  const double radial = std::sqrt(local[0] * local[0] + local[1] * local[1]) - this->Radius;
  const double axial = std::abs(local[2]) - 0.5 * this->Length;
  // sqrt, not hypot: these are millimetres, far from overflow, and a sweep
  // evaluates this hundreds of thousands of times a stroke.
  const double outsideRadial = std::max(radial, 0.0);
  const double outsideAxial = std::max(axial, 0.0);
  const double outside = std::sqrt(outsideRadial * outsideRadial + outsideAxial * outsideAxial);
  return outside + std::min(std::max(radial, axial), 0.0);
}

//------------------------------------------------------------------------------
void vtkVolumeCutCylinderTool::EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances)
{
  vtkVolumeCutKernels::Get().CylinderDistances(static_cast<float>(this->Radius), static_cast<float>(0.5 * this->Length), x, y, z, count, distances);
}

//------------------------------------------------------------------------------
double vtkVolumeCutCylinderTool::GetBoundingRadius()
{
  return std::hypot(this->Radius, 0.5 * this->Length);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutCylinderTool::IsValid()
{
  if (!(this->Radius > 0.0) || !(this->Length > 0.0) || !std::isfinite(this->Radius) || !std::isfinite(this->Length))
  {
    vtkErrorMacro("IsValid: radius (" << this->Radius << ") and length (" << this->Length << ") must be positive numbers");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutCylinderTool::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Radius: " << this->Radius << "\n";
  os << indent << "Length: " << this->Length << "\n";
}
