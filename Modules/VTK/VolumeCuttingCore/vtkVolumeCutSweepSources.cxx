// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutSweepSources.h"
#include "vtkVolumeCutKernels.h"

#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkVolumeCutTool.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vtkVolumeCutSweeps
{
namespace
{
constexpr int BrickSize = vtkVolumeCutField::BrickSize;
constexpr int SamplesPerSlice = BrickSize * BrickSize;
constexpr int SamplesPerBrick = BrickSize * SamplesPerSlice;

/// A brick's samples (origin + offsets) from first on, count of them, in the
/// frame of the tool at pose.
void ToToolFrame(const RigidPose& pose, const double origin[3], const float* offsets, int first, int count, float local[3][SamplesPerBrick])
{
  float rotation[3][3];
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      rotation[row][column] = static_cast<float>(pose.Rotation[row][column]);
    }
  }
  const float w0[3] = { static_cast<float>(origin[0] - pose.Translation[0]), static_cast<float>(origin[1] - pose.Translation[1]),
    static_cast<float>(origin[2] - pose.Translation[2]) };
  vtkVolumeCutKernels::Get().ToToolFrame(rotation, w0, offsets + first, count, local[0] + first, local[1] + first, local[2] + first);
}
} // namespace

//------------------------------------------------------------------------------
double DistanceToSegment(const double p[3], const double a[3], const double ab[3], double abLength2)
{
  double ap[3] = { p[0] - a[0], p[1] - a[1], p[2] - a[2] };
  double t = abLength2 > 0.0 ? (ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / abLength2 : 0.0;
  t = std::min(1.0, std::max(0.0, t));
  const double d[3] = { ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2] };
  return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

//------------------------------------------------------------------------------
bool ToRigidPose(vtkMatrix4x4* matrix, RigidPose& pose)
{
  if (!matrix)
  {
    return false;
  }
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      pose.Rotation[row][column] = matrix->GetElement(row, column);
    }
    pose.Translation[row] = matrix->GetElement(row, 3);
  }
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      if (!std::isfinite(matrix->GetElement(row, column)))
      {
        return false;
      }
    }
  }
  // Rigid: orthonormal columns, no reflection.
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      double dot = 0.0;
      for (int row = 0; row < 3; ++row)
      {
        dot += pose.Rotation[row][a] * pose.Rotation[row][b];
      }
      if (std::abs(dot - (a == b ? 1.0 : 0.0)) > 1e-6)
      {
        return false;
      }
    }
  }
  return vtkMath::Determinant3x3(pose.Rotation) > 0.0;
}

//------------------------------------------------------------------------------
std::vector<RigidPose> InterpolatePoses(const RigidPose& start, const RigidPose& end, double boundingRadius, double step)
{
  // Rotation between the poses as a quaternion, interpolated spherically.
  double q0[4];
  double q1[4];
  vtkMath::Matrix3x3ToQuaternion(start.Rotation, q0);
  vtkMath::Matrix3x3ToQuaternion(end.Rotation, q1);
  double cosine = q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3];
  if (cosine < 0.0)
  {
    cosine = -cosine;
    for (double& component : q1)
    {
      component = -component;
    }
  }
  const double angle = 2.0 * std::acos(std::min(1.0, cosine));
  const double jump = std::sqrt(vtkMath::Distance2BetweenPoints(start.Translation, end.Translation));
  const double travel = jump + angle * boundingRadius;
  const int intervals = std::max(1, std::min(100000, static_cast<int>(std::ceil(travel / step))));
  std::vector<RigidPose> poses(static_cast<size_t>(intervals) + 1);
  for (int n = 0; n <= intervals; ++n)
  {
    const double t = static_cast<double>(n) / intervals;
    double q[4];
    const double half = 0.5 * angle;
    if (half < 1e-9)
    {
      std::copy(q0, q0 + 4, q);
    }
    else
    {
      const double w0 = std::sin((1.0 - t) * half) / std::sin(half);
      const double w1 = std::sin(t * half) / std::sin(half);
      for (int c = 0; c < 4; ++c)
      {
        q[c] = w0 * q0[c] + w1 * q1[c];
      }
    }
    vtkMath::QuaternionToMatrix3x3(q, poses[n].Rotation);
    for (int axis = 0; axis < 3; ++axis)
    {
      poses[n].Translation[axis] = (1.0 - t) * start.Translation[axis] + t * end.Translation[axis];
    }
  }
  return poses;
}

