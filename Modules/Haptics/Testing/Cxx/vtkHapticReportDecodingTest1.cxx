// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The HID devices' reports as pure functions, against byte-level fixtures:
// both SpaceMouse layouts (six axes in report 1; or translation in report 1
// and rotation in report 2), its buttons, and both foot-switch families
// (VEC's bit mask, keyboard pedals' key codes); garbage is refused.
#include "vtkFootSwitchDevice.h"
#include "vtkSpaceMouseDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vector>

int vtkHapticReportDecodingTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  int axes[6] = { 9, 9, 9, 9, 9, 9 };
  unsigned int buttons = 77;

  // Wireless layout: x = 300 (0x012c), y = -2 (0xfffe), z = -350 (0xfea2),
  // rx = 1, ry = 0x7fff, rz = -32768.
  const unsigned char six[13] = { 0x01, 0x2c, 0x01, 0xfe, 0xff, 0xa2, 0xfe, 0x01, 0x00, 0xff, 0x7f, 0x00, 0x80 };
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(six, 13, axes, buttons), vtkSpaceMouseDevice::ReportTranslation | vtkSpaceMouseDevice::ReportRotation);
  CHECK_INT(axes[0], 300);
  CHECK_INT(axes[1], -2);
  CHECK_INT(axes[2], -350);
  CHECK_INT(axes[3], 1);
  CHECK_INT(axes[4], 32767);
  CHECK_INT(axes[5], -32768);
  CHECK_INT(static_cast<int>(buttons), 77);

  // Older layout: report 1 translation only (rotation untouched), report 2 rotation.
  const unsigned char translation[7] = { 0x01, 0x05, 0x00, 0x06, 0x00, 0x07, 0x00 };
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(translation, 7, axes, buttons), vtkSpaceMouseDevice::ReportTranslation);
  CHECK_INT(axes[0], 5);
  CHECK_INT(axes[2], 7);
  CHECK_INT(axes[3], 1);
  const unsigned char rotation[7] = { 0x02, 0x9c, 0xff, 0x64, 0x00, 0x00, 0x00 };
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(rotation, 7, axes, buttons), vtkSpaceMouseDevice::ReportRotation);
  CHECK_INT(axes[3], -100);
  CHECK_INT(axes[4], 100);
  CHECK_INT(axes[5], 0);
  CHECK_INT(axes[0], 5);

  // Buttons: a bit mask from byte 1 on.
  const unsigned char buttonReport[3] = { 0x03, 0x02, 0x01 };
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(buttonReport, 3, axes, buttons), vtkSpaceMouseDevice::ReportButtons);
  CHECK_INT(static_cast<int>(buttons), 0x0102);

  // Other reports are ignored; reports too short for their kind are garbage.
  const unsigned char battery[3] = { 0x17, 0x64, 0x00 };
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(battery, 3, axes, buttons), 0);
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(translation, 5, axes, buttons), -1);
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(rotation, 6, axes, buttons), -1);
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(buttonReport, 1, axes, buttons), -1);
  CHECK_INT(vtkSpaceMouseDevice::DecodeReport(nullptr, 13, axes, buttons), -1);
  CHECK_INT(axes[0], 5);

  // VEC Infinity: left, middle, right in bits 0-2; anything else is not a VEC report.
  const int keys[3] = { 0x04, 0x05, 0x06 };
  const unsigned char vecMiddle[2] = { 0x02, 0x00 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(vecMiddle, 2, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 2);
  const unsigned char vecAll[2] = { 0x07, 0x00 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(vecAll, 2, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 7);
  const unsigned char vecGarbage[2] = { 0x48, 0x00 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(vecGarbage, 2, keys, 3, buttons), false);
  CHECK_INT(static_cast<int>(buttons), 7);

  // Keyboard pedals: 'c' is pedal 2, 'a' pedal 0; another key or a modifier is pedal 0; rollover is nothing.
  const unsigned char keyC[8] = { 0, 0, 0x06, 0, 0, 0, 0, 0 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(keyC, 8, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 4);
  const unsigned char keysAC[8] = { 0, 0, 0x04, 0x06, 0, 0, 0, 0 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(keysAC, 8, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 5);
  const unsigned char other[8] = { 0, 0, 0x2c, 0, 0, 0, 0, 0 }; // space bar
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(other, 8, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 1);
  const unsigned char shift[8] = { 0x02, 0, 0, 0, 0, 0, 0, 0 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(shift, 8, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 1);
  const unsigned char rollover[8] = { 0, 0, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(rollover, 8, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 0);
  const unsigned char released[8] = { 0, 0, 0, 0, 0, 0, 0, 0 };
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(released, 8, keys, 3, buttons), true);
  CHECK_INT(static_cast<int>(buttons), 0);
  // Neither layout.
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(keyC, 5, keys, 3, buttons), false);
  CHECK_BOOL(vtkFootSwitchDevice::DecodeReport(nullptr, 8, keys, 3, buttons), false);
  return EXIT_SUCCESS;
}
