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

/// Convolve the rows (along u) or columns (along v) of a nu x nv slice
/// with kernel, edges clamped, writing only the pixels of [u0, u1] x [v0, v1]
/// into out (which reads values).
void Convolve(const double* values, int nu, int nv, bool alongV, const std::vector<double>& kernel, const int region[4], double* out)
{
  const int radius = static_cast<int>(kernel.size() / 2);
  const int length = alongV ? nv : nu;
  const size_t stride = alongV ? static_cast<size_t>(nu) : 1;
  for (int b = region[2]; b <= region[3]; ++b)
  {
    for (int a = region[0]; a <= region[1]; ++a)
    {
      const int n = alongV ? b : a;
      const size_t first = alongV ? static_cast<size_t>(a) : static_cast<size_t>(b) * nu;
      double sum = 0.0;
      for (int m = -radius; m <= radius; ++m)
      {
        sum += kernel[m + radius] * values[first + std::min(std::max(n + m, 0), length - 1) * stride];
      }
      out[first + n * stride] = sum;
    }
  }
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
  SquaredDistance2D(feature, nu, nv, su, sv, 0, nu - 1, squared, scratch);
}

//------------------------------------------------------------------------------
void vtkVolumeCutSliceDistance::SquaredDistance2D(
  const uint8_t* feature, int nu, int nv, double su, double sv, int firstColumn, int lastColumn, double* squared, Scratch& scratch)
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
  for (int i = firstColumn; i <= lastColumn; ++i)
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
  const int whole[4] = { 0, nu - 1, 0, nv - 1 };
  SmoothedSignedDistance(inside, nu, nv, su, sv, bound, kernel, whole, distance, scratch);
}

//------------------------------------------------------------------------------
void vtkVolumeCutSliceDistance::SmoothedSignedDistance(const uint8_t* inside, int nu, int nv, double su, double sv, double bound,
  const std::vector<double>& kernel, const int region[4], double* distance, Scratch& scratch)
{
  // The pixels the Gaussian reads around the region.
  const int radius = static_cast<int>(kernel.size() / 2);
  const int read[4] = { std::max(0, region[0] - radius), std::min(nu - 1, region[1] + radius), std::max(0, region[2] - radius),
    std::min(nv - 1, region[3] + radius) };
  const size_t count = static_cast<size_t>(nu) * nv;
  scratch.Outside.resize(count);
  for (size_t n = 0; n < count; ++n)
  {
    scratch.Outside[n] = inside[n] ? 0 : 1;
  }
  scratch.ToInside.resize(count);
  // distance holds the squared distance to the outside until it becomes signed.
  SquaredDistance2D(scratch.Outside.data(), nu, nv, su, sv, read[0], read[1], distance, scratch);
  SquaredDistance2D(inside, nu, nv, su, sv, read[0], read[1], scratch.ToInside.data(), scratch);
  const double half = 0.25 * (su + sv); // the outline halfway between pixel centres
  for (int v = read[2]; v <= read[3]; ++v)
  {
    for (int u = read[0]; u <= read[1]; ++u)
    {
      const size_t n = u + static_cast<size_t>(nu) * v;
      const double signedDistance = inside[n] ? -(std::sqrt(distance[n]) - half) : std::sqrt(scratch.ToInside[n]) - half;
      distance[n] = std::min(std::max(signedDistance, -bound), bound);
    }
  }
  if (!kernel.empty())
  {
    // Along u for the rows the second pass reads, then along v in the region.
    scratch.Convolved.resize(count);
    const int rows[4] = { region[0], region[1], read[2], read[3] };
    Convolve(distance, nu, nv, false, kernel, rows, scratch.Convolved.data());
    Convolve(scratch.Convolved.data(), nu, nv, true, kernel, region, distance);
  }
}
