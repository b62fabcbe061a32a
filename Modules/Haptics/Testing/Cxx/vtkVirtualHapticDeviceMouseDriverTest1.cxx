// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The mouse drives the virtual device in a real offscreen view: events go
// through the interactor as a desktop view's would (SetEventInformation +
// InvokeEvent), past the trackball-camera style. The handle follows the
// cursor at constant depth (checked against the perspective camera's
// analytic projection), the wheel moves it along the view direction, the
// left button runs the drill without turning the camera, Shift gives the
// mouse back to the camera, the workspace bounds it, a disabled or
// destroyed driver leaves the camera interaction as it was.
#include "vtkHapticDeviceCapabilities.h"
#include "vtkVirtualHapticDevice.h"
#include "vtkVirtualHapticDeviceMouseDriver.h"

#include <vtkAddonTestingMacros.h>

#include <vtkAutoInit.h>
#include <vtkCamera.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

#include <cmath>
#include <iostream>
#include <limits>

// The window is made by the OpenGL module's factory.
VTK_MODULE_INIT(vtkRenderingOpenGL2);

namespace
{
constexpr int Size = 200;
// Scene mm per device mm, and where the workspace centre is in the scene.
constexpr double Scale = 2.0;
const double Centre[3] = { 10.0, 0.0, 0.0 };

void Event(vtkRenderWindowInteractor* interactor, unsigned long event, int x, int y, bool shift = false)
{
  interactor->SetEventInformation(x, y, 0, shift ? 1 : 0);
  interactor->InvokeEvent(event, nullptr);
}

/// The scene point under display pixel (x, y) on the plane z = depth, for
/// the camera at (0, 0, 100) looking down -z with a 30 degree view angle in
/// a square window (VTK maps display x to view x = 2 x / width - 1).
void ExpectedWorld(int x, int y, double depth, double world[3])
{
  const double halfHeight = (100.0 - depth) * std::tan(vtkMath::RadiansFromDegrees(15.0));
  world[0] = (2.0 * x / Size - 1.0) * halfHeight;
  world[1] = (2.0 * y / Size - 1.0) * halfHeight;
  world[2] = depth;
}

void WorldToDevice(const double world[3], double device[3])
{
  for (int axis = 0; axis < 3; ++axis)
  {
    device[axis] = (world[axis] - Centre[axis]) / Scale;
  }
}

bool SamePoint(const double actual[3], const double expected[3], double tolerance, const char* what)
{
  if (std::sqrt(vtkMath::Distance2BetweenPoints(actual, expected)) <= tolerance)
  {
    return true;
  }
  std::cerr << what << ": (" << actual[0] << ", " << actual[1] << ", " << actual[2] << "), expected (" << expected[0] << ", "
            << expected[1] << ", " << expected[2] << ")" << std::endl;
  return false;
}

void ResetCamera(vtkCamera* camera)
{
  camera->SetPosition(0.0, 0.0, 100.0);
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  camera->SetViewUp(0.0, 1.0, 0.0);
  camera->SetViewAngle(30.0);
  camera->SetClippingRange(1.0, 1000.0);
}

/// A left-button drag across the view; true if the camera moved.
bool DragTurnsCamera(vtkRenderWindowInteractor* interactor, vtkCamera* camera, bool shift)
{
  double before[3];
  camera->GetPosition(before);
  Event(interactor, vtkCommand::MouseMoveEvent, 100, 100, shift);
  Event(interactor, vtkCommand::LeftButtonPressEvent, 100, 100, shift);
  Event(interactor, vtkCommand::MouseMoveEvent, 140, 110, shift);
  Event(interactor, vtkCommand::MouseMoveEvent, 170, 120, shift);
  Event(interactor, vtkCommand::LeftButtonReleaseEvent, 170, 120, shift);
  double after[3];
  camera->GetPosition(after);
  return std::sqrt(vtkMath::Distance2BetweenPoints(before, after)) > 1.0;
}
}

