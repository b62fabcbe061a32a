// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticRealTime.h"

#include "vtkVolumeCutThreadClock.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <system_error>
#include <thread>

#if defined(__linux__)
#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#endif
#if defined(_WIN32)
#include <windows.h>
#else
#include <time.h>
#endif

namespace
{
/// A hint to the processor inside a wait loop.
inline void Relax()
{
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

/// The stack a tick may reach: the force model's and the field's calls are far shallower.
constexpr size_t StackBytesTouched = 128 * 1024;
constexpr size_t PageBytes = 4096;

#if defined(__GNUC__)
__attribute__((noinline))
#elif defined(_MSC_VER)
__declspec(noinline)
#endif
void TouchStack()
{
  volatile unsigned char pages[StackBytesTouched];
  for (size_t offset = 0; offset < StackBytesTouched; offset += PageBytes)
  {
    pages[offset] = 0;
  }
}
} // namespace

//------------------------------------------------------------------------------
bool vtkHapticRealTime::RequestPriority(int level, std::string& status)
{
#if defined(__linux__)
  const int minimum = sched_get_priority_min(SCHED_FIFO);
  const int maximum = sched_get_priority_max(SCHED_FIFO);
  const std::string wanted = "SCHED_FIFO priority " + std::to_string(level);
  if (level < minimum || level > maximum)
  {
    status = "refused: " + wanted + " is outside the system's range (" + std::to_string(minimum) + "-" +
      std::to_string(maximum) + "); normal priority";
    return false;
  }
  sched_param parameters{};
  parameters.sched_priority = level;
  const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameters);
  if (error == 0)
  {
    status = wanted;
    return true;
  }
  rlimit limit{};
  std::string allowed = "unknown";
  if (getrlimit(RLIMIT_RTPRIO, &limit) == 0)
  {
    allowed = limit.rlim_cur == RLIM_INFINITY ? "unlimited" : std::to_string(limit.rlim_cur);
  }
  status = "refused by the system (" + std::system_category().message(error) + "): " + wanted +
    " needs CAP_SYS_NICE or RLIMIT_RTPRIO >= " + std::to_string(level) + " (here " + allowed +
    ", see limits.conf); normal priority";
  return false;
#elif defined(_WIN32)
  (void)level;
  if (SetThreadPriority(GetCurrentThread(), THREAD_PRIORITY_TIME_CRITICAL))
  {
    status = "THREAD_PRIORITY_TIME_CRITICAL";
    return true;
  }
  status = "refused by the system (error " + std::to_string(GetLastError()) + "); normal priority";
  return false;
#else
  (void)level;
  status = "not available on this system; normal priority";
  return false;
#endif
}

//------------------------------------------------------------------------------
bool vtkHapticRealTime::SetUpServoThread(bool requestPriority, int level, int processor, std::string& status)
{
  PrepareThread();
  bool realTime = false;
  if (requestPriority)
  {
    realTime = RequestPriority(level, status);
  }
  else
  {
    status = "not requested (RequestRealTimePriority is off); normal priority";
  }
  if (processor >= 0 && !RunOnProcessor(processor))
  {
    status += "; processor " + std::to_string(processor) + " refused";
  }
  return realTime;
}

//------------------------------------------------------------------------------
bool vtkHapticRealTime::RunOnProcessor(int index)
{
#if defined(__linux__)
  if (index < 0 || index >= CPU_SETSIZE)
  {
    return false;
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(index, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof(set), &set) == 0;
#else
  (void)index;
  return false;
#endif
}

//------------------------------------------------------------------------------
void vtkHapticRealTime::PrepareThread()
{
#if defined(__linux__)
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
#endif
  TouchStack();
}

//------------------------------------------------------------------------------
bool vtkHapticRealTime::WaitUntil(Clock::time_point deadline, Clock::duration spin)
{
  const Clock::time_point wake = deadline - spin;
  const Clock::time_point now = Clock::now();
  if (!(now < deadline))
  {
    return false;
  }
  if (now < wake)
  {
#if defined(__linux__)
    // steady_clock is CLOCK_MONOTONIC (libstdc++ and libc++ on Linux).
    const long long since = std::chrono::duration_cast<std::chrono::nanoseconds>(wake.time_since_epoch()).count();
    timespec until{};
    until.tv_sec = static_cast<time_t>(since / 1000000000LL);
    until.tv_nsec = static_cast<long>(since % 1000000000LL);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, nullptr) == EINTR)
    {
    }
#else
    std::this_thread::sleep_until(wake);
#endif
  }
  while (Clock::now() < deadline)
  {
    Relax();
  }
  return true;
}

//------------------------------------------------------------------------------
double vtkHapticRealTime::ThreadProcessorMicroseconds()
{
  return vtkVolumeCutThreadClock::ProcessorMicroseconds();
}

//------------------------------------------------------------------------------
vtkHapticRealTime::Counters vtkHapticRealTime::ReadCounters()
{
  Counters counters;
#if defined(__linux__)
  rusage usage{};
  if (getrusage(RUSAGE_THREAD, &usage) == 0)
  {
    counters.PageFaults = usage.ru_minflt + usage.ru_majflt;
    counters.Preemptions = usage.ru_nivcsw;
  }
#endif
  return counters;
}

//------------------------------------------------------------------------------
double vtkHapticRealTime::Percentile(std::vector<float> values, double percent)
{
  if (values.empty())
  {
    return 0.0;
  }
  const double rank = std::min(std::max(percent, 0.0), 100.0) / 100.0 * (values.size() - 1);
  const size_t index = static_cast<size_t>(std::ceil(rank));
  std::nth_element(values.begin(), values.begin() + index, values.end());
  return values[index];
}
