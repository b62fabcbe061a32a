// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutResectionPlanner::BuildMask, section 3.4 of the seed paper: the
// depth of every voxel of the box under the skin's sub-voxel surface.
#include "vtkVolumeCutResectionPlannerInternals.h"
#include "vtkVolumeCutDistanceTransform.h"
#include "vtkVolumeCutSoftCutThreads.h"

#include <cmath>
#include <sstream>

using namespace vtkVolumeCutSoftCut;

namespace
{
/// Trilinear value of the plan's box copy at a grid-frame point (clamped to
/// the box); inline, as it was, for the skin search run per skin voxel.
inline double BoxSample(const PlanData& plan, const double spacing[3], const Vec& x)
{
  double f[3];
  int base[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    double index = x[axis] / spacing[axis] - plan.Box[2 * axis];
    index = std::max(0.0, std::min(static_cast<double>(plan.Size[axis] - 1), index));
    base[axis] = std::min(plan.Size[axis] - 2, static_cast<int>(std::floor(index)));
    base[axis] = std::max(0, base[axis]);
    f[axis] = plan.Size[axis] > 1 ? index - base[axis] : 0.0;
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    const int d[3] = { corner & 1, (corner >> 1) & 1, (corner >> 2) & 1 };
    const double w = (d[0] ? f[0] : 1.0 - f[0]) * (d[1] ? f[1] : 1.0 - f[1]) * (d[2] ? f[2] : 1.0 - f[2]);
    if (w != 0.0)
    {
      const int a = std::min(plan.Size[0] - 1, base[0] + d[0]);
      const int b = std::min(plan.Size[1] - 1, base[1] + d[1]);
      const int c = std::min(plan.Size[2] - 1, base[2] + d[2]);
      value += w * plan.Values[plan.Index(a, b, c)];
    }
  }
  return value;
}
} // namespace

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildMask()
{
  Internals& impl = *this->Impl;
  this->ErrorMessage.clear();
  if (!impl.Next)
  {
    return this->Fail("BuildMask: there is no shape to build the mask of; call BuildShape first");
  }
  PlanData& p = *impl.Next;
  const vtkIdType N = p.Count;
  const double* spacing = impl.Grid.Spacing;
  const float iso = static_cast<float>(this->SkinIsoValue);

  // The skin's sub-voxel surface near each of its voxels inside the outline:
  // where the CT crosses the iso-value along the gradient, and the inward
  // normal there.
  std::vector<int>& slot = impl.Scratch;
  slot.resize(N);
  const std::vector<vtkIdType>& skin = p.Skin;
  std::vector<unsigned char>& sites = impl.Sites;
  sites.assign(N, 0);
  for (size_t s = 0; s < skin.size(); ++s)
  {
    slot[skin[s]] = static_cast<int>(s);
    sites[skin[s]] = 1;
  }
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];
  auto position = [&](vtkIdType id) {
    return Vec{ (p.Box[0] + static_cast<int>(id % sx)) * spacing[0], (p.Box[2] + static_cast<int>((id / sx) % p.Size[1])) * spacing[1],
      (p.Box[4] + static_cast<int>(id / sxy)) * spacing[2] };
  };
  std::vector<float> surface(6 * skin.size());
  vtkVolumeCutSoftCutThreads::For(0, static_cast<vtkIdType>(skin.size()), [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType s = begin; s < end; ++s)
    {
      const Vec center = position(skin[s]);
      Vec gradient;
      for (int a = 0; a < 3; ++a)
      {
        Vec up = center;
        Vec down = center;
        up[a] += spacing[a];
        down[a] -= spacing[a];
        gradient[a] = (BoxSample(p, spacing, up) - BoxSample(p, spacing, down)) / (2.0 * spacing[a]);
      }
      Vec normal = Normalized(gradient);
      Vec point = center;
      if (Norm(normal) > 0.0)
      {
        // The voxel is tissue; air lies against the gradient within two voxels.
        const double stepLength = 0.5 * impl.Grid.MinSpacing();
        double previous = 0.0;
        for (double t = stepLength; t <= 2.0 * impl.Grid.MaxSpacing() + 1e-9; t += stepLength)
        {
          if (BoxSample(p, spacing, Sub(center, Scale(normal, t))) < iso)
          {
            double lo = previous;
            double hi = t;
            for (int iteration = 0; iteration < 12; ++iteration)
            {
              const double mid = 0.5 * (lo + hi);
              (BoxSample(p, spacing, Sub(center, Scale(normal, mid))) < iso ? hi : lo) = mid;
            }
            point = Sub(center, Scale(normal, 0.5 * (lo + hi)));
            break;
          }
          previous = t;
        }
      }
      else
      {
        normal = Scale(p.AverageNormal, -1.0);
      }
      for (int a = 0; a < 3; ++a)
      {
        surface[6 * s + a] = static_cast<float>(point[a]);
        surface[6 * s + 3 + a] = static_cast<float>(normal[a]);
      }
    }
  });

  // The third transform: every voxel's nearest skin voxel, then its depth
  // under that voxel's tangent plane.
  impl.Work.resize(N);
  std::vector<int>& nearest = impl.Nearest;
  nearest.resize(N);
  vtkVolumeCutDistanceTransform::Compute(p.Size, spacing, sites.data(), impl.Work.data(), nearest.data());
  p.Depth.resize(N);
  vtkVolumeCutSoftCutThreads::For(0, p.Size[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType c = begin; c < end; ++c)
    {
      const double z = (p.Box[4] + c) * spacing[2];
      for (int b = 0; b < p.Size[1]; ++b)
      {
        const double y = (p.Box[2] + b) * spacing[1];
        vtkIdType id = p.Index(0, b, static_cast<int>(c));
        for (int a = 0; a < p.Size[0]; ++a, ++id)
        {
          const float* site = &surface[6 * static_cast<size_t>(slot[nearest[id]])];
          const double x = (p.Box[0] + a) * spacing[0];
          p.Depth[id] = static_cast<float>(site[3] * (x - site[0]) + site[4] * (y - site[1]) + site[5] * (z - site[2]));
        }
      }
    }
  });
  // Tissue within the maximum depth on a face of the box that is not the CT's: grow there.
  vtkIdType underSkin = 0;
  for (vtkIdType id = 0; id < N; ++id)
  {
    if ((p.Class[id] & FilledTissue) && p.Depth[id] <= this->MaximumDepth)
    {
      // The skin's own partial-volume voxels (air against bone looks like
      // soft tissue there) do not make a resection: tissue under them does.
      underSkin += p.Depth[id] > impl.Grid.MaxSpacing() ? 1 : 0;
      const int at[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
      for (int a = 0; a < 3; ++a)
      {
        p.Reached[2 * a] |= at[a] == 0 && p.Box[2 * a] > 0;
        p.Reached[2 * a + 1] |= at[a] == p.Size[a] - 1 && p.Box[2 * a + 1] < impl.Grid.Dims[a] - 1;
      }
    }
  }
  if (underSkin == 0)
  {
    std::ostringstream text;
    text << "BuildMask: the outline encloses no soft tissue (CT values " << this->SoftTissueRange[0] << " to " << this->SoftTissueRange[1]
         << " HU) more than a voxel under the skin; nothing to resect there";
    impl.Spare = std::move(impl.Next);
    return this->Fail(text.str());
  }
  p.MaskReady = true;
  impl.Spare = std::move(impl.Current);
  impl.Current = std::move(impl.Next);
  return true;
}