//------------------------------------------------------------------------------
CapsuleSource::CapsuleSource(const double p0[3], const double p1[3], double radius, double reach, bool startCovered)
  : Radius(radius)
  , Reach(reach)
  , StartCovered(startCovered)
{
  for (int axis = 0; axis < 3; ++axis)
  {
    this->P0[axis] = p0[axis];
    this->P1[axis] = p1[axis];
    this->Ab[axis] = p1[axis] - p0[axis];
  }
  this->AbLength2 = this->Ab[0] * this->Ab[0] + this->Ab[1] * this->Ab[1] + this->Ab[2] * this->Ab[2];
}

//------------------------------------------------------------------------------
void CapsuleSource::GetReachBounds(double lower[3], double upper[3]) const
{
  for (int axis = 0; axis < 3; ++axis)
  {
    lower[axis] = std::min(this->P0[axis], this->P1[axis]) - this->Reach;
    upper[axis] = std::max(this->P0[axis], this->P1[axis]) + this->Reach;
  }
}

//------------------------------------------------------------------------------
double CapsuleSource::Distance(const double point[3]) const
{
  return DistanceToSegment(point, this->P0, this->Ab, this->AbLength2) - this->Radius;
}

//------------------------------------------------------------------------------
bool CapsuleSource::MayReach(const double center[3], double radius) const
{
  if (DistanceToSegment(center, this->P0, this->Ab, this->AbLength2) - radius > this->Reach)
  {
    return false;
  }
  if (this->StartCovered && this->AbLength2 > 0.0)
  {
    const double ahead = (center[0] - this->P0[0]) * this->Ab[0] + (center[1] - this->P0[1]) * this->Ab[1] + (center[2] - this->P0[2]) * this->Ab[2];
    return ahead + radius * std::sqrt(this->AbLength2) > 0.0;
  }
  return true;
}

//------------------------------------------------------------------------------
void CapsuleSource::BrickDistances(
  const double origin[3], const double* /*center*/, double /*radius*/, const float* offsets, int, int, float* distances) const
{
  const float w0[3] = { static_cast<float>(origin[0] - this->P0[0]), static_cast<float>(origin[1] - this->P0[1]),
    static_cast<float>(origin[2] - this->P0[2]) };
  const float ab[3] = { static_cast<float>(this->Ab[0]), static_cast<float>(this->Ab[1]), static_cast<float>(this->Ab[2]) };
  const float inverseLength2 = this->AbLength2 > 0.0 ? static_cast<float>(1.0 / this->AbLength2) : 0.0f;
  // Behind the start of a continued path the field holds the ball already:
  // far away there means unchanged.
  const float behindLimit = this->StartCovered && this->AbLength2 > 0.0 ? 0.0f : -std::numeric_limits<float>::infinity();
  vtkVolumeCutKernels::Get().CapsuleBrickDistances(
    w0, ab, inverseLength2, static_cast<float>(this->Radius), behindLimit, static_cast<float>(2.0 * this->Reach), offsets, distances);
}

//------------------------------------------------------------------------------
SweptToolSource::SweptToolSource(
  vtkVolumeCutTool* tool, std::vector<RigidPose> poses, double band, double step, bool startCovered, const double* motion)
  : Tool(tool)
  , Poses(std::move(poses))
  , Band(band)
  , Reach(tool->GetBoundingRadius() + band)
  , FirstCopy(startCovered && this->Poses.size() > 1 ? 1 : 0)
  , Step(step)
{
  if (motion && !this->Poses.empty())
  {
    // The motion in the first copy's frame.
    const RigidPose& first = this->Poses.front();
    for (int row = 0; row < 3; ++row)
    {
      this->Motion[row] = first.Rotation[0][row] * motion[0] + first.Rotation[1][row] * motion[1] + first.Rotation[2][row] * motion[2];
    }
    this->Translation = true;
    this->UseMotion = startCovered;
    // Whether the tool has a closed form for its translated sweep (asked at one point).
    const float origin = 0.0f;
    float distance = 0.0f;
    this->ClosedForm = tool->EvaluateTranslatedDistances(this->Motion, step, &origin, &origin, &origin, 1, &distance);
  }
  tool->GetLocalHalfExtents(this->HalfExtents);
  this->Meeting.assign(this->Poses.size(), 0);
}

