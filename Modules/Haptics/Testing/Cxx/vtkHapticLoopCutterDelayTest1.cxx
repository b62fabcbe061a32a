// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// A cutter that is behind must not change what the hand feels. The same
// drilling into the test scene's plane (down and sideways, drill on) is
// replayed three times, deterministically (RunTicks): cutting in the tick;
// with the cuts made by a cutter 8 ticks behind (ReplayCutterDelay) while
// the force model counts the segments queued and not cut yet as removed
// (FeelPendingCuts, the default); and with the same cutter, not counting
// them. The first two must give the same force at every tick, within what
// separates the field's reconstruction from the burr's exact capsules; the
// third shows what the hand felt before: the proxy meeting bone the cutter
// had not removed yet.
#include "vtkHapticTestScene.h"

#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkVirtualHapticDevice.h"
#include "vtkVolumeCutCylinderTool.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
constexpr int DrillingTicks = 700;
constexpr int Delay = 8;

struct Drilling
{
  /// The force sent at every tick (N, three values a tick).
  std::vector<double> Forces;
  /// The most segments the force model counted as pending in a tick.
  int MostPending = 0;
  /// The cut's signed distance (mm) at points of a grid around the hole, after the session.
  std::vector<double> Distances;
};

bool Drill(int delay, bool feelPending, Drilling& drilling)
{
  vtkHapticTestScene scene;
  vtkNew<vtkVirtualHapticDevice> device;
  vtkNew<vtkHapticForceModel> model;
  model->SetAnatomy(scene.CT, scene.IJKToRAS);
  model->SetSurfaceIsoValue(scene.IsoValue);
  model->SetSphereRadius(2.0);
  vtkNew<vtkHapticLoop> loop;
  loop->SetDevice(device);
  loop->SetForceModel(model);
  loop->SetCutField(scene.Field);
  loop->SetAsynchronousCutting(delay > 0);
  loop->SetReplayCutterDelay(delay);
  loop->SetFeelPendingCuts(feelPending);
  vtkNew<vtkMatrix4x4> deviceToRAS;
  deviceToRAS->SetElement(2, 3, scene.PlaneHeight + 3.0);
  loop->SetDeviceToRAS(deviceToRAS);
  if (!device->Open())
  {
    return false;
  }
  const double above[3] = { 0.0, 0.0, 0.0 };
  device->SetPose(above, 0u);
  if (!loop->RunTicks(20))
  {
    return false;
  }
  // Down into the bone and sideways with the drill on: the burr cuts ahead
  // of the proxy at every tick, and the proxy follows into what it cut.
  for (int tick = 0; tick < DrillingTicks; ++tick)
  {
    const double hand[3] = { 2.0 * std::sin(0.004 * tick), 0.0, -std::min(3.5, 0.01 * tick) };
    device->SetPose(hand, 1u);
    loop->RunTicks(1);
    double force[3];
    loop->GetLatestForce(force);
    drilling.Forces.insert(drilling.Forces.end(), force, force + 3);
    drilling.MostPending = std::max(drilling.MostPending, model->GetNumberOfPendingCuts());
  }
  loop->Stop();
  for (double x = -4.0; x <= 4.0; x += 0.5)
  {
    for (double z = scene.PlaneHeight - 4.0; z <= scene.PlaneHeight; z += 0.5)
    {
      const double point[3] = { x, 0.0, z };
      drilling.Distances.push_back(scene.Field->GetSignedDistance(point));
    }
  }
  return true;
}

/// The largest difference between two sessions' forces at the same tick (N).
double LargestForceDifference(const Drilling& a, const Drilling& b)
{
  double largest = 0.0;
  for (size_t n = 0; n + 2 < std::min(a.Forces.size(), b.Forces.size()); n += 3)
  {
    largest = std::max(largest, std::sqrt(vtkMath::Distance2BetweenPoints(&a.Forces[n], &b.Forces[n])));
  }
  return largest;
}

