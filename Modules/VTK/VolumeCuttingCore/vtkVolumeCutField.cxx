// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldFile.h"
#include "vtkVolumeCutFieldDistanceSource.h"
#include "vtkVolumeCutFieldInternals.h"
#include "vtkVolumeCutFieldUndoHistory.h"
#include "vtkVolumeCutKernels.h"
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutProtectionBrick.h"
#include "vtkVolumeCutSampledRegionSource.h"
#include "vtkVolumeCutSweepSources.h"

#include "vtkDataArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkTransform.h"
#include "vtkTransformPolyDataFilter.h"
#include "vtkVolumeCutTool.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

vtkStandardNewMacro(vtkVolumeCutField);

using vtkVolumeCutFieldInternals::BrickSize;
using vtkVolumeCutFieldInternals::Inside;
using vtkVolumeCutFieldInternals::IsFinite;
using vtkVolumeCutFieldInternals::Outside;
using vtkVolumeCutFieldInternals::SamplesPerBrick;
using vtkVolumeCutFieldInternals::Transform;

static_assert(int(vtkVolumeCutField::InstructionSetAVX2) == int(vtkVolumeCutKernels::AVX2) && int(vtkVolumeCutField::InstructionSetAVX512) == int(vtkVolumeCutKernels::AVX512),
  "one numbering of the instruction sets");

//------------------------------------------------------------------------------
vtkVolumeCutField::vtkVolumeCutField()
  : Protection(vtkSmartPointer<vtkVolumeCutProtection>::New())
  , History(vtkSmartPointer<vtkVolumeCutFieldUndoHistory>::New())
{
  this->History->SetField(this);
  vtkMatrix4x4::Identity(&this->SubIJKToRAS[0][0]);
  vtkMatrix4x4::Identity(&this->RASToSubIJK[0][0]);
}

//------------------------------------------------------------------------------
vtkVolumeCutField::~vtkVolumeCutField() = default;

//------------------------------------------------------------------------------
int vtkVolumeCutField::GetNumberOfUndoSteps() const
{
  return this->History->GetNumberOfUndoSteps();
}

