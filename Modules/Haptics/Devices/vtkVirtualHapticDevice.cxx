// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVirtualHapticDevice.h"
#include "vtkHapticDeviceCapabilities.h"

#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"

#include <algorithm>

vtkStandardNewMacro(vtkVirtualHapticDevice);

//------------------------------------------------------------------------------
vtkVirtualHapticDevice::vtkVirtualHapticDevice()
{
  vtkHapticDeviceCapabilities* capabilities = this->Capabilities;
  capabilities->SetModelName("Virtual device");
  capabilities->SetManufacturer("VolumeCutting");
  capabilities->SetInputDegreesOfFreedom(6);
  capabilities->SetForceDegreesOfFreedom(3);
  // What it stands in for: the Novint Falcon's figures (CHAI3D).
  capabilities->SetWorkspaceRadius(40.0);
  capabilities->SetMaximumForce(8.0);
  capabilities->SetMaximumStiffness(3.0);
  capabilities->SetMaximumDamping(0.02);
  capabilities->SetNumberOfButtons(4);
  capabilities->SetUpdateRate(1000.0);
}

//------------------------------------------------------------------------------
vtkVirtualHapticDevice::~vtkVirtualHapticDevice()
{
  this->Close();
}

//------------------------------------------------------------------------------
bool vtkVirtualHapticDevice::OpenDevice()
{
  if (!this->GetPlugged())
  {
    this->SetErrorMessage("the virtual device is unplugged (SetPlugged(true) plugs it back)");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDevice::CloseDevice() {}

//------------------------------------------------------------------------------
void vtkVirtualHapticDevice::SetPlugged(bool plugged)
{
  this->Plugged.store(plugged, std::memory_order_release);
  if (!plugged)
  {
    this->ReportLost("the virtual device was unplugged");
  }
}

//------------------------------------------------------------------------------
bool vtkVirtualHapticDevice::SetPose(const double position[3], unsigned int buttons)
{
  return this->SetPoseAndOrientation(position, this->Orientation, buttons);
}

//------------------------------------------------------------------------------
bool vtkVirtualHapticDevice::SetPoseAndOrientation(const double position[3], const double orientation[4], unsigned int buttons)
{
  // Connected alone is not enough: a reconnection attempt says Connected
  // while it opens (so that a loss reported at once is kept), and a pose
  // taken in that instant from an unplugged device would show the loop a
  // device that came back and went again.
  if (!this->IsConnected() || !this->GetPlugged())
  {
    return false;
  }
  std::copy(orientation, orientation + 4, this->Orientation);
  this->PublishSample(position, orientation, buttons);
  return true;
}

//------------------------------------------------------------------------------
bool vtkVirtualHapticDevice::SetPoseMatrix(vtkMatrix4x4* pose, unsigned int buttons)
{
  if (!pose)
  {
    return false;
  }
  double rotation[3][3];
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      rotation[row][column] = pose->GetElement(row, column);
    }
  }
  double orientation[4];
  vtkMath::Matrix3x3ToQuaternion(rotation, orientation);
  const double position[3] = { pose->GetElement(0, 3), pose->GetElement(1, 3), pose->GetElement(2, 3) };
  return this->SetPoseAndOrientation(position, orientation, buttons);
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDevice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Plugged: " << (this->GetPlugged() ? "yes" : "no") << "\n";
}
