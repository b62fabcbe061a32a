// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutField's writer: merges a tool sweep's distances into the bricks
// it reaches, row by row or a brick at a time (vtkVolumeCutFieldDistanceSource.h),
// quantised and merged by the per-instruction-set kernels, with the shield
// and its contacts, and commits each changed brick under its seqlock after
// the undo history has kept it. The hot path of every stroke.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldDistanceSource.h"
#include "vtkVolumeCutFieldInternals.h"
#include "vtkVolumeCutFieldUndoHistory.h"
#include "vtkVolumeCutKernels.h"
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutProtectionBrick.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

using vtkVolumeCutFieldInternals::BrickSize;
using vtkVolumeCutFieldInternals::Inside;
using vtkVolumeCutFieldInternals::Outside;
using vtkVolumeCutFieldInternals::SamplesPerBrick;
using vtkVolumeCutFieldInternals::Transform;

//------------------------------------------------------------------------------
const vtkVolumeCutProtection::Brick* vtkVolumeCutField::GetProtectionBrick(vtkIdType brickId)
{
  return this->Protection->GetBrick(brickId);
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
