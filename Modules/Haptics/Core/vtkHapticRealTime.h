// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticRealTime
 * @brief   What a servo thread asks of the system, and what it measures of it.
 *
 * The haptic loop's threads call these on themselves: real-time priority
 * (SCHED_FIFO on Linux, THREAD_PRIORITY_TIME_CRITICAL on Windows), a
 * processor of their own, a stack already resident, precise timer wake-ups,
 * sleeps to absolute deadlines; and, per tick, their processor time, page
 * faults and preemptions. Each request may be refused by the system (an
 * unprivileged user usually gets no real-time priority): the caller gets a
 * one-line reason and runs on at normal priority.
 *
 * A thread at real-time priority must sleep between its ticks: on a machine
 * with few processors a real-time thread that waits actively holds its
 * processor against everything else (the kernel's real-time throttling only
 * gives 5 % back). The loop sleeps to each deadline less a short SpinTime.
 *
 * Internal to the haptics module: no wrapping, no export.
 */

#ifndef vtkHapticRealTime_h
#define vtkHapticRealTime_h

#include <chrono>
#include <string>
#include <vector>

class vtkHapticRealTime
{
public:
  using Clock = std::chrono::steady_clock;

  /**
   * Ask real-time priority for the calling thread: SCHED_FIFO at level
   * (1-99) on Linux, time-critical on Windows. Returns whether the system
   * granted it; status says what the thread got, or why the system refused
   * and what would permit it, in one line.
   */
  static bool RequestPriority(int level, std::string& status);

  /**
   * What a servo thread does before its first tick: PrepareThread, then
   * RequestPriority at level if requestPriority (else status says it was
   * not requested), then RunOnProcessor if processor >= 0 (a refusal is
   * added to status). Returns whether the thread got real-time priority.
   */
  static bool SetUpServoThread(bool requestPriority, int level, int processor, std::string& status);

  /// Restrict the calling thread to one processor; false if refused or out of range.
  static bool RunOnProcessor(int index);

  /**
   * Make the calling thread's first ticks as fast as its later ones: touch
   * 128 KiB of its stack below the caller's frame (the pages a tick's
   * deepest calls reach are then resident: no page fault in a tick), and
   * wake its sleeps within a microsecond of their deadline at normal
   * priority too (Linux's default timer slack is 50 us; real-time threads
   * have none).
   */
  static void PrepareThread();

  /**
   * Sleep until deadline - spin (clock_nanosleep to an absolute time on
   * POSIX, so that no time is lost computing a relative sleep), then wait
   * the rest actively. False when the deadline had already passed (the
   * previous tick ended late): then how late the tick starts is not the
   * system's waking.
   */
  static bool WaitUntil(Clock::time_point deadline, Clock::duration spin);

  /// Processor time (us) the calling thread has used.
  static double ThreadProcessorMicroseconds();

  /// What the system did to the calling thread so far: page faults it took (first touches of memory) and the times it
  /// took the processor from it (involuntary context switches). 0 where the system does not count them per thread.
  struct Counters
  {
    long PageFaults = 0;
    long Preemptions = 0;
  };
  static Counters ReadCounters();

  /// The value below which percent (0-100) of the values lie (the nearest rank above); 0 for none.
  static double Percentile(std::vector<float> values, double percent);

private:
  vtkHapticRealTime() = delete;
};

#endif
