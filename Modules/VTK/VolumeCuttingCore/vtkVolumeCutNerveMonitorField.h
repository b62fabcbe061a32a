// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to vtkVolumeCuttingCore (not installed, not wrapped).
/**
 * @class   vtkVolumeCutNerveMonitorField
 * @brief   One monitored structure's signed distance field, immutable once built.
 *
 * Two distances per query. The surface distance, the monitor's reading: to
 * the structure's smoothed surface, the zero set of the trilinear
 * interpolation of its levels (vtkVolumeCutLabelSurface, closed across the
 * slices and divided by their gradient's length as vtkVolumeCutProtection
 * does). Foot points on it are taken where it crosses the edges between
 * voxel centres (exact on the trilinear zero set) and where Newton's
 * iteration from each voxel next to it lands, and each voxel's nearest foot
 * point is propagated outwards by raster sweeps over the 26 neighbours
 * (vector propagation after Danielsson, 1980, with sub-voxel foot points):
 * that distance is interpolated at query time.
 *
 * The shield distance, for contact: the shield keeps the smoothed interior
 * and every voxel of the structure whole, so the cut stops at the nearer of
 * the smoothed surface and the voxel cubes. The cubes' distance is exact: a
 * separable transform (lower envelopes of parabolas, Felzenszwalb and
 * Huttenlocher 2012, with vertices half a voxel off, since a cube's distance
 * is zero across it) gives each voxel its nearest cube, of the structure
 * outside it and of the free voxels inside, and a query measures to the
 * cubes of the eight samples around it. Contact needs it only as far from
 * the cubes as a burr's radius reaches, so the nearest cubes are kept only
 * in the bricks within ContactRange of them (and the transform runs over
 * that box alone); beyond, where the cubes are farther than ContactRange,
 * the shield distance is the surface distance (exact wherever that is below
 * ContactRange, else both exceed it). With no smoothing the shield is the
 * cubes alone, and both distances are theirs.
 *
 * Samples within Range are kept in bricks of 8^3 cells whose 9^3 corners are
 * stored together, so that a lookup reads one brick.
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
   * range mm beyond the box (clipped by the scan); contactRange (at most
   * range): how far from the voxel cubes the shield distance is exact.
   * nullptr for an empty box.
   */
  static std::unique_ptr<const vtkVolumeCutNerveMonitorField> Build(const uint16_t* mask, const int dimensions[3], const int origin[3],
    const double spacing[3], const int labelBox[6], double smoothing, double range, double contactRange);

  /// Signed surface distance (mm) at a continuous anatomy IJK position; beyond the stored band a lower bound of at least Range.
  double GetDistance(const double ijk[3]) const;
  /// The surface distance and the shield distance (never more than the surface distance) at a position.
  void GetDistances(const double ijk[3], double& surface, double& shield) const;
  /// How much nearer than the surface the shield may be anywhere (mm): a query farther than this needs no shield distance.
  double GetMaximumProtrusion() const { return this->MaximumProtrusion; }

  size_t GetMemorySize() const;
  /// Number of foot points found on the surface.
  size_t GetNumberOfFootPoints() const { return this->NumberOfFootPoints; }

private:
  double GetFarDistance(const double ijk[3]) const;
  /// The first of the eight samples around a position in its stored brick, with the position in it; nullptr and
  /// the distance where no brick is stored there.
  const float* Locate(const double ijk[3], double local[3], int brick[3], int cell[3], double t[3], double& outside) const;
  static double Interpolate(const float* samples, const double t[3]);
  /// The shield distance from the cubes nearest to the corners of a stored brick's cell, at most smoothed.
  double GetShieldDistance(const int32_t* nearest, const int brick[3], const int cell[3], const double local[3], const double t[3],
    double smoothed) const;

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
  /// Per stored brick, its bricks of NearestCubes (-1: no cube within ContactRange of it).
  std::vector<int32_t> CubeDirectory;
  /// Per sample of the bricks near the cubes, the voxel whose cube is nearest (of the structure's outside it, of
  /// the free voxels inside): its offset from the sample and the side, packed (-1: none).
  std::vector<int32_t> NearestCubes;
  /// No smoothing: the surface is the voxel cubes (the samples hold no smoothed distance).
  bool SurfaceIsCubes = false;
  double MaximumProtrusion = 0.0;
  size_t NumberOfFootPoints = 0;
};

#endif
