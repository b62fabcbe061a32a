// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutResectionPlanner, sections 3.1 and 3.2 of the seed paper: the
// outline drawn on the skin, put on the skin, its normals, and the inner and
// outer strips offset from it.
#include "vtkVolumeCutResectionPlannerInternals.h"
#include "vtkVolumeCutSoftCutThreads.h"

#include "vtkPoints.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

using namespace vtkVolumeCutSoftCut;

namespace
{
/// Whether 2D segments [a, b] and [c, d] meet (crossing or touching).
bool SegmentsCross(const double a[2], const double b[2], const double c[2], const double d[2])
{
  auto orient = [](const double p[2], const double q[2], const double r[2]) {
    const double value = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
    return (value > 0.0) - (value < 0.0);
  };
  // r on segment [p, q], given the three are collinear.
  auto within = [](const double p[2], const double q[2], const double r[2]) {
    return std::min(p[0], q[0]) <= r[0] && r[0] <= std::max(p[0], q[0]) && std::min(p[1], q[1]) <= r[1] && r[1] <= std::max(p[1], q[1]);
  };
  const int d1 = orient(c, d, a);
  const int d2 = orient(c, d, b);
  const int d3 = orient(a, b, c);
  const int d4 = orient(a, b, d);
  if (d1 != d2 && d3 != d4 && d1 * d2 <= 0 && d3 * d4 <= 0 && (d1 != 0 || d2 != 0))
  {
    return true;
  }
  return (d1 == 0 && within(c, d, a)) || (d2 == 0 && within(c, d, b)) || (d3 == 0 && within(a, b, c)) || (d4 == 0 && within(a, b, d));
}

std::string FormatPoint(const double ras[3])
{
  std::ostringstream text;
  text.precision(1);
  text << std::fixed << "(" << ras[0] << ", " << ras[1] << ", " << ras[2] << ")";
  return text.str();
}
} // namespace

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Internals::ReadOutline(vtkVolumeCutResectionPlanner& planner, std::vector<Vec>& given)
{
  const int* dims = this->Grid.Dims;
  const double* spacing = this->Grid.Spacing;
  given.clear();
  const vtkIdType count = planner.Outline ? planner.Outline->GetNumberOfPoints() : 0;
  for (vtkIdType id = 0; id < count; ++id)
  {
    double ras[3];
    planner.Outline->GetPoint(id, ras);
    if (!std::isfinite(ras[0]) || !std::isfinite(ras[1]) || !std::isfinite(ras[2]))
    {
      return planner.Fail("BuildShape: outline point " + std::to_string(id) + " is not finite");
    }
    const Vec x = this->Grid.FromRAS({ ras[0], ras[1], ras[2] });
    if (given.empty() || Norm(Sub(x, given.back())) > 1e-6)
    {
      given.push_back(x);
    }
  }
  while (given.size() > 1 && Norm(Sub(given.front(), given.back())) <= 1e-6)
  {
    given.pop_back();
  }
  if (given.size() < 3)
  {
    return planner.Fail("BuildShape: the outline has " + std::to_string(given.size()) +
      " distinct point(s); a closed outline on the skin needs at least 3");
  }
  const double iso = planner.SkinIsoValue;
  {
    // Everything the outline's points and normals read: the points' box
    // grown by the search reach and the normals' stencil.
    double lowest[3] = { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity() };
    double highest[3] = { -lowest[0], -lowest[1], -lowest[2] };
    for (const Vec& x : given)
    {
      for (int a = 0; a < 3; ++a)
      {
        lowest[a] = std::min(lowest[a], x[a] / spacing[a]);
        highest[a] = std::max(highest[a], x[a] / spacing[a]);
      }
    }
    const double searchReach = std::max(planner.SkinTolerance, 3.0 * std::max({ spacing[0], spacing[1], spacing[2] }));
    int local[6];
    for (int a = 0; a < 3; ++a)
    {
      const int pad = 2 + static_cast<int>(std::ceil((searchReach + 3.0 * std::max({ spacing[0], spacing[1], spacing[2] })) / spacing[a]));
      local[2 * a] = static_cast<int>(std::floor(lowest[a])) - pad;
      local[2 * a + 1] = static_cast<int>(std::ceil(highest[a])) + pad;
    }
    if (!this->Grid.CacheVoxels(local))
    {
      return planner.Fail("BuildShape: the CT's scalar type is not supported");
    }
  }
  for (size_t k = 0; k < given.size(); ++k)
  {
    const Vec ras = this->Grid.ToRAS(given[k]);
    bool inside = true;
    for (int axis = 0; axis < 3; ++axis)
    {
      const double index = given[k][axis] / spacing[axis];
      inside &= index >= -0.5 && index <= dims[axis] - 0.5;
    }
    if (!inside)
    {
      return planner.Fail("BuildShape: outline point " + std::to_string(k) + " at RAS " + FormatPoint(ras.data()) + " lies outside the CT");
    }
    Vec onSkin;
    if (!this->Grid.ToSkin(given[k], planner.SkinTolerance, iso, onSkin))
    {
      std::ostringstream text;
      text << "BuildShape: outline point " << k << " at RAS " << FormatPoint(ras.data()) << " is more than " << planner.SkinTolerance
           << " mm from the skin (the CT's " << iso << " HU iso-surface); place the outline on the skin";
      return planner.Fail(text.str());
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Internals::PlaceOutline(
  vtkVolumeCutResectionPlanner& planner, const std::vector<Vec>& given, PlanData& plan, double& step)
{
  // Resampled evenly, half the smallest spacing apart, and put on the skin.
  const double iso = planner.SkinIsoValue;
  std::vector<double> arc(given.size() + 1, 0.0);
  for (size_t k = 0; k < given.size(); ++k)
  {
    arc[k + 1] = arc[k] + Norm(Sub(given[(k + 1) % given.size()], given[k]));
  }
  const double total = arc.back();
  const int samples = static_cast<int>(std::min(20000.0, std::max(static_cast<double>(given.size()), std::ceil(total / (0.5 * this->Grid.MinSpacing())))));
  plan.Points.resize(samples);
  const double reach = std::max(planner.SkinTolerance, 3.0 * this->Grid.MaxSpacing());
  size_t segment = 0;
  for (int k = 0; k < samples; ++k)
  {
    const double s = total * k / samples;
    while (segment + 1 < given.size() && arc[segment + 1] <= s)
    {
      ++segment;
    }
    const double length = arc[segment + 1] - arc[segment];
    const double t = length > 0.0 ? (s - arc[segment]) / length : 0.0;
    const Vec x = Add(given[segment], Scale(Sub(given[(segment + 1) % given.size()], given[segment]), t));
    if (!this->Grid.ToSkin(x, reach, iso, plan.Points[k]))
    {
      std::ostringstream text;
      text << "BuildShape: the outline between points " << segment << " and " << (segment + 1) % given.size() << " leaves the skin by more than "
           << reach << " mm near RAS " << FormatPoint(this->Grid.ToRAS(x).data()) << "; add points on the skin there";
      return planner.Fail(text.str());
    }
  }
  const int n = samples;
  step = total / samples;
  plan.Length = 0.0;
  for (int k = 0; k < n; ++k)
  {
    plan.Length += Norm(Sub(plan.Points[(k + 1) % n], plan.Points[k]));
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Internals::BuildStrips(
  vtkVolumeCutResectionPlanner& planner, double step, PlanData& plan, std::vector<Vec>& inward, double& delta)
{
  const int n = static_cast<int>(plan.Points.size());
  // 2. Normals (outward: the inverse gradient). A sharp skin edge sampled
  // by trilinear interpolation has terraces whose gradients tilt by several
  // degrees, which would tilt the wall: the gradient is averaged over a box
  // of five voxels, at points about two voxels apart along the outline, then
  // smoothed along the outline over two voxels on either side.
  std::vector<Vec> local(n);
  {
    const int stride = std::max(1, static_cast<int>(std::lround(2.0 * this->Grid.MinSpacing() / step)));
    std::vector<int> at;
    for (int k = 0; k < n; k += stride)
    {
      at.push_back(k);
    }
    std::vector<Vec> sampled(at.size());
    vtkVolumeCutSoftCutThreads::For(0, static_cast<vtkIdType>(at.size()), [&](vtkIdType begin, vtkIdType end) {
      for (vtkIdType m = begin; m < end; ++m)
      {
        sampled[m] = Normalized(Scale(this->Grid.BoxGradient(plan.Points[at[m]], 2), -1.0));
      }
    });
    for (size_t m = 0; m < at.size(); ++m)
    {
      const int first = at[m];
      const int last = m + 1 < at.size() ? at[m + 1] : n;
      const Vec& a = sampled[m];
      const Vec& b = sampled[(m + 1) % at.size()];
      for (int k = first; k < last; ++k)
      {
        const double t = double(k - first) / (last - first);
        local[k] = Normalized(Add(Scale(a, 1.0 - t), Scale(b, t)));
      }
    }
  }
  const int window = std::max(1, static_cast<int>(std::lround(2.0 * this->Grid.MaxSpacing() / step)));
  plan.Normals.resize(n);
  Vec sum{ 0.0, 0.0, 0.0 };
  for (int k = 0; k < n; ++k)
  {
    Vec smoothed{ 0.0, 0.0, 0.0 };
    for (int offset = -window; offset <= window; ++offset)
    {
      smoothed = Add(smoothed, local[((k + offset) % n + n) % n]);
    }
    plan.Normals[k] = Normalized(smoothed);
    sum = Add(sum, local[k]);
  }
  if (Norm(sum) < 0.2 * n)
  {
    return planner.Fail("BuildShape: the outline's skin normals cancel out (is it drawn around the head or a limb?); draw it on one side of the surface");
  }
  plan.AverageNormal = Normalized(sum);

  // Seen along the average normal: orientation, area, crossings.
  const Vec& axis = plan.AverageNormal;
  Vec helper = std::abs(axis[0]) < 0.9 ? Vec{ 1.0, 0.0, 0.0 } : Vec{ 0.0, 1.0, 0.0 };
  const Vec e1 = Normalized(Cross(axis, helper));
  const Vec e2 = Cross(axis, e1);
  std::vector<std::array<double, 2>> flat(n);
  for (int k = 0; k < n; ++k)
  {
    flat[k] = { Dot(plan.Points[k], e1), Dot(plan.Points[k], e2) };
  }
  double area = 0.0;
  for (int k = 0; k < n; ++k)
  {
    const auto& a = flat[k];
    const auto& b = flat[(k + 1) % n];
    area += 0.5 * (a[0] * b[1] - b[0] * a[1]);
  }
  {
    const int stride = std::max(1, n / 512);
    std::vector<int> kept;
    for (int k = 0; k < n; k += stride)
    {
      kept.push_back(k);
    }
    const int m = static_cast<int>(kept.size());
    for (int a = 0; a < m; ++a)
    {
      for (int b = a + 2; b < m; ++b)
      {
        if (a == 0 && b == m - 1)
        {
          continue;
        }
        if (SegmentsCross(flat[kept[a]].data(), flat[kept[(a + 1) % m]].data(), flat[kept[b]].data(), flat[kept[(b + 1) % m]].data()))
        {
          return planner.Fail("BuildShape: the outline crosses itself near RAS " + FormatPoint(this->Grid.ToRAS(plan.Points[kept[a]]).data()) +
            "; draw a simple closed curve");
        }
      }
    }
  }

  plan.Area = std::abs(area);
  if (plan.Area < this->Grid.MinSpacing() * this->Grid.MinSpacing())
  {
    return planner.Fail("BuildShape: the outline encloses no area seen along its normal; draw a closed curve around the region to resect");
  }
  // Strips: each point offset in the tangent plane, perpendicular to the
  // outline, towards the inside (counter-clockwise seen from outside: left).
  delta = planner.StripOffset > 0.0 ? planner.StripOffset : 2.0 * this->Grid.MaxSpacing();
  const double orientation = area > 0.0 ? 1.0 : -1.0;
  const int reachOfTangent = std::max(1, static_cast<int>(std::lround(this->Grid.MaxSpacing() / step)));
  plan.Inner.resize(n);
  plan.Outer.resize(n);
  inward.assign(n, Vec{ 0.0, 0.0, 0.0 });
  Vec previous{ 0.0, 0.0, 0.0 };
  for (int k = 0; k < n; ++k)
  {
    const Vec tangent = Normalized(Sub(plan.Points[(k + reachOfTangent) % n], plan.Points[((k - reachOfTangent) % n + n) % n]));
    const Vec& normal = planner.NormalMode == LocalNormal ? plan.Normals[k] : plan.AverageNormal;
    Vec w = Cross(normal, tangent);
    w = Norm(w) > 1e-6 ? Scale(Normalized(w), orientation) : previous;
    previous = w;
    inward[k] = w;
    plan.Inner[k] = Add(plan.Points[k], Scale(w, delta));
    plan.Outer[k] = Sub(plan.Points[k], Scale(w, delta));
  }
  return true;
}
