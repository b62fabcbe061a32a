// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutLabelSurface.h"

#include "vtkVolumeCutSliceDistance.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutLabelSurface);

//------------------------------------------------------------------------------
void vtkVolumeCutLabelSurface::ComputeLabelBoxes(
  const uint16_t* labelMap, const int dimensions[3], const std::vector<int>& labels, std::vector<std::vector<int>>& boxes)
{
  boxes.assign(labels.size(), { dimensions[0], -1, dimensions[1], -1, dimensions[2], -1 });
  std::vector<int> slotOfValue(65536, -1);
  for (size_t n = 0; n < labels.size(); ++n)
  {
    if (labels[n] > 0 && labels[n] < 65536)
    {
      slotOfValue[labels[n]] = static_cast<int>(n);
    }
  }
  for (int k = 0; k < dimensions[2]; ++k)
  {
    for (int j = 0; j < dimensions[1]; ++j)
    {
      const uint16_t* row = labelMap + dimensions[0] * (j + static_cast<size_t>(dimensions[1]) * k);
      for (int i = 0; i < dimensions[0]; ++i)
      {
        const int slot = row[i] ? slotOfValue[row[i]] : -1;
        if (slot >= 0)
        {
          std::vector<int>& box = boxes[slot];
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
}

//------------------------------------------------------------------------------
bool vtkVolumeCutLabelSurface::Initialize(const int dims[3], const double spacing[3], const int labelBox[6], double sigma, Levels& levels)
{
  if (labelBox[1] < labelBox[0] || labelBox[3] < labelBox[2] || labelBox[5] < labelBox[4] || !(sigma >= 0.0))
  {
    return false;
  }
  // Slices across the axis of largest spacing; u and v span them.
  int w = 2;
  for (int axis = 1; axis >= 0; --axis)
  {
    w = spacing[axis] > spacing[w] ? axis : w;
  }
  const int u = w == 0 ? 1 : 0;
  const int v = w == 2 ? 1 : 2;
  // The level ramps over 2 * ramp mm, wide enough that the slices on either
  // side of an oblique surface stay on it.
  levels.Ramp = 2.0 * spacing[w];
  levels.SliceAxis = w;
  const double reach = levels.Ramp + 3.0 * sigma * std::max(spacing[u], spacing[v]);
  for (int axis = 0; axis < 3; ++axis)
  {
    const int margin = axis == w ? 1 : static_cast<int>(std::ceil(reach / spacing[axis])) + 1;
    levels.Box[2 * axis] = std::max(0, labelBox[2 * axis] - margin);
    levels.Box[2 * axis + 1] = std::min(dims[axis] - 1, labelBox[2 * axis + 1] + margin);
  }
  const size_t count = static_cast<size_t>(levels.Box[1] - levels.Box[0] + 1) * (levels.Box[3] - levels.Box[2] + 1) *
    (levels.Box[5] - levels.Box[4] + 1);
  levels.Values.assign(count, static_cast<float>(levels.Ramp));
  return true;
}

//------------------------------------------------------------------------------
int vtkVolumeCutLabelSurface::GetNumberOfSlices(const int labelBox[6], const Levels& levels)
{
  return labelBox[2 * levels.SliceAxis + 1] - labelBox[2 * levels.SliceAxis] + 1;
}

//------------------------------------------------------------------------------
void vtkVolumeCutLabelSurface::ComputeSlices(const uint16_t* labelMap, const int dims[3], const double spacing[3], int label,
  const int labelBox[6], double sigma, int begin, int end, Levels& levels)
{
  const int w = levels.SliceAxis;
  const int u = w == 0 ? 1 : 0;
  const int v = w == 2 ? 1 : 2;
  const vtkIdType stride[3] = { 1, dims[0], static_cast<vtkIdType>(dims[0]) * dims[1] };
  const int* box = levels.Box;
  const vtkIdType boxStride[3] = { 1, box[1] - box[0] + 1, static_cast<vtkIdType>(box[1] - box[0] + 1) * (box[3] - box[2] + 1) };
  const double ramp = levels.Ramp;
  const double reach = ramp + 3.0 * sigma * std::max(spacing[u], spacing[v]);
  const std::vector<double> kernel = sigma > 0.0 ? vtkVolumeCutSliceDistance::GaussianKernel(sigma) : std::vector<double>();
  const int nu = box[2 * u + 1] - box[2 * u] + 1;
  const int nv = box[2 * v + 1] - box[2 * v] + 1;
  std::vector<uint8_t> inside(static_cast<size_t>(nu) * nv);
  std::vector<double> distance(inside.size());
  vtkVolumeCutSliceDistance::Scratch scratch;
  for (int slice = begin; slice < end; ++slice)
  {
    const int s = labelBox[2 * w] + slice;
    const vtkIdType origin = stride[w] * s + stride[u] * box[2 * u] + stride[v] * box[2 * v];
    const vtkIdType boxOrigin = boxStride[w] * (s - box[2 * w]);
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
      continue; // nothing of the segment in this slice: outside
    }
    // Signed distance to the outline (negative inside), bounded where the
    // slice has no outline within reach, then smoothed in the slice.
    vtkVolumeCutSliceDistance::SmoothedSignedDistance(inside.data(), nu, nv, spacing[u], spacing[v], 2.0 * reach, kernel, distance.data(), scratch);
    for (int b = 0; b < nv; ++b)
    {
      for (int a = 0; a < nu; ++a)
      {
        const double level = std::min(ramp, std::max(-ramp, distance[a + static_cast<size_t>(nu) * b]));
        levels.Values[boxOrigin + boxStride[u] * a + boxStride[v] * b] = static_cast<float>(level);
      }
    }
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutLabelSurface::ExtrapolateEnds(const int labelBox[6], Levels& levels)
{
  const int w = levels.SliceAxis;
  const int u = w == 0 ? 1 : 0;
  const int v = w == 2 ? 1 : 2;
  const int* box = levels.Box;
  const vtkIdType boxStride[3] = { 1, box[1] - box[0] + 1, static_cast<vtkIdType>(box[1] - box[0] + 1) * (box[3] - box[2] + 1) };
  const float ramp = static_cast<float>(levels.Ramp);
  for (int side = 0; side < 2; ++side)
  {
    const int direction = side == 0 ? -1 : 1;
    const int last = labelBox[2 * w + side];
    const int next = last + direction;
    const int previous = last - direction;
    const bool hasPrevious = previous >= labelBox[2 * w] && previous <= labelBox[2 * w + 1];
    if (next < box[2 * w] || next > box[2 * w + 1])
    {
      continue;
    }
    for (int b = 0; b <= box[2 * v + 1] - box[2 * v]; ++b)
    {
      for (int a = 0; a <= box[2 * u + 1] - box[2 * u]; ++a)
      {
        const vtkIdType offset = boxStride[u] * a + boxStride[v] * b;
        const float level = levels.Values[offset + boxStride[w] * (last - box[2 * w])];
        const float mirrored = std::abs(level);
        const float extrapolated = hasPrevious ? 2.f * level - levels.Values[offset + boxStride[w] * (previous - box[2 * w])] : mirrored;
        levels.Values[offset + boxStride[w] * (next - box[2 * w])] = std::min(ramp, std::max(extrapolated, mirrored));
      }
    }
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutLabelSurface::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
