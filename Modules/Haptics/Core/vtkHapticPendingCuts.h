// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to vtkVolumeCuttingHaptics (not installed, not wrapped): the stroke
// segments the haptic thread queued for the loop's cutter that the cutter has
// not cut yet, for the force model (vtkHapticLoop::FeelPendingCuts).
#ifndef vtkHapticPendingCuts_h
#define vtkHapticPendingCuts_h

#include "vtkHapticForceModel.h"

#include <algorithm>
#include <atomic>

/**
 * The haptic thread numbers the segments it queues (1, 2, ...) and keeps a
 * copy of the last MaximumPendingCuts; the cutter publishes the number of the
 * last one it cut, after the cut. A tick gives the force model the copies
 * numbered above it: the segments the field does not hold yet. Reading the
 * number before the force model reads the field, a segment cut meanwhile is
 * both in the field and pending (the union is the same); never in neither.
 * No lock, no allocation; the one value shared is the atomic number.
 */
class vtkHapticPendingCuts
{
public:
  static constexpr int Capacity = vtkHapticForceModel::MaximumPendingCuts;

  /// Before the threads start: nothing queued, nothing cut.
  void Reset()
  {
    this->Queued = 0;
    this->End = 0;
    this->Cut.store(0, std::memory_order_relaxed);
  }

  /// Haptic thread: the number the next queued segment gets.
  unsigned long long GetNextSequence() const { return this->Queued + 1; }

  /// Haptic thread: the segment numbered sequence (GetNextSequence) was queued; the oldest copy gives way past Capacity.
  void Add(unsigned long long sequence, const double p0[3], const double p1[3])
  {
    this->Queued = sequence;
    Segment& segment = this->Segments[this->End++ % Capacity];
    segment.Sequence = sequence;
    std::copy(p0, p0 + 3, segment.P0);
    std::copy(p1, p1 + 3, segment.P1);
  }

  /// The cutter's thread: the segment numbered sequence is in the field.
  void MarkCut(unsigned long long sequence) { this->Cut.store(sequence, std::memory_order_release); }

  /// Haptic thread: give the force model the segments not cut yet, oldest first.
  void ShowTo(vtkHapticForceModel* model) const
  {
    model->ClearPendingCuts();
    const unsigned long long cut = this->Cut.load(std::memory_order_acquire);
    for (unsigned long long n = this->End > Capacity ? this->End - Capacity : 0; n < this->End; ++n)
    {
      const Segment& segment = this->Segments[n % Capacity];
      if (segment.Sequence > cut)
      {
        model->AddPendingCut(segment.P0, segment.P1);
      }
    }
  }

private:
  struct Segment
  {
    unsigned long long Sequence = 0;
    double P0[3] = { 0.0, 0.0, 0.0 };
    double P1[3] = { 0.0, 0.0, 0.0 };
  };
  Segment Segments[Capacity];
  unsigned long long End = 0;
  unsigned long long Queued = 0;
  std::atomic<unsigned long long> Cut{ 0 };
};

#endif
