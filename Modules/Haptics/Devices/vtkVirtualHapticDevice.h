// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVirtualHapticDevice
 * @brief   A device whose poses are pushed in: the mouse in a 3D view, a script.
 *
 * The application (the 3D view's mouse interaction, a Python script) sets
 * the handle's pose and buttons; the haptic loop reads them like any
 * device's samples. Forces are computed for it as for a force device (its
 * capabilities say what it would render, the Novint Falcon's figures by
 * default), kept as the commanded force for display, and felt by nobody.
 * SetPlugged(false) behaves as an unplugged device: the loop stops the
 * drill, ProcessConnectionEvents reports the loss and reconnects once it is
 * plugged back. SetPose may be called from one thread at a time, any thread.
 *
 * @sa vtkHapticDevice vtkHapticLoop
 */

#ifndef vtkVirtualHapticDevice_h
#define vtkVirtualHapticDevice_h

#include "vtkHapticDevice.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <atomic> // For the plug

class vtkMatrix4x4;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkVirtualHapticDevice : public vtkHapticDevice
{
public:
  static vtkVirtualHapticDevice* New();
  vtkTypeMacro(vtkVirtualHapticDevice, vtkHapticDevice);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The handle's position (mm, device frame) and buttons; the orientation
   * stays as it was (identity at first). Ignored, returning false, while
   * the device is not connected or unplugged; a non-finite position is rejected and
   * counted (see GetNumberOfRejectedInputs).
   */
  bool SetPose(const double position[3], unsigned int buttons);

  /// The same with an orientation (unit quaternion w, x, y, z).
  bool SetPoseAndOrientation(const double position[3], const double orientation[4], unsigned int buttons);

  /// The same from a rigid matrix (rotation and translation; device frame).
  bool SetPoseMatrix(vtkMatrix4x4* pose, unsigned int buttons);

  ///@{
  /**
   * Set/get whether the device is plugged in. Unplugging a connected device
   * makes it Lost at once. Default is true.
   */
  void SetPlugged(bool plugged);
  bool GetPlugged() const { return this->Plugged.load(std::memory_order_acquire); }
  ///@}

protected:
  vtkVirtualHapticDevice();
  ~vtkVirtualHapticDevice() override;

  bool OpenDevice() override;
  void CloseDevice() override;

  std::atomic<bool> Plugged{ true };
  double Orientation[4] = { 1.0, 0.0, 0.0, 0.0 };

private:
  vtkVirtualHapticDevice(const vtkVirtualHapticDevice&) = delete;
  void operator=(const vtkVirtualHapticDevice&) = delete;
};

#endif
