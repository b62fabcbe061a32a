// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkFootSwitchDevice
 * @brief   USB foot switches over hidapi: the pedal that runs the drill.
 *
 * Seed 003's drill is started with a foot switch, as a surgeon's pneumatic
 * drill is. Two families of pedals are read, told apart by their reports'
 * length rather than by model:
 *  - VEC Infinity IN-USB-2 (05f3:00ff): 2-byte reports without report ID,
 *    byte 0 a bit mask (1 left, 2 middle, 4 right);
 *  - PCsensor and iKKEGOL pedals (0c45:7403, 0c45:7404, 413d:2107,
 *    1a86:e026): boot keyboards sending 8-byte reports (modifiers,
 *    reserved, six key codes). Pedal n is pressed while the n-th key of
 *    PedalKeys is down; any other key or modifier presses pedal 0 (a pedal
 *    programmed to an unusual key still works).
 * Buttons are the pedals; there is no pose (the sample's position stays at
 * the origin). Hand it to vtkHapticLoop::SetSwitchDevice.
 *
 * @sa vtkHIDConnection vtkHapticLoop
 */

#ifndef vtkFootSwitchDevice_h
#define vtkFootSwitchDevice_h

#include "vtkHapticDevice.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class vtkHIDConnection;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkFootSwitchDevice : public vtkHapticDevice
{
public:
  static vtkFootSwitchDevice* New();
  vtkTypeMacro(vtkFootSwitchDevice, vtkHapticDevice);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The pedals (bit n: pedal n) an input report says are pressed, given the
   * pedals' key codes (keyboard-style pedals; up to 8). False for a report
   * of neither layout (garbage), buttons then unchanged.
   */
  static bool DecodeReport(const unsigned char* report, int length, const int* pedalKeys, int numberOfPedalKeys, unsigned int& buttons);

  ///@{
  /**
   * Set/get the USB HID key code of each pedal, for keyboard-style pedals
   * (at most 8; set while closed). Default is 'a', 'b', 'c' (4, 5, 6), as
   * these pedals ship.
   */
  void SetPedalKeys(int key0, int key1, int key2);
  int GetPedalKey(int pedal) const;
  ///@}

  /// The link to the device (IDs to look for, path, read timeout).
  vtkHIDConnection* GetConnection();

protected:
  vtkFootSwitchDevice();
  ~vtkFootSwitchDevice() override;

  bool OpenDevice() override;
  void CloseDevice() override;

private:
  struct Internals;
  std::unique_ptr<Internals> Internal;

  vtkFootSwitchDevice(const vtkFootSwitchDevice&) = delete;
  void operator=(const vtkFootSwitchDevice&) = delete;
};

#endif
