// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingSoftCut (not installed, not wrapped): the CT as the
// resection planner reads it.
#ifndef vtkVolumeCutAnatomySampler_h
#define vtkVolumeCutAnatomySampler_h

#include "vtkDataArray.h"
#include "vtkVolumeCutSoftCutVectors.h"

#include <algorithm>
#include <cmath>
#include <vector>

/**
 * The CT in the planner's grid frame (mm along the voxel axes, from voxel 0):
 * trilinear values and gradients anywhere, float copies of voxel boxes, and
 * where the skin's iso-surface crosses a line. The outline and its normals
 * read a few thousand samples around the outline; they come from a float
 * copy of that neighbourhood (CacheVoxels), since reading the image's array
 * through its virtual accessor there would cost more than the shape.
 */
class vtkVolumeCutAnatomySampler
{
public:
  using Vec = vtkVolumeCutSoftCut::Vec;

  vtkVolumeCutAnatomySampler() = default;
  vtkVolumeCutAnatomySampler(const vtkVolumeCutAnatomySampler&) = delete;
  void operator=(const vtkVolumeCutAnatomySampler&) = delete;

  // The anatomy's grid: RAS = Origin + Axes * (Spacing .* ijk), Axes orthonormal.
  int Dims[3] = { 0, 0, 0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Axes[3][3];
  double Origin[3] = { 0.0, 0.0, 0.0 };
  vtkDataArray* Scalars = nullptr;

  double MinSpacing() const { return std::min({ this->Spacing[0], this->Spacing[1], this->Spacing[2] }); }
  double MaxSpacing() const { return std::max({ this->Spacing[0], this->Spacing[1], this->Spacing[2] }); }

  Vec ToRAS(const Vec& x) const
  {
    Vec ras;
    for (int row = 0; row < 3; ++row)
    {
      ras[row] = this->Origin[row] + this->Axes[row][0] * x[0] + this->Axes[row][1] * x[1] + this->Axes[row][2] * x[2];
    }
    return ras;
  }
  Vec FromRAS(const Vec& ras) const
  {
    const Vec d = { ras[0] - this->Origin[0], ras[1] - this->Origin[1], ras[2] - this->Origin[2] };
    return { this->Axes[0][0] * d[0] + this->Axes[1][0] * d[1] + this->Axes[2][0] * d[2],
      this->Axes[0][1] * d[0] + this->Axes[1][1] * d[1] + this->Axes[2][1] * d[2],
      this->Axes[0][2] * d[0] + this->Axes[1][2] * d[1] + this->Axes[2][2] * d[2] };
  }
  Vec VectorToRAS(const Vec& v) const
  {
    Vec ras;
    for (int row = 0; row < 3; ++row)
    {
      ras[row] = this->Axes[row][0] * v[0] + this->Axes[row][1] * v[1] + this->Axes[row][2] * v[2];
    }
    return ras;
  }

  /// Drops the float copy (the CT may have changed): samples read the CT's array again.
  void ForgetCache();

  /**
   * Makes the float copy of box (anatomy voxel indices, inclusive; clipped
   * to the volume) that samples read where they can; false for a scalar
   * type that cannot be copied (then nothing is cached).
   */
  bool CacheVoxels(const int box[6]);

  /// Copies the anatomy's voxels in box (clipped to the volume) into floats: out has the box's size.
  bool CopyVoxels(int box[6], std::vector<float>& out) const;

  /// Trilinear CT value at a grid-frame point, from the whole anatomy (inline:
  /// the gradients and the skin search call it hundreds of times a point).
  double Sample(const Vec& x) const
  {
    double index[3];
    int base[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      index[axis] = x[axis] / this->Spacing[axis];
      base[axis] = static_cast<int>(std::floor(index[axis]));
      index[axis] -= base[axis];
    }
    double value = 0.0;
    for (int corner = 0; corner < 8; ++corner)
    {
      const int d[3] = { corner & 1, (corner >> 1) & 1, (corner >> 2) & 1 };
      const double w = (d[0] ? index[0] : 1.0 - index[0]) * (d[1] ? index[1] : 1.0 - index[1]) * (d[2] ? index[2] : 1.0 - index[2]);
      if (w != 0.0)
      {
        value += w * this->Voxel(base[0] + d[0], base[1] + d[1], base[2] + d[2]);
      }
    }
    return value;
  }

  /// Gradient (HU/mm, grid frame) by central differences one voxel apart.
  Vec Gradient(const Vec& x) const;

  /**
   * The gradient averaged over the (2r+1)^3 points around x spaced the
   * largest voxel spacing apart along every axis (a cube in mm, so that a
   * curved surface's normal is not tilted towards the finer axes): the sum of
   * their central differences telescopes to the layers r and r + 1 steps away
   * on either side.
   */
  Vec BoxGradient(const Vec& x, int r) const;

  /**
   * The skin point on the line x + t * direction nearest t = 0 within
   * |t| <= reach (mm): where the CT crosses the iso-value. False if none.
   */
  bool FindCrossing(const Vec& x, const Vec& direction, double reach, double iso, Vec& found) const;

  /// A point onto the skin along the gradient; false if the skin is beyond reach.
  bool ToSkin(const Vec& x, double reach, double iso, Vec& onSkin) const;

private:
  /// CT value of anatomy voxel (i, j, k), clamped to the volume.
  double Voxel(int i, int j, int k) const
  {
    i = std::max(0, std::min(this->Dims[0] - 1, i));
    j = std::max(0, std::min(this->Dims[1] - 1, j));
    k = std::max(0, std::min(this->Dims[2] - 1, k));
    if (i >= this->LocalBox[0] && i <= this->LocalBox[1] && j >= this->LocalBox[2] && j <= this->LocalBox[3] && k >= this->LocalBox[4] &&
      k <= this->LocalBox[5])
    {
      const int sx = this->LocalBox[1] - this->LocalBox[0] + 1;
      const int sy = this->LocalBox[3] - this->LocalBox[2] + 1;
      return this->Local[(static_cast<size_t>(k - this->LocalBox[4]) * sy + (j - this->LocalBox[2])) * sx + (i - this->LocalBox[0])];
    }
    return this->Scalars->GetComponent((static_cast<vtkIdType>(k) * this->Dims[1] + j) * this->Dims[0] + i, 0);
  }

  int LocalBox[6] = { 0, -1, 0, -1, 0, -1 };
  std::vector<float> Local;
};

#endif
