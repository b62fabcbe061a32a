// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The haptic loop's thread and real-time priority, checked from outside the
// loop (the kernel's record of each thread of this process): where the
// system permits it, the thread runs SCHED_FIFO at the level asked for while
// the loop runs, and nothing of the process does once it stopped; with
// RequestRealTimePriority off it runs at normal priority; without the
// privilege (a child process that dropped it: RLIMIT_RTPRIO 0 and, if root,
// the user nobody) the loop still ticks and its status says why it got no
// real-time priority. At real-time priority the thread must sleep between
// ticks, or it would hold its processor against the rest of the machine:
// its processor time stays a fraction of the time it ran. An overrun the
// thread slept through (woken late, here by a real-time thread holding its
// processor) is counted as such, apart from ticks that worked too long.
#include "vtkHapticTestProcessorHold.h"
#include "vtkHapticTestWaiting.h"

#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkVirtualHapticDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>

#if defined(__linux__)
#include <dirent.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

namespace
{
/// A loop over air (a 4-voxel CT of -1000 HU): ticks that touch nothing, as the product's idle loop.
struct AirLoop
{
  vtkNew<vtkImageData> Air;
  vtkNew<vtkMatrix4x4> Identity;
  vtkNew<vtkHapticForceModel> Model;
  vtkNew<vtkVirtualHapticDevice> Device;
  vtkNew<vtkHapticLoop> Loop;

  AirLoop()
  {
    this->Air->SetDimensions(4, 4, 4);
    this->Air->AllocateScalars(VTK_FLOAT, 1);
    this->Air->GetPointData()->GetScalars()->Fill(-1000.0);
    this->Model->SetAnatomy(this->Air, this->Identity);
    this->Model->SetSphereRadius(2.0);
    this->Device->Open();
    const double position[3] = { 1.5, 1.5, 1.5 };
    this->Device->SetPose(position, 0u);
    this->Loop->SetDevice(this->Device);
    this->Loop->SetForceModel(this->Model);
  }

  /// Run until the loop has ticked count times (a deadline, not a fixed sleep).
  bool Ticks(unsigned long long count)
  {
    return vtkHapticTestWaitFor([this, count]() { return this->Loop->GetNumberOfTicks() >= count; });
  }
};

bool Contains(const char* text, const char* part)
{
  return text && std::strstr(text, part) != nullptr;
}

#if defined(__linux__)
/// The threads of this process that the kernel runs SCHED_FIFO at level, by thread id (0 if none).
int CountFIFOThreads(int level, pid_t* found = nullptr)
{
  int count = 0;
  DIR* tasks = opendir("/proc/self/task");
  if (!tasks)
  {
    return -1;
  }
  while (dirent* entry = readdir(tasks))
  {
    const pid_t tid = static_cast<pid_t>(std::atoi(entry->d_name));
    sched_param parameters{};
    if (tid > 0 && sched_getscheduler(tid) == SCHED_FIFO && sched_getparam(tid, &parameters) == 0 &&
      parameters.sched_priority == level)
    {
      ++count;
      if (found)
      {
        *found = tid;
      }
    }
  }
  closedir(tasks);
  return count;
}

/// The time (ns) the kernel ran a thread of this process on a processor.
long long ProcessorTime(pid_t tid)
{
  std::ifstream schedstat("/proc/self/task/" + std::to_string(tid) + "/schedstat");
  long long onProcessor = -1;
  schedstat >> onProcessor;
  return onProcessor;
}

/// Whether the system lets a thread of this process take SCHED_FIFO at level.
bool RealTimePermitted(int level)
{
  bool permitted = false;
  std::thread probe([&permitted, level]() {
    sched_param parameters{};
    parameters.sched_priority = level;
    permitted = pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameters) == 0;
  });
  probe.join();
  return permitted;
}

/// In a child process: drop the privilege, start the loop; 0 if it ticks at normal priority and says why.
int RunWithoutPrivilege()
{
  const rlimit none{ 0, 0 };
  if (setrlimit(RLIMIT_RTPRIO, &none) != 0)
  {
    return 10;
  }
  // Root keeps CAP_SYS_NICE whatever its limits: become nobody, which has no capabilities.
  if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0))
  {
    return 11;
  }
  AirLoop air;
  if (!air.Loop->Start())
  {
    return 12;
  }
  const bool ticked = air.Ticks(20);
  const bool realTime = air.Loop->GetRealTimePriority();
  const std::string status = air.Loop->GetRealTimePriorityStatus();
  const int fifoThreads = CountFIFOThreads(air.Loop->GetRealTimePriorityLevel());
  air.Loop->Stop();
  std::cout << "Without the privilege: " << status << std::endl;
  if (!ticked)
  {
    return 13;
  }
  if (realTime || fifoThreads != 0)
  {
    return 14;
  }
  return Contains(status.c_str(), "refused") && Contains(status.c_str(), "RLIMIT_RTPRIO") ? 0 : 15;
}
#endif
} // namespace

int vtkHapticLoopRealTimeTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
#if defined(__linux__)
  // Before any thread of this process starts: the child is a copy of a single-threaded process.
  const pid_t child = fork();
  if (child == 0)
  {
    _exit(RunWithoutPrivilege());
  }
  CHECK_BOOL(child > 0, true);
  int childStatus = 0;
  CHECK_INT(static_cast<int>(waitpid(child, &childStatus, 0)), static_cast<int>(child));
  CHECK_BOOL(WIFEXITED(childStatus), true);
  CHECK_INT(WEXITSTATUS(childStatus), 0);

  {
    AirLoop air;
    air.Loop->SetRealTimePriorityLevel(42);
    const bool permitted = RealTimePermitted(42);
    CHECK_BOOL(air.Loop->Start(), true);
    CHECK_BOOL(air.Ticks(20), true);
    std::cout << "Asked for SCHED_FIFO 42: " << air.Loop->GetRealTimePriorityStatus() << std::endl;
    CHECK_BOOL(air.Loop->GetRealTimePriority(), permitted);
    pid_t hapticThread = 0;
    CHECK_INT(CountFIFOThreads(42, &hapticThread), permitted ? 1 : 0);
    CHECK_BOOL(Contains(air.Loop->GetRealTimePriorityStatus(), permitted ? "SCHED_FIFO priority 42" : "refused"), true);
    if (permitted)
    {
      // A second of ticks: the thread sleeps to each deadline less SpinTime (0.2 ms), so it is on a
      // processor for a fraction of the time, not the whole of it.
      const long long processorBefore = ProcessorTime(hapticThread);
      const auto wallBefore = std::chrono::steady_clock::now();
      const unsigned long long ticksBefore = air.Loop->GetNumberOfTicks();
      CHECK_BOOL(air.Ticks(ticksBefore + 1000), true);
      const double wall = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - wallBefore).count();
      const double share = (ProcessorTime(hapticThread) - processorBefore) / wall;
      std::cout << "The real-time thread's share of a processor over 1000 ticks: " << share << std::endl;
      CHECK_BOOL(processorBefore >= 0 && share < 0.6, true);
    }
    air.Loop->Stop();
    CHECK_INT(CountFIFOThreads(42), 0);
  }

  {
    AirLoop air;
    air.Loop->SetRealTimePriorityLevel(42);
    air.Loop->RequestRealTimePriorityOff();
    CHECK_BOOL(air.Loop->Start(), true);
    CHECK_BOOL(air.Ticks(20), true);
    CHECK_BOOL(air.Loop->GetRealTimePriority(), false);
    CHECK_INT(CountFIFOThreads(42), 0);
    CHECK_BOOL(Contains(air.Loop->GetRealTimePriorityStatus(), "not requested"), true);
    air.Loop->Stop();
  }

  {
    // Held off processor 0 three times for 5 ms while asleep between its ticks over air (a few microseconds
    // each): three overruns it slept through. The holds fall a third of a period apart in the ticks' phase, so
    // that at most one can fall in a tick (then the tick itself runs long and is not counted as woken late).
    AirLoop air;
    air.Loop->RequestRealTimePriorityOff();
    air.Loop->SetProcessorIndex(0);
    CHECK_BOOL(air.Loop->Start(), true);
    CHECK_BOOL(air.Ticks(20), true);
    int held = 0;
    for (int hold = 0; hold < 3; ++hold)
    {
      std::this_thread::sleep_for(std::chrono::microseconds(30000 + 333 * hold));
      held += vtkHapticTestHoldProcessor(0, std::chrono::microseconds(5000));
    }
    CHECK_BOOL(air.Ticks(air.Loop->GetNumberOfTicks() + 20), true);
    air.Loop->Stop();
    std::cout << "Held " << held << " times: " << air.Loop->GetNumberOfOverruns() << " overruns, "
              << air.Loop->GetNumberOfLateWakeUpOverruns() << " woken late, latest " << air.Loop->GetMaximumWakeUpLateness()
              << " us" << std::endl;
    CHECK_BOOL(air.Loop->GetNumberOfLateWakeUpOverruns() <= air.Loop->GetNumberOfOverruns(), true);
    if (held == 3)
    {
      CHECK_BOOL(air.Loop->GetNumberOfLateWakeUpOverruns() >= 2, true);
      CHECK_BOOL(air.Loop->GetMaximumWakeUpLateness() >= 3000.0, true);
    }
    air.Loop->ResetStatistics();
    CHECK_INT(static_cast<int>(air.Loop->GetNumberOfLateWakeUpOverruns()), 0);
    CHECK_DOUBLE(air.Loop->GetMaximumWakeUpLateness(), 0.0);
  }
#else
  AirLoop air;
  CHECK_BOOL(air.Loop->Start(), true);
  CHECK_BOOL(air.Ticks(20), true);
  CHECK_BOOL(air.Loop->GetRealTimePriorityStatus()[0] != '\0', true);
  air.Loop->Stop();
#endif
  return EXIT_SUCCESS;
}
