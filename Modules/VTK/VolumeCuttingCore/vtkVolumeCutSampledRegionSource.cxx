// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutSampledRegionSource.h"
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutProtectionBrick.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vtkVolumeCutSweeps
{
namespace
{
constexpr int BrickSize = vtkVolumeCutField::BrickSize;
constexpr int SamplesPerBrick = BrickSize * BrickSize * BrickSize;

void Transform(const double m[4][4], const double in[3], double out[3])
{
  for (int row = 0; row < 3; ++row)
  {
    out[row] = m[row][0] * in[0] + m[row][1] * in[1] + m[row][2] * in[2] + m[row][3];
  }
}
} // namespace

//------------------------------------------------------------------------------
SampledRegionSource::SampledRegionSource(const float* values, int components, const int extent[6], const double rasToIJK[4][4],
  const double ijkToRAS[4][4], double bandWidth, vtkVolumeCutProtection* keep, const double rasToSubIJK[4][4], const int brickDimensions[3],
  double quantum, double keepMargin, const std::vector<char>& keepBricks)
  : Values(values)
  , Components(components)
  , Quantum(quantum)
  , BandWidth(bandWidth)
  , KeepMargin(keepMargin)
  , Far(static_cast<float>(4.0 * bandWidth))
  , Keep(keep)
  , KeepBricks(keepBricks)
{
  std::copy(extent, extent + 6, this->Extent);
  std::copy(brickDimensions, brickDimensions + 3, this->BrickDimensions);
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      this->RASToIJK[row][column] = rasToIJK[row][column];
      this->IJKToRAS[row][column] = ijkToRAS[row][column];
      this->RASToSubIJK[row][column] = rasToSubIJK[row][column];
    }
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    this->Size[axis] = extent[2 * axis + 1] - extent[2 * axis] + 1;
    this->BlockCounts[axis] = (this->Size[axis] + BlockSize - 1) / BlockSize;
  }
  // Cells reach one voxel past their block: each block's minimum covers its
  // voxels and the next layer on the high side, so that a cell's corners are
  // all within the block of its low corner.
  const size_t blocks = static_cast<size_t>(this->BlockCounts[0]) * this->BlockCounts[1] * this->BlockCounts[2];
  this->BlockMinimum.assign(blocks * components, std::numeric_limits<float>::infinity());
  for (int k = 0; k < this->Size[2]; ++k)
  {
    for (int j = 0; j < this->Size[1]; ++j)
    {
      const float* row = values + (static_cast<size_t>(k) * this->Size[1] + j) * this->Size[0] * components;
      for (int i = 0; i < this->Size[0]; ++i)
      {
        // The blocks whose cells have this voxel as a corner.
        const int bi[2] = { i / BlockSize, (i - 1) / BlockSize };
        const int bj[2] = { j / BlockSize, (j - 1) / BlockSize };
        const int bk[2] = { k / BlockSize, (k - 1) / BlockSize };
        for (int corner = 0; corner < 8; ++corner)
        {
          const int b[3] = { bi[corner & 1], bj[(corner >> 1) & 1], bk[(corner >> 2) & 1] };
          if ((i == 0 && (corner & 1)) || (j == 0 && ((corner >> 1) & 1)) || (k == 0 && ((corner >> 2) & 1)))
          {
            continue;
          }
          float* minimum = &this->BlockMinimum[((static_cast<size_t>(b[2]) * this->BlockCounts[1] + b[1]) * this->BlockCounts[0] + b[0]) * components];
          for (int c = 0; c < components; ++c)
          {
            minimum[c] = std::min(minimum[c], row[i * components + c]);
          }
        }
      }
    }
  }
}

//------------------------------------------------------------------------------
void SampledRegionSource::GetReachBounds(double lower[3], double upper[3]) const
{
  for (int axis = 0; axis < 3; ++axis)
  {
    lower[axis] = std::numeric_limits<double>::infinity();
    upper[axis] = -std::numeric_limits<double>::infinity();
  }
  for (int corner = 0; corner < 8; ++corner)
  {
    const double index[3] = { double(this->Extent[(corner & 1) ? 1 : 0]), double(this->Extent[((corner >> 1) & 1) ? 3 : 2]),
      double(this->Extent[((corner >> 2) & 1) ? 5 : 4]) };
    double ras[3];
    Transform(this->IJKToRAS, index, ras);
    for (int axis = 0; axis < 3; ++axis)
    {
      lower[axis] = std::min(lower[axis], ras[axis] - this->BandWidth);
      upper[axis] = std::max(upper[axis], ras[axis] + this->BandWidth);
    }
  }
}

