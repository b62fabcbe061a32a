// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutFractionMirror.h"

#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkObjectFactory.h"
#include "vtkVolumeCutField.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <utility>

vtkStandardNewMacro(vtkVolumeCutFractionMirror);

namespace
{
/// 0-255 from a fraction, as the OpenIGTLink bridge always rounded it (numpy's rint: to nearest, ties to even).
unsigned char ToByte(float fraction)
{
  const double clamped = std::min(1.0, std::max(0.0, static_cast<double>(fraction)));
  return static_cast<unsigned char>(std::nearbyint(255.0 * clamped));
}
} // namespace

//------------------------------------------------------------------------------
vtkVolumeCutFractionMirror::vtkVolumeCutFractionMirror() = default;

//------------------------------------------------------------------------------
vtkVolumeCutFractionMirror::~vtkVolumeCutFractionMirror() = default;

//------------------------------------------------------------------------------
bool vtkVolumeCutFractionMirror::Reset(vtkVolumeCutField* field)
{
  this->Pending.clear();
  this->Next = 0;
  std::fill(this->Box, this->Box + 6, 0);
  this->CopiedBrick = -1;
  const int factor = field ? std::max(field->GetSubVoxelFactor(), 1) : 1;
  int dimensions[3] = { 0, 0, 0 };
  if (field)
  {
    field->GetDimensions(dimensions);
  }
  if (!field || dimensions[0] < factor || dimensions[1] < factor || dimensions[2] < factor)
  {
    vtkErrorMacro("Reset: " << (field ? "the field is not initialized" : "no field"));
    this->Field = nullptr;
    this->Image = nullptr;
    return false;
  }
  this->Field = field;
  for (int axis = 0; axis < 3; ++axis)
  {
    this->AnatomyDimensions[axis] = dimensions[axis] / factor;
  }
  this->VoxelsPerBrick = std::max(1, vtkVolumeCutField::BrickSize / factor);
  this->Image = vtkSmartPointer<vtkImageData>::New();
  this->Image->SetDimensions(this->AnatomyDimensions);
  this->Image->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  unsigned char* voxels = static_cast<unsigned char*>(this->Image->GetScalarPointer());
  std::fill(voxels, voxels + this->Image->GetNumberOfPoints(), static_cast<unsigned char>(0));
  this->Stamp = field->GetCurrentStamp();
  field->ExportRemovedVoxels(this->VoxelIds, this->Fractions);
  this->WriteVoxels(this->VoxelIds, this->Fractions);
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutFractionMirror::WriteVoxels(vtkIdTypeArray* ids, vtkFloatArray* fractions)
{
  unsigned char* voxels = static_cast<unsigned char*>(this->Image->GetScalarPointer());
  const vtkIdType count = this->Image->GetNumberOfPoints();
  for (vtkIdType n = 0; n < ids->GetNumberOfValues(); ++n)
  {
    const vtkIdType id = ids->GetValue(n);
    if (id >= 0 && id < count)
    {
      voxels[id] = ToByte(fractions->GetValue(n));
    }
  }
}

//------------------------------------------------------------------------------
bool vtkVolumeCutFractionMirror::BeginUpdate()
{
  if (!this->Field || !this->Image || this->IsUpdating())
  {
    return false;
  }
  const vtkTypeUInt64 stamp = this->Field->GetCurrentStamp();
  if (stamp <= this->Stamp)
  {
    return false;
  }
  vtkNew<vtkIdList> changed;
  this->Field->GetBricksModifiedSince(this->Stamp, changed);
  this->Stamp = stamp;
  this->Pending.clear();
  this->Next = 0;
  if (changed->GetNumberOfIds() == 0)
  {
    return false;
  }
  // A voxel's fraction reads the samples one sample around its own: the
  // voxels of a changed brick and the one-voxel layer around it may change,
  // not the rest of the neighbouring bricks.
  int bricks[3];
  this->Field->GetBrickDimensions(bricks);
  const int* dims = this->AnatomyDimensions;
  const int step = this->VoxelsPerBrick;
  std::vector<std::array<int, 6>> boxes;
  int lower[3] = { dims[0], dims[1], dims[2] };
  int upper[3] = { 0, 0, 0 };
  for (vtkIdType n = 0; n < changed->GetNumberOfIds(); ++n)
  {
    const vtkIdType id = changed->GetId(n);
    const int index[3] = { static_cast<int>(id % bricks[0]), static_cast<int>((id / bricks[0]) % bricks[1]),
      static_cast<int>(id / (static_cast<vtkIdType>(bricks[0]) * bricks[1])) };
    std::array<int, 6> box;
    for (int axis = 0; axis < 3; ++axis)
    {
      box[2 * axis] = std::max(index[axis] * step - 1, 0);
      box[2 * axis + 1] = std::min((index[axis] + 1) * step + 1, dims[axis]);
      lower[axis] = std::min(lower[axis], box[2 * axis]);
      upper[axis] = std::max(upper[axis], box[2 * axis + 1]);
    }
    if (box[0] < box[1] && box[2] < box[3] && box[4] < box[5])
    {
      boxes.push_back(box);
    }
  }
  if (boxes.empty())
  {
    return false;
  }
  const int size[3] = { upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2] };
  std::vector<char> listed(static_cast<size_t>(size[0]) * size[1] * size[2], 0);
  for (const auto& box : boxes)
  {
    for (int k = box[4]; k < box[5]; ++k)
    {
      for (int j = box[2]; j < box[3]; ++j)
      {
        for (int i = box[0]; i < box[1]; ++i)
        {
          char& seen = listed[(static_cast<size_t>(k - lower[2]) * size[1] + (j - lower[1])) * size[0] + (i - lower[0])];
          if (!seen)
          {
            seen = 1;
            this->Pending.push_back((static_cast<vtkIdType>(k) * dims[1] + j) * dims[0] + i);
          }
        }
      }
    }
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    this->Box[2 * axis] = lower[axis];
    this->Box[2 * axis + 1] = upper[axis];
  }
  // Brick by brick, so that Advance copies each brick's samples once.
  const auto brickOf = [&](vtkIdType id) {
    const vtkIdType i = id % dims[0];
    const vtkIdType j = (id / dims[0]) % dims[1];
    const vtkIdType k = id / (static_cast<vtkIdType>(dims[0]) * dims[1]);
    return i / step + bricks[0] * (j / step + static_cast<vtkIdType>(bricks[1]) * (k / step));
  };
  std::sort(this->Pending.begin(), this->Pending.end(),
    [&](vtkIdType a, vtkIdType b) { return std::make_pair(brickOf(a), a) < std::make_pair(brickOf(b), b); });
  this->CopiedBrick = -1;
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutFractionMirror::Advance(double budgetSeconds)
{
  if (!this->Field || !this->Image)
  {
    return true;
  }
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                         std::chrono::duration<double>(std::max(0.0, budgetSeconds)));
  unsigned char* voxels = static_cast<unsigned char*>(this->Image->GetScalarPointer());
  const int* dims = this->AnatomyDimensions;
  const int f = std::max(this->Field->GetSubVoxelFactor(), 1);
  const int step = this->VoxelsPerBrick;
  const double perSubVoxel = 1.0 / (f * f * f);
  int bricks[3];
  this->Field->GetBrickDimensions(bricks);
  double spacing[3];
  this->Field->GetSubVoxelSpacing(spacing);
  // A sample farther than half a sub-voxel's diagonal from the cut surface is
  // wholly removed or wholly kept (the field's own shortcut); only the others
  // need the field's exact integration. Read from a copy of the brick: the
  // shield lookup and the integration are what a voxel costs.
  const double halfDiagonal = 0.5 * std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
  const double quantum = this->Field->GetQuantum();
  constexpr int B = vtkVolumeCutField::BrickSize;
  // The clock is read every few voxels: a voxel costs microseconds at most.
  constexpr size_t VoxelsBetweenClockReadings = 32;
  while (this->IsUpdating())
  {
    const size_t end = std::min(this->Pending.size(), this->Next + VoxelsBetweenClockReadings);
    for (; this->Next < end; ++this->Next)
    {
      const vtkIdType id = this->Pending[this->Next];
      const int i = static_cast<int>(id % dims[0]);
      const int j = static_cast<int>((id / dims[0]) % dims[1]);
      const int k = static_cast<int>(id / (static_cast<vtkIdType>(dims[0]) * dims[1]));
      // Summed in the order vtkVolumeCutField::AppendRemovedVoxelsOfBrick sums, rounded as the bridge rounds its values.
      const int brick[3] = { i / step, j / step, k / step };
      const vtkIdType brickId = brick[0] + bricks[0] * (brick[1] + static_cast<vtkIdType>(bricks[1]) * brick[2]);
      if (brickId != this->CopiedBrick)
      {
        this->CopiedBrick = brickId;
        this->CopiedBrickWritten = this->Field->CopyBrick(brickId, this->Samples) != 0;
      }
      double sum = 0.0;
      for (int c = 0; c < f && this->CopiedBrickWritten; ++c)
      {
        for (int b = 0; b < f; ++b)
        {
          for (int a = 0; a < f; ++a)
          {
            const int si = i * f + a;
            const int sj = j * f + b;
            const int sk = k * f + c;
            const double distance =
              quantum * this->Samples[((sk - brick[2] * B) * B + (sj - brick[1] * B)) * B + (si - brick[0] * B)];
            sum += distance >= halfDiagonal ? 0.0 : distance <= -halfDiagonal ? 1.0 : this->Field->GetRemovedFraction(si, sj, sk);
          }
        }
      }
      voxels[id] = ToByte(static_cast<float>(std::min(1.0, sum * perSubVoxel)));
    }
    if (Clock::now() >= deadline)
    {
      break;
    }
  }
  return !this->IsUpdating();
}

//------------------------------------------------------------------------------
void vtkVolumeCutFractionMirror::GetUpdateBox(int box[6]) const
{
  std::copy(this->Box, this->Box + 6, box);
}

//------------------------------------------------------------------------------
vtkImageData* vtkVolumeCutFractionMirror::GetImage()
{
  return this->Image;
}

//------------------------------------------------------------------------------
void vtkVolumeCutFractionMirror::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Field: " << this->Field.GetPointer() << "\n";
  os << indent << "Stamp: " << this->Stamp << "\n";
  os << indent << "AnatomyDimensions: " << this->AnatomyDimensions[0] << " x " << this->AnatomyDimensions[1] << " x "
     << this->AnatomyDimensions[2] << "\n";
  os << indent << "PendingVoxels: " << this->GetNumberOfPendingVoxels() << " of " << this->GetNumberOfUpdateVoxels() << "\n";
}
