// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutKernels.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutCylinderTool);

namespace
{
/// Pieces of a translated sweep: its motion along the axis in steps no longer than step.
int TranslationPieces(const double motion[3], double step)
{
  return std::max(1, static_cast<int>(std::ceil(std::abs(motion[2]) / step)));
}
} // namespace

//------------------------------------------------------------------------------
double vtkVolumeCutCylinderTool::EvaluateDistance(const double local[3])
{
  // Exact distance to a finite cylinder: a 2D box distance in (radial, axial).
  const double radial = std::sqrt(local[0] * local[0] + local[1] * local[1]) - this->Radius;
  const double axial = std::abs(local[2]) - 0.5 * this->Length;
  // sqrt, not hypot: these are millimetres, far from overflow, and a sweep
  // evaluates this hundreds of thousands of times a stroke.
  const double outsideRadial = std::max(radial, 0.0);
  const double outsideAxial = std::max(axial, 0.0);
  const double outside = std::sqrt(outsideRadial * outsideRadial + outsideAxial * outsideAxial);
  return outside + std::min(std::max(radial, axial), 0.0);
}

//------------------------------------------------------------------------------
void vtkVolumeCutCylinderTool::EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances)
{
  vtkVolumeCutKernels::Get().CylinderDistances(static_cast<float>(this->Radius), static_cast<float>(0.5 * this->Length), x, y, z, count, distances);
}

//------------------------------------------------------------------------------
double vtkVolumeCutCylinderTool::GetBoundingRadius()
{
  return std::hypot(this->Radius, 0.5 * this->Length);
}

