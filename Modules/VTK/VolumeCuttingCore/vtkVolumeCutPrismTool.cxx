// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutPrismTool.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <limits>

vtkStandardNewMacro(vtkVolumeCutPrismTool);

//------------------------------------------------------------------------------
void vtkVolumeCutPrismTool::RemoveAllVertices()
{
  this->Vertices.clear();
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutPrismTool::AddVertex(double x, double y)
{
  this->Vertices.push_back(x);
  this->Vertices.push_back(y);
  this->Modified();
}

//------------------------------------------------------------------------------
double vtkVolumeCutPrismTool::EvaluateDistance(const double local[3])
{
  // 2D signed distance to the polygon: nearest edge, sign by crossings.
  const size_t count = this->Vertices.size() / 2;
  double nearest2 = std::numeric_limits<double>::max();
  bool inside = false;
  for (size_t a = 0, b = count - 1; a < count; b = a++)
  {
    const double ax = this->Vertices[2 * a];
    const double ay = this->Vertices[2 * a + 1];
    const double bx = this->Vertices[2 * b];
    const double by = this->Vertices[2 * b + 1];
    const double ex = bx - ax;
    const double ey = by - ay;
    const double wx = local[0] - ax;
    const double wy = local[1] - ay;
    const double length2 = ex * ex + ey * ey;
    const double t = length2 > 0.0 ? std::min(1.0, std::max(0.0, (wx * ex + wy * ey) / length2)) : 0.0;
    const double dx = wx - t * ex;
    const double dy = wy - t * ey;
    nearest2 = std::min(nearest2, dx * dx + dy * dy);
    if ((ay > local[1]) != (by > local[1]) && local[0] < ax + (local[1] - ay) * ex / ey)
    {
      inside = !inside;
    }
  }
  const double planar = inside ? -std::sqrt(nearest2) : std::sqrt(nearest2);
  // Combine with the slab 0 <= z <= Depth as for a box: exact for a prism.
  const double axial = std::abs(local[2] - 0.5 * this->Depth) - 0.5 * this->Depth;
  // sqrt, not hypot: millimetres, far from overflow, and evaluated per sample.
  const double outsidePlanar = std::max(planar, 0.0);
  const double outsideAxial = std::max(axial, 0.0);
  const double outside = std::sqrt(outsidePlanar * outsidePlanar + outsideAxial * outsideAxial);
  return outside + std::min(std::max(planar, axial), 0.0);
}

//------------------------------------------------------------------------------
double vtkVolumeCutPrismTool::GetBoundingRadius()
{
  double radius2 = 0.0;
  for (size_t n = 0; n + 1 < this->Vertices.size(); n += 2)
  {
    radius2 = std::max(radius2, this->Vertices[n] * this->Vertices[n] + this->Vertices[n + 1] * this->Vertices[n + 1]);
  }
  return std::sqrt(radius2 + this->Depth * this->Depth);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutPrismTool::IsValid()
{
  if (this->GetNumberOfVertices() < 3)
  {
    vtkErrorMacro("IsValid: a sawing polygon needs at least 3 vertices (has " << this->GetNumberOfVertices() << ")");
    return false;
  }
  double twiceArea = 0.0;
  const size_t count = this->Vertices.size() / 2;
  for (size_t a = 0, b = count - 1; a < count; b = a++)
  {
    if (!std::isfinite(this->Vertices[2 * a]) || !std::isfinite(this->Vertices[2 * a + 1]))
    {
      vtkErrorMacro("IsValid: a polygon vertex is not finite");
      return false;
    }
    twiceArea += this->Vertices[2 * b] * this->Vertices[2 * a + 1] - this->Vertices[2 * a] * this->Vertices[2 * b + 1];
  }
  if (!(std::abs(twiceArea) > 1e-12) || !(this->Depth > 0.0) || !std::isfinite(this->Depth))
  {
    vtkErrorMacro("IsValid: the polygon must enclose an area and the depth (" << this->Depth << ") must be positive");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutPrismTool::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfVertices: " << this->GetNumberOfVertices() << "\n";
  os << indent << "Depth: " << this->Depth << "\n";
}
