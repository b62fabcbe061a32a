// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The haptic loop end to end without hardware: a virtual device drills into
// the analytic plane; it is unplugged mid-stroke (the drill stops, every cut
// stays as one undo step, the force drops to zero) and plugged back (the
// drill resumes without sweeping across the gap); bad input is rejected and
// reported; the recorded session replays through a fresh scene to the same
// forces and the same field, bit for bit; the loop's own thread runs it.
#include "vtkHapticTestScene.h"

#include "vtkHapticDevice.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkHapticRecorder.h"
#include "vtkReplayHapticDevice.h"
#include "vtkVirtualHapticDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vtkCallbackCommand.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

namespace
{
struct EventCounts
{
  int Connected = 0;
  int Disconnected = 0;
};

void CountEvent(vtkObject*, unsigned long event, void* clientData, void*)
{
  EventCounts* counts = static_cast<EventCounts*>(clientData);
  if (event == vtkHapticDevice::DeviceConnectedEvent)
  {
    ++counts->Connected;
  }
  else if (event == vtkHapticDevice::DeviceDisconnectedEvent)
  {
    ++counts->Disconnected;
  }
}

/// A loop on a scene: the tool's centre starts 2 mm above the plane's first contact at (5, 5).
void Configure(vtkHapticLoop* loop, vtkHapticForceModel* model, vtkHapticTestScene& scene, vtkHapticDevice* device, vtkHapticRecorder* recorder)
{
  model->SetAnatomy(scene.CT, scene.IJKToRAS);
  model->SetSurfaceIsoValue(scene.IsoValue);
  model->SetSphereRadius(2.5);
  loop->SetDevice(device);
  loop->SetForceModel(model);
  loop->SetCutField(scene.Field);
  loop->SetRecorder(recorder);
  vtkNew<vtkMatrix4x4> deviceToRAS;
  deviceToRAS->SetElement(0, 3, 5.0);
  deviceToRAS->SetElement(1, 3, 5.0);
  deviceToRAS->SetElement(2, 3, scene.PlaneHeight + 2.5 + 2.0);
  loop->SetDeviceToRAS(deviceToRAS);
}

/// Every brick of two fields holds the same samples.
bool SameField(vtkVolumeCutField* a, vtkVolumeCutField* b)
{
  const int* dims = a->GetBrickDimensions();
  const vtkIdType count = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  std::vector<short> va(512), vb(512);
  for (vtkIdType id = 0; id < count; ++id)
  {
    a->CopyBrick(id, va.data());
    b->CopyBrick(id, vb.data());
    if (std::memcmp(va.data(), vb.data(), 512 * sizeof(short)) != 0)
    {
      return false;
    }
  }
  return true;
}
} // namespace

