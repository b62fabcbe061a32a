// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Shared by the device tests: waiting for what a device's own thread brings
// about. A deadline rather than a fixed sleep or a count of polls, because
// the sanitizer builds run these tests at nice 19 beside the Python tests,
// where a device thread may get little of a core for a while; how fast the
// threads are is the benchmarks' business, not a pass/fail test's.
#ifndef vtkHapticTestWaiting_h
#define vtkHapticTestWaiting_h

#include <chrono>
#include <functional>
#include <thread>

/// Poll the condition every 5 ms for up to twenty seconds.
inline bool vtkHapticTestWaitFor(const std::function<bool()>& condition)
{
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline)
  {
    if (condition())
    {
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return condition();
}

#endif