//------------------------------------------------------------------------------
float SampledRegionSource::Evaluate(double i, double j, double k) const
{
  const double local[3] = { i - this->Extent[0], j - this->Extent[2], k - this->Extent[4] };
  int base[3];
  double f[3];
  bool inside = true;
  for (int axis = 0; axis < 3; ++axis)
  {
    const double floor = std::floor(local[axis]);
    if (!(floor >= -1.0 && floor < this->Size[axis]))
    {
      return this->Far; // no corner within the box
    }
    base[axis] = static_cast<int>(floor);
    f[axis] = local[axis] - floor;
    inside &= base[axis] >= 0 && base[axis] + 1 < this->Size[axis];
  }
  const size_t strideY = static_cast<size_t>(this->Size[0]) * this->Components;
  const size_t strideZ = strideY * this->Size[1];
  float result = -std::numeric_limits<float>::infinity();
  for (int c = 0; c < this->Components; ++c)
  {
    double corners[8];
    for (int corner = 0; corner < 8; ++corner)
    {
      const int ci = base[0] + (corner & 1);
      const int cj = base[1] + ((corner >> 1) & 1);
      const int ck = base[2] + ((corner >> 2) & 1);
      if (inside || (ci >= 0 && cj >= 0 && ck >= 0 && ci < this->Size[0] && cj < this->Size[1] && ck < this->Size[2]))
      {
        corners[corner] = this->Values[ck * strideZ + cj * strideY + static_cast<size_t>(ci) * this->Components + c];
      }
      else
      {
        corners[corner] = this->Far;
      }
    }
    const double x00 = corners[0] + f[0] * (corners[1] - corners[0]);
    const double x10 = corners[2] + f[0] * (corners[3] - corners[2]);
    const double x01 = corners[4] + f[0] * (corners[5] - corners[4]);
    const double x11 = corners[6] + f[0] * (corners[7] - corners[6]);
    const double y0 = x00 + f[1] * (x10 - x00);
    const double y1 = x01 + f[1] * (x11 - x01);
    result = std::max(result, static_cast<float>(y0 + f[2] * (y1 - y0)));
  }
  return result;
}

//------------------------------------------------------------------------------
double SampledRegionSource::Distance(const double point[3]) const
{
  double index[3];
  Transform(this->RASToIJK, point, index);
  return this->Evaluate(index[0], index[1], index[2]);
}

//------------------------------------------------------------------------------
bool SampledRegionSource::MayReach(const double center[3], double radius) const
{
  double index[3];
  Transform(this->RASToIJK, center, index);
  int lower[3];
  int upper[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    // A ball of this radius spans radius * |row| along index axis `axis`;
    // interpolation reads the next voxel up.
    const double halfWidth = radius *
      std::sqrt(this->RASToIJK[axis][0] * this->RASToIJK[axis][0] + this->RASToIJK[axis][1] * this->RASToIJK[axis][1] +
        this->RASToIJK[axis][2] * this->RASToIJK[axis][2]);
    const double low = std::floor(index[axis] - halfWidth) - this->Extent[2 * axis];
    const double high = std::floor(index[axis] + halfWidth) - this->Extent[2 * axis];
    if (high < 0.0 || low >= this->Size[axis])
    {
      return false;
    }
    lower[axis] = std::max(0, static_cast<int>(low)) / BlockSize;
    upper[axis] = std::min(this->Size[axis] - 1, static_cast<int>(high)) / BlockSize;
  }
  // The region's value anywhere in the ball is at least the largest of the
  // components' smallest values there.
  float bound = -std::numeric_limits<float>::infinity();
  for (int c = 0; c < this->Components; ++c)
  {
    float smallest = std::numeric_limits<float>::infinity();
    for (int bk = lower[2]; bk <= upper[2]; ++bk)
    {
      for (int bj = lower[1]; bj <= upper[1]; ++bj)
      {
        for (int bi = lower[0]; bi <= upper[0]; ++bi)
        {
          smallest = std::min(smallest,
            this->BlockMinimum[((static_cast<size_t>(bk) * this->BlockCounts[1] + bj) * this->BlockCounts[0] + bi) * this->Components + c]);
        }
      }
    }
    bound = std::max(bound, smallest);
  }
  return bound < this->BandWidth;
}

//------------------------------------------------------------------------------
void SampledRegionSource::BrickDistances(const double origin[3], const double*, double, const float* offsets, int, int, float* distances) const
{
  for (int n = 0; n < SamplesPerBrick; ++n)
  {
    const double point[3] = { origin[0] + offsets[n], origin[1] + offsets[SamplesPerBrick + n], origin[2] + offsets[2 * SamplesPerBrick + n] };
    double index[3];
    Transform(this->RASToIJK, point, index);
    distances[n] = this->Evaluate(index[0], index[1], index[2]);
  }
  if (!this->Keep)
  {
    return;
  }
  // The brick's own index: its first sample's sub-voxel index over BrickSize.
  double sub[3];
  Transform(this->RASToSubIJK, origin, sub);
  vtkIdType brick[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    brick[axis] = static_cast<vtkIdType>(std::lround(sub[axis])) / BrickSize;
  }
  const vtkIdType brickId = (brick[2] * this->BrickDimensions[1] + brick[1]) * this->BrickDimensions[0] + brick[0];
  if (!this->KeepBricks[brickId])
  {
    return;
  }
  const vtkVolumeCutProtection::Brick* kept = this->Keep->GetBrick(brickId);
  if (!kept)
  {
    return;
  }
  for (int n = 0; n < SamplesPerBrick; ++n)
  {
    distances[n] = std::max(distances[n], static_cast<float>(this->KeepMargin - kept->Distance[n] * this->Quantum));
  }
}
} // namespace vtkVolumeCutSweeps