//------------------------------------------------------------------------------
void SweptToolSource::GetReachBounds(double lower[3], double upper[3]) const
{
  // Each copy's local box, turned into the grid's axes, plus the band (and
  // Meets' margin for rounding): no sample outside it comes within the band.
  for (int axis = 0; axis < 3; ++axis)
  {
    lower[axis] = std::numeric_limits<double>::max();
    upper[axis] = -std::numeric_limits<double>::max();
  }
  for (const RigidPose& pose : this->Poses)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      double extent = this->Band + 1e-3;
      for (int column = 0; column < 3; ++column)
      {
        extent += std::abs(pose.Rotation[axis][column]) * this->HalfExtents[column];
      }
      extent = std::min(extent, this->Reach);
      lower[axis] = std::min(lower[axis], pose.Translation[axis] - extent);
      upper[axis] = std::max(upper[axis], pose.Translation[axis] + extent);
    }
  }
}

//------------------------------------------------------------------------------
const std::vector<char>& SweptToolSource::Copies(const double center[3], double radius) const
{
  if (radius != this->MeetingRadius || center[0] != this->MeetingCenter[0] || center[1] != this->MeetingCenter[1] ||
    center[2] != this->MeetingCenter[2])
  {
    std::copy(center, center + 3, this->MeetingCenter);
    this->MeetingRadius = radius;
    std::fill(this->Meeting.begin(), this->Meeting.end(), 0);
    bool behind = false;
    if (this->UseMotion)
    {
      const RigidPose& first = this->Poses.front();
      const double w[3] = { center[0] - first.Translation[0], center[1] - first.Translation[1], center[2] - first.Translation[2] };
      double local[3];
      for (int row = 0; row < 3; ++row)
      {
        local[row] = first.Rotation[0][row] * w[0] + first.Rotation[1][row] * w[1] + first.Rotation[2][row] * w[2];
      }
      behind = this->Tool->IsLeftBehind(local, radius, this->Motion);
    }
    if (this->ClosedForm && !behind)
    {
      // The closed form's own distance at the centre, less the ball's
      // radius, bounds the sweep's distance below over the ball (a minimum
      // of distances changes no faster than the point moves), as in Meets.
      const RigidPose& first = this->Poses.front();
      const double w[3] = { center[0] - first.Translation[0], center[1] - first.Translation[1], center[2] - first.Translation[2] };
      float local[3];
      for (int row = 0; row < 3; ++row)
      {
        local[row] = static_cast<float>(first.Rotation[0][row] * w[0] + first.Rotation[1][row] * w[1] + first.Rotation[2][row] * w[2]);
      }
      float distance = 0.0f;
      this->Tool->EvaluateTranslatedDistances(this->Motion, this->Step, &local[0], &local[1], &local[2], 1, &distance);
      const bool reaches = distance - radius <= this->Band + 1e-3;
      for (size_t n = this->FirstCopy; n < this->Poses.size(); ++n)
      {
        this->Meeting[n] = reaches ? 1 : 0;
      }
    }
    else
    {
      for (size_t n = this->FirstCopy; n < this->Poses.size() && !behind; ++n)
      {
        this->Meeting[n] = this->Meets(this->Poses[n], center, radius) ? 1 : 0;
      }
    }
  }
  return this->Meeting;
}

//------------------------------------------------------------------------------
bool SweptToolSource::MayReach(const double center[3], double radius) const
{
  const std::vector<char>& meeting = this->Copies(center, radius);
  return std::find(meeting.begin(), meeting.end(), 1) != meeting.end();
}

