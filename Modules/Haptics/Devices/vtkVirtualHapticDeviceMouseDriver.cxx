// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVirtualHapticDeviceMouseDriver.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkVirtualHapticDevice.h"

#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVirtualHapticDeviceMouseDriver);

namespace
{
bool IsFinite(const double point[3])
{
  return std::isfinite(point[0]) && std::isfinite(point[1]) && std::isfinite(point[2]);
}

void TransformPoint(vtkMatrix4x4* matrix, const double in[3], double out[3])
{
  const double homogeneous[4] = { in[0], in[1], in[2], 1.0 };
  double result[4];
  matrix->MultiplyPoint(homogeneous, result);
  for (int axis = 0; axis < 3; ++axis)
  {
    out[axis] = result[axis] / result[3];
  }
}
}

//------------------------------------------------------------------------------
vtkVirtualHapticDeviceMouseDriver::vtkVirtualHapticDeviceMouseDriver()
{
  this->EventCallbackCommand->SetCallback(vtkVirtualHapticDeviceMouseDriver::ProcessEvents);
  // Above the interactor style (0), as VTK's widgets: the events used are aborted before it sees them.
  this->Priority = 0.5f;
  // Enabled by the application only, not by a key press in the view.
  this->KeyPressActivation = 0;
}

//------------------------------------------------------------------------------
vtkVirtualHapticDeviceMouseDriver::~vtkVirtualHapticDeviceMouseDriver()
{
  // The base class's destructor cannot reach this class's SetEnabled.
  this->SetEnabled(0);
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDeviceMouseDriver::SetDevice(vtkVirtualHapticDevice* device)
{
  if (this->Device != device)
  {
    this->Device = device;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkVirtualHapticDevice* vtkVirtualHapticDeviceMouseDriver::GetDevice()
{
  return this->Device;
}

//------------------------------------------------------------------------------
bool vtkVirtualHapticDeviceMouseDriver::SetWorldToDevice(vtkMatrix4x4* worldToDevice)
{
  if (!worldToDevice)
  {
    vtkErrorMacro("SetWorldToDevice: no matrix given");
    return false;
  }
  for (int element = 0; element < 16; ++element)
  {
    if (!std::isfinite(worldToDevice->GetData()[element]))
    {
      vtkErrorMacro("SetWorldToDevice: the matrix has a non-finite element; the previous one is kept");
      return false;
    }
  }
  const double determinant = worldToDevice->Determinant();
  if (!(std::abs(determinant) > 1e-12))
  {
    vtkErrorMacro("SetWorldToDevice: the matrix is singular (determinant " << determinant << "); the previous one is kept");
    return false;
  }
  this->WorldToDevice->DeepCopy(worldToDevice);
  vtkMatrix4x4::Invert(this->WorldToDevice, this->DeviceToWorld);
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDeviceMouseDriver::GetWorldToDevice(vtkMatrix4x4* worldToDevice)
{
  if (worldToDevice)
  {
    worldToDevice->DeepCopy(this->WorldToDevice);
  }
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDeviceMouseDriver::GetPosition(double position[3])
{
  std::copy(this->Position, this->Position + 3, position);
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDeviceMouseDriver::SetEnabled(int enabling)
{
  if (enabling && !this->Enabled)
  {
    if (!this->Interactor || !this->Device)
    {
      vtkErrorMacro("SetEnabled: " << (this->Interactor ? "no virtual device" : "no interactor")
                                   << " to drive; set it before enabling the mouse driver");
      return;
    }
    const int* cursor = this->Interactor->GetLastEventPosition();
    this->SetCurrentRenderer(this->Interactor->FindPokedRenderer(cursor[0], cursor[1]));
    if (!this->CurrentRenderer)
    {
      vtkErrorMacro("SetEnabled: the interactor's window has no renderer; set DefaultRenderer to the 3D view's");
      return;
    }
    if (!this->Device->GetLatestPosition(this->Position))
    {
      std::fill(this->Position, this->Position + 3, 0.0);
    }
    this->Drilling = false;
    for (unsigned long event : { vtkCommand::MouseMoveEvent, vtkCommand::LeftButtonPressEvent, vtkCommand::LeftButtonReleaseEvent,
           vtkCommand::MouseWheelForwardEvent, vtkCommand::MouseWheelBackwardEvent })
    {
      this->Interactor->AddObserver(event, this->EventCallbackCommand, this->Priority);
    }
    this->Enabled = 1;
    this->InvokeEvent(vtkCommand::EnableEvent, nullptr);
  }
  else if (!enabling && this->Enabled)
  {
    if (this->Interactor)
    {
      this->Interactor->RemoveObserver(this->EventCallbackCommand);
    }
    if (this->Drilling)
    {
      // The drill does not keep running after the mouse stopped driving it.
      this->Drilling = false;
      this->Send(this->Position);
    }
    this->Enabled = 0;
    this->SetCurrentRenderer(nullptr);
    this->InvokeEvent(vtkCommand::DisableEvent, nullptr);
  }
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDeviceMouseDriver::ProcessEvents(vtkObject*, unsigned long event, void* clientData, void*)
{
  auto* self = static_cast<vtkVirtualHapticDeviceMouseDriver*>(clientData);
  vtkRenderWindowInteractor* interactor = self->Interactor;
  if (!interactor || !self->Device || !self->CurrentRenderer)
  {
    return;
  }
  const bool camera = interactor->GetShiftKey() != 0;
  double position[3];
  switch (event)
  {
    case vtkCommand::MouseMoveEvent:
      // Not aborted, and nothing to hold back during a camera drag: VTK's
      // interactor styles grab the interactor's focus while they turn, pan
      // or zoom, and then only they hear the mouse.
      if (!camera && self->PositionUnderCursor(position))
      {
        self->Send(position);
      }
      break;
    case vtkCommand::LeftButtonPressEvent:
      if (camera)
      {
        break;
      }
      self->Drilling = true;
      self->Send(self->Position);
      self->EventCallbackCommand->SetAbortFlag(1);
      break;
    case vtkCommand::LeftButtonReleaseEvent:
      if (self->Drilling)
      {
        self->Drilling = false;
        self->Send(self->Position);
        self->EventCallbackCommand->SetAbortFlag(1);
      }
      break;
    case vtkCommand::MouseWheelForwardEvent:
    case vtkCommand::MouseWheelBackwardEvent:
      if (camera)
      {
        break;
      }
      if (self->PositionAlongView(event == vtkCommand::MouseWheelForwardEvent ? self->WheelStep : -self->WheelStep, position))
      {
        self->Send(position);
      }
      self->EventCallbackCommand->SetAbortFlag(1);
      break;
    default:
      break;
  }
}

//------------------------------------------------------------------------------
bool vtkVirtualHapticDeviceMouseDriver::PositionUnderCursor(double position[3])
{
  vtkRenderer* renderer = this->CurrentRenderer;
  vtkCamera* camera = renderer->GetActiveCamera();
  double handle[3];
  TransformPoint(this->DeviceToWorld, this->Position, handle);
  double normal[3];
  camera->GetDirectionOfProjection(normal);
  // The ray under the cursor, from the near to the far clipping plane (perspective or parallel).
  const int* cursor = this->Interactor->GetEventPosition();
  double nearPoint[4];
  double farPoint[4];
  vtkInteractorObserver::ComputeDisplayToWorld(renderer, cursor[0], cursor[1], 0.0, nearPoint);
  vtkInteractorObserver::ComputeDisplayToWorld(renderer, cursor[0], cursor[1], 1.0, farPoint);
  double ray[3];
  double toHandle[3];
  vtkMath::Subtract(farPoint, nearPoint, ray);
  vtkMath::Subtract(handle, nearPoint, toHandle);
  const double along = vtkMath::Dot(ray, normal);
  if (!(std::abs(along) > 1e-12))
  {
    return false;
  }
  const double t = vtkMath::Dot(toHandle, normal) / along;
  double world[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    world[axis] = nearPoint[axis] + t * ray[axis];
  }
  TransformPoint(this->WorldToDevice, world, position);
  return IsFinite(position);
}

//------------------------------------------------------------------------------
bool vtkVirtualHapticDeviceMouseDriver::PositionAlongView(double distance, double position[3])
{
  double handle[3];
  TransformPoint(this->DeviceToWorld, this->Position, handle);
  double direction[3];
  this->CurrentRenderer->GetActiveCamera()->GetDirectionOfProjection(direction);
  vtkMath::Normalize(direction);
  double world[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    world[axis] = handle[axis] + distance * direction[axis];
  }
  TransformPoint(this->WorldToDevice, world, position);
  return IsFinite(position);
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDeviceMouseDriver::Send(const double position[3])
{
  double clamped[3] = { position[0], position[1], position[2] };
  if (!IsFinite(clamped))
  {
    return;
  }
  const double radius = this->Device->GetCapabilities()->GetWorkspaceRadius();
  const double norm = vtkMath::Norm(clamped);
  // A radius of 0: the device reports no workspace to stay in.
  if (radius > 0.0 && norm > radius)
  {
    vtkMath::MultiplyScalar(clamped, radius / norm);
    ++this->NumberOfClampedPositions;
  }
  std::copy(clamped, clamped + 3, this->Position);
  this->Device->SetPose(clamped, this->Drilling ? this->DrillButtons : 0u);
}

//------------------------------------------------------------------------------
void vtkVirtualHapticDeviceMouseDriver::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Device: " << this->Device.GetPointer() << "\n";
  os << indent << "WorldToDevice:\n";
  this->WorldToDevice->PrintSelf(os, indent.GetNextIndent());
  os << indent << "WheelStep: " << this->WheelStep << "\n";
  os << indent << "DrillButtons: " << this->DrillButtons << "\n";
  os << indent << "Position: (" << this->Position[0] << ", " << this->Position[1] << ", " << this->Position[2] << ")\n";
  os << indent << "Drilling: " << (this->Drilling ? "yes" : "no") << "\n";
  os << indent << "NumberOfClampedPositions: " << this->NumberOfClampedPositions << "\n";
}
