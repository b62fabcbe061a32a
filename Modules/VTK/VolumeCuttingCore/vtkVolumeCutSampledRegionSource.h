// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore (not installed, not wrapped): a region given
// as signed distances sampled on the anatomy's voxels, written into
// vtkVolumeCutField a brick at a time (vtkVolumeCutField::CutSampledRegion).
#ifndef vtkVolumeCutSampledRegionSource_h
#define vtkVolumeCutSampledRegionSource_h

#include "vtkVolumeCutFieldDistanceSource.h"

#include <vector>

class vtkVolumeCutProtection;

namespace vtkVolumeCutSweeps
{
/**
 * The intersection of the regions where each of several sampled signed
 * distances (mm, negative inside) is negative: at any point, the maximum of
 * the components, each interpolated trilinearly between the anatomy voxels
 * (so the crease where two of them meet stays sharp), minus the voxel cubes
 * of a keep-out set grown by a margin (the union of cubes is exact, as the
 * shield's).
 */
class SampledRegionSource : public vtkVolumeCutField::BrickDistanceSource
{
public:
  /**
   * values: components-interleaved floats over the anatomy voxel box
   * extent (inclusive; x fastest). rasToIJK: RAS to anatomy IJK.
   * keep: nullptr, or a protection on the field's geometry whose shield
   * marks the voxels never removed. rasToSubIJK, brickDimensions and
   * quantum: the field's sub-voxel grid, bricks and unit, for the keep-out
   * bricks. keepMargin (mm): how far the region stays from the kept cubes.
   * keepBricks: by brick ID, whether a kept cube comes within the band.
   */
  SampledRegionSource(const float* values, int components, const int extent[6], const double rasToIJK[4][4], const double ijkToRAS[4][4],
    double bandWidth, vtkVolumeCutProtection* keep, const double rasToSubIJK[4][4], const int brickDimensions[3], double quantum,
    double keepMargin, const std::vector<char>& keepBricks);
  void GetReachBounds(double lower[3], double upper[3]) const override;
  double Distance(const double point[3]) const override;
  bool MayReach(const double center[3], double radius) const override;
  void BrickDistances(const double origin[3], const double center[3], double radius, const float* offsets, int firstSlice, int lastSlice,
    float* distances) const override;

private:
  /// Maximum over the components, interpolated at anatomy index (i, j, k).
  float Evaluate(double i, double j, double k) const;

  const float* Values;
  int Components;
  int Extent[6];
  int Size[3];
  double RASToIJK[4][4];
  double IJKToRAS[4][4];
  double RASToSubIJK[4][4];
  int BrickDimensions[3];
  double Quantum;
  double BandWidth;
  double KeepMargin;
  /// Farther than any distance the field keeps: voxels outside the box.
  float Far;
  vtkVolumeCutProtection* Keep;
  const std::vector<char>& KeepBricks;
  /// Per block of BlockSize^3 voxels and component: the smallest value (a
  /// lower bound of the interpolation inside the block's cells).
  static constexpr int BlockSize = 4;
  int BlockCounts[3];
  std::vector<float> BlockMinimum;
};
} // namespace vtkVolumeCutSweeps

#endif
