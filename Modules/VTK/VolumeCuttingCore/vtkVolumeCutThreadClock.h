// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCutting (not installed, not wrapped); exported because the
// haptic loop (vtkHapticRealTime) reads the same clock as the nerve monitor.
/**
 * @class   vtkVolumeCutThreadClock
 * @brief   The processor time the calling thread has used.
 *
 * A wall-clock duration on a shared machine includes whatever the system
 * did meanwhile (another process, a timer interrupt, the hypervisor); the
 * thread's processor time is what the work itself cost. Read both to tell a
 * slow computation from a preempted thread.
 */
#ifndef vtkVolumeCutThreadClock_h
#define vtkVolumeCutThreadClock_h

#include "vtkVolumeCuttingCoreExport.h" // For export macro

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutThreadClock
{
public:
  /// Processor time (us) of the calling thread since it started; 0 where the system cannot say.
  static double ProcessorMicroseconds();

private:
  vtkVolumeCutThreadClock() = delete;
};

#endif