//------------------------------------------------------------------------------
bool SweptToolSource::BoundSlices(const double origin[3], const float* offsets, double bounds[BrickSize]) const
{
  if (!this->ClosedForm)
  {
    return false;
  }
  // The brick's slices in the first copy's frame, as the samples lie.
  const RigidPose& first = this->Poses.front();
  double base[3];
  double stride[3];
  double edges[2][3];
  for (int row = 0; row < 3; ++row)
  {
    base[row] = stride[row] = edges[0][row] = edges[1][row] = 0.0;
    for (int axis = 0; axis < 3; ++axis)
    {
      const float* run = offsets + axis * SamplesPerBrick;
      const double r = first.Rotation[axis][row];
      base[row] += r * (origin[axis] + run[0] - first.Translation[axis]);
      stride[row] += r * (static_cast<double>(run[SamplesPerSlice]) - run[0]);
      edges[0][row] += r * (static_cast<double>(run[BrickSize - 1]) - run[0]);
      edges[1][row] += r * (static_cast<double>(run[SamplesPerSlice - BrickSize]) - run[0]);
    }
  }
  return this->Tool->BoundTranslatedDistances(this->Motion, this->Step, base, stride, edges, BrickSize, bounds);
}

//------------------------------------------------------------------------------
void SweptToolSource::BrickDistances(const double origin[3], const double center[3], double radius, const float* offsets, int firstSlice,
  int lastSlice, float* distances) const
{
  // Beyond the band: clamped to Outside, so a copy out of reach changes nothing.
  float local[3][SamplesPerBrick];
  if (this->ClosedForm)
  {
    // One evaluation of the whole translated sweep, over the slices asked for.
    const int begin = firstSlice * SamplesPerSlice;
    const int count = (lastSlice - firstSlice + 1) * SamplesPerSlice;
    ToToolFrame(this->Poses.front(), origin, offsets, begin, count, local);
    this->Tool->EvaluateTranslatedDistances(this->Motion, this->Step, local[0] + begin, local[1] + begin, local[2] + begin, count, distances + begin);
    return;
  }
  const float far = static_cast<float>(this->Reach);
  std::fill(distances, distances + SamplesPerBrick, far);
  float copy[SamplesPerBrick];
  const std::vector<char>& meeting = this->Copies(center, radius);
  for (size_t n = 0; n < this->Poses.size(); ++n)
  {
    if (!meeting[n])
    {
      continue;
    }
    ToToolFrame(this->Poses[n], origin, offsets, 0, SamplesPerBrick, local);
    this->Tool->EvaluateDistances(local[0], local[1], local[2], SamplesPerBrick, copy);
    vtkVolumeCutKernels::Get().MergeCopy(local[0], local[1], local[2], copy, static_cast<float>(this->Reach * this->Reach), distances);
  }
}

//------------------------------------------------------------------------------
double SweptToolSource::Distance(const double point[3]) const
{
  double nearest = this->Reach; // beyond the band: any value this large is clamped
  for (const RigidPose& pose : this->Poses)
  {
    const double w[3] = { point[0] - pose.Translation[0], point[1] - pose.Translation[1], point[2] - pose.Translation[2] };
    const double centreDistance2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    if (centreDistance2 > this->Reach * this->Reach)
    {
      continue; // this copy of the tool is farther than the band
    }
    double local[3];
    for (int row = 0; row < 3; ++row)
    {
      local[row] = pose.Rotation[0][row] * w[0] + pose.Rotation[1][row] * w[1] + pose.Rotation[2][row] * w[2];
    }
    nearest = std::min(nearest, this->Tool->EvaluateDistance(local));
  }
  return nearest;
}

//------------------------------------------------------------------------------
bool SweptToolSource::Meets(const RigidPose& pose, const double center[3], double radius) const
{
  const double w[3] = { center[0] - pose.Translation[0], center[1] - pose.Translation[1], center[2] - pose.Translation[2] };
  const double limit = this->Reach + radius;
  if (w[0] * w[0] + w[1] * w[1] + w[2] * w[2] > limit * limit)
  {
    return false;
  }
  // The tool's own distance at the centre, less the ball's radius, bounds it
  // below over the ball (a distance changes no faster than the point moves;
  // far from the surface a tool may underestimate, which only keeps more).
  // Beyond the band every sample would be clamped to Outside: no change. The
  // margin covers single-precision rounding of the samples' distances.
  double local[3];
  for (int row = 0; row < 3; ++row)
  {
    local[row] = pose.Rotation[0][row] * w[0] + pose.Rotation[1][row] * w[1] + pose.Rotation[2][row] * w[2];
  }
  return this->Tool->EvaluateDistance(local) - radius <= this->Band + 1e-3;
}
} // namespace vtkVolumeCutSweeps
