// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutField's brick store: the directory of 8x8x8 bricks, allocated
// where a tool first writes and never freed while the field lives, their
// modification stamps, and the seqlock through which readers copy a brick
// consistently while the writer changes it.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldInternals.h"

#include "vtkIdList.h"

#include <algorithm>

using vtkVolumeCutFieldInternals::BrickSize;
using vtkVolumeCutFieldInternals::Outside;
using vtkVolumeCutFieldInternals::SamplesPerBrick;

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
void vtkVolumeCutField::GetBrickIndex(vtkIdType brickId, int index[3]) const
{
  index[0] = static_cast<int>(brickId % this->BrickDimensions[0]);
  index[1] = static_cast<int>((brickId / this->BrickDimensions[0]) % this->BrickDimensions[1]);
  index[2] = static_cast<int>(brickId / (static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1]));
}
