// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutTool.h"

#include <algorithm>

//------------------------------------------------------------------------------
void vtkVolumeCutTool::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}

//------------------------------------------------------------------------------
void vtkVolumeCutTool::EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances)
{
  for (int n = 0; n < count; ++n)
  {
    const double local[3] = { x[n], y[n], z[n] };
    distances[n] = static_cast<float>(this->EvaluateDistance(local));
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutTool::GetLocalHalfExtents(double halfExtents[3])
{
  const double radius = this->GetBoundingRadius();
  std::fill(halfExtents, halfExtents + 3, radius);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutTool::IsLeftBehind(const double*, double, const double*)
{
  return false;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutTool::EvaluateTranslatedDistances(const double*, double, const float*, const float*, const float*, int, float*)
{
  return false;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutTool::BoundTranslatedDistances(const double*, double, const double*, const double*, const double[2][3], int, double*)
{
  return false;
}
