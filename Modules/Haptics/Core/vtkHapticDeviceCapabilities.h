// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticDeviceCapabilities
 * @brief   What a haptic or 3D input device can sense and render, as data.
 *
 * As CHAI3D keeps a device's specification (src/devices/CGenericHapticDevice.h),
 * every device describes itself with these figures instead of the product
 * branching on the kind of device: the force model limits its stiffness,
 * damping, force and vibration to them, the loop knows whether there is a
 * force to send at all. Units follow the product's (millimetres, newtons,
 * seconds): a stiffness of 3000 N/m is 3 N/mm.
 *
 * @sa vtkHapticDevice
 */

#ifndef vtkHapticDeviceCapabilities_h
#define vtkHapticDeviceCapabilities_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <string> // For the names

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticDeviceCapabilities : public vtkObject
{
public:
  static vtkHapticDeviceCapabilities* New();
  vtkTypeMacro(vtkHapticDeviceCapabilities, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the device's model and manufacturer, for lists and logs.
   * Defaults are empty.
   */
  void SetModelName(const char* name) { this->ModelName = name ? name : ""; }
  const char* GetModelName() const { return this->ModelName.c_str(); }
  void SetManufacturer(const char* name) { this->Manufacturer = name ? name : ""; }
  const char* GetManufacturer() const { return this->Manufacturer.c_str(); }
  ///@}

  ///@{
  /**
   * Set/get the degrees of freedom the device senses (3: position; 6:
   * position and orientation; 0: buttons only, as a foot switch) and those
   * it renders forces in (0 for input-only devices). Defaults are 0.
   */
  vtkSetClampMacro(InputDegreesOfFreedom, int, 0, 7);
  vtkGetMacro(InputDegreesOfFreedom, int);
  vtkSetClampMacro(ForceDegreesOfFreedom, int, 0, 7);
  vtkGetMacro(ForceDegreesOfFreedom, int);
  ///@}

  ///@{
  /**
   * Set/get the radius (mm) of the sphere, about the workspace centre, that
   * the handle can reach; 0 where the device reports rates or has no
   * workspace. Default is 0.
   */
  vtkSetClampMacro(WorkspaceRadius, double, 0.0, 1.0e4);
  vtkGetMacro(WorkspaceRadius, double);
  ///@}

  ///@{
  /**
   * Set/get the largest continuous force (N), stiffness (N/mm) and damping
   * (N s/mm) the device renders stably. Forces above the maximum are clamped
   * by vtkHapticDevice::SetForce; the force model keeps its stiffness and
   * damping below the others. Defaults are 0 (no force output).
   */
  vtkSetClampMacro(MaximumForce, double, 0.0, 1.0e3);
  vtkGetMacro(MaximumForce, double);
  vtkSetClampMacro(MaximumStiffness, double, 0.0, 1.0e3);
  vtkGetMacro(MaximumStiffness, double);
  vtkSetClampMacro(MaximumDamping, double, 0.0, 1.0e2);
  vtkGetMacro(MaximumDamping, double);
  ///@}

  ///@{
  /**
   * Set/get the number of buttons (grip buttons, pedals). Default is 0.
   */
  vtkSetClampMacro(NumberOfButtons, int, 0, 32);
  vtkGetMacro(NumberOfButtons, int);
  ///@}

  ///@{
  /**
   * Set/get the rate (Hz) at which the device exchanges samples and forces:
   * vibration above half of it cannot be rendered. Default is 1000.
   */
  vtkSetClampMacro(UpdateRate, double, 1.0, 1.0e5);
  vtkGetMacro(UpdateRate, double);
  ///@}

  /// Whether the device senses orientation (six or more input degrees of freedom).
  bool GetSensesRotation() const { return this->InputDegreesOfFreedom >= 6; }

  /// Whether the device renders forces.
  bool GetRendersForce() const { return this->ForceDegreesOfFreedom > 0 && this->MaximumForce > 0.0; }

  void DeepCopy(vtkHapticDeviceCapabilities* source);

protected:
  vtkHapticDeviceCapabilities() = default;
  ~vtkHapticDeviceCapabilities() override = default;

  std::string ModelName;
  std::string Manufacturer;
  int InputDegreesOfFreedom = 0;
  int ForceDegreesOfFreedom = 0;
  double WorkspaceRadius = 0.0;
  double MaximumForce = 0.0;
  double MaximumStiffness = 0.0;
  double MaximumDamping = 0.0;
  int NumberOfButtons = 0;
  double UpdateRate = 1000.0;

private:
  vtkHapticDeviceCapabilities(const vtkHapticDeviceCapabilities&) = delete;
  void operator=(const vtkHapticDeviceCapabilities&) = delete;
};

#endif
