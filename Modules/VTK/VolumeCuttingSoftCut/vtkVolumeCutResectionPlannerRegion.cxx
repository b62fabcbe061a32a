// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutResectionPlanner::BuildRegion and Carve, section 3.5 of the
// seed paper: the resection at a depth of cut as the signed distances and
// kept voxels that vtkVolumeCutField::CutSampledRegion carves.
#include "vtkVolumeCutResectionPlannerInternals.h"
#include "vtkVolumeCutSoftCutThreads.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutProtection.h"

#include <cmath>
#include <limits>
#include <sstream>

using namespace vtkVolumeCutSoftCut;

//------------------------------------------------------------------------------
namespace
{
/// Nearest point of segment [a, b] to p, and the squared distance.
double SegmentDistance2(const Vec& p, const Vec& a, const Vec& b, Vec& nearest)
{
  const Vec ab = Sub(b, a);
  const double length2 = Dot(ab, ab);
  double t = length2 > 0.0 ? Dot(Sub(p, a), ab) / length2 : 0.0;
  t = std::min(1.0, std::max(0.0, t));
  nearest = Add(a, Scale(ab, t));
  const Vec d = Sub(p, nearest);
  return Dot(d, d);
}

/**
 * Signed distance (mm, negative inside) of a box voxel to the shape's wall,
 * where the inner and outer strips are equally near: to first order,
 * (D_in - D_out) / |grad D_in - grad D_out|, with D the exact distances to
 * the strips' segments. The strips are offsets of the same outline points,
 * so the nearest segments of both lie around the index of the nearest site.
 */
float WallDistance(const PlanData& p, const double spacing[3], double maxSpacing, vtkIdType id)
{
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];
  const Vec x = { (p.Box[0] + static_cast<int>(id % sx)) * spacing[0], (p.Box[2] + static_cast<int>((id / sx) % p.Size[1])) * spacing[1],
    (p.Box[4] + static_cast<int>(id / sxy)) * spacing[2] };
  const auto found = p.StripSites.find(p.Feature[id]);
  const int n = static_cast<int>(p.Points.size());
  const int center = found != p.StripSites.end() ? found->second : 0;
  auto evaluate = [&](int window) {
    double bestIn = std::numeric_limits<double>::infinity();
    double bestOut = std::numeric_limits<double>::infinity();
    Vec footIn{ 0.0, 0.0, 0.0 };
    Vec footOut{ 0.0, 0.0, 0.0 };
    for (int offset = -window; offset <= window; ++offset)
    {
      const int k = ((center + offset) % n + n) % n;
      Vec candidate;
      double d2 = SegmentDistance2(x, p.Inner[k], p.Inner[(k + 1) % n], candidate);
      if (d2 < bestIn)
      {
        bestIn = d2;
        footIn = candidate;
      }
      d2 = SegmentDistance2(x, p.Outer[k], p.Outer[(k + 1) % n], candidate);
      if (d2 < bestOut)
      {
        bestOut = d2;
        footOut = candidate;
      }
    }
    const double dIn = std::sqrt(bestIn);
    const double dOut = std::sqrt(bestOut);
    const Vec gradient = Sub(dIn > 0.0 ? Scale(Sub(x, footIn), 1.0 / dIn) : Vec{ 0.0, 0.0, 0.0 },
      dOut > 0.0 ? Scale(Sub(x, footOut), 1.0 / dOut) : Vec{ 0.0, 0.0, 0.0 });
    return (dIn - dOut) / std::max(0.05, Norm(gradient));
  };
  // Far from the wall a rough value is enough: it only has to say which side.
  const double rough = evaluate(1);
  if (std::abs(rough) > 6.0 * maxSpacing)
  {
    return static_cast<float>(rough);
  }
  // Segments within three voxels of arc on either side.
  const double arcStep = std::max(1e-6, p.Length / n);
  const int window = std::min(n / 2, 1 + static_cast<int>(std::ceil(3.0 * maxSpacing / arcStep)));
  return static_cast<float>(evaluate(window));
}

/**
 * The bone's side (positive inside bone) of the CT's iso-surface at the top
 * of the soft-tissue range, as a distance-like value (mm): (CT - threshold)
 * / slope, clamped to a few voxels, with one slope for the whole box (the
 * jump from soft tissue to the threshold over two voxels), so that its
 * trilinear zero set is exactly the CT's trilinear iso-surface. The
 * resection stops at that smooth surface, so the print it leaves on bone is
 * the bone's shape, not voxel steps.
 */
float BoneDistance(const PlanData& p, double slope, double maxSpacing, float threshold, vtkIdType id)
{
  const double reach = 4.0 * maxSpacing;
  return static_cast<float>(std::max(-reach, std::min(reach, (p.Values[id] - threshold) / slope)));
}

/**
 * Whether a box voxel is bone through and through: its value and its 26
 * neighbours' are above the soft-tissue range. Its cube is kept exactly;
 * the voxels of the bone's surface, mixtures of bone and soft tissue, are
 * kept by the smooth surface of BoneDistance up to their centres.
 */
