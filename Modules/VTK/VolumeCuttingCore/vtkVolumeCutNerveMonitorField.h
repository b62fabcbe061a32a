// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to vtkVolumeCuttingCore (not installed, not wrapped).
/**
 * @class   vtkVolumeCutNerveMonitorField
 * @brief   One monitored structure's signed distance field, immutable once built.
 *
 * What the cut protects: the shield keeps the structure's smoothed interior
 * and every voxel of it whole. The smoothed surface is the zero set of the
 * trilinear interpolation of its levels (vtkVolumeCutLabelSurface, closed
 * across the slices and divided by their gradient's length as
 * vtkVolumeCutProtection does). Foot points on it are taken where it
 * crosses the edges between voxel centres (exact on the trilinear zero set)
 * and where Newton's iteration from each voxel next to it lands, and each
 * voxel's nearest foot point is propagated outwards by raster sweeps over
 * the 26 neighbours (vector propagation after Danielsson, 1980, with
 * sub-voxel foot points): that distance is interpolated at query time. The
 * voxel cubes' distance is exact: a separable transform (lower envelopes of
 * parabolas, Felzenszwalb and Huttenlocher 2012, with vertices half a voxel
 * off, since a cube's distance is zero across it) gives each voxel its
 * nearest cube, of the structure outside it and of the free voxels inside,
 * and a query measures to the cubes of the eight samples around it. The
 * distance is the smaller of the two. Samples within Range are kept in
 * bricks of 8^3 cells whose 9^3 corners are stored together, so that a
 * lookup reads one brick.
 */
#ifndef vtkVolumeCutNerveMonitorField_h
#define vtkVolumeCutNerveMonitorField_h

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

class vtkVolumeCutNerveMonitorField
{
public:
  static constexpr int BrickCells = 8;
  static constexpr int BrickSamples = BrickCells + 1;

  /**
   * Build from a binary mask (1: the structure) of dimensions voxels, x
   * fastest, whose first voxel is anatomy voxel origin; labelBox: the
   * structure's voxels' bounds in the mask (inclusive). The mask must reach
   * range mm beyond the box (clipped by the scan). nullptr for an empty box.
   */
  static std::unique_ptr<const vtkVolumeCutNerveMonitorField> Build(const uint16_t* mask, const int dimensions[3], const int origin[3],
    const double spacing[3], const int labelBox[6], double smoothing, double range);

  /// Signed distance (mm) at a continuous anatomy IJK position; beyond the stored band a lower bound of at least Range.
  double GetDistance(const double ijk[3]) const;

  size_t GetMemorySize() const;
  /// Number of foot points found on the surface.
  size_t GetNumberOfFootPoints() const { return this->NumberOfFootPoints; }

private:
  double GetFarDistance(const double ijk[3]) const;

  int Origin[3] = { 0, 0, 0 };
  int Dimensions[3] = { 0, 0, 0 };
  int BrickCounts[3] = { 0, 0, 0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  double Range = 0.0;
  /// The structure's voxels' bounds (anatomy IJK), for the lower bound beyond the band.
  double LabelLower[3] = { 0.0, 0.0, 0.0 };
  double LabelUpper[3] = { 0.0, 0.0, 0.0 };
  /// Brick index by brick (x fastest), -1 where nothing is within Range.
  std::vector<int32_t> Directory;
  std::vector<float> Bricks;
  /// Per sample of Bricks, the voxel whose cube is nearest (of the structure's outside it, of the free voxels
  /// inside): its offset from the sample and the side, packed (-1: none).
  std::vector<int32_t> NearestCubes;
  size_t NumberOfFootPoints = 0;
};

#endif
