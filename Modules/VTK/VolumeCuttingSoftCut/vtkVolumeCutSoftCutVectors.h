// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingSoftCut (not installed, not wrapped): the 3-vectors
// the resection planner computes with, in the grid frame (mm along the CT's
// voxel axes). Inline, so that the planner's per-voxel loops stay free of calls.
#ifndef vtkVolumeCutSoftCutVectors_h
#define vtkVolumeCutSoftCutVectors_h

#include <array>
#include <cmath>

namespace vtkVolumeCutSoftCut
{
using Vec = std::array<double, 3>;

inline Vec Add(const Vec& a, const Vec& b)
{
  return { a[0] + b[0], a[1] + b[1], a[2] + b[2] };
}
inline Vec Sub(const Vec& a, const Vec& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
inline Vec Scale(const Vec& a, double s)
{
  return { a[0] * s, a[1] * s, a[2] * s };
}
inline double Dot(const Vec& a, const Vec& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec Cross(const Vec& a, const Vec& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}
inline double Norm(const Vec& a)
{
  return std::sqrt(Dot(a, a));
}
inline Vec Normalized(const Vec& a)
{
  const double n = Norm(a);
  return n > 0.0 ? Scale(a, 1.0 / n) : Vec{ 0.0, 0.0, 0.0 };
}
} // namespace vtkVolumeCutSoftCut

#endif
