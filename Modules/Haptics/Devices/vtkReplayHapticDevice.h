// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkReplayHapticDevice
 * @brief   Plays a recorded session back, one recorded tick per loop tick.
 *
 * The device of tests, demos and session review: the samples of a
 * recording (vtkHapticRecorder, from a file or in memory) are published in
 * order, one each time the haptic loop calls Synchronize, so a replay does
 * not depend on timing: the same recording through the same loop and scene
 * gives the same forces and the same cut, bit for bit. The capabilities are
 * the recorded device's, so forces are limited as they were. Ticks recorded
 * while the device was absent (unplugged, silent) replay as absent samples,
 * so the loop stops and resumes the drill where it did. After the last tick
 * the last pose is held with the buttons released and IsFinished() is true.
 *
 * @sa vtkHapticRecorder vtkHapticLoop
 */

#ifndef vtkReplayHapticDevice_h
#define vtkReplayHapticDevice_h

#include "vtkHapticDevice.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <atomic> // For the cursor

class vtkHapticRecorder;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkReplayHapticDevice : public vtkHapticDevice
{
public:
  static vtkReplayHapticDevice* New();
  vtkTypeMacro(vtkReplayHapticDevice, vtkHapticDevice);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Replay this recording (kept by reference; do not record into it meanwhile).
  void SetRecording(vtkHapticRecorder* recording);
  vtkHapticRecorder* GetRecording();

  /// Read the recording from a file (see vtkHapticRecorder::ReadFile).
  bool ReadFile(const char* fileName);

  /// Publish the next recorded tick (the loop calls this once per tick).
  void Synchronize(unsigned long long tick) override;

  /// Start again from the first tick.
  void Rewind();

  /// Ticks published so far, and whether all were.
  int GetNumberOfTicksPlayed() const { return this->Cursor.load(std::memory_order_acquire); }
  bool IsFinished() const;

protected:
  vtkReplayHapticDevice();
  ~vtkReplayHapticDevice() override;

  bool OpenDevice() override;
  void CloseDevice() override;

  vtkHapticRecorder* Recording = nullptr;
  std::atomic<int> Cursor{ 0 };
  double LastPosition[3] = { 0.0, 0.0, 0.0 };
  double LastOrientation[4] = { 1.0, 0.0, 0.0, 0.0 };

private:
  vtkReplayHapticDevice(const vtkReplayHapticDevice&) = delete;
  void operator=(const vtkReplayHapticDevice&) = delete;
};

#endif
