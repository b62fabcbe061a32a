// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutField's cut and restore entry points: each validates a tool's
// input, describes the tool's sweep as a distance source and hands it to the
// writer (vtkVolumeCutFieldSweeps.cxx); consecutive strokes of one path are
// recognised here so that the sources can skip what the last one cut.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldInternals.h"
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutSampledRegionSource.h"
#include "vtkVolumeCutSweepSources.h"
#include "vtkVolumeCutTool.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

using vtkVolumeCutFieldInternals::BrickSize;
using vtkVolumeCutFieldInternals::IsFinite;

//------------------------------------------------------------------------------
bool vtkVolumeCutField::ValidateStroke(const double p0[3], const double p1[3], double radius, const char* caller) const
{
  if (!this->Directory)
  {
    vtkErrorMacro(<< caller << ": the cut field is not initialized");
    return false;
  }
  if (!p0 || !p1 || !IsFinite(p0) || !IsFinite(p1))
  {
    vtkErrorMacro(<< caller << ": the tool pose is not finite; nothing was cut");
    return false;
  }
  if (!(radius > 0.0) || !std::isfinite(radius))
  {
    vtkErrorMacro(<< caller << ": the tool radius must be a positive number (got " << radius << ")");
    return false;
  }
  const double length = std::sqrt(vtkMath::Distance2BetweenPoints(p0, p1));
  if (length > this->MaximumStrokeLength)
  {
    vtkErrorMacro(<< caller << ": the tool jumped " << length << " mm between two poses, more than the " << this->MaximumStrokeLength
                  << " mm accepted as one stroke; nothing was cut");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::CutCapsule(const double p0[3], const double p1[3], double radius)
{
  return this->ApplyCapsule(p0, p1, radius, Operation::Cut);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::RestoreCapsule(const double p0[3], const double p1[3], double radius)
{
  return this->ApplyCapsule(p0, p1, radius, Operation::Restore);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::CutToolSweep(vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  return this->ApplyToolSweep(tool, pose0, pose1, Operation::Cut);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::RestoreToolSweep(vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  return this->ApplyToolSweep(tool, pose0, pose1, Operation::Restore);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::ApplyToolSweep(vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1, Operation operation)
{
  const char* caller = operation == Operation::Cut ? "CutToolSweep" : "RestoreToolSweep";
  if (!this->Directory)
  {
    vtkErrorMacro(<< caller << ": the cut field is not initialized");
    return false;
  }
  if (!tool || !tool->IsValid())
  {
    vtkErrorMacro(<< caller << ": no valid tool; nothing was cut");
    return false;
  }
  vtkVolumeCutSweeps::RigidPose start;
  vtkVolumeCutSweeps::RigidPose end;
  if (!vtkVolumeCutSweeps::ToRigidPose(pose0, start) || !vtkVolumeCutSweeps::ToRigidPose(pose1, end))
  {
    vtkErrorMacro(<< caller << ": a tool pose is not a finite rigid transform; nothing was cut");
    return false;
  }
  const double jump = std::sqrt(vtkMath::Distance2BetweenPoints(start.Translation, end.Translation));
  if (jump > this->MaximumStrokeLength)
  {
    vtkErrorMacro(<< caller << ": the tool jumped " << jump << " mm between two poses, more than the " << this->MaximumStrokeLength
                  << " mm accepted as one stroke; nothing was cut");
    return false;
  }
  // No tool point moves more than half a sub-voxel from one pose to the next.
  double spacing[3];
  this->GetSubVoxelSpacing(spacing);
  const double step = 0.5 * std::min({ spacing[0], spacing[1], spacing[2] });
  std::vector<vtkVolumeCutSweeps::RigidPose> poses = vtkVolumeCutSweeps::InterpolatePoses(start, end, tool->GetBoundingRadius(), step);
  // A sweep that starts where the last one ended, on an unchanged field, has
  // its first pose cut already; a pure translation then leaves whole regions
  // behind (vtkVolumeCutSweepSources). Paths of a haptic stroke are such sweeps.
  const ToolSweepContinuation& last = this->LastToolSweep;
  const bool continued = operation == Operation::Cut && last.Valid && last.Tool == tool && last.ToolTime == tool->GetMTime() &&
    last.Stamp == this->GetCurrentStamp() && last.ProtectionTime == this->Protection->GetMTime() &&
    std::equal(&start.Rotation[0][0], &start.Rotation[0][0] + 9, &last.End.Rotation[0][0]) &&
    std::equal(start.Translation, start.Translation + 3, last.End.Translation);
  const bool translation = std::equal(&start.Rotation[0][0], &start.Rotation[0][0] + 9, &end.Rotation[0][0]);
  const double motion[3] = { end.Translation[0] - start.Translation[0], end.Translation[1] - start.Translation[1],
    end.Translation[2] - start.Translation[2] };
  const vtkVolumeCutSweeps::SweptToolSource source(tool, std::move(poses), this->BandWidth, step, continued, translation ? motion : nullptr);
  this->ApplyDistance(source, operation);
  this->LastToolSweep.Valid = operation == Operation::Cut;
  this->LastToolSweep.Tool = tool;
  this->LastToolSweep.ToolTime = tool->GetMTime();
  std::copy(&end.Rotation[0][0], &end.Rotation[0][0] + 9, &this->LastToolSweep.End.Rotation[0][0]);
  std::copy(end.Translation, end.Translation + 3, this->LastToolSweep.End.Translation);
  this->LastToolSweep.Stamp = this->GetCurrentStamp();
  this->LastToolSweep.ProtectionTime = this->Protection->GetMTime();
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::CutSampledRegion(vtkImageData* distances, vtkImageData* keep)
{
  if (!this->Directory)
  {
    vtkErrorMacro("CutSampledRegion: the cut field is not initialized");
    return false;
  }
  vtkDataArray* values = distances ? distances->GetPointData()->GetScalars() : nullptr;
  if (!values || (values->GetDataType() != VTK_FLOAT && values->GetDataType() != VTK_DOUBLE) || values->GetNumberOfTuples() == 0)
  {
    vtkErrorMacro("CutSampledRegion: the distances need float or double scalars; nothing was cut");
    return false;
  }
  vtkDataArray* keepValues = keep ? keep->GetPointData()->GetScalars() : nullptr;
  if (keep && (!keepValues || !keepValues->IsIntegral() || keepValues->GetNumberOfComponents() != 1))
  {
    vtkErrorMacro("CutSampledRegion: the voxels to keep need one integer scalar component; nothing was cut");
    return false;
  }
  const int components = values->GetNumberOfComponents();
  std::vector<float> converted;
  const float* samples = nullptr;
  if (values->GetDataType() == VTK_FLOAT)
  {
    samples = static_cast<const float*>(values->GetVoidPointer(0));
  }
  else
  {
    converted.resize(static_cast<size_t>(values->GetNumberOfValues()));
    const double* source = static_cast<const double*>(values->GetVoidPointer(0));
    std::transform(source, source + converted.size(), converted.begin(), [](double v) { return static_cast<float>(v); });
    samples = converted.data();
  }
  const int f = this->SubVoxelFactor;
  double spacing[3];
  this->GetSubVoxelSpacing(spacing);
  vtkSmartPointer<vtkVolumeCutProtection> keepOut;
  std::vector<char> keepBricks;
  if (keep)
  {
    // The keep-out set is a shield of its own, built where the region reaches.
    const int anatomyDimensions[3] = { this->Dimensions[0] / f, this->Dimensions[1] / f, this->Dimensions[2] / f };
    const double anatomySpacing[3] = { spacing[0] * f, spacing[1] * f, spacing[2] * f };
    keepOut = vtkSmartPointer<vtkVolumeCutProtection>::New();
    keepOut->SetSurfaceSmoothing(0.0); // the kept voxels exactly, as given
    keepOut->SetFieldGeometry(anatomyDimensions, f, anatomySpacing, this->BandWidth, this->Quantum);
    const int image = keepOut->AddLabelImage(keep);
    double range[2];
    keepValues->GetRange(range, 0);
    const int largest = static_cast<int>(std::min<double>(range[1], vtkVolumeCutProtection::MaximumLabelValue));
    for (int value = 1; value <= largest; ++value)
    {
      keepOut->SetShieldLabel(image, value, 1);
    }
    // The bricks a kept voxel's cube comes within the band of: only those
    // need the keep-out shield built (most of a region has none).
    const int* extent = keep->GetExtent();
    keepBricks.assign(static_cast<size_t>(this->BrickDimensions[0]) * this->BrickDimensions[1] * this->BrickDimensions[2], 0);
    int reach[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      reach[axis] = static_cast<int>(std::ceil(this->BandWidth / anatomySpacing[axis])) + 1;
    }
    vtkIdType id = 0;
    for (int k = extent[4]; k <= extent[5]; ++k)
    {
      for (int j = extent[2]; j <= extent[3]; ++j)
      {
        for (int i = extent[0]; i <= extent[1]; ++i, ++id)
        {
          if (!(keepValues->GetComponent(id, 0) > 0.0))
          {
            continue;
          }
          const int voxel[3] = { i, j, k };
          int lower[3];
          int upper[3];
          for (int axis = 0; axis < 3; ++axis)
          {
            lower[axis] = std::max(0, (voxel[axis] - reach[axis]) * f / BrickSize);
            upper[axis] = std::min(this->BrickDimensions[axis] - 1, ((voxel[axis] + reach[axis] + 1) * f - 1) / BrickSize);
          }
          for (int bk = lower[2]; bk <= upper[2]; ++bk)
          {
            for (int bj = lower[1]; bj <= upper[1]; ++bj)
            {
              for (int bi = lower[0]; bi <= upper[0]; ++bi)
              {
                keepBricks[(static_cast<size_t>(bk) * this->BrickDimensions[1] + bj) * this->BrickDimensions[0] + bi] = 1;
              }
            }
          }
        }
      }
    }
  }
  vtkNew<vtkMatrix4x4> ijkToRAS;
  ijkToRAS->DeepCopy(this->AnatomyIJKToRAS);
  vtkNew<vtkMatrix4x4> rasToIJK;
  vtkMatrix4x4::Invert(ijkToRAS, rasToIJK);
  double ijkToRASRows[4][4];
  double rasToIJKRows[4][4];
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      ijkToRASRows[row][column] = ijkToRAS->GetElement(row, column);
      rasToIJKRows[row][column] = rasToIJK->GetElement(row, column);
    }
  }
  const vtkVolumeCutSweeps::SampledRegionSource source(samples, components, distances->GetExtent(), rasToIJKRows, ijkToRASRows, this->BandWidth,
    keepOut, this->RASToSubIJK, this->BrickDimensions, this->Quantum, 0.5 * std::max({ spacing[0], spacing[1], spacing[2] }), keepBricks);
  this->ApplyDistance(source, Operation::Cut);
  this->LastCapsule.Valid = false;
  this->LastToolSweep.Valid = false;
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::ApplyCapsule(const double p0[3], const double p1[3], double radius, Operation operation)
{
  const char* caller = operation == Operation::Cut ? "CutCapsule" : "RestoreCapsule";
  if (!this->ValidateStroke(p0, p1, radius, caller))
  {
    return false;
  }
  const CapsuleContinuation& last = this->LastCapsule;
  const bool continued = operation == Operation::Cut && last.Valid && last.Stamp == this->GetCurrentStamp() &&
    last.ProtectionTime == this->Protection->GetMTime() && last.Radius == radius &&
    last.End[0] == p0[0] && last.End[1] == p0[1] && last.End[2] == p0[2];
  const vtkVolumeCutSweeps::CapsuleSource source(p0, p1, radius, radius + this->BandWidth, continued);
  this->ApplyDistance(source, operation);
  this->LastCapsule.Valid = operation == Operation::Cut;
  std::copy(p1, p1 + 3, this->LastCapsule.End);
  this->LastCapsule.Radius = radius;
  this->LastCapsule.Stamp = this->GetCurrentStamp();
  this->LastCapsule.ProtectionTime = this->Protection->GetMTime();
  return true;
}
