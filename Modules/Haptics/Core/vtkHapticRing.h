// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to vtkVolumeCuttingHaptics (not installed, not wrapped): the queue
// between the haptic thread and the thread that owns the scene.
#ifndef vtkHapticRing_h
#define vtkHapticRing_h

#include <atomic>
#include <cstddef>
#include <memory>
#include <type_traits>

/**
 * Single-producer, single-consumer ring of plain values. Its memory is
 * allocated once, by the constructor: Push and Pop never allocate, never
 * lock and never wait. A full ring refuses the value (Push returns false) so
 * the producer, the haptic thread, is never held up by a slow consumer.
 */
template <typename T>
class vtkHapticRing
{
  static_assert(std::is_trivially_copyable<T>::value, "vtkHapticRing holds plain data only");

public:
  /// capacity is rounded up to a power of two (at least 2).
  explicit vtkHapticRing(std::size_t capacity)
  {
    std::size_t size = 2;
    while (size < capacity)
    {
      size *= 2;
    }
    this->Mask = size - 1;
    this->Items.reset(new T[size]);
  }

  /// Producer only.
  bool Push(const T& value)
  {
    const std::size_t head = this->Head.load(std::memory_order_relaxed);
    if (head - this->Tail.load(std::memory_order_acquire) > this->Mask)
    {
      return false;
    }
    this->Items[head & this->Mask] = value;
    this->Head.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer only.
  bool Pop(T& value)
  {
    const std::size_t tail = this->Tail.load(std::memory_order_relaxed);
    if (tail == this->Head.load(std::memory_order_acquire))
    {
      return false;
    }
    value = this->Items[tail & this->Mask];
    this->Tail.store(tail + 1, std::memory_order_release);
    return true;
  }

  std::size_t GetCapacity() const { return this->Mask + 1; }

private:
  std::size_t Mask = 1;
  std::unique_ptr<T[]> Items;
  alignas(64) std::atomic<std::size_t> Head{ 0 };
  alignas(64) std::atomic<std::size_t> Tail{ 0 };
};

#endif
