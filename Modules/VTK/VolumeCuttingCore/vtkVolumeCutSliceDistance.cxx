// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutSliceDistance.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace
{
constexpr double Far = 1e20; // squared mm: no feature on this line

/// Squared distance (mm^2) from each of n points spacing mm apart to the
/// nearest feature, given f (0 at features, Far elsewhere, or the squared
/// distances of a previous pass): the lower envelope of parabolas.
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

/// Convolve a nu x nv slice with kernel along u (stride 1) or v (stride nu); edges clamped.
void Convolve(double* values, int nu, int nv, bool alongV, const std::vector<double>& kernel, std::vector<double>& out)
{
  const int radius = static_cast<int>(kernel.size() / 2);
  out.resize(static_cast<size_t>(nu) * nv);
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
  std::copy(out.begin(), out.end(), values);
}
} // namespace

//------------------------------------------------------------------------------
std::vector<double> vtkVolumeCutSliceDistance::GaussianKernel(double sigma)
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

//------------------------------------------------------------------------------
void vtkVolumeCutSliceDistance::SquaredDistance2D(const uint8_t* feature, int nu, int nv, double su, double sv, double* squared, Scratch& scratch)
{
  const int longest = std::max(nu, nv);
  scratch.Line.resize(longest);
  scratch.Result.resize(longest);
  for (int j = 0; j < nv; ++j)
  {
    for (int i = 0; i < nu; ++i)
    {
      scratch.Line[i] = feature[i + static_cast<size_t>(nu) * j] ? 0.0 : Far;
    }
    DistanceTransform1D(scratch.Line.data(), nu, su, squared + static_cast<size_t>(nu) * j, scratch.Parabolas, scratch.Envelope);
  }
  for (int i = 0; i < nu; ++i)
  {
    for (int j = 0; j < nv; ++j)
    {
      scratch.Line[j] = squared[i + static_cast<size_t>(nu) * j];
    }
    DistanceTransform1D(scratch.Line.data(), nv, sv, scratch.Result.data(), scratch.Parabolas, scratch.Envelope);
    for (int j = 0; j < nv; ++j)
    {
      squared[i + static_cast<size_t>(nu) * j] = scratch.Result[j];
    }
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutSliceDistance::SmoothedSignedDistance(const uint8_t* inside, int nu, int nv, double su, double sv, double bound,
  const std::vector<double>& kernel, double* distance, Scratch& scratch)
{
  const size_t count = static_cast<size_t>(nu) * nv;
  scratch.Outside.resize(count);
  for (size_t n = 0; n < count; ++n)
  {
    scratch.Outside[n] = inside[n] ? 0 : 1;
  }
  scratch.ToInside.resize(count);
  // distance holds the squared distance to the outside until it becomes signed.
  SquaredDistance2D(scratch.Outside.data(), nu, nv, su, sv, distance, scratch);
  SquaredDistance2D(inside, nu, nv, su, sv, scratch.ToInside.data(), scratch);
  const double half = 0.25 * (su + sv); // the outline halfway between pixel centres
  for (size_t n = 0; n < count; ++n)
  {
    const double signedDistance = inside[n] ? -(std::sqrt(distance[n]) - half) : std::sqrt(scratch.ToInside[n]) - half;
    distance[n] = std::min(std::max(signedDistance, -bound), bound);
  }
  if (!kernel.empty())
  {
    Convolve(distance, nu, nv, false, kernel, scratch.Convolved);
    Convolve(distance, nu, nv, true, kernel, scratch.Convolved);
  }
}
