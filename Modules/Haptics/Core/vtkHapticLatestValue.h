// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to vtkVolumeCuttingHaptics (not installed, not wrapped): the latest
// value one thread publishes for others to read, without a lock.
#ifndef vtkHapticLatestValue_h
#define vtkHapticLatestValue_h

#include <atomic>
#include <cstdint>
#include <cstring>
#include <type_traits>

/**
 * A sequence lock over a small trivially copyable value: one writer stores,
 * any number of readers load. The writer does not wait for readers. A reader retries while
 * a store overlaps its copy, at most maximumAttempts times, and then gives up
 * (returns false): a haptic thread must not spin on a writer that the
 * scheduler has paused half-way. The value is kept in atomic words so that
 * the overlapping copy is not a data race (ThreadSanitizer agrees).
 */
template <typename T>
class vtkHapticLatestValue
{
  static_assert(std::is_trivially_copyable<T>::value, "vtkHapticLatestValue holds plain data only");

public:
  /// Writers: normally one; two that overlap (a device reopened by the main
  /// thread while its publisher still runs) take turns.
  void Store(const T& value)
  {
    std::uint64_t words[WordCount] = {};
    std::memcpy(words, &value, sizeof(T));
    std::uint64_t sequence = this->Sequence.load(std::memory_order_relaxed);
    for (;;)
    {
      if (!(sequence & 1u) &&
        this->Sequence.compare_exchange_weak(sequence, sequence + 1, std::memory_order_acquire, std::memory_order_relaxed))
      {
        break;
      }
      sequence = this->Sequence.load(std::memory_order_relaxed);
    }
    std::atomic_thread_fence(std::memory_order_release);
    for (int n = 0; n < WordCount; ++n)
    {
      this->Words[n].store(words[n], std::memory_order_relaxed);
    }
    this->Sequence.store(sequence + 2, std::memory_order_release);
  }

  /// Any reader. False if nothing was stored yet, or if no consistent copy
  /// could be taken in maximumAttempts tries (value is then unchanged).
  bool Load(T& value, int maximumAttempts = 64) const
  {
    for (int attempt = 0; attempt < maximumAttempts; ++attempt)
    {
      const std::uint64_t before = this->Sequence.load(std::memory_order_acquire);
      if (before & 1u)
      {
        continue;
      }
      std::uint64_t words[WordCount];
      for (int n = 0; n < WordCount; ++n)
      {
        words[n] = this->Words[n].load(std::memory_order_relaxed);
      }
      std::atomic_thread_fence(std::memory_order_acquire);
      if (this->Sequence.load(std::memory_order_relaxed) == before)
      {
        if (before == 0)
        {
          return false;
        }
        std::memcpy(&value, words, sizeof(T));
        return true;
      }
    }
    return false;
  }

  /// Number of stores so far (two per store, read as a change counter).
  std::uint64_t GetVersion() const { return this->Sequence.load(std::memory_order_acquire) / 2; }

private:
  static constexpr int WordCount = static_cast<int>((sizeof(T) + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t));
  std::atomic<std::uint64_t> Sequence{ 0 };
  std::atomic<std::uint64_t> Words[WordCount] = {};
};

#endif
