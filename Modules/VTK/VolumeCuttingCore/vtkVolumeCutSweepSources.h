// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore (not installed, not wrapped): the tool sweeps
// that vtkVolumeCutField's writer merges into the field, a brick at a time.
#ifndef vtkVolumeCutSweepSources_h
#define vtkVolumeCutSweepSources_h

#include "vtkVolumeCutFieldDistanceSource.h"

#include <vector>

class vtkMatrix4x4;
class vtkVolumeCutTool;

namespace vtkVolumeCutSweeps
{
/// A rigid pose: tool-to-RAS rotation and translation.
struct RigidPose
{
  double Rotation[3][3];
  double Translation[3];
};

/// False for a matrix that is missing, not finite or not a rigid motion
/// (orthonormal rotation without reflection).
bool ToRigidPose(vtkMatrix4x4* matrix, RigidPose& pose);

/**
 * Poses from start to end, linear in translation and spherical in rotation,
 * close enough that no point within boundingRadius of the tool's origin moves
 * more than step from one to the next (so the union of the copies covers the
 * continuous sweep). At most 100001 poses.
 */
std::vector<RigidPose> InterpolatePoses(const RigidPose& start, const RigidPose& end, double boundingRadius, double step);

/// Distance from p to the segment from a to a + ab.
double DistanceToSegment(const double p[3], const double a[3], const double ab[3], double abLength2);

/// The sweep of a sphere: a capsule, written a brick at a time with a
/// vectorised distance loop.
class CapsuleSource : public vtkVolumeCutField::BrickDistanceSource
{
public:
  /// startCovered: the ball at p0 was cut already (a continued path), so
  /// only samples ahead of p0 along the segment can change.
  CapsuleSource(const double p0[3], const double p1[3], double radius, double reach, bool startCovered);
  void GetReachBounds(double lower[3], double upper[3]) const override;
  double Distance(const double point[3]) const override;
  bool MayReach(const double center[3], double radius) const override;
  void BrickDistances(const double origin[3], const double* center, double radius, const float* offsets, int firstSlice, int lastSlice,
    float* distances) const override;

private:
  double P0[3];
  double P1[3];
  double Ab[3];
  double AbLength2 = 0.0;
  double Radius;
  double Reach;
  bool StartCovered;
};

/// The sweep of any tool: the tool at poses close enough that the union of
/// its copies covers the continuous sweep to within half a sub-voxel. Written
/// a brick at a time: each copy that comes within the band of a brick (the
/// tool's own distance at the brick's centre says so) is evaluated at all its
/// samples in one batch (vtkVolumeCutTool::EvaluateDistances).
///
/// A pure translation (motion, RAS; nullptr otherwise) of a tool with a
/// closed form for its translated sweep is evaluated once per brick instead
/// of once per copy (vtkVolumeCutTool::EvaluateTranslatedDistances, within
/// step of the exact sweep). A sweep that continues the previous one
/// (startCovered: the field holds the copy at the first pose already) skips
/// that copy; a continuing translation moreover skips every brick the tool
/// leaves behind (vtkVolumeCutTool::IsLeftBehind): there no copy is nearer
/// than the first one, which the field holds. A tool moving along its path
/// therefore costs the bricks ahead of it, not all it touches.
class SweptToolSource : public vtkVolumeCutField::BrickDistanceSource
{
public:
  SweptToolSource(vtkVolumeCutTool* tool, std::vector<RigidPose> poses, double band, double step, bool startCovered, const double* motion);
  void GetReachBounds(double lower[3], double upper[3]) const override;
  bool MayReach(const double center[3], double radius) const override;
  void BrickDistances(const double origin[3], const double center[3], double radius, const float* offsets, int firstSlice, int lastSlice,
    float* distances) const override;
  /// The tool's own bounds (vtkVolumeCutTool::BoundTranslatedDistances) for
  /// a translation with a closed form.
  bool BoundSlices(const double origin[3], const float* offsets, double bounds[vtkVolumeCutField::BrickSize]) const override;
  double Distance(const double point[3]) const override;

private:
  /// Whether the copy of the tool at pose reaches into the band around the ball.
  bool Meets(const RigidPose& pose, const double center[3], double radius) const;
  /// Which copies meet the ball (cached for the brick MayReach saw last).
  const std::vector<char>& Copies(const double center[3], double radius) const;

  vtkVolumeCutTool* Tool;
  std::vector<RigidPose> Poses;
  double Band;
  double Reach;
  double HalfExtents[3];
  size_t FirstCopy;
  double Step;
  bool Translation = false;
  bool ClosedForm = false;
  bool UseMotion = false;
  double Motion[3] = { 0.0, 0.0, 0.0 };
  mutable std::vector<char> Meeting;
  mutable double MeetingCenter[3] = { 0.0, 0.0, 0.0 };
  mutable double MeetingRadius = -1.0;
};
} // namespace vtkVolumeCutSweeps

#endif
