// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutResectionPlanner::BuildShape, section 3.3 of the seed paper: the
// shape (nearer the inner strip than the outer one) in a bounding box, the
// skin inside the outline, and the flood fill through soft tissue from it.
#include "vtkVolumeCutResectionPlannerInternals.h"
#include "vtkVolumeCutDistanceTransform.h"
#include "vtkVolumeCutSoftCutThreads.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

using namespace vtkVolumeCutSoftCut;

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildShape()
{
  Internals& impl = *this->Impl;
  this->ErrorMessage.clear();
  if (!this->UpdateGrid("BuildShape"))
  {
    return false;
  }
  const int* dims = impl.Grid.Dims;
  const double* spacing = impl.Grid.Spacing;
  if (this->GetMTime() != impl.GrowthTime)
  {
    std::fill(impl.Growth, impl.Growth + 6, 0);
    impl.GrowthTime = this->GetMTime();
  }
  if (!(this->SoftTissueRange[0] <= this->SoftTissueRange[1]))
  {
    return this->Fail("BuildShape: the soft-tissue range is empty (its minimum is above its maximum)");
  }
  if (!(this->MaximumDepth > 0.0))
  {
    return this->Fail("BuildShape: the maximum depth must be positive");
  }
  const double diagonal = std::sqrt(std::pow(dims[0] * spacing[0], 2) + std::pow(dims[1] * spacing[1], 2) + std::pow(dims[2] * spacing[2], 2));
  if (this->MaximumDepth > diagonal)
  {
    std::ostringstream text;
    text << "BuildShape: the maximum depth " << this->MaximumDepth << " mm goes beyond the CT (" << diagonal << " mm across)";
    return this->Fail(text.str());
  }

  // 1. The outline, on the skin, and 2. its normals and strips.
  std::vector<Vec> given;
  if (!impl.ReadOutline(*this, given))
  {
    return false;
  }
  // An outline refused above keeps the shape built before; from here on a
  // failure leaves no shape for BuildMask.
  if (impl.Next)
  {
    impl.Spare = std::move(impl.Next);
  }
  auto plan = impl.NewPlan();
  double step = 0.0;
  std::vector<Vec> inward;
  double delta = 0.0;
  if (!impl.PlaceOutline(*this, given, *plan, step) || !impl.BuildStrips(*this, step, *plan, inward, delta))
  {
    return false;
  }
  const int n = static_cast<int>(plan->Points.size());
  const double iso = this->SkinIsoValue;

  // 3. The box: strips, the outline moved the maximum depth in, a margin.
  double lower[3] = { std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity() };
  double upper[3] = { -lower[0], -lower[1], -lower[2] };
  auto include = [&](const Vec& x) {
    for (int a = 0; a < 3; ++a)
    {
      lower[a] = std::min(lower[a], x[a] / spacing[a]);
      upper[a] = std::max(upper[a], x[a] / spacing[a]);
    }
  };
  Vec centroid{ 0.0, 0.0, 0.0 };
  for (int k = 0; k < n; ++k)
  {
    const Vec& normal = this->NormalMode == LocalNormal ? plan->Normals[k] : plan->AverageNormal;
    include(plan->Inner[k]);
    include(plan->Outer[k]);
    include(Sub(plan->Points[k], Scale(normal, this->MaximumDepth)));
    include(Add(plan->Points[k], Scale(normal, 2.0 * impl.Grid.MaxSpacing())));
    centroid = Add(centroid, Scale(plan->Points[k], 1.0 / n));
  }
  include(Sub(centroid, Scale(plan->AverageNormal, this->MaximumDepth)));
  const int margin = 3 + static_cast<int>(std::ceil(delta / impl.Grid.MinSpacing()));
  for (int a = 0; a < 3; ++a)
  {
    plan->Box[2 * a] = std::max(0, static_cast<int>(std::floor(lower[a])) - margin - impl.Growth[2 * a]);
    plan->Box[2 * a + 1] = std::min(dims[a] - 1, static_cast<int>(std::ceil(upper[a])) + margin + impl.Growth[2 * a + 1]);
    plan->Size[a] = plan->Box[2 * a + 1] - plan->Box[2 * a] + 1;
    if (plan->Size[a] < 2)
    {
      return this->Fail("BuildShape: the outline lies outside the CT");
    }
  }
  const double voxels = double(plan->Size[0]) * plan->Size[1] * plan->Size[2];
  if (voxels > 1.5e9)
  {
    return this->Fail("BuildShape: the resection's bounding box is too large (" + std::to_string(static_cast<long long>(voxels)) +
      " voxels); draw a smaller outline or lower the maximum depth");
  }
  PlanData& p = *plan;
  p.Count = static_cast<vtkIdType>(voxels);
  const vtkIdType N = p.Count;
  {
    int box[6];
    std::copy(p.Box, p.Box + 6, box);
    impl.Grid.CopyVoxels(box, p.Values);
  }

  // One exact distance transform towards both strips: a voxel is in the
  // shape when its nearest strip site lies on the inner strip (the paper's
  // two transforms and their comparison, in one pass).
  std::vector<unsigned char>& sites = impl.Sites;
  sites.assign(N, 0);
  std::vector<int>& onStrip = impl.Scratch; // read only at sites: 1 inner, 2 outer
  onStrip.resize(N);
  p.StripSites.clear();
  for (int which = 1; which <= 2; ++which)
  {
    const std::vector<Vec>& strip = which == 1 ? p.Inner : p.Outer;
    for (int k = 0; k < n; ++k)
    {
      const Vec& a = strip[k];
      const Vec& b = strip[(k + 1) % n];
      const int steps = 1 + static_cast<int>(std::ceil(Norm(Sub(b, a)) / (0.25 * impl.Grid.MinSpacing())));
      for (int s = 0; s <= steps; ++s)
      {
        const Vec x = Add(a, Scale(Sub(b, a), double(s) / steps));
        int index[3];
        bool inside = true;
        for (int axisIndex = 0; axisIndex < 3; ++axisIndex)
        {
          index[axisIndex] = static_cast<int>(std::lround(x[axisIndex] / spacing[axisIndex])) - p.Box[2 * axisIndex];
          inside &= index[axisIndex] >= 0 && index[axisIndex] < p.Size[axisIndex];
        }
        if (inside)
        {
          const vtkIdType id = p.Index(index[0], index[1], index[2]);
          if (!sites[id])
          {
            sites[id] = 1;
            onStrip[id] = which;
            p.StripSites.emplace(static_cast<int>(id), k);
          }
        }
      }
    }
  }
  p.Feature.resize(N);
  impl.Work.resize(N);
  vtkVolumeCutDistanceTransform::Compute(p.Size, spacing, sites.data(), impl.Work.data(), p.Feature.data());
  p.Class.resize(N);
  vtkVolumeCutSoftCutThreads::For(0, N, [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType id = begin; id < end; ++id)
    {
      const int site = p.Feature[id];
      p.Class[id] = site >= 0 && onStrip[site] == 1 ? vtkVolumeCutResectionPlanner::InShape : 0;
    }
  });

  // The skin inside the outline: tissue voxels next to air, connected
  // (26-neighbours) to the skin just inside the outline.
  const float isoValue = static_cast<float>(iso);
  auto isSkin = [&](int a, int b, int c) {
    const vtkIdType id = p.Index(a, b, c);
    if (!(p.Class[id] & InShape) || !(p.Values[id] >= isoValue) || (p.Class[id] & SkinPatch))
    {
      return false;
    }
    const int neighbour[6][3] = { { -1, 0, 0 }, { 1, 0, 0 }, { 0, -1, 0 }, { 0, 1, 0 }, { 0, 0, -1 }, { 0, 0, 1 } };
    for (const auto& d : neighbour)
    {
      const int q[3] = { a + d[0], b + d[1], c + d[2] };
      if (q[0] >= 0 && q[1] >= 0 && q[2] >= 0 && q[0] < p.Size[0] && q[1] < p.Size[1] && q[2] < p.Size[2] &&
        p.Values[p.Index(q[0], q[1], q[2])] < isoValue)
      {
        return true;
      }
    }
    return false;
  };
  std::vector<vtkIdType> stack;
  const int seedStride = std::max(1, n / 256);
  for (int k = 0; k < n; k += seedStride)
  {
    const Vec y = Add(plan->Points[k], Scale(inward[k], 0.5 * delta));
    int center[3];
    for (int a = 0; a < 3; ++a)
    {
      center[a] = static_cast<int>(std::lround(y[a] / spacing[a])) - p.Box[2 * a];
    }
    double best = std::numeric_limits<double>::infinity();
    vtkIdType bestId = -1;
    for (int dc = -2; dc <= 2; ++dc)
    {
      for (int db = -2; db <= 2; ++db)
      {
        for (int da = -2; da <= 2; ++da)
        {
          const int q[3] = { center[0] + da, center[1] + db, center[2] + dc };
          if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= p.Size[0] || q[1] >= p.Size[1] || q[2] >= p.Size[2] || !isSkin(q[0], q[1], q[2]))
          {
            continue;
          }
          const Vec x = { (p.Box[0] + q[0]) * spacing[0], (p.Box[2] + q[1]) * spacing[1], (p.Box[4] + q[2]) * spacing[2] };
          const double d = Norm(Sub(x, y));
          if (d < best)
          {
            best = d;
            bestId = p.Index(q[0], q[1], q[2]);
          }
        }
      }
    }
    if (bestId >= 0 && !(p.Class[bestId] & SkinPatch))
    {
      p.Class[bestId] |= SkinPatch;
      stack.push_back(bestId);
      p.Skin.push_back(bestId);
    }
  }
  if (stack.empty())
  {
    return this->Fail("BuildShape: no skin (CT values above the " + std::to_string(static_cast<int>(iso)) +
      " HU iso-value next to air) was found inside the outline; check the skin iso-value for this CT");
  }
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];
  while (!stack.empty())
  {
    const vtkIdType id = stack.back();
    stack.pop_back();
    const int a = static_cast<int>(id % sx);
    const int b = static_cast<int>((id / sx) % p.Size[1]);
    const int c = static_cast<int>(id / sxy);
    for (int dc = -1; dc <= 1; ++dc)
    {
      for (int db = -1; db <= 1; ++db)
      {
        for (int da = -1; da <= 1; ++da)
        {
          const int q[3] = { a + da, b + db, c + dc };
          if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= p.Size[0] || q[1] >= p.Size[1] || q[2] >= p.Size[2] || !isSkin(q[0], q[1], q[2]))
          {
            continue;
          }
          const vtkIdType neighbour = p.Index(q[0], q[1], q[2]);
          p.Class[neighbour] |= SkinPatch;
          stack.push_back(neighbour);
          p.Skin.push_back(neighbour);
        }
      }
    }
  }

  // The flood fill (face neighbours) from the skin through soft tissue in
  // the shape: bone and air stop it.
  const float low = static_cast<float>(this->SoftTissueRange[0]);
  const float high = static_cast<float>(this->SoftTissueRange[1]);
  p.FilledCount = 0;
  for (const vtkIdType id : p.Skin)
  {
    if (p.Values[id] >= low && p.Values[id] <= high)
    {
      p.Class[id] |= FilledTissue;
      stack.push_back(id);
      ++p.FilledCount;
    }
  }
  const vtkIdType faceSteps[6] = { -1, 1, -sx, sx, -sxy, sxy };
  while (!stack.empty())
  {
    const vtkIdType id = stack.back();
    stack.pop_back();
    const int position[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
    for (int face = 0; face < 6; ++face)
    {
      const int axisIndex = face / 2;
      const int moved = position[axisIndex] + ((face & 1) ? 1 : -1);
      if (moved < 0 || moved >= p.Size[axisIndex])
      {
        continue;
      }
      const vtkIdType neighbour = id + faceSteps[face];
      const uint8_t cls = p.Class[neighbour];
      const float value = p.Values[neighbour];
      if ((cls & InShape) && !(cls & FilledTissue) && value >= low && value <= high)
      {
        p.Class[neighbour] = cls | FilledTissue;
        stack.push_back(neighbour);
        ++p.FilledCount;
      }
    }
  }
  for (const vtkIdType id : p.Skin)
  {
    // The skin reaching a face of the box that is not the CT's: grow there.
    const int position[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
    for (int a = 0; a < 3; ++a)
    {
      p.Reached[2 * a] |= position[a] == 0 && p.Box[2 * a] > 0;
      p.Reached[2 * a + 1] |= position[a] == p.Size[a] - 1 && p.Box[2 * a + 1] < dims[a] - 1;
    }
  }
  if (p.FilledCount == 0)
  {
    std::ostringstream text;
    text << "BuildShape: the outline encloses no soft tissue (CT values " << low << " to " << high
         << " HU) under the skin; nothing to resect there";
    return this->Fail(text.str());
  }

  impl.Next = std::move(plan);
  return true;
}