double LargestForce(const Drilling& drilling)
{
  double largest = 0.0;
  for (size_t n = 0; n + 2 < drilling.Forces.size(); n += 3)
  {
    largest = std::max(largest, vtkMath::Norm(&drilling.Forces[n]));
  }
  return largest;
}
} // namespace

int vtkHapticLoopCutterDelayTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  Drilling inTicks, felt, unfelt;
  CHECK_BOOL(Drill(0, true, inTicks), true);
  CHECK_BOOL(Drill(Delay, true, felt), true);
  CHECK_BOOL(Drill(Delay, false, unfelt), true);
  CHECK_INT(static_cast<int>(inTicks.Forces.size()), 3 * DrillingTicks);
  CHECK_INT(static_cast<int>(felt.Forces.size()), 3 * DrillingTicks);

  // The replays did what they stand for: cutting in the tick has nothing
  // pending; the delayed cutter has cut, before a tick, the segments queued
  // Delay ticks before it and earlier: those of the Delay - 1 ticks since are pending.
  CHECK_INT(inTicks.MostPending, 0);
  CHECK_INT(felt.MostPending, Delay - 1);
  CHECK_INT(unfelt.MostPending, 0);

  const double largest = LargestForce(inTicks);
  const double feltDifference = LargestForceDifference(inTicks, felt);
  const double unfeltDifference = LargestForceDifference(inTicks, unfelt);
  std::cout << "largest force cutting in the tick " << largest << " N; largest difference at a tick with a cutter " << Delay
            << " ticks behind: " << feltDifference << " N counting its pending cuts, " << unfeltDifference << " N not counting them"
            << std::endl;
  // The drilling pushes against the bone: a force the comparison can see.
  CHECK_BOOL(largest > 1.0, true);
  // Counting the pending capsules, the hand feels what cutting in the tick
  // gives, within 5 % of the largest force: the capsules are the exact sweep,
  // the field its reconstruction on 0.25 mm samples. While both follow the
  // same path the forces agree within 0.5 %; the small differences of where
  // the burr cut then move the proxy's later path a little (3 % late in the stroke).
  if (!(feltDifference <= 0.05 * largest))
  {
    std::cerr << "a cutter " << Delay << " ticks behind changed the force by " << feltDifference << " N (largest force " << largest
              << " N)" << std::endl;
    return EXIT_FAILURE;
  }
  // Without them the hand meets bone the cutter has not removed: a
  // difference many times that (what the loop rendered before).
  CHECK_BOOL(unfeltDifference > 5.0 * std::max(feltDifference, 0.01 * largest), true);

  // The delayed cutter cut the same hole (every segment, the stroke closed by Stop).
  double fieldDifference = 0.0;
  for (size_t n = 0; n < inTicks.Distances.size(); ++n)
  {
    fieldDifference = std::max(fieldDifference, std::abs(inTicks.Distances[n] - felt.Distances[n]));
  }
  std::cout << "largest difference of the cut's distance around the hole: " << fieldDifference << " mm" << std::endl;
  CHECK_BOOL(fieldDifference <= 0.05, true);

  // Pending sweeps are the spherical burr's capsules: a tool of another shape's are refused.
  vtkNew<vtkHapticForceModel> model;
  vtkNew<vtkVolumeCutCylinderTool> cylinder;
  model->SetTool(cylinder);
  const double p0[3] = { 0.0, 0.0, 0.0 };
  const double p1[3] = { 0.1, 0.0, 0.0 };
  CHECK_BOOL(model->AddPendingCut(p0, p1), false);
  model->SetTool(nullptr);
  CHECK_BOOL(model->AddPendingCut(p0, p1), true);
  CHECK_INT(model->GetNumberOfPendingCuts(), 1);
  model->ClearPendingCuts();
  CHECK_INT(model->GetNumberOfPendingCuts(), 0);
  return EXIT_SUCCESS;
}
