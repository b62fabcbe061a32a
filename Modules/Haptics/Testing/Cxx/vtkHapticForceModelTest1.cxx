// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The force model against analytic scenes: a spherical burr pressed into a
// plane, into a hole cut in it, against the wall of a cavity cut in it, and
// at the end of a bore it drilled. Force starts where the shell touches the
// surface the renderer draws (the CT's iso-surface minus the cut field), to
// well within 0.1 voxel; the proxy stays on the surface; limits, guide,
// drilling bite, vibration and bad input behave.
#include "vtkHapticTestScene.h"

#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticPointShell.h"
#include "vtkHapticVibration.h"

#include <vtkAddonTestingMacros.h>

#include <vtkBinaryVoxelCutter.h>
#include <vtkMath.h>
#include <vtkNew.h>
#include <vtkVolumeCutCylinderTool.h>

#include <cmath>
#include <iostream>

namespace
{
/// The highest tool height (RAS z of its centre above (x, y)) at which the
/// shell touches material: bisection on "any contact".
double OnsetHeight(vtkHapticForceModel* model, double x, double y, double low, double high)
{
  double force[3];
  for (int step = 0; step < 60; ++step)
  {
    const double middle = 0.5 * (low + high);
    const double position[3] = { x, y, middle };
    (model->ComputeContactForce(position, force) > 0 ? low : high) = middle;
  }
  return 0.5 * (low + high);
}
} // namespace

int vtkHapticForceModelTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkHapticTestScene scene;
  const double radius = 2.5;
  vtkNew<vtkHapticForceModel> model;
  model->SetAnatomy(scene.CT, scene.IJKToRAS);
  model->SetSurfaceIsoValue(scene.IsoValue);
  model->SetCutField(scene.Field);
  model->SetSphereRadius(radius);
  CHECK_BOOL(model->Prepare(), true);
  CHECK_INT(model->GetPointShell()->GetNumberOfPoints(), 82);

  // The classification is the renderer's: solid just below the plane, not above.
  const double below[3] = { 1.0, 2.0, scene.PlaneHeight - 1e-6 };
  const double above[3] = { 1.0, 2.0, scene.PlaneHeight + 1e-6 };
  CHECK_BOOL(model->IsSolid(below), true);
  CHECK_BOOL(model->IsSolid(above), false);

  // 1. Plane: force starts when the shell's lowest point reaches the plane.
  const double tolerance = 0.1 * scene.Spacing;
  const double onset = OnsetHeight(model, 0.7, -1.1, scene.PlaneHeight, scene.PlaneHeight + 2.0 * radius);
  std::cout << "plane: force starts " << (onset - (scene.PlaneHeight + radius)) / scene.Spacing << " voxel from the rendered surface"
            << std::endl;
  CHECK_BOOL(std::abs(onset - (scene.PlaneHeight + radius)) < tolerance, true);
  // Pressed 0.05 mm in: one point touches, pushing straight up with k * depth.
  double force[3];
  const double pressed[3] = { 0.7, -1.1, scene.PlaneHeight + radius - 0.05 };
  CHECK_INT(model->ComputeContactForce(pressed, force), 1);
  // The exit is found to 1/256 of a trace step (half a voxel).
  CHECK_DOUBLE_TOLERANCE(force[2], model->GetContactStiffness() * 0.05, model->GetContactStiffness() * scene.Spacing / 256.0);
  CHECK_DOUBLE_TOLERANCE(force[0], 0.0, 1e-9);
  CHECK_DOUBLE_TOLERANCE(force[1], 0.0, 1e-9);

  // 2. A hole of radius 1.25 mm cut down through the plane: the sphere above
  // it rests on the rim. Analytically, the centre's height at first contact
  // is the highest plane contact among the shell points outside the hole.
  const double axis[2] = { -0.4, 0.9 };
  const double holeRadius = 1.25;
  const double top[3] = { axis[0], axis[1], scene.PlaneHeight + 6.0 };
  const double bottom[3] = { axis[0], axis[1], scene.PlaneHeight - 6.0 };
  CHECK_BOOL(scene.Field->CutCapsule(top, bottom, holeRadius), true);
  CHECK_BOOL(model->Prepare(), true);
  double expected = -1e300;
  double closest = 1e300;
  vtkHapticPointShell* shell = model->GetPointShell();
  for (int n = 0; n < shell->GetNumberOfPoints(); ++n)
  {
    double offset[3];
    shell->GetPoint(n, offset);
    const double horizontal = std::hypot(offset[0], offset[1]);
    closest = std::min(closest, std::abs(horizontal - holeRadius));
    if (horizontal > holeRadius && offset[2] < 0.0)
    {
      expected = std::max(expected, scene.PlaneHeight - offset[2]);
    }
  }
  // No shell point lies so near the rim that the field's sub-voxel error could decide.
  CHECK_BOOL(closest > 0.01, true);
  const double holeOnset = OnsetHeight(model, axis[0], axis[1], bottom[2], scene.PlaneHeight + 2.0 * radius);
  std::cout << "hole: force starts " << (holeOnset - expected) / scene.Spacing << " voxel from the rendered rim (" << holeOnset - scene.PlaneHeight
            << " mm above the plane)" << std::endl;
  CHECK_BOOL(std::abs(holeOnset - expected) < tolerance, true);
  CHECK_BOOL(holeOnset < scene.PlaneHeight + radius - 0.1, true); // the sphere sinks into the hole

  // 3. Proxy: a hand pushed 1 mm below first contact; the proxy stays on the
  // surface, the hand feels the coupling spring (device limits applied).
  vtkNew<vtkHapticDeviceCapabilities> falcon;
  falcon->SetForceDegreesOfFreedom(3);
  falcon->SetMaximumForce(8.0);
  falcon->SetMaximumStiffness(3.0);
  falcon->SetMaximumDamping(0.02);
  model->SetDeviceLimits(falcon, 1.0);
  model->SetCouplingStiffness(1.0);
  CHECK_BOOL(model->Prepare(), true);
  const double free[3] = { 5.0, 5.0, scene.PlaneHeight + radius + 1.0 };
  model->Reset(free);
  double hand[3] = { 5.0, 5.0, scene.PlaneHeight + radius - 1.0 };
  for (int tick = 0; tick < 200; ++tick)
  {
    model->Step(hand, 1e-3, false);
  }
  double proxy[3];
  model->GetProxyPosition(proxy);
  model->GetForce(force);
  std::cout << "proxy rests " << proxy[2] - (scene.PlaneHeight + radius) << " mm from the surface, hand feels " << force[2] << " N" << std::endl;
  // Balance: coupling 1 N/mm * 1 mm against the contact: the proxy sinks 1/k_contact mm at most.
  CHECK_BOOL(proxy[2] < scene.PlaneHeight + radius && proxy[2] > scene.PlaneHeight + radius - 1.5 / model->GetContactStiffness(), true);
  CHECK_DOUBLE_TOLERANCE(force[2], proxy[2] - hand[2], 1e-3);
  CHECK_DOUBLE_TOLERANCE(proxy[0], 5.0, 1e-3);

  // 4. Limits: a hand 20 mm deep asks 20 N; the device gets its 8 N, never more.
  hand[2] = scene.PlaneHeight + radius - 20.0;
  for (int tick = 0; tick < 50; ++tick)
  {
    model->Step(hand, 1e-3, false);
  }
  model->GetForce(force);
  CHECK_DOUBLE_TOLERANCE(vtkMath::Norm(force), 8.0, 1e-9);
  CHECK_BOOL(force[2] > 7.9, true);
  // Stiffness above the device's is not applied.
  model->SetCouplingStiffness(50.0);
  CHECK_BOOL(model->Prepare(), true);
  CHECK_DOUBLE(model->GetAppliedCouplingStiffness(), 3.0);
  // The scene scaled 2x relative to the device: half the stiffness per scene mm.
  model->SetDeviceLimits(falcon, 2.0);
  CHECK_BOOL(model->Prepare(), true);
  CHECK_DOUBLE(model->GetAppliedCouplingStiffness(), 1.5);
  model->SetDeviceLimits(falcon, 1.0);
  model->SetCouplingStiffness(1.0);
  CHECK_BOOL(model->Prepare(), true);

  // 5. Bad input: a non-finite hand gives no force and keeps the proxy.
  model->Reset(free);
  model->Step(free, 1e-3, false);
  const double nan[3] = { std::nan(""), 0.0, 0.0 };
  model->Step(nan, 1e-3, true);
  model->GetForce(force);
  model->GetProxyPosition(proxy);
  CHECK_DOUBLE(force[0], 0.0);
  CHECK_DOUBLE(force[2], 0.0);
  CHECK_DOUBLE_TOLERANCE(proxy[2], free[2], 1e-12);
  CHECK_BOOL(model->GetLastStepCut(), false);

  // 6. Drilling: touching and pushed, the cut is made a bite ahead of the
  // proxy toward the hand: feed rate per newton of push times the step.
  hand[0] = 5.0;
  hand[1] = 5.0;
  hand[2] = scene.PlaneHeight + radius - 0.5;
  for (int tick = 0; tick < 100; ++tick)
  {
    model->Step(hand, 1e-3, false);
  }
  model->Step(hand, 1e-3, true);
  CHECK_BOOL(model->GetLastStepCut(), true);
  double cutAt[3];
  model->GetProxyPosition(proxy);
  model->GetCutPosition(cutAt);
  const double push = model->GetCouplingStiffness() * (proxy[2] - hand[2]);
  CHECK_DOUBLE_TOLERANCE(proxy[2] - cutAt[2], std::min(4.0 * push, 20.0) * 1e-3, 1e-9);
  // Out of contact, the drill runs and vibrates but cuts nothing; the
  // vibration stays below the device's rate and force.
  model->Reset(free);
  for (int tick = 0; tick < 10; ++tick)
  {
    model->Step(free, 1e-3, true);
  }
  CHECK_BOOL(model->GetLastStepCut(), false);
  CHECK_BOOL(model->GetVibration()->GetLastAmplitude() > 0.0, true);
  CHECK_BOOL(model->GetVibration()->GetLastFrequency() <= model->GetMaximumVibrationFrequency(), true);
  model->SetMaximumVibrationFrequency(50.0);
  model->Step(free, 1e-3, true);
  CHECK_DOUBLE(model->GetVibration()->GetLastFrequency(), 50.0);

  // 7. Guided drilling: in free space, 2 mm off a vertical guide the hand is
  // pulled back by the guide's stiffness (within the device's).
  const double guidePoint[3] = { 5.0, 5.0, 0.0 };
  const double guideDirection[3] = { 0.0, 0.0, 3.0 };
  CHECK_BOOL(model->SetGuideAxis(guidePoint, guideDirection), true);
  model->SetGuideStiffness(0.5);
  CHECK_BOOL(model->Prepare(), true);
  const double offAxis[3] = { 7.0, 5.0, scene.PlaneHeight + radius + 3.0 };
  model->Reset(offAxis);
  model->Step(offAxis, 1e-3, false);
  model->GetForce(force);
  CHECK_DOUBLE_TOLERANCE(force[0], -1.0, 1e-9);
  CHECK_DOUBLE_TOLERANCE(force[1], 0.0, 1e-9);
  CHECK_DOUBLE_TOLERANCE(force[2], 0.0, 1e-9);
  const double zero[3] = { 0.0, 0.0, 0.0 };
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(model->SetGuideAxis(guidePoint, zero), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(model->GetGuideEnabled(), true);
  model->RemoveGuide();

  // 8. An input-only device: no force, the proxy still keeps out of the bone.
  model->SetDeviceLimits(nullptr, 1.0);
  CHECK_BOOL(model->Prepare(), true);
  model->Reset(free);
  hand[2] = scene.PlaneHeight + radius - 1.0;
  for (int tick = 0; tick < 100; ++tick)
  {
    model->Step(hand, 1e-3, false);
  }
  model->GetForce(force);
  model->GetProxyPosition(proxy);
  CHECK_DOUBLE(vtkMath::Norm(force), 0.0);
  CHECK_BOOL(proxy[2] > scene.PlaneHeight + radius - 0.1, true);

  // 9. A cylinder burr (2.5 mm radius, 5 mm long, axis along z): its flat
  // tip meets the plane at half its length.
  vtkNew<vtkVolumeCutCylinderTool> cylinder;
  cylinder->SetRadius(2.5);
  cylinder->SetLength(5.0);
  model->SetTool(cylinder);
  CHECK_BOOL(model->Prepare(), true);
  const double cylinderOnset = OnsetHeight(model, 4.0, 4.0, scene.PlaneHeight, scene.PlaneHeight + 10.0);
  CHECK_BOOL(std::abs(cylinderOnset - (scene.PlaneHeight + 2.5)) < tolerance, true);
  model->SetTool(nullptr);
  CHECK_BOOL(model->Prepare(), true);

  // 10. The whole-voxel baseline sees the same plane, to within a voxel.
  vtkNew<vtkBinaryVoxelCutter> removed;
  const int dims[3] = { scene.Size, scene.Size, scene.Size };
  removed->Initialize(dims, scene.IJKToRAS);
  const double deep[3] = { 5.0, 5.0, scene.PlaneHeight + radius - scene.Spacing - 0.01 };
  const double clear[3] = { 5.0, 5.0, scene.PlaneHeight + radius + scene.Spacing + 0.01 };
  CHECK_BOOL(model->CountWholeVoxelContacts(deep, removed) > 0, true);
  CHECK_INT(model->CountWholeVoxelContacts(clear, removed), 0);

  // 11. A spherical cavity cut deep in the material: the burr pressed against
  // its wall meets the cut field, not the CT. Each immersed point's depth is
  // where its trace toward the centre leaves the material, analytically the
  // ray's exit into the cavity sphere; the force is their sum.
  model->SetSphereRadius(radius);
  CHECK_BOOL(model->Prepare(), true);
  const double cavity[3] = { 0.3, -0.4, scene.PlaneHeight - 7.0 };
  const double cavityRadius = 4.0;
  CHECK_BOOL(scene.Field->CutCapsule(cavity, cavity, cavityRadius), true);
  // Directions where no shell point lies within 0.02 mm of the wall.
  const double pushes[4][3] = { { -0.41, 1.59, 0.11 }, { 0.28, 1.61, -0.3 }, { 1.36, 0.61, 0.61 }, { 0.15, -1.61, -0.48 } };
  for (const auto& push : pushes)
  {
    const double center[3] = { cavity[0] + push[0], cavity[1] + push[1], cavity[2] + push[2] };
    double expectedForce[3] = { 0.0, 0.0, 0.0 };
    int expectedContacts = 0;
    double nearestToWall = 1e300;
    for (int n = 0; n < shell->GetNumberOfPoints(); ++n)
    {
      double offset[3];
      shell->GetPoint(n, offset);
      const double p[3] = { center[0] + offset[0], center[1] + offset[1], center[2] + offset[2] };
      const double fromCavity = std::sqrt(vtkMath::Distance2BetweenPoints(p, cavity));
      nearestToWall = std::min(nearestToWall, std::abs(fromCavity - cavityRadius));
      if (fromCavity <= cavityRadius)
      {
        continue;
      }
      // |p + t u - c| = R, the smaller root: where the trace enters the cavity.
      const double length = vtkMath::Norm(offset);
      const double u[3] = { -offset[0] / length, -offset[1] / length, -offset[2] / length };
      const double w[3] = { p[0] - cavity[0], p[1] - cavity[1], p[2] - cavity[2] };
      const double b = vtkMath::Dot(w, u);
      const double c = vtkMath::Dot(w, w) - cavityRadius * cavityRadius;
      const double depth = std::min(-b - std::sqrt(b * b - c), length);
      for (int axis = 0; axis < 3; ++axis)
      {
        expectedForce[axis] += model->GetContactStiffness() * depth * u[axis];
      }
      ++expectedContacts;
    }
    CHECK_BOOL(nearestToWall > 0.01, true);
    double cavityForce[3];
    CHECK_INT(model->ComputeContactForce(center, cavityForce), expectedContacts);
    // The cut field's reconstruction of the sphere (0.25 mm samples) is good
    // to a few micrometres; 0.005 mm per contact is 0.01 voxel.
    const double forceTolerance = model->GetContactStiffness() * 0.005 * expectedContacts;
    std::cout << "cavity wall: " << expectedContacts << " contacts, force (" << cavityForce[0] << ", " << cavityForce[1] << ", "
              << cavityForce[2] << ") N, analytic (" << expectedForce[0] << ", " << expectedForce[1] << ", " << expectedForce[2] << ")"
              << std::endl;
    CHECK_BOOL(expectedContacts > 0, true);
    for (int axis = 0; axis < 3; ++axis)
    {
      CHECK_DOUBLE_TOLERANCE(cavityForce[axis], expectedForce[axis], forceTolerance);
    }
  }

  // 12. The burr at the end of the bore it drilled, the hand 2 mm beyond it
  // in the bone: where each tick starts while drilling, the last bite
  // having freed the front. The proxy stops where the material begins
  // instead of stepping into it, and rests on the bore's end within a few
  // contact tests: analytically, a drop delta below the end's centre where
  // the front points' push, ContactStiffness * delta * sum(cos^2), balances
  // the coupling's CouplingStiffness * (2 - delta).
  const double boreEnd[3] = { 7.0, 6.5, scene.PlaneHeight - 3.0 };
  const double boreTop[3] = { boreEnd[0], boreEnd[1], scene.PlaneHeight + 5.0 };
  CHECK_BOOL(scene.Field->CutCapsule(boreTop, boreEnd, radius), true);
  CHECK_BOOL(model->Prepare(), true);
  double frontShare = 0.0;
  for (int n = 0; n < shell->GetNumberOfPoints(); ++n)
  {
    double offset[3];
    shell->GetPoint(n, offset);
    if (offset[2] < 0.0)
    {
      frontShare += offset[2] * offset[2] / vtkMath::Dot(offset, offset);
    }
  }
  const double coupling = model->GetCouplingStiffness();
  const double drop = 2.0 * coupling / (model->GetContactStiffness() * frontShare + coupling);
  const double behind[3] = { boreEnd[0], boreEnd[1], boreEnd[2] + 0.3 };
  model->Reset(behind);
  const double beyond[3] = { boreEnd[0], boreEnd[1], boreEnd[2] - 2.0 };
  model->Step(beyond, 1e-3, false);
  model->GetProxyPosition(proxy);
  std::cout << "bore end: proxy " << proxy[2] - boreEnd[2] << " mm from the end's centre (analytic " << -drop << ") after "
            << model->GetNumberOfProxySteps() << " contact tests, " << model->GetNumberOfContacts() << " contacts" << std::endl;
  CHECK_BOOL(model->GetNumberOfProxySteps() <= 4, true);
  CHECK_DOUBLE_TOLERANCE(proxy[2], boreEnd[2] - drop, 0.01);
  CHECK_DOUBLE_TOLERANCE(proxy[0], boreEnd[0], 0.005);
  CHECK_DOUBLE_TOLERANCE(proxy[1], boreEnd[1], 0.005);

  // Missing inputs are refused with a reason.
  vtkNew<vtkHapticForceModel> empty;
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(empty->Prepare(), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();

  model->Print(std::cout);
  return EXIT_SUCCESS;
}
