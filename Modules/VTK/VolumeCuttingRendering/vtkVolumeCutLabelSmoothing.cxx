// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutLabelSmoothing.h"

#include "vtkVolumeCutParallelFor.h"
#include "vtkVolumeCutSliceDistance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

//------------------------------------------------------------------------------
void vtkVolumeCutLabelSmoothing::Smooth(const std::vector<uint16_t>& labelMap, const int dims[3], const double spacing[3],
  const std::vector<int>& labels, double sigma, int maximumThreads, std::vector<vtkVolumeCutRayScene::FractionVolume>& fractions)
{
  if (labels.empty() || !(sigma >= 0.0) || labelMap.empty())
  {
    return;
  }
  // Slices across the axis of largest spacing; u and v span them.
  int w = 2;
  for (int axis = 1; axis >= 0; --axis)
  {
    w = spacing[axis] > spacing[w] ? axis : w;
  }
  const int u = w == 0 ? 1 : 0;
  const int v = w == 2 ? 1 : 2;
  const vtkIdType stride[3] = { 1, dims[0], static_cast<vtkIdType>(dims[0]) * dims[1] };
  // The fraction ramps from 1 to 0 over 2 * ramp mm of distance, wide enough
  // that the slices on either side of an oblique surface stay on it.
  const double ramp = 2.0 * spacing[w];
  const double reach = ramp + 3.0 * sigma * std::max(spacing[u], spacing[v]);
  const int margin[3] = { static_cast<int>(std::ceil(reach / spacing[0])) + 1, static_cast<int>(std::ceil(reach / spacing[1])) + 1,
    static_cast<int>(std::ceil(reach / spacing[2])) + 1 };

  // Each label's bounding box, in one pass over the label map.
  std::map<int, std::array<int, 6>> boxes;
  for (int label : labels)
  {
    boxes[label] = { dims[0], -1, dims[1], -1, dims[2], -1 };
  }
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      const uint16_t* row = labelMap.data() + stride[1] * j + stride[2] * k;
      for (int i = 0; i < dims[0]; ++i)
      {
        auto found = row[i] ? boxes.find(row[i]) : boxes.end();
        if (found != boxes.end())
        {
          std::array<int, 6>& box = found->second;
          box[0] = std::min(box[0], i);
          box[1] = std::max(box[1], i);
          box[2] = std::min(box[2], j);
          box[3] = std::max(box[3], j);
          box[4] = std::min(box[4], k);
          box[5] = std::max(box[5], k);
        }
      }
    }
  }
  const std::vector<double> kernel = sigma > 0.0 ? vtkVolumeCutSliceDistance::GaussianKernel(sigma) : std::vector<double>();
  for (int label : labels)
  {
    std::array<int, 6> box = boxes[label];
    if (box[1] < box[0])
    {
      continue; // not in the label map
    }
    for (int axis : { u, v })
    {
      box[2 * axis] = std::max(0, box[2 * axis] - margin[axis]);
      box[2 * axis + 1] = std::min(dims[axis] - 1, box[2 * axis + 1] + margin[axis]);
    }
    vtkVolumeCutRayScene::FractionVolume fraction;
    fraction.Label = label;
    fraction.Values.assign(static_cast<size_t>(dims[0]) * dims[1] * dims[2], 0.f);
    const int nu = box[2 * u + 1] - box[2 * u] + 1;
    const int nv = box[2 * v + 1] - box[2 * v] + 1;
    vtkVolumeCutParallelFor(maximumThreads, box[2 * w + 1] - box[2 * w] + 1, [&](vtkIdType begin, vtkIdType end) {
      std::vector<uint8_t> inside(static_cast<size_t>(nu) * nv);
      std::vector<double> distance(inside.size());
      vtkVolumeCutSliceDistance::Scratch scratch;
      for (vtkIdType slice = begin; slice < end; ++slice)
      {
        const vtkIdType origin = stride[w] * (box[2 * w] + slice) + stride[u] * box[2 * u] + stride[v] * box[2 * v];
        for (int b = 0; b < nv; ++b)
        {
          for (int a = 0; a < nu; ++a)
          {
            const bool in = labelMap[origin + stride[u] * a + stride[v] * b] == label;
            inside[a + static_cast<size_t>(nu) * b] = in ? 1 : 0;
          }
        }
        if (std::find(inside.begin(), inside.end(), 1) == inside.end())
        {
          continue; // nothing of the segment in this slice: fraction 0
        }
        // Signed distance to the outline (negative inside), bounded where
        // the slice has no outline within reach.
        vtkVolumeCutSliceDistance::SmoothedSignedDistance(inside.data(), nu, nv, spacing[u], spacing[v], 2.0 * reach, kernel, distance.data(), scratch);
        for (int b = 0; b < nv; ++b)
        {
          for (int a = 0; a < nu; ++a)
          {
            const double f = 0.5 - distance[a + static_cast<size_t>(nu) * b] / (2.0 * ramp);
            fraction.Values[origin + stride[u] * a + stride[v] * b] = static_cast<float>(std::min(1.0, std::max(0.0, f)));
          }
        }
      }
    });
    // Beyond the first and last slices that hold the segment: the distance
    // extrapolated from the last two slices, so that a tapering end (the
    // pole of a ball) closes where its outlines shrink to, but no further
    // than halfway to the next slice over the last outline (its mirror),
    // where a blunt end closes as the binary indicator does.
    for (int side = 0; side < 2; ++side)
    {
      const int direction = side == 0 ? -1 : 1;
      const int last = box[2 * w + side];
      const int next = last + direction;
      const int previous = last - direction;
      const bool hasPrevious = previous >= box[2 * w] && previous <= box[2 * w + 1];
      if (next < 0 || next >= dims[w])
      {
        continue;
      }
      for (int b = 0; b < nv; ++b)
      {
        for (int a = 0; a < nu; ++a)
        {
          const vtkIdType offset = stride[u] * (box[2 * u] + a) + stride[v] * (box[2 * v] + b);
          const float f = fraction.Values[offset + stride[w] * last];
          const float mirrored = std::min(f, 1.f - f);
          const float extrapolated = hasPrevious ? 2.f * f - fraction.Values[offset + stride[w] * previous] : mirrored;
          fraction.Values[offset + stride[w] * next] = std::max(0.f, std::min(extrapolated, mirrored));
        }
      }
    }
    fractions.push_back(std::move(fraction));
  }
}
