// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutLabelSmoothing.h"

#include "vtkVolumeCutParallelFor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

namespace
{
constexpr double Far = 1e20; // squared mm: no feature on this line

/// Squared distance (mm^2) from each of n points \a spacing mm apart to the
/// nearest feature, given f (0 at features, Far elsewhere, or the squared
/// distances of a previous pass): Felzenszwalb and Huttenlocher's lower
/// envelope of parabolas.
void DistanceTransform1D(const double* f, int n, double spacing, double* d, std::vector<int>& v, std::vector<double>& z)
{
  v.resize(n);
  z.resize(n + 1);
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  auto intersection = [&](int q, int p) {
    const double xq = q * spacing;
    const double xp = p * spacing;
    return ((f[q] + xq * xq) - (f[p] + xp * xp)) / (2.0 * (xq - xp));
  };
  for (int q = 1; q < n; ++q)
  {
    double s = intersection(q, v[k]);
    while (s <= z[k])
    {
      --k;
      s = intersection(q, v[k]);
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q)
  {
    const double x = q * spacing;
    while (z[k + 1] < x)
    {
      ++k;
    }
    const double dx = x - v[k] * spacing;
    d[q] = dx * dx + f[v[k]];
  }
}

/// Squared distance (mm^2) of each pixel of a nu x nv slice to the nearest
/// pixel where \a feature is true.
void DistanceTransform2D(const std::vector<uint8_t>& feature, int nu, int nv, double su, double sv, std::vector<double>& out)
{
  out.assign(static_cast<size_t>(nu) * nv, Far);
  std::vector<double> line(std::max(nu, nv));
  std::vector<double> result(std::max(nu, nv));
  std::vector<int> v;
  std::vector<double> z;
  for (int j = 0; j < nv; ++j)
  {
    for (int i = 0; i < nu; ++i)
    {
      line[i] = feature[i + static_cast<size_t>(nu) * j] ? 0.0 : Far;
    }
    DistanceTransform1D(line.data(), nu, su, result.data(), v, z);
    std::copy(result.begin(), result.begin() + nu, out.begin() + static_cast<size_t>(nu) * j);
  }
  for (int i = 0; i < nu; ++i)
  {
    for (int j = 0; j < nv; ++j)
    {
      line[j] = out[i + static_cast<size_t>(nu) * j];
    }
    DistanceTransform1D(line.data(), nv, sv, result.data(), v, z);
    for (int j = 0; j < nv; ++j)
    {
      out[i + static_cast<size_t>(nu) * j] = result[j];
    }
  }
}

std::vector<double> GaussianKernel(double sigma)
{
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0.0;
  for (int n = -radius; n <= radius; ++n)
  {
    kernel[n + radius] = std::exp(-0.5 * n * n / (sigma * sigma));
    sum += kernel[n + radius];
  }
  for (double& weight : kernel)
  {
    weight /= sum;
  }
  return kernel;
}

/// Convolve a nu x nv slice with \a kernel along u (stride 1) or v (stride nu); edges clamped.
void Convolve(std::vector<double>& values, int nu, int nv, bool alongV, const std::vector<double>& kernel)
{
  const int radius = static_cast<int>(kernel.size() / 2);
  std::vector<double> out(values.size());
  const int length = alongV ? nv : nu;
  const int lines = alongV ? nu : nv;
  const size_t stride = alongV ? static_cast<size_t>(nu) : 1;
  for (int line = 0; line < lines; ++line)
  {
    const size_t first = alongV ? static_cast<size_t>(line) : static_cast<size_t>(line) * nu;
    for (int n = 0; n < length; ++n)
    {
      double sum = 0.0;
      for (int m = -radius; m <= radius; ++m)
      {
        sum += kernel[m + radius] * values[first + std::min(std::max(n + m, 0), length - 1) * stride];
      }
      out[first + n * stride] = sum;
    }
  }
  values.swap(out);
}
}

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
  const double half = 0.25 * (spacing[u] + spacing[v]); // outline halfway between pixel centres
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
  const std::vector<double> kernel = sigma > 0.0 ? GaussianKernel(sigma) : std::vector<double>();
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
      std::vector<uint8_t> outside(inside.size());
      std::vector<double> toOutside;
      std::vector<double> toInside;
      for (vtkIdType slice = begin; slice < end; ++slice)
      {
        const vtkIdType origin = stride[w] * (box[2 * w] + slice) + stride[u] * box[2 * u] + stride[v] * box[2 * v];
        for (int b = 0; b < nv; ++b)
        {
          for (int a = 0; a < nu; ++a)
          {
            const bool in = labelMap[origin + stride[u] * a + stride[v] * b] == label;
            inside[a + static_cast<size_t>(nu) * b] = in ? 1 : 0;
            outside[a + static_cast<size_t>(nu) * b] = in ? 0 : 1;
          }
        }
        if (std::find(inside.begin(), inside.end(), 1) == inside.end())
        {
          continue; // nothing of the segment in this slice: fraction 0
        }
        DistanceTransform2D(outside, nu, nv, spacing[u], spacing[v], toOutside);
        DistanceTransform2D(inside, nu, nv, spacing[u], spacing[v], toInside);
        // Signed distance to the outline (negative inside), bounded where
        // the slice has no outline within reach.
        for (size_t n = 0; n < toOutside.size(); ++n)
        {
          const double distance = inside[n] ? -(std::sqrt(toOutside[n]) - half) : std::sqrt(toInside[n]) - half;
          toOutside[n] = std::min(std::max(distance, -2.0 * reach), 2.0 * reach);
        }
        if (!kernel.empty())
        {
          Convolve(toOutside, nu, nv, false, kernel);
          Convolve(toOutside, nu, nv, true, kernel);
        }
        for (int b = 0; b < nv; ++b)
        {
          for (int a = 0; a < nu; ++a)
          {
            const double f = 0.5 - toOutside[a + static_cast<size_t>(nu) * b] / (2.0 * ramp);
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
