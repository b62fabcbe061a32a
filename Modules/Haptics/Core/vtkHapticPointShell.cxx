// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticPointShell.h"

#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkVolumeCutTool.h"

#include <algorithm>
#include <cmath>
#include <limits>

vtkStandardNewMacro(vtkHapticPointShell);

namespace
{
/// Unit directions (x y z each) of the spiral: Saff and Kuijlaars (1997),
/// heights evenly spaced from pole to pole, each azimuth 3.6 / sqrt(count
/// (1 - h^2)) past the previous one, both poles included.
std::vector<double> SpiralDirections(int count)
{
  std::vector<double> directions(3 * static_cast<size_t>(count));
  double azimuth = 0.0;
  for (int n = 0; n < count; ++n)
  {
    const double height = -1.0 + 2.0 * n / (count - 1.0);
    azimuth = (n == 0 || n == count - 1) ? 0.0 : azimuth + 3.6 / std::sqrt(count * (1.0 - height * height));
    const double radial = std::sqrt(std::max(0.0, 1.0 - height * height));
    directions[3 * n] = radial * std::cos(azimuth);
    directions[3 * n + 1] = radial * std::sin(azimuth);
    directions[3 * n + 2] = height;
  }
  return directions;
}
} // namespace

//------------------------------------------------------------------------------
bool vtkHapticPointShell::BuildSphere(double radius)
{
  if (!(radius > 0.0) || !std::isfinite(radius))
  {
    vtkErrorMacro("BuildSphere: the radius (" << radius << " mm) must be a positive number");
    return false;
  }
  this->Points = SpiralDirections(this->NumberOfPointsToBuild);
  for (double& coordinate : this->Points)
  {
    coordinate *= radius;
  }
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticPointShell::BuildTool(vtkVolumeCutTool* tool)
{
  if (!tool || !tool->IsValid())
  {
    vtkErrorMacro("BuildTool: a valid tool is required");
    return false;
  }
  const double origin[3] = { 0.0, 0.0, 0.0 };
  if (!(tool->EvaluateDistance(origin) < 0.0))
  {
    vtkErrorMacro("BuildTool: the tool's origin is not inside it, so its surface cannot be sampled from there");
    return false;
  }
  const double outside = 1.01 * tool->GetBoundingRadius() + 1e-6;
  const int count = this->NumberOfPointsToBuild;
  std::vector<double> points = SpiralDirections(count);
  for (int n = 0; n < count; ++n)
  {
    const double direction[3] = { points[3 * n], points[3 * n + 1], points[3 * n + 2] };
    // The surface crossing between the origin (inside) and the bounding
    // sphere (outside): bisection to 1e-9 of the radius.
    double inside = 0.0;
    double beyond = outside;
    for (int step = 0; step < 60 && beyond - inside > 1e-9 * outside; ++step)
    {
      const double middle = 0.5 * (inside + beyond);
      const double point[3] = { middle * direction[0], middle * direction[1], middle * direction[2] };
      (tool->EvaluateDistance(point) < 0.0 ? inside : beyond) = middle;
    }
    const double t = 0.5 * (inside + beyond);
    for (int axis = 0; axis < 3; ++axis)
    {
      points[3 * n + axis] = t * direction[axis];
    }
  }
  this->Points.swap(points);
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticPointShell::GetPoint(int n, double point[3]) const
{
  if (n < 0 || n >= this->GetNumberOfPoints())
  {
    point[0] = point[1] = point[2] = 0.0;
    return;
  }
  std::copy(this->Points.begin() + 3 * n, this->Points.begin() + 3 * n + 3, point);
}

//------------------------------------------------------------------------------
double vtkHapticPointShell::GetLargestSpacing() const
{
  const int count = this->GetNumberOfPoints();
  double largest = 0.0;
  for (int a = 0; a < count; ++a)
  {
    double nearest = std::numeric_limits<double>::max();
    for (int b = 0; b < count; ++b)
    {
      if (a != b)
      {
        nearest = std::min(nearest, vtkMath::Distance2BetweenPoints(&this->Points[3 * a], &this->Points[3 * b]));
      }
    }
    largest = std::max(largest, count > 1 ? std::sqrt(nearest) : 0.0);
  }
  return largest;
}

//------------------------------------------------------------------------------
void vtkHapticPointShell::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfPointsToBuild: " << this->NumberOfPointsToBuild << "\n";
  os << indent << "NumberOfPoints: " << this->GetNumberOfPoints() << "\n";
}
