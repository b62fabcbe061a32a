// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The Novint Falcon over plain libusb, end to end against a fake Falcon in
// user space (umockdev; run under libumockdev-preload): a missing firmware
// file is refused with a clear message; the firmware the user supplies is
// uploaded through the boot loader's handshake with every byte echoed;
// frames then carry the handle's position (forward kinematics of the
// encoders) and the forces (J^T F in 16-bit motor commands, clamped to the
// device's maximum); garbage between frames is dropped; a Falcon that stops
// answering or is unplugged is lost, and reconnected (with a new upload
// after a power cycle) when it is back.
#include "vtkHapticFakeFalcon.h"
#include "vtkHapticTestWaiting.h"

#include "vtkFTDIConnection.h"
#include "vtkFalconFirmwareLoader.h"
#include "vtkFalconKinematics.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkNovintFalconDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMath.h>
#include <vtkNew.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

namespace
{
bool Has(const std::vector<std::pair<int, int>>& controls, int request, int value)
{
  return std::find(controls.begin(), controls.end(), std::make_pair(request, value)) != controls.end();
}
} // namespace

int vtkNovintFalconDeviceTest1(int argc, char* argv[])
{
  const std::string temporary = argv[argc - 1];
  UMockdevTestbed* bed = umockdev_testbed_new();
  // Asked once the test bed exists (it looks at /sys, which the bed replaces).
  if (!umockdev_in_mock_environment())
  {
    std::cerr << "this test needs libumockdev-preload (run it with umockdev-wrapper)" << std::endl;
    g_object_unref(bed);
    return EXIT_FAILURE;
  }
  vtkHapticFakeFalcon fake(bed);
  CHECK_BOOL(fake.Plug(), true);
  fake.SetHomingFrames(10);
  const double handle[3] = { 5.0, -3.0, 8.0 };
  fake.SetPosition(handle);

  // Stand-in firmware: bytes of every value (Novint's file is never shipped).
  std::vector<unsigned char> firmware(300);
  for (size_t n = 0; n < firmware.size(); ++n)
  {
    firmware[n] = static_cast<unsigned char>((n * 37 + 11) & 0xff);
  }
  const std::string firmwareFile = temporary + "/vtkNovintFalconDeviceTest1-firmware.bin";
  {
    std::FILE* out = std::fopen(firmwareFile.c_str(), "wb");
    std::fwrite(firmware.data(), 1, firmware.size(), out);
    std::fclose(out);
  }

  vtkNew<vtkNovintFalconDevice> falcon;
  falcon->SetReconnectInterval(0.0);
  // No firmware file, then one that does not exist: refused, saying what to do.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(falcon->Open(), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  std::cout << falcon->GetLastErrorMessage() << std::endl;
  CHECK_BOOL(std::string(falcon->GetLastErrorMessage()).find("does not ship") != std::string::npos, true);
  falcon->SetFirmwareFileName((temporary + "/no-such-firmware.bin").c_str());
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(falcon->Open(), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(std::string(falcon->GetLastErrorMessage()).find("no-such-firmware.bin") != std::string::npos, true);
  CHECK_BOOL(fake.GetFirmwareLoaded(), false);
  CHECK_INT(falcon->GetConnectionState(), vtkHapticDevice::Closed);

  // With the user's file: uploaded byte for byte through the handshake.
  falcon->SetFirmwareFileName(firmwareFile.c_str());
  CHECK_BOOL(falcon->Open(), true);
  CHECK_BOOL(falcon->GetFirmwareUploaded(), true);
  CHECK_BOOL(fake.GetFirmware() == firmware, true);
  const auto controls = fake.GetControls();
  CHECK_BOOL(Has(controls, 3, vtkFalconFirmwareLoader::HandshakeBaudRateDivisor), true);
  CHECK_BOOL(Has(controls, 9, 16), true);
  CHECK_BOOL(Has(controls, 1, 0x0101), true); // DTR high
  CHECK_BOOL(Has(controls, 3, vtkFalconFirmwareLoader::UploadBaudRateDivisor), true);
  CHECK_BOOL(Has(controls, 3, vtkFalconFirmwareLoader::NormalBaudRateDivisor), true);
  CHECK_BOOL(Has(controls, 9, 1), true); // 1 ms latency for 1 kHz frames

  // Homing first (absent samples, homing bit sent), then the handle's position.
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetHomedAxes() == 7; }), true);
  double position[3];
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetLatestPosition(position); }), true);
  std::cout << "Falcon at " << position[0] << " " << position[1] << " " << position[2] << " mm (handle at 5 -3 8)" << std::endl;
  // Encoders quantise the arms to 0.036 degree: a few hundredths of a millimetre.
  CHECK_BOOL(std::sqrt(vtkMath::Distance2BetweenPoints(position, handle)) < 0.2, true);
  // Frames keep streaming by themselves (how fast is the haptic loop's
  // benchmark, not a test's: a starved machine must not fail it).
  const int frames = fake.GetNumberOfCommandFrames();
  const auto streamStart = std::chrono::steady_clock::now();
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return fake.GetNumberOfCommandFrames() - frames > 10; }), true);
  std::cout << fake.GetNumberOfCommandFrames() - frames << " frames in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - streamStart).count() << " s" << std::endl;

  // A force becomes the motor commands J^T F at that position; a force above
  // 8 N is clamped to 8 N first.
  const double force[3] = { 0.5, -1.0, 2.0 };
  CHECK_BOOL(falcon->SetForce(force), true);
  short expected[3];
  bool saturated = false;
  falcon->GetKinematics()->ForceToMotorCommands(position, force, expected, saturated);
  short motors[3] = { 0, 0, 0 };
  int control = 0;
  CHECK_BOOL(vtkHapticTestWaitFor([&]() {
    fake.GetLastMotors(motors, control);
    return motors[0] == expected[0] && motors[1] == expected[1] && motors[2] == expected[2];
  }),
    true);
  CHECK_BOOL(expected[0] != 0 || expected[1] != 0 || expected[2] != 0, true);
  CHECK_INT(control & 0x1, 0); // homed: no homing bit
  const double tooStrong[3] = { 0.0, 0.0, 80.0 };
  CHECK_BOOL(falcon->SetForce(tooStrong), false);
  const double clamped[3] = { 0.0, 0.0, 8.0 };
  falcon->GetKinematics()->ForceToMotorCommands(position, clamped, expected, saturated);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() {
    fake.GetLastMotors(motors, control);
    return motors[0] == expected[0] && motors[1] == expected[1] && motors[2] == expected[2];
  }),
    true);
  fake.SetButtons(0x5);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetLatestButtons() == 5u; }), true);

  // Garbage between frames: dropped and counted, frames still read.
  const unsigned long long samples = falcon->GetNumberOfSamples();
  fake.InjectGarbage({ '<', 'A', 'B', 0xff, '>', 0x00, 'Q', '<', 'P' });
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetNumberOfRejectedInputs() > 0; }), true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetNumberOfSamples() > samples + 20; }), true);

  // Stops answering: lost after the silence timeout; back without a new upload.
  fake.SetSilent(true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetConnectionState() == vtkHapticDevice::Lost; }), true);
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  falcon->ProcessConnectionEvents();
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  std::cout << "lost: " << falcon->GetLastErrorMessage() << std::endl;
  fake.SetSilent(false);
  falcon->ProcessConnectionEvents();
  CHECK_BOOL(falcon->IsConnected(), true);
  CHECK_BOOL(falcon->GetFirmwareUploaded(), false);

  // Unplugged: lost; not found while away; plugged back (powered afresh)
  // the firmware goes up again and the Falcon is back.
  fake.Unplug();
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetConnectionState() == vtkHapticDevice::Lost; }), true);
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  falcon->ProcessConnectionEvents();
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  falcon->ProcessConnectionEvents();
  CHECK_INT(falcon->GetConnectionState(), vtkHapticDevice::Lost);
  CHECK_BOOL(fake.Plug(), true);
  falcon->ProcessConnectionEvents();
  CHECK_BOOL(falcon->IsConnected(), true);
  CHECK_BOOL(falcon->GetFirmwareUploaded(), true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return falcon->GetLatestPosition(position); }), true);
  CHECK_INT(falcon->GetNumberOfConnections(), 3);

  // Closing sends zero force last.
  falcon->SetForce(force);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  falcon->Close();
  fake.GetLastMotors(motors, control);
  CHECK_INT(motors[0], 0);
  CHECK_INT(motors[1], 0);
  CHECK_INT(motors[2], 0);
  falcon->Print(std::cout);
  fake.Unplug();
  g_object_unref(bed);
  return EXIT_SUCCESS;
}
