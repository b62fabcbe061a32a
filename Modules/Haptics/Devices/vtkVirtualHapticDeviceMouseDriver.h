// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVirtualHapticDeviceMouseDriver
 * @brief   The mouse in a 3D view moves a vtkVirtualHapticDevice.
 *
 * An interactor observer (as VTK's widgets are) on a view's
 * vtkRenderWindowInteractor and renderer that turns the mouse into the
 * virtual device's handle, for drilling without a haptic device:
 * - moving the mouse puts the handle under the cursor on the plane through
 *   the handle's current position that faces the camera, so the tool
 *   follows the cursor at constant depth;
 * - the wheel moves the handle along the view direction by WheelStep
 *   (forward: away from the viewer, into the bone);
 * - the left button runs the drill (DrillButtons while it is down).
 * Scene positions are mapped to the device frame by WorldToDevice (for a
 * vtkSlicerVolumeCuttingHapticSession, the inverse of its loop's
 * DeviceToRAS) and kept inside the device's workspace sphere; a position
 * that is not finite is never sent.
 *
 * The driver observes with a priority above the interactor style's and
 * aborts only the events it uses (left button, wheel): the right and middle
 * buttons still zoom and pan (while the style drags it holds the
 * interactor's focus, so the handle stays). With Shift held the left button
 * and the wheel go to the interactor style (the camera turns, pans, zooms)
 * and the handle stays where it is. Disabled, it observes nothing.
 *
 * @sa vtkVirtualHapticDevice vtkHapticLoop vtkInteractorObserver
 */

#ifndef vtkVirtualHapticDeviceMouseDriver_h
#define vtkVirtualHapticDeviceMouseDriver_h

#include "vtkInteractorObserver.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include "vtkNew.h"          // For the matrices
#include "vtkSmartPointer.h" // For the device

class vtkMatrix4x4;
class vtkVirtualHapticDevice;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkVirtualHapticDeviceMouseDriver : public vtkInteractorObserver
{
public:
  static vtkVirtualHapticDeviceMouseDriver* New();
  vtkTypeMacro(vtkVirtualHapticDeviceMouseDriver, vtkInteractorObserver);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The device the mouse moves (not opened here; poses are ignored while it is not connected).
  void SetDevice(vtkVirtualHapticDevice* device);
  vtkVirtualHapticDevice* GetDevice();

  /**
   * Observe the interactor (set with SetInteractor) and the renderer (the
   * DefaultRenderer, or the one under the cursor when enabling), or stop.
   * Enabling without an interactor, a renderer or a device fails with an
   * error and leaves the driver disabled. The handle starts from the
   * device's latest position (the workspace centre if it has none).
   */
  void SetEnabled(int enabling) override;

  /**
   * Set/get the scene-to-device-frame matrix: a rotation, a uniform scale
   * and a translation. A singular or non-finite matrix is refused (false,
   * with an error). Default is the identity.
   */
  bool SetWorldToDevice(vtkMatrix4x4* worldToDevice);
  void GetWorldToDevice(vtkMatrix4x4* worldToDevice);

  ///@{
  /**
   * Set/get how far (scene mm) one wheel notch moves the handle along the
   * view direction. Default is 0.5.
   */
  vtkSetClampMacro(WheelStep, double, 0.0, 100.0);
  vtkGetMacro(WheelStep, double);
  ///@}

  ///@{
  /**
   * Set/get the device buttons (a bit mask) pressed while the left mouse
   * button is down. Default is 1 (the haptic loop's default drill button).
   */
  vtkSetMacro(DrillButtons, unsigned int);
  vtkGetMacro(DrillButtons, unsigned int);
  ///@}

  /// The handle's position last sent (mm, device frame).
  void GetPosition(double position[3]);

  /// Whether the drill buttons are down.
  bool GetDrilling() const { return this->Drilling; }

  /// How many positions were pulled back into the workspace since created.
  vtkGetMacro(NumberOfClampedPositions, unsigned long long);

protected:
  vtkVirtualHapticDeviceMouseDriver();
  ~vtkVirtualHapticDeviceMouseDriver() override;

  static void ProcessEvents(vtkObject* object, unsigned long event, void* clientData, void* callData);

  /// The handle under the cursor at constant depth; false if the view gives no such point.
  bool PositionUnderCursor(double position[3]);
  /// The handle moved along the view direction by distance (scene mm).
  bool PositionAlongView(double distance, double position[3]);
  /// Clamp to the workspace, send, remember.
  void Send(const double position[3]);

  vtkSmartPointer<vtkVirtualHapticDevice> Device;
  vtkNew<vtkMatrix4x4> WorldToDevice;
  vtkNew<vtkMatrix4x4> DeviceToWorld;
  double WheelStep = 0.5;
  unsigned int DrillButtons = 1u;
  double Position[3] = { 0.0, 0.0, 0.0 };
  bool Drilling = false;
  unsigned long long NumberOfClampedPositions = 0;

private:
  vtkVirtualHapticDeviceMouseDriver(const vtkVirtualHapticDeviceMouseDriver&) = delete;
  void operator=(const vtkVirtualHapticDeviceMouseDriver&) = delete;
};

#endif
