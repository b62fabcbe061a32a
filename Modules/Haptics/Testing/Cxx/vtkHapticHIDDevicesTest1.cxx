// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The hidapi backends end to end against fake devices in user space
// (umockdev; run under libumockdev-preload): unmodified hidapi enumerates,
// opens, reads and writes them. A SpaceMouse moves the integrated pose,
// presses buttons, takes the LED, drops garbage, is unplugged (reported
// lost) and plugged back (reconnected); foot switches of both families
// report their pedals, and a pedal runs the haptic loop's drill.
#include "vtkHapticFakeHIDDevice.h"
#include "vtkHapticTestScene.h"
#include "vtkHapticTestWaiting.h"

#include "vtkFootSwitchDevice.h"
#include "vtkHIDConnection.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkSpaceMouseDevice.h"
#include "vtkVirtualHapticDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vtkCallbackCommand.h>
#include <vtkNew.h>

#include <chrono>
#include <functional>
#include <iostream>
#include <thread>

namespace
{
std::vector<unsigned char> SixAxes(int x, int y, int z, int rx, int ry, int rz)
{
  std::vector<unsigned char> report = { 0x01 };
  for (int value : { x, y, z, rx, ry, rz })
  {
    report.push_back(static_cast<unsigned char>(value & 0xff));
    report.push_back(static_cast<unsigned char>((value >> 8) & 0xff));
  }
  return report;
}

void CountEvent(vtkObject*, unsigned long event, void* clientData, void*)
{
  int* counts = static_cast<int*>(clientData);
  ++counts[event == vtkHapticDevice::DeviceConnectedEvent ? 0 : 1];
}

// A generic-desktop multi-axis controller's descriptor start: hidapi reads
// its usage page and usage from sysfs.
const std::vector<unsigned char> Descriptor = { 0x05, 0x01, 0x09, 0x08, 0xa1, 0x01, 0xc0 };
} // namespace

int vtkHapticHIDDevicesTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  UMockdevTestbed* bed = umockdev_testbed_new();
  // Asked once the test bed exists (it looks at /sys, which the bed replaces).
  if (!umockdev_in_mock_environment())
  {
    std::cerr << "this test needs libumockdev-preload (run it with umockdev-wrapper)" << std::endl;
    g_object_unref(bed);
    return EXIT_FAILURE;
  }

  // --- SpaceMouse (wireless layout, 256f:c62e) ---
  vtkHapticFakeHIDDevice fakeMouse(bed, 0x256f, 0xc62e, 0, Descriptor);
  CHECK_BOOL(fakeMouse.Plug(), true);
  fakeMouse.SetStream(SixAxes(0, 0, 0, 0, 0, 0));
  vtkNew<vtkSpaceMouseDevice> mouse;
  mouse->GetConnection()->SetReadTimeout(-1);
  mouse->SetReconnectInterval(0.0);
  int events[2] = { 0, 0 };
  vtkNew<vtkCallbackCommand> observer;
  observer->SetCallback(CountEvent);
  observer->SetClientData(events);
  mouse->AddObserver(vtkHapticDevice::DeviceConnectedEvent, observer);
  mouse->AddObserver(vtkHapticDevice::DeviceDisconnectedEvent, observer);
  CHECK_BOOL(mouse->Open(), true);
  CHECK_STRING(mouse->GetConnection()->GetOpenedPath(), "/dev/hidraw0");
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return mouse->GetNumberOfSamples() > 3; }), true);

  // Full deflection to the right moves it at 50 mm/s: until it has gone
  // 2 mm, then released; it cannot have gone faster than 50 mm/s over the
  // time it was held.
  double position[3] = { 0.0, 0.0, 0.0 };
  const auto pushed = std::chrono::steady_clock::now();
  fakeMouse.SetStream(SixAxes(350, 0, 0, 0, 0, 0));
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return mouse->GetLatestPosition(position) && position[0] > 2.0; }), true);
  fakeMouse.SetStream(SixAxes(0, 0, 0, 0, 0, 0));
  // Released once two readings agree with reports read between them (the
  // reports already queued at full deflection may still be on their way;
  // reports come in order, so once one read after them moved nothing, they
  // are all in). Two readings alone agreed when a loaded machine had not run
  // the reader between them (an ASan run beside other tests).
  CHECK_BOOL(vtkHapticTestWaitFor([&]() {
    double before[3];
    mouse->GetLatestPosition(before);
    const auto samples = mouse->GetNumberOfSamples();
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    mouse->GetLatestPosition(position);
    return position[0] == before[0] && mouse->GetNumberOfSamples() > samples + 1;
  }),
    true);
  const double held = std::chrono::duration<double>(std::chrono::steady_clock::now() - pushed).count();
  CHECK_BOOL(mouse->GetLatestPosition(position), true);
  std::cout << "SpaceMouse moved to x = " << position[0] << " mm in " << held << " s" << std::endl;
  CHECK_BOOL(position[0] > 2.0 && position[0] < 50.0 * held + 1.0, true);
  CHECK_DOUBLE(position[1], 0.0);
  // Within the dead zone nothing moves.
  fakeMouse.SetStream(SixAxes(5, -8, 10, 3, 0, -2));
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  double still[3];
  mouse->GetLatestPosition(still);
  CHECK_DOUBLE_TOLERANCE(still[0], position[0], 1e-9);
  // A twist about z turns the orientation.
  fakeMouse.SetStream(SixAxes(0, 0, 0, 0, 0, 350));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  fakeMouse.SetStream(SixAxes(0, 0, 0, 0, 0, 0));
  double orientation[4];
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return mouse->GetLatestOrientation(orientation) && orientation[3] > 0.01; }), true);
  // Buttons, the LED, and garbage.
  fakeMouse.Send({ 0x03, 0x02, 0x00 });
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return mouse->GetLatestButtons() == 2u; }), true);
  CHECK_BOOL(mouse->SetLED(true), true);
  const auto written = fakeMouse.Written();
  CHECK_BOOL(!written.empty() && written.back() == std::vector<unsigned char>({ 0x04, 0x01 }), true);
  fakeMouse.Send({ 0x01, 0x10 });
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return mouse->GetNumberOfRejectedInputs() == 1; }), true);

  // Unplugged: lost, reported, not found again while it is away...
  fakeMouse.Unplug();
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return mouse->GetConnectionState() == vtkHapticDevice::Lost; }), true);
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  mouse->ProcessConnectionEvents();
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  CHECK_INT(events[1], 1);
  mouse->ProcessConnectionEvents();
  CHECK_INT(mouse->GetConnectionState(), vtkHapticDevice::Lost);
  CHECK_INT(events[0], 0);
  // ...and reconnected once it is back.
  CHECK_BOOL(fakeMouse.Plug(), true);
  mouse->ProcessConnectionEvents();
  CHECK_INT(events[0], 1);
  CHECK_BOOL(mouse->IsConnected(), true);
  CHECK_INT(mouse->GetNumberOfConnections(), 2);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return mouse->GetNumberOfSamples() > 3; }), true);
  mouse->Close();
  CHECK_INT(mouse->GetConnectionState(), vtkHapticDevice::Closed);

  // --- Foot switches: VEC (bit mask) and PCsensor (keyboard) ---
  vtkHapticFakeHIDDevice fakeVEC(bed, 0x05f3, 0x00ff, 1, Descriptor);
  CHECK_BOOL(fakeVEC.Plug(), true);
  fakeVEC.SetStream({ 0x00, 0x00 });
  vtkNew<vtkFootSwitchDevice> vec;
  vec->GetConnection()->SetReadTimeout(-1);
  CHECK_BOOL(vec->Open(), true);
  CHECK_INT(vec->GetConnection()->GetOpenedVendorID(), 0x05f3);
  fakeVEC.SetStream({ 0x04, 0x00 });
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return vec->GetLatestButtons() == 4u; }), true);
  fakeVEC.Send({ 0xf0, 0x00 });
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return vec->GetNumberOfRejectedInputs() == 1; }), true);
  CHECK_INT(static_cast<int>(vec->GetLatestButtons()), 4);

  vtkHapticFakeHIDDevice fakeKeyboard(bed, 0x0c45, 0x7403, 2, Descriptor);
  CHECK_BOOL(fakeKeyboard.Plug(), true);
  fakeKeyboard.SetStream({ 0, 0, 0, 0, 0, 0, 0, 0 });
  vtkNew<vtkFootSwitchDevice> keyboard;
  keyboard->GetConnection()->SetReadTimeout(-1);
  keyboard->GetConnection()->SetDevicePath("/dev/hidraw2");
  CHECK_BOOL(keyboard->Open(), true);
  fakeKeyboard.SetStream({ 0, 0, 0x05, 0, 0, 0, 0, 0 });
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return keyboard->GetLatestButtons() == 2u; }), true);

  // The pedal runs the loop's drill; released, it stops.
  vtkHapticTestScene scene;
  vtkNew<vtkVirtualHapticDevice> hand;
  CHECK_BOOL(hand->Open(), true);
  const double up[3] = { 0.0, 0.0, 10.0 };
  hand->SetPose(up, 0u);
  vtkNew<vtkHapticForceModel> model;
  model->SetAnatomy(scene.CT, scene.IJKToRAS);
  vtkNew<vtkHapticLoop> loop;
  loop->SetDevice(hand);
  loop->SetSwitchDevice(vec);
  loop->SetForceModel(model);
  loop->SetCutField(scene.Field);
  loop->SetDrillButtons(4u); // the right pedal
  CHECK_BOOL(loop->RunTicks(3), true);
  CHECK_BOOL(loop->GetDrilling(), true);
  fakeVEC.SetStream({ 0x00, 0x00 });
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return vec->GetLatestButtons() == 0u; }), true);
  CHECK_BOOL(loop->RunTicks(3), true);
  CHECK_BOOL(loop->GetDrilling(), false);
  loop->Stop();

  vec->Close();
  keyboard->Close();
  hand->Close();
  // The fakes leave the test bed before it goes.
  fakeMouse.Unplug();
  fakeVEC.Unplug();
  fakeKeyboard.Unplug();
  g_object_unref(bed);
  return EXIT_SUCCESS;
}
