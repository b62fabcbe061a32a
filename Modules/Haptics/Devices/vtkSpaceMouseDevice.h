// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkSpaceMouseDevice
 * @brief   3Dconnexion SpaceMouse over hidapi: six degrees of freedom, buttons, LED.
 *
 * A SpaceMouse reports how far its cap is pushed and turned (about +-350
 * counts per axis), not where it is: this backend integrates those rates
 * into a pose (MaximumSpeed mm/s and MaximumAngularSpeed rad/s at full
 * deflection, nothing within DeadZone counts), so that the haptic loop
 * reads it like any positional device; it renders no force.
 *
 * Reports (public references: spacenavd src/dev.c, PySpaceMouse):
 *  - report 1: x, y, z as little-endian int16 in bytes 1-6; the wireless and
 *    newer models send 13 bytes with the rotations in bytes 7-12 too;
 *  - report 2 (older models): rotations about x, y, z in bytes 1-6;
 *  - report 3: the buttons' bit mask from byte 1.
 * Both layouts are told apart by the report's length, not by a table of
 * models. The LED is output report [0x04, on].
 *
 * Axes are as the device reports them; the loop's DeviceToRAS turns them
 * into the scene.
 *
 * @sa vtkHIDConnection vtkHapticDevice
 */

#ifndef vtkSpaceMouseDevice_h
#define vtkSpaceMouseDevice_h

#include "vtkHapticDevice.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class vtkHIDConnection;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkSpaceMouseDevice : public vtkHapticDevice
{
public:
  static vtkSpaceMouseDevice* New();
  vtkTypeMacro(vtkSpaceMouseDevice, vtkHapticDevice);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// What DecodeReport found in a report (bits).
  enum ReportContents
  {
    ReportTranslation = 1,
    ReportRotation = 2,
    ReportButtons = 4
  };

  /**
   * Decode one input report (report ID first). Returns the ReportContents
   * bits it carried and writes those parts of axes (x, y, z, rx, ry, rz) and
   * buttons; 0 for a report of another kind (ignored), -1 for one too short
   * for its kind (garbage).
   */
  static int DecodeReport(const unsigned char* report, int length, int axes[6], unsigned int& buttons);

  /// The link to the device (IDs to look for, path, read timeout).
  vtkHIDConnection* GetConnection();

  ///@{
  /**
   * Set/get the speed (mm/s) and turning rate (rad/s) at full deflection
   * (350 counts); set them while the device is closed. Defaults are 50 and 1.5.
   */
  vtkSetClampMacro(MaximumSpeed, double, 0.0, 1.0e4);
  vtkGetMacro(MaximumSpeed, double);
  vtkSetClampMacro(MaximumAngularSpeed, double, 0.0, 100.0);
  vtkGetMacro(MaximumAngularSpeed, double);
  ///@}

  ///@{
  /**
   * Set/get the deflection (counts) below which an axis counts as at rest
   * (while the device is closed). Default is 12.
   */
  vtkSetClampMacro(DeadZone, int, 0, 350);
  vtkGetMacro(DeadZone, int);
  ///@}

  /// Turn the LED on or off. False (with a warning) if the device did not take it.
  bool SetLED(bool on);

  /// Put the integrated pose back at the origin.
  void ResetPose();

protected:
  vtkSpaceMouseDevice();
  ~vtkSpaceMouseDevice() override;

  bool OpenDevice() override;
  void CloseDevice() override;

  double MaximumSpeed = 50.0;
  double MaximumAngularSpeed = 1.5;
  int DeadZone = 12;

private:
  struct Internals;
  std::unique_ptr<Internals> Internal;

  vtkSpaceMouseDevice(const vtkSpaceMouseDevice&) = delete;
  void operator=(const vtkSpaceMouseDevice&) = delete;
};

#endif
