// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Shared by the real-time tests: a late wake-up made on purpose. A thread at
// real-time priority that spins on a processor keeps every normal-priority
// thread pinned there from running, so a servo thread asleep on it wakes
// when the hold ends, however long after its deadline: the same thing a
// hypervisor does to a virtual machine's sleeping processor, at a time and
// for a length the test chooses.
#ifndef vtkHapticTestProcessorHold_h
#define vtkHapticTestProcessorHold_h

#include <chrono>
#include <thread>

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#endif

/// Hold the processor for the time given at SCHED_FIFO level (below the loop's 80); false where the system refuses
/// real-time priority or pinning (nothing was held).
inline bool vtkHapticTestHoldProcessor(int processor, std::chrono::microseconds time, int level = 30)
{
#if defined(__linux__)
  bool held = false;
  std::thread holder([&held, processor, time, level]() {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(processor, &one);
    sched_param parameters{};
    parameters.sched_priority = level;
    if (pthread_setaffinity_np(pthread_self(), sizeof(one), &one) != 0 ||
      pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameters) != 0)
    {
      return;
    }
    held = true;
    const auto end = std::chrono::steady_clock::now() + time;
    while (std::chrono::steady_clock::now() < end)
    {
    }
  });
  holder.join();
  return held;
#else
  (void)processor;
  (void)time;
  (void)level;
  return false;
#endif
}

#endif