int vtkVirtualHapticDeviceMouseDriverTest1(int, char*[])
{
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(Size, Size);
  window->AddRenderer(renderer);
  vtkNew<vtkGenericRenderWindowInteractor> interactor;
  interactor->SetRenderWindow(window);
  vtkNew<vtkInteractorStyleTrackballCamera> style;
  interactor->SetInteractorStyle(style);
  vtkCamera* camera = renderer->GetActiveCamera();
  ResetCamera(camera);
  window->Render();

  vtkNew<vtkVirtualHapticDevice> device;
  CHECK_BOOL(device->Open(), true);
  vtkNew<vtkVirtualHapticDeviceMouseDriver> driver;
  vtkNew<vtkMatrix4x4> worldToDevice;
  for (int axis = 0; axis < 3; ++axis)
  {
    worldToDevice->SetElement(axis, axis, 1.0 / Scale);
    worldToDevice->SetElement(axis, 3, -Centre[axis] / Scale);
  }
  CHECK_BOOL(driver->SetWorldToDevice(worldToDevice), true);

  // Nothing to drive yet: refused, still disabled.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  driver->SetEnabled(1);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_INT(driver->GetEnabled(), 0);
  driver->SetInteractor(interactor);
  driver->SetDefaultRenderer(renderer);
  driver->SetDevice(device);
  driver->SetWheelStep(4.0);
  driver->SetEnabled(1);
  CHECK_INT(driver->GetEnabled(), 1);

  // The handle starts at the workspace centre, (10, 0, 0) in the scene, on
  // the plane z = 0 facing the camera; it follows the cursor on that plane.
  // The expectation is the camera's analytic projection: what separates the
  // two is double round-off through the view matrices, far below 1e-6 mm.
  const double tolerance = 1e-6;
  double world[3];
  double expected[3];
  double position[3];
  Event(interactor, vtkCommand::MouseMoveEvent, 150, 100);
  ExpectedWorld(150, 100, 0.0, world);
  WorldToDevice(world, expected);
  CHECK_BOOL(device->GetLatestPosition(position), true);
  CHECK_BOOL(SamePoint(position, expected, tolerance, "handle under the cursor"), true);
  CHECK_INT(static_cast<int>(device->GetLatestButtons()), 0);

  // Two wheel notches forward: 8 scene mm away from the viewer (-z); the
  // cursor then moves the handle on the plane z = -8.
  Event(interactor, vtkCommand::MouseWheelForwardEvent, 150, 100);
  Event(interactor, vtkCommand::MouseWheelForwardEvent, 150, 100);
  world[2] = -8.0;
  WorldToDevice(world, expected);
  device->GetLatestPosition(position);
  CHECK_BOOL(SamePoint(position, expected, tolerance, "handle after the wheel"), true);
  Event(interactor, vtkCommand::MouseMoveEvent, 60, 170);
  ExpectedWorld(60, 170, -8.0, world);
  WorldToDevice(world, expected);
  device->GetLatestPosition(position);
  CHECK_BOOL(SamePoint(position, expected, tolerance, "handle at the new depth"), true);
  Event(interactor, vtkCommand::MouseWheelBackwardEvent, 60, 170);
  world[2] = -4.0;
  WorldToDevice(world, expected);
  device->GetLatestPosition(position);
  CHECK_BOOL(SamePoint(position, expected, tolerance, "handle after the wheel back"), true);
  // The wheel was the driver's: the camera did not zoom.
  double cameraPosition[3];
  camera->GetPosition(cameraPosition);
  CHECK_DOUBLE_TOLERANCE(cameraPosition[2], 100.0, 1e-12);

  // The left button runs the drill while it is down, the camera stays.
  Event(interactor, vtkCommand::LeftButtonPressEvent, 60, 170);
  CHECK_INT(static_cast<int>(device->GetLatestButtons()), 1);
  CHECK_BOOL(driver->GetDrilling(), true);
  Event(interactor, vtkCommand::MouseMoveEvent, 120, 130);
  CHECK_INT(static_cast<int>(device->GetLatestButtons()), 1);
  ExpectedWorld(120, 130, -4.0, world);
  WorldToDevice(world, expected);
  device->GetLatestPosition(position);
  CHECK_BOOL(SamePoint(position, expected, tolerance, "handle while drilling"), true);
  Event(interactor, vtkCommand::LeftButtonReleaseEvent, 120, 130);
  CHECK_INT(static_cast<int>(device->GetLatestButtons()), 0);
  camera->GetPosition(cameraPosition);
  CHECK_DOUBLE_TOLERANCE(cameraPosition[0], 0.0, 1e-12);
  CHECK_DOUBLE_TOLERANCE(cameraPosition[1], 0.0, 1e-12);
  CHECK_DOUBLE_TOLERANCE(cameraPosition[2], 100.0, 1e-12);

  // Shift gives the left drag to the camera; the handle stays and does not drill.
  device->GetLatestPosition(expected);
  const unsigned long long samples = device->GetNumberOfSamples();
  CHECK_BOOL(DragTurnsCamera(interactor, camera, true), true);
  CHECK_INT(static_cast<int>(device->GetNumberOfSamples() - samples), 0);
  device->GetLatestPosition(position);
  CHECK_BOOL(SamePoint(position, expected, 0.0, "handle during a camera drag"), true);
  ResetCamera(camera);

  // The workspace (40 mm about its centre) bounds the handle: 20 notches of
  // 4 scene mm towards the viewer ask for z = 76 (33 device mm from the
  // centre's plane, and 40 away from the centre in x).
  Event(interactor, vtkCommand::MouseMoveEvent, 0, 100);
  for (int notch = 0; notch < 20; ++notch)
  {
    Event(interactor, vtkCommand::MouseWheelBackwardEvent, 0, 100);
  }
  device->GetLatestPosition(position);
  CHECK_BOOL(driver->GetNumberOfClampedPositions() > 0, true);
  CHECK_DOUBLE_TOLERANCE(vtkMath::Norm(position), device->GetCapabilities()->GetWorkspaceRadius(), 1e-9);
  // A view that gives no point (a degenerate camera) sends nothing, never NaN.
  camera->SetClippingRange(0.0, 0.0);
  const unsigned long long beforeDegenerate = device->GetNumberOfSamples();
  Event(interactor, vtkCommand::MouseMoveEvent, 30, 30);
  CHECK_BOOL(device->GetLatestPosition(position), true);
  CHECK_BOOL(std::isfinite(position[0]) && std::isfinite(position[1]) && std::isfinite(position[2]), true);
  CHECK_INT(static_cast<int>(device->GetNumberOfRejectedInputs()), 0);
  CHECK_BOOL(device->GetNumberOfSamples() - beforeDegenerate <= 1, true);
  ResetCamera(camera);

  // A bad matrix is refused and the previous one kept.
  vtkNew<vtkMatrix4x4> bad;
  bad->SetElement(0, 0, std::numeric_limits<double>::quiet_NaN());
  vtkNew<vtkMatrix4x4> singular;
  singular->SetElement(2, 2, 0.0);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(driver->SetWorldToDevice(bad), false);
  CHECK_BOOL(driver->SetWorldToDevice(singular), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  vtkNew<vtkMatrix4x4> kept;
  driver->GetWorldToDevice(kept);
  CHECK_DOUBLE(kept->GetElement(0, 0), 1.0 / Scale);

  // Disabled while drilling: the drill stops; the camera turns again and the device hears nothing.
  Event(interactor, vtkCommand::LeftButtonPressEvent, 100, 100);
  CHECK_INT(static_cast<int>(device->GetLatestButtons()), 1);
  driver->SetEnabled(0);
  CHECK_INT(static_cast<int>(device->GetLatestButtons()), 0);
  const unsigned long long disabledSamples = device->GetNumberOfSamples();
  CHECK_BOOL(DragTurnsCamera(interactor, camera, false), true);
  Event(interactor, vtkCommand::MouseWheelForwardEvent, 100, 100);
  CHECK_INT(static_cast<int>(device->GetNumberOfSamples() - disabledSamples), 0);
  ResetCamera(camera);

  // A driver destroyed while enabled leaves no observer behind (the events
  // below would reach a deleted object) and the camera its mouse.
  {
    vtkNew<vtkVirtualHapticDeviceMouseDriver> shortLived;
    shortLived->SetInteractor(interactor);
    shortLived->SetDefaultRenderer(renderer);
    shortLived->SetDevice(device);
    shortLived->SetEnabled(1);
    CHECK_BOOL(DragTurnsCamera(interactor, camera, false), false);
  }
  ResetCamera(camera);
  const unsigned long long afterSamples = device->GetNumberOfSamples();
  CHECK_BOOL(DragTurnsCamera(interactor, camera, false), true);
  CHECK_INT(static_cast<int>(device->GetNumberOfSamples() - afterSamples), 0);

  driver->Print(std::cout);
  return EXIT_SUCCESS;
}
