// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutThreadClock.h"

#if defined(_WIN32)
#include <windows.h>
#else
#include <time.h>
#endif

//------------------------------------------------------------------------------
double vtkVolumeCutThreadClock::ProcessorMicroseconds()
{
#if defined(_WIN32)
  FILETIME creation, exit, kernel, user;
  if (!GetThreadTimes(GetCurrentThread(), &creation, &exit, &kernel, &user))
  {
    return 0.0;
  }
  const auto hundreds = [](const FILETIME& time) { return (static_cast<unsigned long long>(time.dwHighDateTime) << 32) | time.dwLowDateTime; };
  return 0.1 * static_cast<double>(hundreds(kernel) + hundreds(user));
#else
  timespec now{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now) != 0)
  {
    return 0.0;
  }
  return 1e6 * static_cast<double>(now.tv_sec) + 1e-3 * static_cast<double>(now.tv_nsec);
#endif
}