//------------------------------------------------------------------------------
void vtkVolumeCutCylinderTool::GetLocalHalfExtents(double halfExtents[3])
{
  halfExtents[0] = this->Radius;
  halfExtents[1] = this->Radius;
  halfExtents[2] = 0.5 * this->Length;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutCylinderTool::IsLeftBehind(const double center[3], double radius, const double motion[3])
{
  // Every (sub)gradient of the distance is a radial unit vector times
  // alpha >= 0 plus the axis times sign(z) times beta >= 0. The ball is left
  // behind if, for each term, the ball is behind the motion or the term is
  // zero throughout it.
  const double halfLength = 0.5 * this->Length;
  const double radialMotion = std::sqrt(motion[0] * motion[0] + motion[1] * motion[1]);
  const double radialCenter = std::sqrt(center[0] * center[0] + center[1] * center[1]);
  // Radial term: x . motion <= 0 over the ball, or the ball is so near the
  // axis of a wide cylinder (a disk) that the faces are always nearer.
  const bool radial = radialMotion == 0.0 || center[0] * motion[0] + center[1] * motion[1] + radius * radialMotion <= 0.0 ||
    radialCenter + radius < this->Radius - halfLength;
  // Axial term: sign(z) motion_z <= 0 over the ball, or the ball is so far
  // from the ends of a long cylinder that the side is always nearer.
  const bool axial = motion[2] == 0.0 || (motion[2] > 0.0 ? center[2] + radius <= 0.0 : center[2] - radius >= 0.0) ||
    std::abs(center[2]) + radius < halfLength - this->Radius;
  return radial && axial;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutCylinderTool::EvaluateTranslatedDistances(
  const double motion[3], double step, const float* x, const float* y, const float* z, int count, float* distances)
{
  // Moved across its axis, a cylinder sweeps a 2D capsule times its length:
  // exact. The motion along the axis is taken in pieces no longer than
  // step: piece k sweeps across from where the tool is at t = k / n to
  // where it is at (k + 1) / n, at the height of the latter. The union is
  // within step of the sweep and holds the end pose exactly (a continuing
  // sweep relies on the field holding it).
  if (!(step > 0.0))
  {
    return false;
  }
  // One piece (a stroke within a haptic frame, usually) needs no divisions:
  // x / 1 is x.
  const int pieces = TranslationPieces(motion, step);
  const float segment[2] = { static_cast<float>(pieces == 1 ? motion[0] : motion[0] / pieces),
    static_cast<float>(pieces == 1 ? motion[1] : motion[1] / pieces) };
  const double length2 = static_cast<double>(segment[0]) * segment[0] + static_cast<double>(segment[1]) * segment[1];
  const float inverseLength2 = length2 > 0.0 ? static_cast<float>(1.0 / length2) : 0.0f;
  const vtkVolumeCutKernels::Table& kernels = vtkVolumeCutKernels::Get();
  for (int piece = 0; piece < pieces; ++piece)
  {
    const double start = pieces == 1 ? 0.0 : static_cast<double>(piece) / pieces;
    const double end = pieces == 1 ? 1.0 : static_cast<double>(piece + 1) / pieces;
    const float offset[3] = { static_cast<float>(start * motion[0]), static_cast<float>(start * motion[1]), static_cast<float>(end * motion[2]) };
    // The first piece stores its distances: the minimum with nothing yet.
    (piece == 0 ? kernels.CylinderSwept : kernels.CylinderSweptMinimum)(
      static_cast<float>(this->Radius), static_cast<float>(0.5 * this->Length), offset, segment, inverseLength2, x, y, z, count, distances);
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutCylinderTool::BoundTranslatedDistances(
  const double motion[3], double step, const double origin[3], const double stride[3], const double edges[2][3], int count, double* bounds)
{
  if (!(step > 0.0) || count < 1)
  {
    return false; // no closed form (EvaluateTranslatedDistances)
  }
  // Each piece of the closed form is a disk moved along part of the segment
  // from the origin to motion (x, y), times a slab at one of the pieces'
  // heights: all lie within the 2D capsule of the whole segment times the
  // slab spanning those heights. Its distance grows, as a cylinder's, with
  // a radial and an axial term, each no smaller for a piece than for that
  // hull. The radial term is bounded once for all slices (their middle less
  // their spread), the axial one for each slice (its lowest and highest point).
  const int pieces = TranslationPieces(motion, step);
  const double halfLength = 0.5 * this->Length;
  const double lowest = std::min(motion[2] / pieces, motion[2]) - halfLength;
  const double highest = std::max(motion[2] / pieces, motion[2]) + halfLength;
  const double middleSlice = 0.5 * (count - 1);
  double middle[2];
  double spread2 = 0.0;
  for (int corner = 0; corner < 4; ++corner)
  {
    const double u = corner & 1 ? 0.5 : -0.5;
    const double v = corner & 2 ? 0.5 : -0.5;
    double offset[2];
    for (int axis = 0; axis < 2; ++axis)
    {
      middle[axis] = origin[axis] + middleSlice * stride[axis] + 0.5 * (edges[0][axis] + edges[1][axis]);
      offset[axis] = u * edges[0][axis] + v * edges[1][axis] + middleSlice * stride[axis];
    }
    spread2 = std::max(spread2, offset[0] * offset[0] + offset[1] * offset[1]);
  }
  const double segmentLength2 = motion[0] * motion[0] + motion[1] * motion[1];
  double along = segmentLength2 > 0.0 ? (middle[0] * motion[0] + middle[1] * motion[1]) / segmentLength2 : 0.0;
  along = std::min(1.0, std::max(0.0, along));
  const double dx = middle[0] - along * motion[0];
  const double dy = middle[1] - along * motion[1];
  const double radial = std::sqrt(dx * dx + dy * dy) - std::sqrt(spread2) - this->Radius;
  const double below = std::min(0.0, edges[0][2]) + std::min(0.0, edges[1][2]);
  const double above = std::max(0.0, edges[0][2]) + std::max(0.0, edges[1][2]);
  for (int s = 0; s < count; ++s)
  {
    const double base = origin[2] + s * stride[2];
    const double axial = std::max(lowest - (base + above), base + below - highest);
    // The cylinder's combination of the terms, which grows with each.
    bounds[s] = radial > 0.0 && axial > 0.0 ? std::sqrt(radial * radial + axial * axial) : std::max(radial, axial);
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutCylinderTool::IsValid()
{
  if (!(this->Radius > 0.0) || !(this->Length > 0.0) || !std::isfinite(this->Radius) || !std::isfinite(this->Length))
  {
    vtkErrorMacro("IsValid: radius (" << this->Radius << ") and length (" << this->Length << ") must be positive numbers");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutCylinderTool::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Radius: " << this->Radius << "\n";
  os << indent << "Length: " << this->Length << "\n";
}