bool IsInsideBone(const PlanData& p, vtkIdType id, float threshold)
{
  if (!(p.Values[id] > threshold))
  {
    return false;
  }
  const int at[3] = { static_cast<int>(id % p.Size[0]), static_cast<int>((id / p.Size[0]) % p.Size[1]),
    static_cast<int>(id / (static_cast<vtkIdType>(p.Size[0]) * p.Size[1])) };
  for (int a = 0; a < 3; ++a)
  {
    if (at[a] == 0 || at[a] + 1 == p.Size[a])
    {
      return false;
    }
  }
  for (int dc = -1; dc <= 1; ++dc)
  {
    for (int db = -1; db <= 1; ++db)
    {
      for (int da = -1; da <= 1; ++da)
      {
        if (!(p.Values[p.Index(at[0] + da, at[1] + db, at[2] + dc)] > threshold))
        {
          return false;
        }
      }
    }
  }
  return true;
}
} // namespace

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildRegion(double depth, vtkImageData* distances, vtkImageData* keep, vtkVolumeCutField* shieldSource)
{
  this->ErrorMessage.clear();
  Internals& impl = *this->Impl;
  if (!impl.Current)
  {
    return this->Fail("BuildRegion: there is no plan; call Plan with an outline first");
  }
  if (!distances || !keep)
  {
    return this->Fail("BuildRegion: give images for the distances and the voxels kept");
  }
  if (!(depth > 0.0) || !std::isfinite(depth))
  {
    std::ostringstream text;
    text << "BuildRegion: the depth of cut must be a positive number of mm (got " << depth << "); nothing to carve";
    return this->Fail(text.str());
  }
  if (depth > this->MaximumDepth + 1e-9)
  {
    std::ostringstream text;
    text << "BuildRegion: the depth of cut " << depth << " mm is beyond the planned maximum depth of " << this->MaximumDepth
         << " mm; plan again with a larger maximum depth";
    return this->Fail(text.str());
  }
  PlanData& p = *impl.Current;
  const double* spacing = impl.Grid.Spacing;
  const double margin = 2.0 * impl.Grid.MaxSpacing();
  const int sx = p.Size[0];
  const vtkIdType sxy = static_cast<vtkIdType>(p.Size[0]) * p.Size[1];

  // Voxels next to filled tissue (26-neighbours): removable, so that the
  // smooth wall and depth, not voxel cubes, bound the region. The wall's and
  // the bone's distances are computed where a region first needs them.
  if (!p.NearFilledReady)
  {
    p.Wall.assign(p.Count, std::numeric_limits<float>::quiet_NaN());
    p.Bone.assign(p.Count, std::numeric_limits<float>::quiet_NaN());
    std::vector<uint8_t> near(p.Count);
    for (vtkIdType id = 0; id < p.Count; ++id)
    {
      near[id] = (p.Class[id] & FilledTissue) ? 1 : 0;
    }
    const vtkIdType steps[3] = { 1, sx, sxy };
    for (int a = 0; a < 3; ++a)
    {
      std::vector<uint8_t> grown(near);
      for (vtkIdType id = 0; id < p.Count; ++id)
      {
        const int at = a == 0 ? static_cast<int>(id % sx) : a == 1 ? static_cast<int>((id / sx) % p.Size[1]) : static_cast<int>(id / sxy);
        if ((at > 0 && near[id - steps[a]]) || (at + 1 < p.Size[a] && near[id + steps[a]]))
        {
          grown[id] = 1;
        }
      }
      near.swap(grown);
    }
    for (vtkIdType id = 0; id < p.Count; ++id)
    {
      p.Class[id] |= near[id] ? NearFilled : 0;
    }
    p.NearFilledReady = true;
  }

  // The part of the box the region reaches: filled tissue above the depth
  // of cut, and a few voxels around it.
  int lower[3] = { p.Size[0], p.Size[1], p.Size[2] };
  int upper[3] = { -1, -1, -1 };
  for (vtkIdType id = 0; id < p.Count; ++id)
  {
    if ((p.Class[id] & FilledTissue) && p.Depth[id] <= depth)
    {
      const int at[3] = { static_cast<int>(id % sx), static_cast<int>((id / sx) % p.Size[1]), static_cast<int>(id / sxy) };
      for (int a = 0; a < 3; ++a)
      {
        lower[a] = std::min(lower[a], at[a]);
        upper[a] = std::max(upper[a], at[a]);
      }
    }
  }
  if (upper[0] < 0)
  {
    std::ostringstream text;
    text << "BuildRegion: no soft tissue inside the outline lies within " << depth << " mm of the skin; nothing to carve";
    return this->Fail(text.str());
  }
  int sub[6];
  for (int a = 0; a < 3; ++a)
  {
    const int pad = 3 + static_cast<int>(std::ceil(margin / spacing[a]));
    sub[2 * a] = std::max(0, lower[a] - pad);
    sub[2 * a + 1] = std::min(p.Size[a] - 1, upper[a] + pad);
  }
  const int size[3] = { sub[1] - sub[0] + 1, sub[3] - sub[2] + 1, sub[5] - sub[4] + 1 };
  const int extent[6] = { p.Box[0] + sub[0], p.Box[0] + sub[1], p.Box[2] + sub[2], p.Box[2] + sub[3], p.Box[4] + sub[4], p.Box[4] + sub[5] };
  const vtkIdType count = static_cast<vtkIdType>(size[0]) * size[1] * size[2];

  distances->Initialize();
  distances->SetExtent(const_cast<int*>(extent));
  distances->SetOrigin(0.0, 0.0, 0.0);
  distances->SetSpacing(1.0, 1.0, 1.0);
  vtkNew<vtkFloatArray> values;
  values->SetName("ResectionDistance");
  values->SetNumberOfComponents(RegionComponents);
  values->SetNumberOfTuples(count);
  distances->GetPointData()->SetScalars(values);
  keep->Initialize();
  keep->SetExtent(const_cast<int*>(extent));
  keep->SetOrigin(0.0, 0.0, 0.0);
  keep->SetSpacing(1.0, 1.0, 1.0);
  vtkNew<vtkUnsignedCharArray> kept;
  kept->SetName("Keep");
  kept->SetNumberOfTuples(count);
  keep->GetPointData()->SetScalars(kept);
  std::vector<uint8_t> shield;
  if (shieldSource && shieldSource->GetProtection())
  {
    shield.resize(count);
    const int voxelLower[3] = { extent[0], extent[2], extent[4] };
    const int voxelUpper[3] = { extent[1], extent[3], extent[5] };
    shieldSource->GetProtection()->GetShieldLabels(voxelLower, voxelUpper, shield.data());
  }
  float* out = values->GetPointer(0);
  unsigned char* keepOut = kept->GetPointer(0);
  const float low = static_cast<float>(this->SoftTissueRange[0]);
  const float high = static_cast<float>(this->SoftTissueRange[1]);
  const double maxSpacing = impl.Grid.MaxSpacing();
  // A voxel's cube meets the region only where the region's value at its
  // centre is below the cube's half diagonal.
  const float nearKept = static_cast<float>(maxSpacing);
  const double boneSlope = std::max(1.0, this->SoftTissueRange[1] - this->SoftTissueRange[0]) / (2.0 * maxSpacing);
  vtkVolumeCutSoftCutThreads::For(0, size[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType c = begin; c < end; ++c)
    {
      for (int b = 0; b < size[1]; ++b)
      {
        vtkIdType target = (c * size[1] + b) * static_cast<vtkIdType>(size[0]);
        vtkIdType id = p.Index(sub[0], sub[2] + b, sub[4] + static_cast<int>(c));
        for (int a = 0; a < size[0]; ++a, ++id, ++target)
        {
          float& wall = p.Wall[id];
          if (std::isnan(wall))
          {
            wall = WallDistance(p, spacing, maxSpacing, id);
          }
          float& bone = p.Bone[id];
          if (std::isnan(bone))
          {
            bone = BoneDistance(p, boneSlope, maxSpacing, high, id);
          }
          const float d = p.Depth[id];
          float* components = out + RegionComponents * target;
          components[0] = wall;
          components[1] = static_cast<float>(d - depth);
          components[2] = static_cast<float>(-(d + margin));
          components[3] = bone;
          // Voxels kept as cubes, where the region comes near them (farther
          // ones change nothing, and each costs the writer a shield brick):
          // bone through and through, and tissue the fill did not reach
          // (behind bone or air) that the region could reach.
          const bool near = std::max({ components[0], components[1], components[2], components[3] }) < nearKept;
          const float value = p.Values[id];
          const bool unreached = value >= low && !(p.Class[id] & NearFilled);
          keepOut[target] = ((near && (unreached || IsInsideBone(p, id, high))) || (!shield.empty() && shield[target])) ? 1 : 0;
        }
      }
    }
  });
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Carve(vtkVolumeCutField* field, double depth, vtkVolumeCutField* shieldSource)
{
  if (!field || field->GetSubVoxelFactor() < 1)
  {
    return this->Fail("Carve: the cut field is not initialized; initialize it on the CT's grid first");
  }
  const int* fieldDims = field->GetDimensions();
  const int f = field->GetSubVoxelFactor();
  if (this->Impl->Current && (fieldDims[0] != this->Impl->Grid.Dims[0] * f || fieldDims[1] != this->Impl->Grid.Dims[1] * f || fieldDims[2] != this->Impl->Grid.Dims[2] * f))
  {
    return this->Fail("Carve: the cut field is not on the planned CT's grid; nothing was carved");
  }
  vtkNew<vtkImageData> distances;
  vtkNew<vtkImageData> keep;
  if (!this->BuildRegion(depth, distances, keep, shieldSource))
  {
    return false;
  }
  if (!field->CutSampledRegion(distances, keep))
  {
    return this->Fail("Carve: the cut field refused the region (see the log); nothing was carved");
  }
  return true;
}
