// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The field's life cycle and geometry, its shield and its settings. The rest of
// the class is split by responsibility: vtkVolumeCutFieldTools.cxx (the cut and
// restore entry points), vtkVolumeCutFieldSweeps.cxx (the writer),
// vtkVolumeCutFieldBricks.cxx (the brick store), vtkVolumeCutFieldQueries.cxx
// (readers and exports), vtkVolumeCutFieldLattice.cxx (copies between fields);
// the undo history is vtkVolumeCutFieldUndoHistory.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldFile.h"
#include "vtkVolumeCutFieldInternals.h"
#include "vtkVolumeCutFieldUndoHistory.h"
#include "vtkVolumeCutKernels.h"
#include "vtkVolumeCutProtection.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"

#include <algorithm>
#include <cmath>
#include <limits>

using vtkVolumeCutFieldInternals::BrickSize;
using vtkVolumeCutFieldInternals::IsFinite;
using vtkVolumeCutFieldInternals::Outside;
using vtkVolumeCutFieldInternals::SamplesPerBrick;
using vtkVolumeCutFieldInternals::Transform;

vtkStandardNewMacro(vtkVolumeCutField);

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
vtkIdType vtkVolumeCutField::PrepareProtection(const double center[3], double radius)
{
  if (!this->CollectProtectionBricks(center, radius, this->PreparationBrickIds))
  {
    return 0;
  }
  const vtkIdType before = this->Protection->GetNumberOfBuiltBricks();
  for (vtkIdType brickId : this->PreparationBrickIds)
  {
    this->GetProtectionBrick(brickId);
  }
  return this->Protection->GetNumberOfBuiltBricks() - before;
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutField::PrepareProtectionAhead(const double center[3], double radius)
{
  std::vector<vtkIdType> brickIds;
  if (!this->CollectProtectionBricks(center, radius, brickIds))
  {
    return 0;
  }
  return this->Protection->PrepareBricks(brickIds.data(), static_cast<vtkIdType>(brickIds.size()));
}

//------------------------------------------------------------------------------
bool vtkVolumeCutField::CollectProtectionBricks(const double center[3], double radius, std::vector<vtkIdType>& brickIds) const
{
  brickIds.clear();
  if (!this->Directory || !center || !IsFinite(center) || !(radius >= 0.0) || !this->Protection->HasShieldedLabels())
  {
    return false;
  }
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
          brickIds.push_back((static_cast<vtkIdType>(bk) * this->BrickDimensions[1] + bj) * this->BrickDimensions[0] + bi);
        }
      }
    }
  }
  return true;
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
vtkMTimeType vtkVolumeCutField::GetMTime()
{
  return std::max(this->Superclass::GetMTime(), this->Protection->GetMTime());
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
