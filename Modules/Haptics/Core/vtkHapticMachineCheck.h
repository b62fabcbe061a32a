// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticMachineCheck
 * @brief   What this machine gives a 1 kHz real-time thread whose work never changes.
 *
 * A haptic tick that is slow may have had more to do, or the machine may
 * have taken its processor: preempted it (the thread's processor time stays
 * short), or slowed it in ways the thread cannot see, as a hypervisor does
 * when it runs the virtual processor late or on a busy core, or the kernel
 * when it handles interrupts on the thread's time. Only the last kind looks
 * like the tick's own work: its processor time is as long as its wall time.
 *
 * The check does what the haptic loop's thread does (vtkHapticLoop: the same
 * real-time priority, resident stack, sleeps to absolute deadlines and wait
 * before each), but its ticks do arithmetic only, reading no memory: each
 * for WorkTime seconds of processor time, or for its own of WorkTimes (a
 * loop's ticks, one by one), as calibrated on the thread before the first. Whatever makes one of its ticks slower than
 * SlowTickTime, or late, is the machine's: compared with the loop's own
 * slow ticks over the same time and work, it tells the product's stalls
 * from the machine's (cyclictest's question, asked with work in the tick).
 *
 * Nothing else of the haptics module is touched: it may run beside a haptic
 * loop, before one starts, or while the caller renders (Start, then Wait).
 * The statistics are read once it has ended.
 */

#ifndef vtkHapticMachineCheck_h
#define vtkHapticMachineCheck_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class vtkDoubleArray;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticMachineCheck : public vtkObject
{
public:
  static vtkHapticMachineCheck* New();
  vtkTypeMacro(vtkHapticMachineCheck, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Ticks per second (1 kHz by default, as the haptic loop).
  vtkSetClampMacro(Rate, double, 1.0, 4000.0);
  vtkGetMacro(Rate, double);
  ///@}

  ///@{
  /// How long Run ticks, in seconds (5 s by default).
  vtkSetClampMacro(Duration, double, 0.01, 600.0);
  vtkGetMacro(Duration, double);
  ///@}

  ///@{
  /// Processor time of each tick's constant work, in seconds (100 us by
  /// default: about a haptic tick's mean in contact); at most 0.9 of the period.
  vtkSetClampMacro(WorkTime, double, 0.0, 0.01);
  vtkGetMacro(WorkTime, double);
  ///@}

  ///@{
  /**
   * Each tick's work instead, in seconds (one value per tick, cycled): a
   * loop's own sequence of processor times per tick, so that the check
   * does the same work tick by tick. Copied at Start; none (the default)
   * or an empty array: WorkTime for every tick.
   */
  virtual void SetWorkTimes(vtkDoubleArray* seconds);
  vtkGetObjectMacro(WorkTimes, vtkDoubleArray);
  ///@}

  ///@{
  /// A tick longer than this (seconds, wall clock) is slow (500 us by
  /// default: half the 1 kHz period, the haptic loop's target).
  vtkSetClampMacro(SlowTickTime, double, 1e-6, 1.0);
  vtkGetMacro(SlowTickTime, double);
  ///@}

  ///@{
  /// As vtkHapticLoop's: real-time priority at this level, the wait before each deadline, one processor if set.
  vtkSetMacro(RequestRealTimePriority, bool);
  vtkGetMacro(RequestRealTimePriority, bool);
  vtkBooleanMacro(RequestRealTimePriority, bool);
  vtkSetClampMacro(RealTimePriorityLevel, int, 1, 99);
  vtkGetMacro(RealTimePriorityLevel, int);
  vtkSetClampMacro(SpinTime, double, 0.0, 0.01);
  vtkGetMacro(SpinTime, double);
  vtkSetMacro(ProcessorIndex, int);
  vtkGetMacro(ProcessorIndex, int);
  ///@}

  /**
   * Start ticking for Duration on a thread of its own and return at once,
   * so that the caller can go on with what it would do beside a haptic
   * loop (render, say), which makes the check's conditions the loop's.
   * False, with an error, if a check is running, the settings leave no
   * time for the work (a WorkTime or WorkTimes value over 0.9 of the period) or the thread
   * cannot start; the statistics are then empty.
   */
  bool Start();

  /// Whether the started check still ticks.
  bool IsRunning() const;

  /// Wait for the started check to end (at once if none runs); the statistics are then those of its ticks.
  void Wait();

  /// Start and Wait: the caller waits for Duration.
  bool Run();

  /// Ticks of the last check. Every statistic is 0 (the status "running") while a check runs.
  vtkIdType GetNumberOfTicks() const;

  ///@{
  /// The ticks' wall-clock and processor times, in microseconds (percent 0-100; 100 is the maximum).
  double GetTickDurationPercentile(double percent) const;
  double GetTickProcessorTimePercentile(double percent) const;
  ///@}

  /// Ticks that ended after their deadline, as vtkHapticLoop::GetNumberOfOverruns counts them.
  vtkIdType GetNumberOfOverruns() const;

  ///@{
  /// As vtkHapticLoop's: overruns of ticks woken later than they took, and the latest waking, in microseconds.
  vtkIdType GetNumberOfLateWakeUpOverruns() const;
  double GetMaximumWakeUpLateness() const;
  ///@}

  /// Ticks longer than SlowTickTime.
  vtkIdType GetNumberOfSlowTicks() const;

  /**
   * Slow ticks whose processor time was longer than SlowTickTime too: with
   * work that never changes, time taken from the thread without its
   * knowing (interrupts, a hypervisor).
   */
  vtkIdType GetNumberOfProcessorBoundSlowTicks() const;

  /// Processor time of the ticks' mean work as measured before the first tick, in microseconds.
  double GetCalibratedWorkTime() const;

  ///@{
  /// What the system granted the thread, in one line (as vtkHapticLoop's).
  bool GetRealTimePriority() const;
  const char* GetRealTimePriorityStatus() const;
  ///@}

protected:
  vtkHapticMachineCheck();
  ~vtkHapticMachineCheck() override;

  double Rate = 1000.0;
  double Duration = 5.0;
  double WorkTime = 0.0001;
  double SlowTickTime = 0.0005;
  bool RequestRealTimePriority = true;
  int RealTimePriorityLevel = 80;
  double SpinTime = 0.0002;
  int ProcessorIndex = -1;
  vtkDoubleArray* WorkTimes = nullptr;

private:
  vtkHapticMachineCheck(const vtkHapticMachineCheck&) = delete;
  void operator=(const vtkHapticMachineCheck&) = delete;

  /// The check's thread: priority, calibration, ticks.
  void Measure();

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
