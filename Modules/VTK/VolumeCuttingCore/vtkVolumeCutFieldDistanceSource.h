// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore (not installed, not wrapped): the interface
// through which a tool sweep tells vtkVolumeCutField's writer where it
// reaches and how far each sample is from it.
#ifndef vtkVolumeCutFieldDistanceSource_h
#define vtkVolumeCutFieldDistanceSource_h

#include "vtkVolumeCutField.h"

/// What ApplyDistance needs to know of a tool sweep: where it reaches and its
/// signed distance (mm, negative inside) at a point.
struct vtkVolumeCutField::DistanceSource
{
  virtual ~DistanceSource() = default;
  /// RAS box holding every point within reach (the swept tool grown by the band).
  virtual void GetReachBounds(double lower[3], double upper[3]) const = 0;
  /// Distance at one point (contacts).
  virtual double Distance(const double point[3]) const = 0;
};

/// A sweep written row by row, within the exact stretch of each grid row in
/// reach: for sources whose work per sample is costly and tied to the voxel
/// (material removal looks up each brick's exposure), not to the brick.
struct vtkVolumeCutField::RowDistanceSource : vtkVolumeCutField::DistanceSource
{
  /// Stretch [first, last] (row index units) of the row origin + t * step within reach.
  virtual bool RowInterval(const double origin[3], double& first, double& last) const = 0;
  /// Distances at t = first .. last into distances[0 .. last - first].
  virtual void RowDistances(const double origin[3], int first, int last, float* distances) const = 0;
};

/// A sweep written a brick at a time: for tools whose distance is cheap
/// everywhere, one long vectorised loop per brick costs less than setting up
/// many short rows.
struct vtkVolumeCutField::BrickDistanceSource : vtkVolumeCutField::DistanceSource
{
  /// False when no point within radius of center is within reach.
  virtual bool MayReach(const double center[3], double radius) const = 0;
  /// Distances at origin + offsets, the field's brick sample offsets (x, y
  /// and z runs of BrickSize^3 each); the samples lie within radius of center.
  /// Only those of the z-slices firstSlice..lastSlice (BrickSize^2 samples
  /// of one k each, contiguous) are read; a source may leave others unwritten.
  virtual void BrickDistances(const double origin[3], const double center[3], double radius, const float* offsets, int firstSlice,
    int lastSlice, float* distances) const = 0;
  /// Lower bounds (mm) of BrickDistances over each z-slice of the brick, or
  /// false (the default) when the source cannot tell. The writer skips the
  /// slices whose bound is beyond the band, or above every value the field
  /// holds there: their distances would change nothing.
  virtual bool BoundSlices(const double /*origin*/[3], const float* /*offsets*/, double /*bounds*/[vtkVolumeCutField::BrickSize]) const
  {
    return false;
  }
};

#endif