//------------------------------------------------------------------------------
int vtkVolumeCutField::GetNumberOfRedoSteps() const
{
  return this->History->GetNumberOfRedoSteps();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::Initialize(const int anatomyDimensions[3], vtkMatrix4x4* anatomyIJKToRAS, int subVoxelFactor)
{
  if (!anatomyDimensions || anatomyDimensions[0] < 1 || anatomyDimensions[1] < 1 || anatomyDimensions[2] < 1)
  {
    vtkErrorMacro("Initialize: the anatomy must have at least one voxel along each axis");
    return false;
  }
  if (subVoxelFactor != 1 && subVoxelFactor != 2 && subVoxelFactor != 4)
  {
    vtkErrorMacro("Initialize: sub-voxel factor " << subVoxelFactor << " is not supported; use 1, 2 or 4");
    return false;
  }
  if (!anatomyIJKToRAS)
  {
    vtkErrorMacro("Initialize: no IJK-to-RAS matrix");
    return false;
  }
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      if (!std::isfinite(anatomyIJKToRAS->GetElement(row, column)))
      {
        vtkErrorMacro("Initialize: the IJK-to-RAS matrix has a value that is not finite");
        return false;
      }
    }
  }
  const double determinant = anatomyIJKToRAS->Determinant();
  if (!(std::abs(determinant) > 1e-12))
  {
    vtkErrorMacro("Initialize: the IJK-to-RAS matrix is not invertible (zero spacing?)");
    return false;
  }
  int dimensions[3];
  int brickDimensions[3];
  double brickCount = 1.0;
  for (int axis = 0; axis < 3; ++axis)
  {
    dimensions[axis] = anatomyDimensions[axis] * subVoxelFactor;
    brickDimensions[axis] = (dimensions[axis] + BrickSize - 1) / BrickSize;
    brickCount *= brickDimensions[axis];
  }
  // The brick directory is dense (two words per brick): refuse grids whose
  // directory alone would take more than 1 GiB instead of failing to allocate.
  const double directoryBytes = brickCount * (sizeof(std::atomic<Brick*>) + sizeof(std::atomic<vtkIdType>));
  if (brickCount > static_cast<double>(std::numeric_limits<int32_t>::max()) || directoryBytes > static_cast<double>(1u << 30))
  {
    vtkErrorMacro("Initialize: " << anatomyDimensions[0] << " x " << anatomyDimensions[1] << " x " << anatomyDimensions[2]
                                 << " voxels at sub-voxel factor " << subVoxelFactor << " is too large for a cut field ("
                                 << directoryBytes / (1u << 20) << " MiB of brick directory); use a lower factor or crop the volume");
    return false;
  }

  // Sub-voxel s lies at anatomy continuous index (s + 0.5) / f - 0.5: sub-voxels
  // tile each anatomy voxel, and factor 1 reproduces the anatomy grid.
  vtkNew<vtkMatrix4x4> subToAnatomy;
  for (int axis = 0; axis < 3; ++axis)
  {
    subToAnatomy->SetElement(axis, axis, 1.0 / subVoxelFactor);
    subToAnatomy->SetElement(axis, 3, 0.5 / subVoxelFactor - 0.5);
  }
  vtkNew<vtkMatrix4x4> subToRAS;
  vtkMatrix4x4::Multiply4x4(anatomyIJKToRAS, subToAnatomy, subToRAS);
  vtkNew<vtkMatrix4x4> rasToSub;
  vtkMatrix4x4::Invert(subToRAS, rasToSub);

  this->Reset();
  std::copy(dimensions, dimensions + 3, this->Dimensions);
  std::copy(brickDimensions, brickDimensions + 3, this->BrickDimensions);
  this->SubVoxelFactor = subVoxelFactor;
  vtkMatrix4x4::DeepCopy(this->AnatomyIJKToRAS, anatomyIJKToRAS);
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      this->SubIJKToRAS[row][column] = subToRAS->GetElement(row, column);
      this->RASToSubIJK[row][column] = rasToSub->GetElement(row, column);
    }
  }
  double spacing[3];
  this->GetSubVoxelSpacing(spacing);
  // The band must hold every sample whose interpolation cell the surface
  // crosses (up to the cell diagonal away) and their neighbours, whose second
  // differences correct the interpolation for curvature.
  this->BandWidth = 3.5 * std::max({ spacing[0], spacing[1], spacing[2] });
  this->Quantum = this->BandWidth / (Outside - 1);
  this->HalfDiagonal = 0.5 * std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
  // Beyond the correction's largest size (0.75 of the largest spacing) and
  // the normal's finite differences: 3 spacings, inside the band.
  this->CorrectionReach = 3.0 * std::max({ spacing[0], spacing[1], spacing[2] });
  double anatomySpacing[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    anatomySpacing[axis] = spacing[axis] * subVoxelFactor;
  }
  this->Protection->SetFieldGeometry(anatomyDimensions, subVoxelFactor, anatomySpacing, this->BandWidth, this->Quantum);
  this->RowScratch.assign(static_cast<size_t>(BrickSize) * BrickSize * dimensions[0], Outside);
  this->DistanceScratch.assign(static_cast<size_t>(dimensions[0]), 0.0f);
  this->BrickSampleOffsets.resize(3 * SamplesPerBrick);
  for (int local = 0; local < SamplesPerBrick; ++local)
  {
    const int step[3] = { local % BrickSize, (local / BrickSize) % BrickSize, local / (BrickSize * BrickSize) };
    for (int axis = 0; axis < 3; ++axis)
    {
      this->BrickSampleOffsets[axis * SamplesPerBrick + local] = static_cast<float>(
        step[0] * this->SubIJKToRAS[axis][0] + step[1] * this->SubIJKToRAS[axis][1] + step[2] * this->SubIJKToRAS[axis][2]);
    }
  }
  // Half the longest of the four diagonals (oblique grids have unequal ones).
  this->BrickBoundingRadius = 0.0;
  for (int diagonal = 0; diagonal < 4; ++diagonal)
  {
    const double signs[3] = { 1.0, diagonal & 1 ? -1.0 : 1.0, diagonal & 2 ? -1.0 : 1.0 };
    double length2 = 0.0;
    for (int axis = 0; axis < 3; ++axis)
    {
      double component = 0.0;
      for (int column = 0; column < 3; ++column)
      {
        component += signs[column] * (BrickSize - 1) * this->SubIJKToRAS[axis][column];
      }
      length2 += component * component;
    }
    this->BrickBoundingRadius = std::max(this->BrickBoundingRadius, 0.5 * std::sqrt(length2));
  }
  const vtkIdType totalBricks = static_cast<vtkIdType>(brickCount);
  this->Directory.reset(new std::atomic<Brick*>[totalBricks]);
  this->AllocatedBrickIds.reset(new std::atomic<vtkIdType>[totalBricks]);
  for (vtkIdType id = 0; id < totalBricks; ++id)
  {
    this->Directory[id].store(nullptr, std::memory_order_relaxed);
  }
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::Reset()
{
  this->Directory.reset();
  this->AllocatedBrickIds.reset();
  this->NumberOfAllocatedBricks.store(0, std::memory_order_release);
  this->OwnedBricks.clear();
  this->History->Clear();
  this->Protection->RemoveAllLabelImages();
  this->LastCapsule.Valid = false;
  this->LastToolSweep.Valid = false;
  this->ResetContact();
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ResetContact()
{
  // The next capsule reports its whole reach again, the ball it starts in too.
  this->LastCapsule.Valid = false;
  this->LastToolSweep.Valid = false;
  this->MaximumContactDepth = 0.0;
  this->ContactLabel = 0;
  std::fill(this->ContactPosition, this->ContactPosition + 3, 0.0);
}

//------------------------------------------------------------------------------
const vtkVolumeCutProtection::Brick* vtkVolumeCutField::GetProtectionBrick(vtkIdType brickId)
{
  return this->Protection->GetBrick(brickId);
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutField::PrepareProtection(const double center[3], double radius)
{
  if (!this->Directory || !center || !IsFinite(center) || !(radius >= 0.0) || !this->Protection->HasShieldedLabels())
  {
    return 0;
  }
  const vtkIdType before = this->Protection->GetNumberOfBuiltBricks();
  const double reach = radius + this->BandWidth;
  // The bricks of the sub-voxel box around the ball, then those the ball meets.
  int lower[3] = { std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), std::numeric_limits<int>::max() };
  int upper[3] = { std::numeric_limits<int>::min(), std::numeric_limits<int>::min(), std::numeric_limits<int>::min() };
  for (int corner = 0; corner < 8; ++corner)
  {
    double ras[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      ras[axis] = center[axis] + ((corner >> axis) & 1 ? reach : -reach);
    }
    double index[3];
    Transform(this->RASToSubIJK, ras, index);
    for (int axis = 0; axis < 3; ++axis)
    {
      const double clamped = std::max(-1.0, std::min(static_cast<double>(this->Dimensions[axis]), index[axis]));
      lower[axis] = std::min(lower[axis], static_cast<int>(std::floor(clamped)));
      upper[axis] = std::max(upper[axis], static_cast<int>(std::ceil(clamped)));
    }
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    lower[axis] = std::max(lower[axis], 0) / BrickSize;
    upper[axis] = std::min(upper[axis], this->Dimensions[axis] - 1) / BrickSize;
  }
  const double limit = reach + this->BrickBoundingRadius;
  for (int bk = lower[2]; bk <= upper[2]; ++bk)
  {
    for (int bj = lower[1]; bj <= upper[1]; ++bj)
    {
      for (int bi = lower[0]; bi <= upper[0]; ++bi)
      {
        const double middle = 0.5 * (BrickSize - 1);
        const double centerSample[3] = { bi * BrickSize + middle, bj * BrickSize + middle, bk * BrickSize + middle };
        double brickCenter[3];
        Transform(this->SubIJKToRAS, centerSample, brickCenter);
        if (vtkMath::Distance2BetweenPoints(brickCenter, center) <= limit * limit)
        {
          this->GetProtectionBrick((static_cast<vtkIdType>(bk) * this->BrickDimensions[1] + bj) * this->BrickDimensions[0] + bi);
        }
      }
    }
  }
  return this->Protection->GetNumberOfBuiltBricks() - before;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::SetProtectedLabels(vtkImageData* labels)
{
  if (labels)
  {
    const int f = this->SubVoxelFactor;
    int dims[3];
    labels->GetDimensions(dims);
    if (!this->Directory || f < 1 || dims[0] * f != this->Dimensions[0] || dims[1] * f != this->Dimensions[1] || dims[2] * f != this->Dimensions[2])
    {
      vtkErrorMacro("SetProtectedLabels: the labels must have the anatomy's dimensions (" << this->Dimensions[0] / std::max(f, 1) << " x "
                                                                                          << this->Dimensions[1] / std::max(f, 1) << " x "
                                                                                          << this->Dimensions[2] / std::max(f, 1) << ")");
      return false;
    }
    vtkDataArray* scalars = labels->GetPointData()->GetScalars();
    if (!scalars || !scalars->IsIntegral() || scalars->GetNumberOfComponents() != 1)
    {
      vtkErrorMacro("SetProtectedLabels: the labels need one integer scalar component");
      return false;
    }
  }
  this->Protection->RemoveAllLabelImages();
  if (!labels)
  {
    return true;
  }
  // Anatomy IJK: the image's extent starts at voxel 0 whatever its origin.
  vtkNew<vtkImageData> ijkLabels;
  ijkLabels->ShallowCopy(labels);
  int dims[3];
  labels->GetDimensions(dims);
  ijkLabels->SetExtent(0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1);
  const int image = this->Protection->AddLabelImage(ijkLabels);
  double range[2];
  labels->GetPointData()->GetScalars()->GetRange(range, 0);
  const int largest = static_cast<int>(std::min<double>(range[1], vtkVolumeCutProtection::MaximumLabelValue));
  for (int value = 1; value <= largest; ++value)
  {
    this->Protection->SetShieldLabel(image, value, std::min(value, 255));
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::GetSubVoxelIJKToRAS(vtkMatrix4x4* matrix) const
{
  if (matrix)
  {
    matrix->DeepCopy(&this->SubIJKToRAS[0][0]);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::GetSubVoxelSpacing(double spacing[3]) const
{
  for (int axis = 0; axis < 3; ++axis)
  {
    spacing[axis] = std::sqrt(this->SubIJKToRAS[0][axis] * this->SubIJKToRAS[0][axis] + this->SubIJKToRAS[1][axis] * this->SubIJKToRAS[1][axis]
      + this->SubIJKToRAS[2][axis] * this->SubIJKToRAS[2][axis]);
  }
}

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
vtkVolumeCutField::Brick* vtkVolumeCutField::GetOrCreateBrick(vtkIdType brickId)
{
  Brick* brick = this->Directory[brickId].load(std::memory_order_relaxed);
  if (brick)
  {
    return brick;
  }
  this->OwnedBricks.emplace_back(new Brick(brickId));
  brick = this->OwnedBricks.back().get();
  const vtkIdType count = this->NumberOfAllocatedBricks.load(std::memory_order_relaxed);
  this->AllocatedBrickIds[count].store(brickId, std::memory_order_relaxed);
  // Publish the brick (initialised values) before readers can find it.
  this->Directory[brickId].store(brick, std::memory_order_release);
  this->NumberOfAllocatedBricks.store(count + 1, std::memory_order_release);
  return brick;
}

//------------------------------------------------------------------------------

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

//------------------------------------------------------------------------------
bool vtkVolumeCutField::GetReachIndexRange(const DistanceSource& source, int lower[3], int upper[3]) const
{
  double reachLower[3];
  double reachUpper[3];
  source.GetReachBounds(reachLower, reachUpper);
  for (int axis = 0; axis < 3; ++axis)
  {
    lower[axis] = std::numeric_limits<int>::max();
    upper[axis] = std::numeric_limits<int>::min();
  }
  for (int corner = 0; corner < 8; ++corner)
  {
    double ras[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      ras[axis] = (corner >> axis) & 1 ? reachUpper[axis] : reachLower[axis];
    }
    double index[3];
    Transform(this->RASToSubIJK, ras, index);
    for (int axis = 0; axis < 3; ++axis)
    {
      const double clampedLow = std::max(-1.0, std::min(static_cast<double>(this->Dimensions[axis]), std::floor(index[axis])));
      const double clampedHigh = std::max(-1.0, std::min(static_cast<double>(this->Dimensions[axis]), std::ceil(index[axis])));
      lower[axis] = std::min(lower[axis], static_cast<int>(clampedLow));
      upper[axis] = std::max(upper[axis], static_cast<int>(clampedHigh));
    }
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    lower[axis] = std::max(lower[axis], 0);
    upper[axis] = std::min(upper[axis], this->Dimensions[axis] - 1);
    if (lower[axis] > upper[axis])
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
template <typename Writer>
void vtkVolumeCutField::ApplyWithinStroke(const DistanceSource& source, Writer&& write)
{
  int lower[3];
  int upper[3];
  if (!this->GetReachIndexRange(source, lower, upper))
  {
    return; // wholly outside the volume: nothing to do
  }
  const bool ownStroke = !this->History->IsStrokeOpen();
  if (ownStroke)
  {
    this->History->BeginStroke();
  }
  const bool anyChange = write(lower, upper);
  if (ownStroke)
  {
    this->History->EndStroke();
  }
  if (anyChange)
  {
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ApplyDistance(const RowDistanceSource& source, Operation operation)
{
  this->ApplyWithinStroke(source, [&](const int lower[3], const int upper[3]) { return this->ApplyRowwise(source, operation, lower, upper); });
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ApplyDistance(const BrickDistanceSource& source, Operation operation)
{
  this->ApplyWithinStroke(source, [&](const int lower[3], const int upper[3]) { return this->ApplyBrickwise(source, operation, lower, upper); });
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::QuantizeDistances(const float* distances, int count, Operation operation, int16_t* quantized) const
{
  vtkVolumeCutKernels::Get().QuantizeRun(distances, count, static_cast<float>((operation == Operation::Cut ? 1.0 : -1.0) / this->Quantum), quantized);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::MergeSegment(const Brick* brick, const vtkVolumeCutProtection::Brick* protection, const int brickIndex[3], const int16_t* quantized,
  int rowStart, int count, Operation operation, const DistanceSource& source, int16_t* merged)
{
  // Cut: min(field, tool distance). Restore: max(field, -tool distance).
  // The brick is read directly: this thread is its only writer.
  const int16_t* current = brick ? brick->WriterView() + rowStart : nullptr;
  int changed = 0;
  if (operation == Operation::Cut && !protection)
  {
    if (current)
    {
      return vtkVolumeCutKernels::Get().MinimumRun(quantized, current, count, merged);
    }
    else
    {
      for (int n = 0; n < count; ++n)
      {
        merged[n] = quantized[n];
        changed |= quantized[n] != Outside;
      }
    }
    return changed != 0;
  }
  if (operation == Operation::Restore)
  {
    for (int n = 0; n < count; ++n)
    {
      const int16_t old = current ? current[n] : Outside;
      merged[n] = quantized[n] > old ? quantized[n] : old;
      changed |= merged[n] != old;
    }
    return changed != 0;
  }
  // The tool minus the protected voxels: max(tool, -protection).
  for (int n = 0; n < count; ++n)
  {
    const int16_t old = current ? current[n] : Outside;
    const int local = rowStart + n;
    const int16_t protectedDistance = protection->Distance[local];
    const int16_t effective = std::max<int16_t>(quantized[n], static_cast<int16_t>(-protectedDistance));
    if (quantized[n] < 0 && protectedDistance < 0)
    {
      // A protected sample inside the tool: how far inside (exact, not
      // clamped to the band) is the depth of the contact.
      const double index[3] = { double(brickIndex[0] * BrickSize + local % BrickSize),
        double(brickIndex[1] * BrickSize + (local / BrickSize) % BrickSize), double(brickIndex[2] * BrickSize + local / (BrickSize * BrickSize)) };
      double point[3];
      Transform(this->SubIJKToRAS, index, point);
      const double depth = -source.Distance(point);
      if (depth > this->MaximumContactDepth)
      {
        this->MaximumContactDepth = depth;
        this->ContactLabel = protection->Label[local];
        std::copy(point, point + 3, this->ContactPosition);
      }
    }
    merged[n] = effective < old ? effective : old;
    changed |= merged[n] != old;
  }
  return changed != 0;
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::CommitBrick(vtkIdType brickId, Brick* brick, const int16_t* merged, const ChangedRun* runs, int runCount)
{
  this->History->RememberBrickBeforeChange(brickId, brick);
  if (!brick)
  {
    brick = this->GetOrCreateBrick(brickId);
  }
  brick->RememberedInStroke = this->History->GetStrokeSerial();
  // Seqlock write: readers that overlap it see an odd or changed sequence and retry.
  const uint32_t sequence = brick->Sequence.load(std::memory_order_relaxed);
  brick->Sequence.store(sequence + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  for (int r = 0; r < runCount; ++r)
  {
    // A whole row at a time, written out: atomic stores do not vectorise,
    // and compilers do not unroll a loop of them by themselves.
    static_assert(BrickSize == 8, "a row is eight samples");
    int n = runs[r].Start;
    const int end = n + runs[r].Count;
    for (; n + BrickSize <= end; n += BrickSize)
    {
      std::atomic<int16_t>* row = brick->Values + n;
      const int16_t* values = merged + n;
      row[0].store(values[0], std::memory_order_relaxed);
      row[1].store(values[1], std::memory_order_relaxed);
      row[2].store(values[2], std::memory_order_relaxed);
      row[3].store(values[3], std::memory_order_relaxed);
      row[4].store(values[4], std::memory_order_relaxed);
      row[5].store(values[5], std::memory_order_relaxed);
      row[6].store(values[6], std::memory_order_relaxed);
      row[7].store(values[7], std::memory_order_relaxed);
    }
    for (; n < end; ++n)
    {
      brick->Values[n].store(merged[n], std::memory_order_relaxed);
    }
  }
  // One writer: the brick's stamp is published before the counter passes
  // it, so a reader that has seen the counter sees the brick as modified.
  const vtkTypeUInt64 stamp = this->StampCounter.load(std::memory_order_relaxed) + 1;
  brick->Stamp.store(stamp, std::memory_order_release);
  this->StampCounter.store(stamp, std::memory_order_release);
  brick->Sequence.store(sequence + 2, std::memory_order_release);
  // A changed sample left short of Inside settles it without a scan.
  if (merged[runs[0].Start] != Inside)
  {
    brick->AllInside = false;
  }
  else
  {
    brick->UpdateAllInside();
  }
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::ApplyRowwise(const RowDistanceSource& source, Operation operation, const int lower[3], const int upper[3])
{
  // Where each row crosses the reach is computed once per line of bricks,
  // then split among the bricks along it.
  struct Row
  {
    int First;
    int Last;
    int LocalOffset; // (k, j) part of the sample index inside the brick
  };
  Row rows[BrickSize * BrickSize];
  int16_t merged[SamplesPerBrick];
  ChangedRun runs[BrickSize * BrickSize];
  bool anyChange = false;
  for (int bk = lower[2] / BrickSize; bk <= upper[2] / BrickSize; ++bk)
  {
    for (int bj = lower[1] / BrickSize; bj <= upper[1] / BrickSize; ++bj)
    {
      int rowCount = 0;
      for (int k = std::max(lower[2], bk * BrickSize); k <= std::min(upper[2], bk * BrickSize + BrickSize - 1); ++k)
      {
        for (int j = std::max(lower[1], bj * BrickSize); j <= std::min(upper[1], bj * BrickSize + BrickSize - 1); ++j)
        {
          Row& row = rows[rowCount];
          const double rowOriginIndex[3] = { 0.0, static_cast<double>(j), static_cast<double>(k) };
          double origin[3];
          Transform(this->SubIJKToRAS, rowOriginIndex, origin);
          double first;
          double last;
          if (!source.RowInterval(origin, first, last))
          {
            continue;
          }
          row.First = std::max(lower[0], static_cast<int>(std::ceil(first)));
          row.Last = std::min(upper[0], static_cast<int>(std::floor(last)));
          if (row.First > row.Last)
          {
            continue;
          }
          row.LocalOffset = ((k - bk * BrickSize) * BrickSize + (j - bj * BrickSize)) * BrickSize;
          float* distances = &this->DistanceScratch[row.First];
          source.RowDistances(origin, row.First, row.Last, distances);
          this->QuantizeDistances(distances, row.Last - row.First + 1, operation,
            &this->RowScratch[static_cast<size_t>(rowCount) * this->Dimensions[0] + row.First]);
          ++rowCount;
        }
      }
      for (int bi = lower[0] / BrickSize; rowCount > 0 && bi <= upper[0] / BrickSize; ++bi)
      {
        const vtkIdType brickId = (static_cast<vtkIdType>(bk) * this->BrickDimensions[1] + bj) * this->BrickDimensions[0] + bi;
        Brick* brick = this->Directory[brickId].load(std::memory_order_relaxed);
        if (!brick && operation == Operation::Restore)
        {
          continue; // nothing removed here, nothing to put back
        }
        const vtkVolumeCutProtection::Brick* protection = this->GetProtectionBrick(brickId);
        const int brickIndex[3] = { bi, bj, bk };
        int runCount = 0;
        for (int r = 0; r < rowCount; ++r)
        {
          const Row& row = rows[r];
          const int iBegin = std::max(row.First, bi * BrickSize);
          const int iEnd = std::min(row.Last, bi * BrickSize + BrickSize - 1);
          if (iBegin > iEnd)
          {
            continue;
          }
          const int rowStart = row.LocalOffset + (iBegin - bi * BrickSize);
          const int count = iEnd - iBegin + 1;
          if (this->MergeSegment(brick, protection, brickIndex, &this->RowScratch[static_cast<size_t>(r) * this->Dimensions[0] + iBegin], rowStart,
                count, operation, source, merged + rowStart))
          {
            runs[runCount++] = { rowStart, count };
          }
        }
        if (runCount > 0)
        {
          this->CommitBrick(brickId, brick, merged, runs, runCount);
          anyChange = true;
        }
      }
    }
  }
  return anyChange;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::TrimSlices(const BrickDistanceSource& source, const double origin[3], const Brick* brick,
  const vtkVolumeCutProtection::Brick* protection, Operation operation, int& firstSlice, int& lastSlice) const
{
  double bounds[BrickSize];
  if (!source.BoundSlices(origin, this->BrickSampleOffsets.data(), bounds))
  {
    return true;
  }
  // A slice cannot change where its distances (in single precision: 1e-3 mm
  // of margin, as for the bricks) lie beyond the band, clamped to the
  // extreme that changes nothing. A cut moreover keeps the least value: no
  // sample changes where they round to no less than the most the field
  // holds in the slice. Not so with protection, whose contacts are measured
  // at every sample inside the tool.
  const bool againstField = operation == Operation::Cut && !protection;
  auto unchanged = [&](int slice)
  {
    double limit = this->BandWidth + 1e-3;
    if (bounds[slice] > limit)
    {
      return true;
    }
    if (againstField && brick)
    {
      const int16_t* values = brick->WriterView() + slice * BrickSize * BrickSize;
      int16_t highest = Inside;
      for (int n = 0; n < BrickSize * BrickSize; ++n)
      {
        highest = values[n] > highest ? values[n] : highest;
      }
      limit = std::min(limit, (highest + 1.0) * this->Quantum + 1e-3);
    }
    return bounds[slice] > limit;
  };
  while (firstSlice <= lastSlice && unchanged(firstSlice))
  {
    ++firstSlice;
  }
  while (lastSlice >= firstSlice && unchanged(lastSlice))
  {
    --lastSlice;
  }
  return firstSlice <= lastSlice;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::ApplyBrickwise(const BrickDistanceSource& source, Operation operation, const int lower[3], const int upper[3])
{
  // Whole bricks in one uniform loop each: near a small tool the rows are a
  // few samples long, and their set-up, not the distances, would dominate.
  float distances[SamplesPerBrick];
  int16_t quantized[SamplesPerBrick];
  int16_t merged[SamplesPerBrick];
  ChangedRun runs[BrickSize * BrickSize];
  bool anyChange = false;
  for (int bk = lower[2] / BrickSize; bk <= upper[2] / BrickSize; ++bk)
  {
    for (int bj = lower[1] / BrickSize; bj <= upper[1] / BrickSize; ++bj)
    {
      for (int bi = lower[0] / BrickSize; bi <= upper[0] / BrickSize; ++bi)
      {
        const vtkIdType brickId = (static_cast<vtkIdType>(bk) * this->BrickDimensions[1] + bj) * this->BrickDimensions[0] + bi;
        Brick* brick = this->Directory[brickId].load(std::memory_order_relaxed);
        if (!brick && operation == Operation::Restore)
        {
          continue; // nothing removed here, nothing to put back
        }
        if (brick && brick->AllInside && operation == Operation::Cut)
        {
          continue; // removed through and through already
        }
        const int brickIndex[3] = { bi, bj, bk };
        const double firstSample[3] = { double(bi * BrickSize), double(bj * BrickSize), double(bk * BrickSize) };
        const double middle = 0.5 * (BrickSize - 1);
        const double centerSample[3] = { firstSample[0] + middle, firstSample[1] + middle, firstSample[2] + middle };
        double center[3];
        Transform(this->SubIJKToRAS, centerSample, center);
        if (!source.MayReach(center, this->BrickBoundingRadius))
        {
          continue;
        }
        double origin[3];
        Transform(this->SubIJKToRAS, firstSample, origin);
        const vtkVolumeCutProtection::Brick* protection = this->GetProtectionBrick(brickId);
        int firstSlice = 0;
        int lastSlice = BrickSize - 1;
        if (!this->TrimSlices(source, origin, brick, protection, operation, firstSlice, lastSlice))
        {
          continue;
        }
        source.BrickDistances(origin, center, this->BrickBoundingRadius, this->BrickSampleOffsets.data(), firstSlice, lastSlice, distances);
        const int begin = firstSlice * BrickSize * BrickSize;
        const int count = (lastSlice - firstSlice + 1) * BrickSize * BrickSize;
        this->QuantizeDistances(distances + begin, count, operation, quantized + begin);

        // Samples past the volume's far faces exist in the brick, not in the field.
        const int valid[3] = { std::min(BrickSize, this->Dimensions[0] - bi * BrickSize), std::min(BrickSize, this->Dimensions[1] - bj * BrickSize),
          std::min(BrickSize, this->Dimensions[2] - bk * BrickSize) };
        const bool whole = valid[0] == BrickSize && valid[1] == BrickSize && valid[2] == BrickSize;
        if (whole && !this->MergeSegment(brick, protection, brickIndex, quantized + begin, begin, count, operation, source, merged + begin))
        {
          continue;
        }
        // Rows that changed: the seqlock write stores only those.
        int runCount = 0;
        for (int k = firstSlice; k <= std::min(lastSlice, valid[2] - 1); ++k)
        {
          for (int j = 0; j < valid[1]; ++j)
          {
            const int rowStart = (k * BrickSize + j) * BrickSize;
            bool changed;
            if (whole)
            {
              // A row of 16-bit samples compared as one block: a per-sample
              // loop here cost as much as the merge.
              static const int16_t outsideRow[BrickSize] = { Outside, Outside, Outside, Outside, Outside, Outside, Outside, Outside };
              const int16_t* current = brick ? brick->WriterView() + rowStart : outsideRow;
              changed = std::memcmp(merged + rowStart, current, sizeof(outsideRow)) != 0;
            }
            else
            {
              changed = this->MergeSegment(brick, protection, brickIndex, quantized + rowStart, rowStart, valid[0], operation, source, merged + rowStart);
            }
            if (changed && runCount > 0 && runs[runCount - 1].Start + runs[runCount - 1].Count == rowStart)
            {
              runs[runCount - 1].Count += valid[0]; // one run over adjacent rows
            }
            else if (changed)
            {
              runs[runCount++] = { rowStart, valid[0] };
            }
          }
        }
        if (runCount > 0)
        {
          this->CommitBrick(brickId, brick, merged, runs, runCount);
          anyChange = true;
        }
      }
    }
  }
  return anyChange;
}


//------------------------------------------------------------------------------
void vtkVolumeCutField::BeginStroke()
{
  this->History->BeginStroke();
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::EndStroke()
{
  this->History->EndStroke();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::IsStrokeOpen() const
{
  return this->History->IsStrokeOpen();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::Undo()
{
  return this->History->Undo();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::Redo()
{
  return this->History->Redo();
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutField::GetUndoMemorySize() const
{
  return this->History->GetMemorySize();
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::WriteBricks(const BrickStates& bricks)
{
  for (const auto& entry : bricks)
  {
    Brick* brick = this->GetOrCreateBrick(entry.first);
    const uint32_t sequence = brick->Sequence.load(std::memory_order_relaxed);
    brick->Sequence.store(sequence + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    const bool absent = entry.second.empty(); // a brick remembered before it existed
    for (int index = 0; index < SamplesPerBrick; ++index)
    {
      brick->Values[index].store(absent ? Outside : entry.second[index], std::memory_order_relaxed);
    }
    // One writer: the brick's stamp is published before the counter passes
    // it, so a reader that has seen the counter sees the brick as modified.
    const vtkTypeUInt64 stamp = this->StampCounter.load(std::memory_order_relaxed) + 1;
    brick->Stamp.store(stamp, std::memory_order_release);
    this->StampCounter.store(stamp, std::memory_order_release);
    brick->Sequence.store(sequence + 2, std::memory_order_release);
    brick->UpdateAllInside();
  }
  this->Modified();
}


//------------------------------------------------------------------------------
int16_t vtkVolumeCutField::ReadSample(int i, int j, int k) const
{
  if (!this->Directory || i < 0 || j < 0 || k < 0 || i >= this->Dimensions[0] || j >= this->Dimensions[1] || k >= this->Dimensions[2])
  {
    return Outside;
  }
  const vtkIdType brickId =
    (static_cast<vtkIdType>(k / BrickSize) * this->BrickDimensions[1] + j / BrickSize) * this->BrickDimensions[0] + i / BrickSize;
  const Brick* brick = this->Directory[brickId].load(std::memory_order_acquire);
  if (!brick)
  {
    return Outside;
  }
  const int local = ((k % BrickSize) * BrickSize + (j % BrickSize)) * BrickSize + (i % BrickSize);
  return brick->Values[local].load(std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
vtkTypeUInt64 vtkVolumeCutField::CopyBrick(vtkIdType brickId, short* values) const
{
  const vtkIdType total = static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1] * this->BrickDimensions[2];
  if (!values || !this->Directory || brickId < 0 || brickId >= total)
  {
    vtkErrorMacro("CopyBrick: no brick " << brickId);
    return 0;
  }
  const Brick* brick = this->Directory[brickId].load(std::memory_order_acquire);
  if (!brick)
  {
    std::fill(values, values + SamplesPerBrick, Outside);
    return 0;
  }
  for (;;)
  {
    const uint32_t before = brick->Sequence.load(std::memory_order_acquire);
    if (before & 1u)
    {
      continue; // a write is under way
    }
    for (int index = 0; index < SamplesPerBrick; ++index)
    {
      values[index] = brick->Values[index].load(std::memory_order_relaxed);
    }
    const vtkTypeUInt64 stamp = brick->Stamp.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (brick->Sequence.load(std::memory_order_relaxed) == before)
    {
      return stamp;
    }
  }
}

//------------------------------------------------------------------------------
template <typename SampleReader>
double vtkVolumeCutField::Interpolate(const double index[3], SampleReader&& read) const
{
  const int i0 = static_cast<int>(std::floor(index[0]));
  const int j0 = static_cast<int>(std::floor(index[1]));
  const int k0 = static_cast<int>(std::floor(index[2]));
  const double f[3] = { index[0] - i0, index[1] - j0, index[2] - k0 };
  double weights[8];
  double centers[8];
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    weights[corner] =
      ((corner & 1) ? f[0] : 1.0 - f[0]) * (((corner >> 1) & 1) ? f[1] : 1.0 - f[1]) * (((corner >> 2) & 1) ? f[2] : 1.0 - f[2]);
    if (weights[corner] == 0.0)
    {
      continue;
    }
    centers[corner] = read(i0 + (corner & 1), j0 + ((corner >> 1) & 1), k0 + ((corner >> 2) & 1));
    value += weights[corner] * centers[corner];
  }
  if (std::abs(value) * this->Quantum > this->CorrectionReach)
  {
    return value * this->Quantum;
  }
  double secondDifference[3] = { 0.0, 0.0, 0.0 };
  for (int corner = 0; corner < 8; ++corner)
  {
    const double weight = weights[corner];
    const double center = centers[corner];
    if (weight == 0.0 || center == Outside || center == Inside)
    {
      continue; // clamped: no curvature information
    }
    const int c[3] = { i0 + (corner & 1), j0 + ((corner >> 1) & 1), k0 + ((corner >> 2) & 1) };
    const double neighbors[3][2] = { { double(read(c[0] - 1, c[1], c[2])), double(read(c[0] + 1, c[1], c[2])) },
      { double(read(c[0], c[1] - 1, c[2])), double(read(c[0], c[1] + 1, c[2])) },
      { double(read(c[0], c[1], c[2] - 1)), double(read(c[0], c[1], c[2] + 1)) } };
    for (int axis = 0; axis < 3; ++axis)
    {
      if (neighbors[axis][0] != Outside && neighbors[axis][1] != Outside && neighbors[axis][0] != Inside && neighbors[axis][1] != Inside)
      {
        secondDifference[axis] += weight * (neighbors[axis][0] - 2.0 * center + neighbors[axis][1]);
      }
    }
  }
  // Linear interpolation of a curved distance field is biased by half the
  // second derivative times t(1-t) along each axis (h^2/(6R) on average for a
  // sphere of radius R); subtracting that estimate makes the reconstructed
  // surface third-order accurate.
  for (int axis = 0; axis < 3; ++axis)
  {
    value -= 0.5 * f[axis] * (1.0 - f[axis]) * secondDifference[axis];
  }
  return value * this->Quantum;
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::InterpolateAtIndex(const double index[3]) const
{
  // One interpolation reads up to 56 samples (8 corners and their curvature
  // neighbours), all in the 4x4x4 block around the cell, which spans at most
  // 2x2x2 bricks: their pointers and each row's offsets are looked up once,
  // so a read is two table lookups and a load, with the value ReadSample gives.
  const int first[3] = { static_cast<int>(std::floor(index[0])) - 1, static_cast<int>(std::floor(index[1])) - 1,
    static_cast<int>(std::floor(index[2])) - 1 };
  const bool blockInside = this->Directory && first[0] >= 0 && first[1] >= 0 && first[2] >= 0 &&
    first[0] + 3 < this->Dimensions[0] && first[1] + 3 < this->Dimensions[1] && first[2] + 3 < this->Dimensions[2];
  if (!blockInside)
  {
    return this->Interpolate(index, [this](int i, int j, int k) { return this->ReadSample(i, j, k); });
  }
  int brickOf[3][4];
  int offsetOf[3][4];
  int brickCount[3];
  constexpr int strides[3] = { 1, BrickSize, BrickSize * BrickSize };
  for (int axis = 0; axis < 3; ++axis)
  {
    const int firstBrick = first[axis] / BrickSize;
    for (int n = 0; n < 4; ++n)
    {
      brickOf[axis][n] = (first[axis] + n) / BrickSize - firstBrick;
      offsetOf[axis][n] = ((first[axis] + n) % BrickSize) * strides[axis];
    }
    brickCount[axis] = brickOf[axis][3] + 1;
  }
  const Brick* bricks[2][2][2] = {};
  for (int dk = 0; dk < brickCount[2]; ++dk)
  {
    for (int dj = 0; dj < brickCount[1]; ++dj)
    {
      for (int di = 0; di < brickCount[0]; ++di)
      {
        const vtkIdType brickId = (static_cast<vtkIdType>(first[2] / BrickSize + dk) * this->BrickDimensions[1] + first[1] / BrickSize + dj) *
            this->BrickDimensions[0] + first[0] / BrickSize + di;
        bricks[dk][dj][di] = this->Directory[brickId].load(std::memory_order_acquire);
      }
    }
  }
  return this->Interpolate(index, [&](int i, int j, int k) -> int16_t {
    const int a = i - first[0];
    const int b = j - first[1];
    const int c = k - first[2];
    const Brick* brick = bricks[brickOf[2][c]][brickOf[1][b]][brickOf[0][a]];
    return brick ? brick->Values[offsetOf[0][a] + offsetOf[1][b] + offsetOf[2][c]].load(std::memory_order_relaxed) : Outside;
  });
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::GetSignedDistance(const double ras[3]) const
{
  if (!this->Directory || !ras || !IsFinite(ras))
  {
    return this->BandWidth;
  }
  double index[3];
  Transform(this->RASToSubIJK, ras, index);
  return this->InterpolateAtIndex(index);
}

//------------------------------------------------------------------------------
vtkMTimeType vtkVolumeCutField::GetMTime()
{
  return std::max(this->Superclass::GetMTime(), this->Protection->GetMTime());
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::GetRemovedFraction(int i, int j, int k) const
{
  const int f = std::max(this->SubVoxelFactor, 1);
  if (this->ReadSample(i, j, k) >= 0 && i >= 0 && j >= 0 && k >= 0 && this->Protection->GetShieldLabel(i / f, j / f, k / f) != 0)
  {
    return 0.0;
  }
  return this->ComputeRemovedFraction(i, j, k);
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::ComputeRemovedFraction(int i, int j, int k) const
{
  const int16_t sample = this->ReadSample(i, j, k);
  const double distance = sample * this->Quantum;
  // No part of the surface is nearer the sample than its distance: a cell
  // whose half diagonal is shorter lies wholly on one side.
  if (std::abs(distance) >= this->HalfDiagonal)
  {
    return distance < 0.0 ? 1.0 : 0.0;
  }
  // Cut cells: average, over n^3 points of the cell, the partial-volume ramp
  // of the reconstructed distance across a sub-cell's extent along the
  // surface normal.
  const double gradientIndex[3] = { 0.5 * (this->ReadSample(i + 1, j, k) - this->ReadSample(i - 1, j, k)),
    0.5 * (this->ReadSample(i, j + 1, k) - this->ReadSample(i, j - 1, k)), 0.5 * (this->ReadSample(i, j, k + 1) - this->ReadSample(i, j, k - 1)) };
  double gradient[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    gradient[axis] =
      this->RASToSubIJK[0][axis] * gradientIndex[0] + this->RASToSubIJK[1][axis] * gradientIndex[1] + this->RASToSubIJK[2][axis] * gradientIndex[2];
  }
  const double norm = vtkMath::Norm(gradient);
  double width = 0.0;
  for (int axis = 0; axis < 3; ++axis)
  {
    width += norm > 0.0
      ? std::abs(this->SubIJKToRAS[0][axis] * gradient[0] + this->SubIJKToRAS[1][axis] * gradient[1] + this->SubIJKToRAS[2][axis] * gradient[2]) / norm
      : 0.0;
  }
  constexpr int n = 4;
  const double subWidth = std::max(width / n, 1e-12);
  // The points read samples at most two away: read those 5^3 once, not
  // up to 56 per point through the brick directory.
  int16_t block[5][5][5];
  for (int dk = 0; dk < 5; ++dk)
  {
    for (int dj = 0; dj < 5; ++dj)
    {
      for (int di = 0; di < 5; ++di)
      {
        block[dk][dj][di] = this->ReadSample(i + di - 2, j + dj - 2, k + dk - 2);
      }
    }
  }
  auto fromBlock = [&](int si, int sj, int sk) { return block[sk - k + 2][sj - j + 2][si - i + 2]; };
  double fraction = 0.0;
  for (int c = 0; c < n; ++c)
  {
    for (int b = 0; b < n; ++b)
    {
      for (int a = 0; a < n; ++a)
      {
        const double index[3] = { i - 0.5 + (a + 0.5) / n, j - 0.5 + (b + 0.5) / n, k - 0.5 + (c + 0.5) / n };
        fraction += std::min(1.0, std::max(0.0, 0.5 - this->Interpolate(index, fromBlock) / subWidth));
      }
    }
  }
  return fraction / (n * n * n);
}

//------------------------------------------------------------------------------
template <typename Visitor>
void vtkVolumeCutField::ForEachSampleOfBrickWithShield(vtkIdType brickId, Visitor&& visit) const
{
  const int f = std::max(this->SubVoxelFactor, 1);
  const int anatomyPerBrick = BrickSize / f; // bricks hold whole anatomy voxels
  uint8_t shield[BrickSize * BrickSize * BrickSize];
  int b[3];
  this->GetBrickIndex(brickId, b);
  const int voxelLower[3] = { b[0] * anatomyPerBrick, b[1] * anatomyPerBrick, b[2] * anatomyPerBrick };
  const int voxelUpper[3] = { voxelLower[0] + anatomyPerBrick - 1, voxelLower[1] + anatomyPerBrick - 1, voxelLower[2] + anatomyPerBrick - 1 };
  this->Protection->GetShieldLabels(voxelLower, voxelUpper, shield);
  for (int k = b[2] * BrickSize; k < std::min((b[2] + 1) * BrickSize, this->Dimensions[2]); ++k)
  {
    for (int j = b[1] * BrickSize; j < std::min((b[1] + 1) * BrickSize, this->Dimensions[1]); ++j)
    {
      const uint8_t* shieldRow = &shield[((k / f - voxelLower[2]) * anatomyPerBrick + (j / f - voxelLower[1])) * anatomyPerBrick];
      for (int i = b[0] * BrickSize; i < std::min((b[0] + 1) * BrickSize, this->Dimensions[0]); ++i)
      {
        visit(i, j, k, shieldRow[i / f - voxelLower[0]] != 0);
      }
    }
  }
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::ComputeRemovedVolume() const
{
  if (!this->Directory)
  {
    return 0.0;
  }
  double removed = 0.0;
  const vtkIdType count = this->NumberOfAllocatedBricks.load(std::memory_order_acquire);
  for (vtkIdType n = 0; n < count; ++n)
  {
    this->ForEachSampleOfBrickWithShield(this->AllocatedBrickIds[n].load(std::memory_order_relaxed), [&](int i, int j, int k, bool shielded) {
      if (!shielded || this->ReadSample(i, j, k) < 0)
      {
        removed += this->ComputeRemovedFraction(i, j, k);
      }
    });
  }
  const double subVoxelVolume = std::abs(vtkMatrix4x4::Determinant(&this->SubIJKToRAS[0][0]));
  return removed * subVoxelVolume;
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ExportRemovedFraction(vtkImageData* anatomyFraction) const
{
  if (!anatomyFraction)
  {
    vtkErrorMacro("ExportRemovedFraction: no output image");
    return;
  }
  const int f = std::max(this->SubVoxelFactor, 1);
  const int dims[3] = { this->Dimensions[0] / f, this->Dimensions[1] / f, this->Dimensions[2] / f };
  anatomyFraction->SetOrigin(0.0, 0.0, 0.0);
  anatomyFraction->SetSpacing(1.0, 1.0, 1.0);
  anatomyFraction->SetDimensions(std::max(dims[0], 1), std::max(dims[1], 1), std::max(dims[2], 1));
  anatomyFraction->AllocateScalars(VTK_FLOAT, 1);
  vtkFloatArray* scalars = vtkFloatArray::SafeDownCast(anatomyFraction->GetPointData()->GetScalars());
  scalars->SetName("RemovedFraction");
  scalars->FillValue(0.0f);
  if (!this->Directory)
  {
    return;
  }
  vtkNew<vtkIdTypeArray> voxelIds;
  vtkNew<vtkFloatArray> fractions;
  this->ExportRemovedVoxels(voxelIds, fractions);
  float* values = scalars->GetPointer(0);
  for (vtkIdType n = 0; n < voxelIds->GetNumberOfValues(); ++n)
  {
    values[voxelIds->GetValue(n)] = fractions->GetValue(n);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ExportRemovedVoxels(vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const
{
  if (!anatomyVoxelIds || !fractions)
  {
    vtkErrorMacro("ExportRemovedVoxels: no output arrays");
    return;
  }
  anatomyVoxelIds->Reset();
  fractions->Reset();
  fractions->SetName("RemovedFraction");
  const vtkIdType count = this->Directory ? this->NumberOfAllocatedBricks.load(std::memory_order_acquire) : 0;
  for (vtkIdType n = 0; n < count; ++n)
  {
    this->AppendRemovedVoxelsOfBrick(this->AllocatedBrickIds[n].load(std::memory_order_relaxed), anatomyVoxelIds, fractions);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::AppendRemovedVoxelsOfBrick(vtkIdType brickId, vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const
{
  const vtkIdType total = static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1] * this->BrickDimensions[2];
  if (!anatomyVoxelIds || !fractions || !this->Directory || brickId < 0 || brickId >= total ||
    !this->Directory[brickId].load(std::memory_order_acquire))
  {
    return;
  }
  // Bricks hold whole anatomy voxels: sum each voxel's sub-voxels here.
  const int f = std::max(this->SubVoxelFactor, 1);
  const int anatomyPerBrick = BrickSize / f;
  const int dims[3] = { this->Dimensions[0] / f, this->Dimensions[1] / f, this->Dimensions[2] / f };
  int b[3];
  this->GetBrickIndex(brickId, b);
  double sums[BrickSize * BrickSize * BrickSize] = {};
  this->ForEachSampleOfBrickWithShield(brickId, [&](int i, int j, int k, bool shielded) {
    if (shielded && this->ReadSample(i, j, k) >= 0)
    {
      return;
    }
    const int local = ((k / f - b[2] * anatomyPerBrick) * anatomyPerBrick + (j / f - b[1] * anatomyPerBrick)) * anatomyPerBrick + (i / f - b[0] * anatomyPerBrick);
    sums[local] += this->ComputeRemovedFraction(i, j, k);
  });
  const double perSubVoxel = 1.0 / (f * f * f);
  for (int local = 0; local < anatomyPerBrick * anatomyPerBrick * anatomyPerBrick; ++local)
  {
    const int v[3] = { b[0] * anatomyPerBrick + local % anatomyPerBrick, b[1] * anatomyPerBrick + (local / anatomyPerBrick) % anatomyPerBrick,
      b[2] * anatomyPerBrick + local / (anatomyPerBrick * anatomyPerBrick) };
    if (sums[local] > 0.0 && v[0] < dims[0] && v[1] < dims[1] && v[2] < dims[2])
    {
      anatomyVoxelIds->InsertNextValue((static_cast<vtkIdType>(v[2]) * dims[1] + v[1]) * dims[0] + v[0]);
      fractions->InsertNextValue(static_cast<float>(std::min(1.0, sums[local] * perSubVoxel)));
    }
  }
}

//------------------------------------------------------------------------------
vtkTypeUInt64 vtkVolumeCutField::GetBrickStamp(vtkIdType brickId) const
{
  const vtkIdType total = static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1] * this->BrickDimensions[2];
  const Brick* brick = this->Directory && brickId >= 0 && brickId < total ? this->Directory[brickId].load(std::memory_order_acquire) : nullptr;
  return brick ? brick->Stamp.load(std::memory_order_acquire) : 0;
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::GetBricksModifiedSince(vtkTypeUInt64 stamp, vtkIdList* brickIds) const
{
  if (!brickIds)
  {
    return;
  }
  brickIds->Reset();
  const vtkIdType count = this->NumberOfAllocatedBricks.load(std::memory_order_acquire);
  for (vtkIdType n = 0; n < count; ++n)
  {
    const vtkIdType brickId = this->AllocatedBrickIds[n].load(std::memory_order_relaxed);
    const Brick* brick = this->Directory[brickId].load(std::memory_order_acquire);
    if (brick && brick->Stamp.load(std::memory_order_relaxed) > stamp)
    {
      brickIds->InsertNextId(brickId);
    }
  }
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutField::GetBrickMemorySize() const
{
  const vtkIdType total = static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1] * this->BrickDimensions[2];
  return static_cast<size_t>(this->GetNumberOfAllocatedBricks()) * sizeof(Brick)
    + static_cast<size_t>(total) * (sizeof(std::atomic<Brick*>) + sizeof(std::atomic<vtkIdType>));
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutField::GetDenseMemorySize() const
{
  return static_cast<size_t>(this->Dimensions[0]) * this->Dimensions[1] * this->Dimensions[2] * sizeof(int16_t);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::SetInstructionSet(int set)
{
  return vtkVolumeCutKernels::Select(set);
}

//------------------------------------------------------------------------------
int vtkVolumeCutField::GetInstructionSet()
{
  return vtkVolumeCutKernels::GetSelected();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::IsInstructionSetAvailable(int set)
{
  return vtkVolumeCutKernels::IsAvailable(set);
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutField::GetInstructionSetAsString(int set)
{
  return vtkVolumeCutKernels::GetName(set);
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " " << this->Dimensions[2] << "\n";
  os << indent << "SubVoxelFactor: " << this->SubVoxelFactor << "\n";
  os << indent << "BandWidth: " << this->BandWidth << "\n";
  os << indent << "CorrectionReach: " << this->CorrectionReach << "\n";
  os << indent << "MaximumStrokeLength: " << this->MaximumStrokeLength << "\n";
  os << indent << "InstructionSet: " << GetInstructionSetAsString(GetInstructionSet()) << "\n";
  os << indent << "NumberOfAllocatedBricks: " << this->GetNumberOfAllocatedBricks() << "\n";
  os << indent << "UndoSteps: " << this->History->GetNumberOfUndoSteps() << " (" << this->History->GetMemorySize() / 1024 << " KiB of "
     << this->UndoMemoryBudget / 1024
     << " KiB)\n";
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ExtractRemovedSurface(vtkPolyData* surface) const
{
  if (!surface)
  {
    return;
  }
  surface->Initialize();
  const vtkIdType count = this->NumberOfAllocatedBricks.load(std::memory_order_acquire);
  if (!this->Directory || count == 0)
  {
    return;
  }
  // Sub-voxel box of the allocated bricks, one sample wider on each side so
  // that the surface closes where the removed region meets the volume's edge.
  int lower[3] = { std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), std::numeric_limits<int>::max() };
  int upper[3] = { std::numeric_limits<int>::min(), std::numeric_limits<int>::min(), std::numeric_limits<int>::min() };
  for (vtkIdType n = 0; n < count; ++n)
  {
    const vtkIdType brickId = this->AllocatedBrickIds[n].load(std::memory_order_relaxed);
    int b[3];
    this->GetBrickIndex(brickId, b);
    for (int axis = 0; axis < 3; ++axis)
    {
      lower[axis] = std::min(lower[axis], b[axis] * BrickSize - 1);
      upper[axis] = std::max(upper[axis], b[axis] * BrickSize + BrickSize);
    }
  }
  vtkNew<vtkImageData> samples;
  samples->SetExtent(lower[0], upper[0], lower[1], upper[1], lower[2], upper[2]);
  samples->AllocateScalars(VTK_FLOAT, 1);
  float* values = static_cast<float*>(samples->GetScalarPointer());
  vtkIdType index = 0;
  for (int k = lower[2]; k <= upper[2]; ++k)
  {
    for (int j = lower[1]; j <= upper[1]; ++j)
    {
      for (int i = lower[0]; i <= upper[0]; ++i, ++index)
      {
        values[index] = static_cast<float>(this->ReadSample(i, j, k) * this->Quantum);
      }
    }
  }
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(samples);
  contour->SetValue(0, 0.0);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  // Index space to RAS.
  vtkNew<vtkTransform> subToRas;
  subToRas->SetMatrix(&this->SubIJKToRAS[0][0]);
  vtkNew<vtkTransformPolyDataFilter> toRas;
  toRas->SetInputConnection(contour->GetOutputPort());
  toRas->SetTransform(subToRas);
  toRas->Update();
  surface->ShallowCopy(toRas->GetOutput());
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::WriteFile(const char* fileName) const
{
  vtkNew<vtkVolumeCutFieldFile> file;
  file->SetFileName(fileName);
  return file->Write(const_cast<vtkVolumeCutField*>(this));
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::ReadFile(const char* fileName)
{
  vtkNew<vtkVolumeCutFieldFile> file;
  file->SetFileName(fileName);
  return file->Read(this);
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::GetBrickIndex(vtkIdType brickId, int index[3]) const
{
  index[0] = static_cast<int>(brickId % this->BrickDimensions[0]);
  index[1] = static_cast<int>((brickId / this->BrickDimensions[0]) % this->BrickDimensions[1]);
  index[2] = static_cast<int>(brickId / (static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1]));
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ReplaceBricks(const BrickStates& bricks)
{
  // A field made from another has its own history, starting now.
  this->History->EndStroke();
  this->History->Clear();
  this->LastCapsule.Valid = false;
  this->LastToolSweep.Valid = false;
  this->WriteBricks(bricks);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::GetLatticeMap(vtkVolumeCutField* source, int permutation[3][3], int offset[3]) const
{
  if (!source || !source->Directory || !this->Directory || std::abs(source->Quantum - this->Quantum) > 1e-12 * this->Quantum)
  {
    return false; // another band: values would need rescaling
  }
  // Source index of each target index: s = M t + m. The same lattice indexed
  // another way (axes flipped or swapped, as volume readers reorient scans)
  // makes M a signed permutation and m whole numbers, to a thousandth of a
  // sample over the whole grid.
  double m[4][4];
  vtkMatrix4x4::Multiply4x4(&source->RASToSubIJK[0][0], &this->SubIJKToRAS[0][0], &m[0][0]);
  const double tolerance = 1e-3 / std::max({ this->Dimensions[0], this->Dimensions[1], this->Dimensions[2], 1 });
  for (int row = 0; row < 3; ++row)
  {
    int ones = 0;
    for (int column = 0; column < 3; ++column)
    {
      const double nearest = std::round(m[row][column]);
      if (!(std::abs(m[row][column] - nearest) <= tolerance) || std::abs(nearest) > 1.0)
      {
        return false;
      }
      permutation[row][column] = static_cast<int>(nearest);
      ones += permutation[row][column] != 0;
    }
    const double nearest = std::round(m[row][3]);
    if (ones != 1 || !(std::abs(m[row][3] - nearest) <= 1e-3))
    {
      return false;
    }
    offset[row] = static_cast<int>(nearest);
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::IsSameLattice(vtkVolumeCutField* other)
{
  int permutation[3][3];
  int offset[3];
  return this->GetLatticeMap(other, permutation, offset);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::CopyFromSameLattice(vtkVolumeCutField* source)
{
  int permutation[3][3];
  int offset[3];
  if (!this->GetLatticeMap(source, permutation, offset))
  {
    return false;
  }
  BrickStates bricks;
  const vtkIdType sourceCount = source->GetNumberOfAllocatedBricks();
  short values[SamplesPerBrick];
  for (vtkIdType n = 0; n < sourceCount; ++n)
  {
    const vtkIdType brickId = source->AllocatedBrickIds[n].load(std::memory_order_relaxed);
    source->CopyBrick(brickId, values);
    int b[3];
    source->GetBrickIndex(brickId, b);
    for (int local = 0; local < SamplesPerBrick; ++local)
    {
      if (values[local] == Outside)
      {
        continue;
      }
      const int sample[3] = { b[0] * BrickSize + local % BrickSize, b[1] * BrickSize + (local / BrickSize) % BrickSize,
        b[2] * BrickSize + local / (BrickSize * BrickSize) };
      if (sample[0] >= source->Dimensions[0] || sample[1] >= source->Dimensions[1] || sample[2] >= source->Dimensions[2])
      {
        continue;
      }
      // t = M^T (s - m): the inverse of a signed permutation is its transpose.
      int target[3];
      bool inside = true;
      for (int column = 0; column < 3; ++column)
      {
        target[column] = 0;
        for (int row = 0; row < 3; ++row)
        {
          target[column] += permutation[row][column] * (sample[row] - offset[row]);
        }
        inside &= target[column] >= 0 && target[column] < this->Dimensions[column];
      }
      if (!inside)
      {
        continue;
      }
      const vtkIdType targetBrick =
        (static_cast<vtkIdType>(target[2] / BrickSize) * this->BrickDimensions[1] + target[1] / BrickSize) * this->BrickDimensions[0] + target[0] / BrickSize;
      BrickValues& targetValues = bricks[targetBrick];
      if (targetValues.empty())
      {
        targetValues.assign(SamplesPerBrick, Outside);
      }
      targetValues[((target[2] % BrickSize) * BrickSize + target[1] % BrickSize) * BrickSize + target[0] % BrickSize] = values[local];
    }
  }
  this->ReplaceBricks(bricks);
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::ResampleFrom(vtkVolumeCutField* source)
{
  if (!source || !source->Directory || !this->Directory)
  {
    vtkErrorMacro("ResampleFrom: both fields must be initialized");
    return false;
  }
  if (this->CopyFromSameLattice(source))
  {
    return true;
  }
  // The target bricks that any allocated source brick can reach: elsewhere
  // the source reads +BandWidth, which is what an unallocated brick holds.
  std::vector<vtkIdType> targets;
  const vtkIdType sourceCount = source->GetNumberOfAllocatedBricks();
  for (vtkIdType n = 0; n < sourceCount; ++n)
  {
    const vtkIdType brickId = source->AllocatedBrickIds[n].load(std::memory_order_relaxed);
    int b[3];
    source->GetBrickIndex(brickId, b);
    int lower[3] = { std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), std::numeric_limits<int>::max() };
    int upper[3] = { std::numeric_limits<int>::min(), std::numeric_limits<int>::min(), std::numeric_limits<int>::min() };
    for (int corner = 0; corner < 8; ++corner)
    {
      // One source sample beyond the brick: interpolation reaches that far.
      double index[3];
      for (int axis = 0; axis < 3; ++axis)
      {
        index[axis] = (corner >> axis) & 1 ? b[axis] * BrickSize + BrickSize : b[axis] * BrickSize - 1.0;
      }
      double ras[3];
      Transform(source->SubIJKToRAS, index, ras);
      double target[3];
      Transform(this->RASToSubIJK, ras, target);
      for (int axis = 0; axis < 3; ++axis)
      {
        lower[axis] = std::min(lower[axis], static_cast<int>(std::floor(target[axis])));
        upper[axis] = std::max(upper[axis], static_cast<int>(std::ceil(target[axis])));
      }
    }
    int brickLower[3];
    int brickUpper[3];
    bool inside = true;
    for (int axis = 0; axis < 3; ++axis)
    {
      brickLower[axis] = std::max(0, lower[axis]) / BrickSize;
      brickUpper[axis] = std::min(this->Dimensions[axis] - 1, upper[axis]) / BrickSize;
      inside &= upper[axis] >= 0 && lower[axis] < this->Dimensions[axis];
    }
    for (int k = brickLower[2]; inside && k <= brickUpper[2]; ++k)
    {
      for (int j = brickLower[1]; j <= brickUpper[1]; ++j)
      {
        for (int i = brickLower[0]; i <= brickUpper[0]; ++i)
        {
          targets.push_back((static_cast<vtkIdType>(k) * this->BrickDimensions[1] + j) * this->BrickDimensions[0] + i);
        }
      }
    }
  }
  std::sort(targets.begin(), targets.end());
  targets.erase(std::unique(targets.begin(), targets.end()), targets.end());

  BrickStates bricks;
  const double inverseQuantum = 1.0 / this->Quantum;
  for (vtkIdType brickId : targets)
  {
    int b[3];
    this->GetBrickIndex(brickId, b);
    BrickValues values(SamplesPerBrick, Outside);
    bool any = false;
    for (int local = 0; local < SamplesPerBrick; ++local)
    {
      const double index[3] = { double(b[0] * BrickSize + local % BrickSize), double(b[1] * BrickSize + (local / BrickSize) % BrickSize),
        double(b[2] * BrickSize + local / (BrickSize * BrickSize)) };
      double ras[3];
      Transform(this->SubIJKToRAS, index, ras);
      // Beyond the source's band its value says only "at least this far".
      const double distance = source->GetSignedDistance(ras);
      const double beyond = source->BandWidth - source->Quantum;
      values[local] = distance >= beyond ? Outside
        : distance <= -beyond            ? Inside
                                         : static_cast<int16_t>(std::lround(std::min(this->BandWidth, std::max(-this->BandWidth, distance)) * inverseQuantum));
      any |= values[local] != Outside;
    }
    if (any)
    {
      bricks[brickId] = std::move(values);
    }
  }
  this->ReplaceBricks(bricks);
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::DeepCopy(vtkVolumeCutField* source)
{
  if (!source || source == this)
  {
    return;
  }
  if (!source->Directory)
  {
    this->Reset();
    std::fill(this->Dimensions, this->Dimensions + 3, 0);
    this->SubVoxelFactor = 0;
    this->Modified();
    return;
  }
  vtkNew<vtkMatrix4x4> ijkToRas;
  ijkToRas->DeepCopy(source->AnatomyIJKToRAS);
  const int f = source->SubVoxelFactor;
  const int dimensions[3] = { source->Dimensions[0] / f, source->Dimensions[1] / f, source->Dimensions[2] / f };
  this->Initialize(dimensions, ijkToRas, f);
  this->MaximumStrokeLength = source->MaximumStrokeLength;
  this->UndoMemoryBudget = source->UndoMemoryBudget;
  BrickStates bricks;
  const vtkIdType count = source->GetNumberOfAllocatedBricks();
  short values[SamplesPerBrick];
  for (vtkIdType n = 0; n < count; ++n)
  {
    const vtkIdType brickId = source->AllocatedBrickIds[n].load(std::memory_order_relaxed);
    source->CopyBrick(brickId, values);
    bricks[brickId].assign(values, values + SamplesPerBrick);
  }
  this->WriteBricks(bricks);
}
