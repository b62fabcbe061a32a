// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutField's copies between fields: DeepCopy, the exact copy between
// grids that are one lattice indexed another way, and the resampling of
// another field's cut onto this field's grid. Each starts a new history.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldInternals.h"
#include "vtkVolumeCutFieldUndoHistory.h"

#include "vtkMatrix4x4.h"
#include "vtkNew.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

using vtkVolumeCutFieldInternals::BrickSize;
using vtkVolumeCutFieldInternals::Inside;
using vtkVolumeCutFieldInternals::Outside;
using vtkVolumeCutFieldInternals::SamplesPerBrick;
using vtkVolumeCutFieldInternals::Transform;

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
  // The shield keeps every sample of a shielded voxel, not the whole voxel:
  // its wall (the structure's smoothed surface) may pass between them, where
  // a finer grid has samples. Those are kept as the source's nearest sample
  // of the same voxel was, so that a finer grid removes nothing inside a
  // shielded voxel that the source did not.
  const bool shielded = source->Protection->HasShieldedLabels();
  const int sourceFactor = std::max(source->SubVoxelFactor, 1);
  auto keptBySource = [&](const double ras[3]) {
    double sourceIndex[3];
    Transform(source->RASToSubIJK, ras, sourceIndex);
    int voxel[3];
    int nearest[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      voxel[axis] = static_cast<int>(std::lround((sourceIndex[axis] + 0.5) / sourceFactor - 0.5));
      nearest[axis] = std::max(voxel[axis] * sourceFactor, std::min(voxel[axis] * sourceFactor + sourceFactor - 1, static_cast<int>(std::lround(sourceIndex[axis]))));
    }
    return source->Protection->GetShieldLabel(voxel[0], voxel[1], voxel[2]) != 0 && source->ReadSample(nearest[0], nearest[1], nearest[2]) >= 0;
  };
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
      if (shielded && values[local] < 0 && keptBySource(ras))
      {
        values[local] = 0;
      }
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