int vtkHapticLoopTest1(int argc, char* argv[])
{
  const std::string temporary = argv[argc - 1];
  vtkHapticTestScene scene;
  vtkNew<vtkVirtualHapticDevice> device;
  device->SetReconnectInterval(0.0);
  EventCounts counts;
  vtkNew<vtkCallbackCommand> observer;
  observer->SetCallback(CountEvent);
  observer->SetClientData(&counts);
  device->AddObserver(vtkHapticDevice::DeviceConnectedEvent, observer);
  device->AddObserver(vtkHapticDevice::DeviceDisconnectedEvent, observer);

  vtkNew<vtkHapticLoop> loop;
  vtkNew<vtkHapticForceModel> model;
  vtkNew<vtkHapticRecorder> recorder;
  recorder->SetCapacity(5000);
  Configure(loop, model, scene, device, recorder);

  // Not open: refused, saying so.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(loop->RunTicks(1), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(device->Open(), true);

  // Hovering: no force, the tool where the hand is.
  const double up[3] = { 0.0, 0.0, 0.0 };
  CHECK_BOOL(device->SetPose(up, 0), true);
  CHECK_BOOL(loop->RunTicks(50), true);
  double force[3];
  loop->GetLatestForce(force);
  CHECK_DOUBLE(vtkMath::Norm(force), 0.0);
  vtkNew<vtkMatrix4x4> pose;
  CHECK_BOOL(loop->GetLatestToolPose(pose), true);
  CHECK_DOUBLE_TOLERANCE(pose->GetElement(2, 3), scene.PlaneHeight + 4.5, 1e-12);

  // Down into the plane with the drill running: it cuts, the tool sinks in.
  for (int tick = 0; tick < 400; ++tick)
  {
    const double hand[3] = { 0.0, 0.0, -std::min(3.5, 0.01 * tick) };
    device->SetPose(hand, 1u);
    loop->RunTicks(1);
  }
  CHECK_BOOL(loop->GetDrilling(), true);
  CHECK_BOOL(scene.Field->IsStrokeOpen(), true);
  CHECK_BOOL(loop->ProcessEvents() > 0, true);
  CHECK_INT(loop->GetNumberOfDrillPresses(), 1);
  CHECK_BOOL(loop->GetLatestToolPose(pose), true);
  const double sunk = pose->GetElement(2, 3);
  std::cout << "after 400 ticks the burr is " << scene.PlaneHeight + 2.5 - sunk << " mm into the bone" << std::endl;
  CHECK_BOOL(sunk < scene.PlaneHeight + 2.5 - 0.2, true);
  const double drilled[3] = { 5.0, 5.0, scene.PlaneHeight - 0.1 };
  CHECK_BOOL(scene.Field->GetSignedDistance(drilled) < 0.0, true);
  loop->GetLatestForce(force);
  CHECK_BOOL(force[2] > 0.1, true);

  // Unplugged mid-stroke: the stroke is closed (one undo step, the cut
  // kept), the force is zero, the drill reported stopped.
  device->SetPlugged(false);
  CHECK_BOOL(loop->RunTicks(5), true);
  CHECK_BOOL(scene.Field->IsStrokeOpen(), false);
  CHECK_INT(scene.Field->GetNumberOfUndoSteps(), 1);
  CHECK_BOOL(scene.Field->GetSignedDistance(drilled) < 0.0, true);
  CHECK_BOOL(loop->GetDrilling(), false);
  device->GetCommandedForce(force);
  CHECK_DOUBLE(vtkMath::Norm(force), 0.0);
  loop->GetLatestForce(force);
  CHECK_DOUBLE(vtkMath::Norm(force), 0.0);
  loop->ProcessEvents();
  CHECK_INT(loop->GetNumberOfDeviceLosses(), 1);
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  device->ProcessConnectionEvents();
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  CHECK_INT(counts.Disconnected, 1);
  CHECK_INT(device->GetConnectionState(), vtkHapticDevice::Lost);
  // Still unplugged: no reconnection.
  device->ProcessConnectionEvents();
  CHECK_INT(counts.Connected, 0);
  CHECK_BOOL(loop->RunTicks(5), true);

  // Plugged back, the hand now 8 mm aside and above: no sweep across the gap.
  device->SetPlugged(true);
  device->ProcessConnectionEvents();
  CHECK_INT(counts.Connected, 1);
  CHECK_BOOL(device->IsConnected(), true);
  CHECK_BOOL(loop->RunTicks(3), true); // no sample yet since it came back: still stopped
  CHECK_BOOL(loop->GetDrilling(), false);
  const double aside[3] = { 0.0, -8.0, 0.0 };
  device->SetPose(aside, 1u);
  CHECK_BOOL(loop->RunTicks(20), true);
  loop->ProcessEvents();
  CHECK_INT(loop->GetNumberOfDeviceReturns(), 1);
  CHECK_BOOL(loop->GetDrilling(), true);
  CHECK_BOOL(loop->GetLatestToolPose(pose), true);
  CHECK_DOUBLE_TOLERANCE(pose->GetElement(1, 3), -3.0, 1e-9);
  const double between[3] = { 5.0, 1.0, scene.PlaneHeight - 0.1 };
  CHECK_BOOL(scene.Field->GetSignedDistance(between) > 0.0, true);
  // Drilling resumes there.
  for (int tick = 0; tick < 300; ++tick)
  {
    const double hand[3] = { 0.0, -8.0, -std::min(3.5, 0.01 * tick) };
    device->SetPose(hand, 1u);
    loop->RunTicks(1);
  }
  const double drilledAside[3] = { 5.0, -3.0, scene.PlaneHeight - 0.1 };
  CHECK_BOOL(scene.Field->GetSignedDistance(drilledAside) < 0.0, true);
  CHECK_BOOL(scene.Field->GetSignedDistance(between) > 0.0, true);

  // Bad input: a pose that is not a number is dropped (the loop keeps the
  // last one), counted and reported; forces stay finite.
  const double nan[3] = { std::nan(""), 0.0, 0.0 };
  device->SetPose(nan, 1u);
  CHECK_BOOL(loop->RunTicks(5), true);
  loop->GetLatestForce(force);
  CHECK_BOOL(std::isfinite(force[0]) && std::isfinite(force[1]) && std::isfinite(force[2]), true);
  CHECK_INT(static_cast<int>(device->GetNumberOfRejectedInputs()), 1);
  // Released: the stroke ends; two undo steps in all.
  const double lifted[3] = { 0.0, -8.0, 1.0 };
  device->SetPose(lifted, 0u);
  CHECK_BOOL(loop->RunTicks(10), true);
  CHECK_INT(scene.Field->GetNumberOfUndoSteps(), 2);
  loop->Stop();
  const int recorded = recorder->GetNumberOfTicks();
  CHECK_INT(recorded, static_cast<int>(loop->GetNumberOfTicks()));

  // Each tick's profile: its parts, timed inside it on the same clock, fit
  // in its wall time; ticks that drilled spent time cutting (RunTicks cuts
  // in the tick: the cutter has cut nothing).
  CHECK_INT(loop->GetNumberOfKeptTicks(), recorded);
  double profile[vtkHapticLoop::NumberOfTickProfileFields];
  int cuttingTicks = 0;
  int contactTicks = 0;
  int overfull = 0;
  int cutFieldTicks = 0;
  for (int n = 0; n < loop->GetNumberOfKeptTicks(); ++n)
  {
    CHECK_BOOL(loop->GetTickProfile(n, profile), true);
    const double parts = profile[vtkHapticLoop::ProfileForceModel] + profile[vtkHapticLoop::ProfileCut] + profile[vtkHapticLoop::ProfileNerveMonitor];
    overfull += parts > profile[vtkHapticLoop::ProfileDuration] + 0.01 ? 1 : 0;
    cuttingTicks += profile[vtkHapticLoop::ProfileCut] > 0.0 ? 1 : 0;
    CHECK_BOOL(profile[vtkHapticLoop::ProfilePageFaults] >= 0.0 && profile[vtkHapticLoop::ProfilePreemptions] >= 0.0, true);
    // The force model's work: each contact test looks up every shell point (82) and traces the contacts;
    // a deepest contact deeper than the burr (2.5 mm) would be a trace past its centre.
    const double steps = profile[vtkHapticLoop::ProfileProxySteps];
    CHECK_BOOL(steps <= model->GetProxyIterations(), true);
    CHECK_BOOL(profile[vtkHapticLoop::ProfileSamples] >= 82.0 * steps, true);
    CHECK_BOOL(profile[vtkHapticLoop::ProfileContacts] <= 82.0, true);
    CHECK_BOOL(profile[vtkHapticLoop::ProfileImmersion] >= 0.0 && profile[vtkHapticLoop::ProfileImmersion] <= 2.5, true);
    contactTicks += profile[vtkHapticLoop::ProfileContacts] > 0.0 && profile[vtkHapticLoop::ProfileImmersion] > 0.0 ? 1 : 0;
    // Of the points looked up, the cut field's: where the CT is solid, once the burr has cut.
    CHECK_BOOL(profile[vtkHapticLoop::ProfileCutFieldSamples] >= 0.0 &&
        profile[vtkHapticLoop::ProfileCutFieldSamples] <= profile[vtkHapticLoop::ProfileSamples], true);
    cutFieldTicks += profile[vtkHapticLoop::ProfileCutFieldSamples] > 0.0 ? 1 : 0;
  }
  CHECK_INT(overfull, 0);
  CHECK_BOOL(cutFieldTicks > 0 && cutFieldTicks >= cuttingTicks / 2, true);
  CHECK_BOOL(contactTicks >= cuttingTicks, true);
  std::cout << cuttingTicks << " of " << recorded << " ticks cut" << std::endl;
  CHECK_BOOL(cuttingTicks > 100, true);
  CHECK_BOOL(loop->GetTickProfile(recorded, profile), false);
  CHECK_BOOL(loop->GetTickProfile(-1, profile), false);
  CHECK_DOUBLE(loop->GetCutterDurationPercentile(100.0), 0.0);

  // Forces the device cannot render: not a number, or above its maximum.
  CHECK_BOOL(device->SetForce(nan), false);
  device->GetCommandedForce(force);
  CHECK_DOUBLE(vtkMath::Norm(force), 0.0);
  const double tooStrong[3] = { 30.0, 40.0, 0.0 };
  CHECK_BOOL(device->SetForce(tooStrong), false);
  device->GetCommandedForce(force);
  CHECK_DOUBLE_TOLERANCE(force[0], 4.8, 1e-12);
  CHECK_DOUBLE_TOLERANCE(force[1], 6.4, 1e-12);
  CHECK_INT(static_cast<int>(device->GetNumberOfRejectedForces()), 1);
  CHECK_INT(static_cast<int>(device->GetNumberOfClampedForces()), 1);
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  device->ProcessConnectionEvents();
  TESTING_OUTPUT_ASSERT_WARNINGS_END();

  // The session, saved and replayed through a fresh scene: the same forces
  // and tool poses tick by tick and the same field, bit for bit.
  const std::string file = temporary + "/vtkHapticLoopTest1.vchr";
  CHECK_BOOL(recorder->WriteFile(file.c_str()), true);
  vtkNew<vtkReplayHapticDevice> replay;
  CHECK_BOOL(replay->ReadFile(file.c_str()), true);
  CHECK_INT(replay->GetRecording()->GetNumberOfTicks(), recorded);
  CHECK_DOUBLE(replay->GetCapabilities()->GetMaximumForce(), 8.0);
  CHECK_BOOL(replay->Open(), true);
  vtkHapticTestScene replayScene;
  vtkNew<vtkHapticLoop> replayLoop;
  vtkNew<vtkHapticForceModel> replayModel;
  vtkNew<vtkHapticRecorder> replayRecorder;
  replayRecorder->SetCapacity(recorded);
  Configure(replayLoop, replayModel, replayScene, replay, replayRecorder);
  CHECK_BOOL(replayLoop->RunTicks(recorded), true);
  replayLoop->Stop();
  CHECK_BOOL(replay->IsFinished(), true);
  int differences = 0;
  for (int n = 0; n < recorded; ++n)
  {
    const vtkHapticRecorder::Tick& a = recorder->GetTick(n);
    const vtkHapticRecorder::Tick& b = replayRecorder->GetTick(n);
    if (a.Present != b.Present || std::memcmp(a.Force, b.Force, sizeof(a.Force)) != 0 || std::memcmp(a.Proxy, b.Proxy, sizeof(a.Proxy)) != 0 ||
      a.Cut != b.Cut)
    {
      ++differences;
    }
  }
  CHECK_INT(differences, 0);
  CHECK_BOOL(SameField(scene.Field, replayScene.Field), true);
  CHECK_INT(replayScene.Field->GetNumberOfUndoSteps(), 2);

  // A foreign or truncated recording is refused with its name.
  const std::string foreign = temporary + "/vtkHapticLoopTest1-foreign.vchr";
  {
    std::FILE* out = std::fopen(foreign.c_str(), "w");
    std::fputs("# VolumeCutting haptic recording 1\nrate 1000\ndevice 6 3\n", out);
    std::fclose(out);
  }
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(replay->ReadFile(foreign.c_str()), false);
  CHECK_BOOL(replay->ReadFile((temporary + "/missing.vchr").c_str()), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_INT(replay->GetRecording()->GetNumberOfTicks(), recorded);

  // The loop's own thread, at 1 kHz for 0.3 s with the hand hovering.
  loop->SetRecorder(nullptr);
  device->SetPose(up, 0u);
  CHECK_BOOL(loop->Start(), true);
  CHECK_BOOL(loop->IsRunning(), true);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(loop->RunTicks(1), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  // At least 30 ticks (0.03 s of a 1 kHz loop), waited for up to 20 s: how
  // steady the ticks are is the benchmark's business, and the sanitizer
  // builds run this test starved of a core.
  const auto started = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  while (loop->GetNumberOfTicks() <= 30 && std::chrono::steady_clock::now() - started < std::chrono::seconds(20))
  {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  loop->Stop();
  CHECK_BOOL(loop->IsRunning(), false);
  std::cout << loop->GetNumberOfTicks() << " ticks in " << std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() << " s; tick p50 " << loop->GetTickDurationPercentile(50) << " us, period jitter p99 "
            << loop->GetPeriodJitterPercentile(99) << " us" << (loop->GetRealTimePriority() ? " (real-time priority)" : "") << std::endl;
  CHECK_BOOL(loop->GetNumberOfTicks() > 30, true);
  CHECK_BOOL(loop->GetTickDurationPercentile(50) > 0.0, true);
  // The thread's processor time within a tick: some, and no more than the
  // tick's wall time (a microsecond allowed for the clocks' own reading).
  std::cout << "tick processor time p50 " << loop->GetTickProcessorTimePercentile(50) << " us, max " << loop->GetTickProcessorTimePercentile(100)
            << " us" << std::endl;
  CHECK_BOOL(loop->GetTickProcessorTimePercentile(50) > 0.0, true);
  CHECK_BOOL(loop->GetTickProcessorTimePercentile(100) <= loop->GetMaximumTickDuration() + 1.0, true);
  loop->Print(std::cout);
  return EXIT_SUCCESS;
}
