// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticDevice.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticLatestValue.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

namespace
{
using Clock = std::chrono::steady_clock;

/// A force as the haptic thread hands it to the backend and readers.
struct ForceValue
{
  double Force[3];
};
}

struct vtkHapticDevice::Internals
{
  std::atomic<int> State{ vtkHapticDevice::Closed };
  /// The state ProcessConnectionEvents last reported (main thread only).
  int ReportedState = vtkHapticDevice::Closed;
  vtkHapticLatestValue<vtkHapticDevice::Sample> Latest;
  vtkHapticLatestValue<ForceValue> Commanded;
  std::atomic<unsigned long long> SampleCount{ 0 };
  std::atomic<unsigned long long> RejectedForces{ 0 };
  std::atomic<unsigned long long> ClampedForces{ 0 };
  std::atomic<unsigned long long> RejectedInputs{ 0 };
  // What ProcessConnectionEvents has reported of the counts above.
  unsigned long long ReportedRejectedForces = 0;
  unsigned long long ReportedClampedForces = 0;
  unsigned long long ReportedRejectedInputs = 0;
  // Written once by the I/O thread before it publishes State = Lost.
  char LostReason[256] = { 0 };
  std::string ErrorMessage;
  /// When the device was last opened (steady clock ticks): read by publishers.
  std::atomic<Clock::rep> OpenTime{ Clock::now().time_since_epoch().count() };
  Clock::time_point LastAttempt = Clock::now();
};

//------------------------------------------------------------------------------
vtkHapticDevice::vtkHapticDevice()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkHapticDevice::~vtkHapticDevice() = default;

//------------------------------------------------------------------------------
vtkHapticDeviceCapabilities* vtkHapticDevice::GetCapabilities()
{
  return this->Capabilities;
}

//------------------------------------------------------------------------------
bool vtkHapticDevice::OpenAndStart()
{
  Internals& internal = *this->Internal;
  internal.LastAttempt = Clock::now();
  internal.OpenTime.store(internal.LastAttempt.time_since_epoch().count(), std::memory_order_release);
  internal.SampleCount.store(0, std::memory_order_relaxed);
  internal.LostReason[0] = '\0';
  const ForceValue zero = { { 0.0, 0.0, 0.0 } };
  internal.Commanded.Store(zero);
  // No sample from before: a reconnected device starts without one.
  this->PublishAbsence();
  // The state says Connected before the backend's thread starts, so that a
  // loss it reports at once is not overwritten.
  internal.State.store(Connected, std::memory_order_release);
  if (!this->OpenDevice())
  {
    internal.State.store(Closed, std::memory_order_release);
    return false;
  }
  ++this->NumberOfConnections;
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticDevice::Open()
{
  Internals& internal = *this->Internal;
  if (internal.State.load(std::memory_order_acquire) == Connected)
  {
    return true;
  }
  if (internal.State.load(std::memory_order_acquire) == Lost)
  {
    this->CloseDevice();
  }
  internal.ErrorMessage.clear();
  if (!this->OpenAndStart())
  {
    vtkErrorMacro("Open: " << (internal.ErrorMessage.empty() ? std::string("the device could not be opened") : internal.ErrorMessage));
    internal.ReportedState = Closed;
    return false;
  }
  internal.ReportedState = Connected;
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticDevice::Close()
{
  Internals& internal = *this->Internal;
  if (internal.State.load(std::memory_order_acquire) == Closed)
  {
    return;
  }
  const double zero[3] = { 0.0, 0.0, 0.0 };
  if (internal.State.load(std::memory_order_acquire) == Connected)
  {
    this->WriteForce(zero);
  }
  this->CloseDevice();
  internal.State.store(Closed, std::memory_order_release);
  internal.ReportedState = Closed;
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkHapticDevice::GetConnectionState() const
{
  return this->Internal->State.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
bool vtkHapticDevice::GetLatestSample(Sample& sample) const
{
  return this->Internal->Latest.Load(sample);
}

//------------------------------------------------------------------------------
bool vtkHapticDevice::GetLatestPosition(double position[3]) const
{
  Sample sample;
  if (!this->GetLatestSample(sample) || !sample.Present)
  {
    return false;
  }
  std::copy(sample.Position, sample.Position + 3, position);
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticDevice::GetLatestOrientation(double orientation[4]) const
{
  Sample sample;
  if (!this->GetLatestSample(sample) || !sample.Present)
  {
    return false;
  }
  std::copy(sample.Orientation, sample.Orientation + 4, orientation);
  return true;
}

//------------------------------------------------------------------------------
unsigned int vtkHapticDevice::GetLatestButtons() const
{
  Sample sample;
  return this->GetLatestSample(sample) && sample.Present ? sample.Buttons : 0u;
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticDevice::GetNumberOfSamples() const
{
  return this->Internal->SampleCount.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
bool vtkHapticDevice::SetForce(const double force[3])
{
  Internals& internal = *this->Internal;
  ForceValue value = { { 0.0, 0.0, 0.0 } };
  bool asked = true;
  if (!force || !std::isfinite(force[0]) || !std::isfinite(force[1]) || !std::isfinite(force[2]))
  {
    internal.RejectedForces.fetch_add(1, std::memory_order_relaxed);
    asked = false;
  }
  else
  {
    const double maximum = this->Capabilities->GetMaximumForce();
    const double magnitude = std::sqrt(force[0] * force[0] + force[1] * force[1] + force[2] * force[2]);
    const double scale = magnitude > maximum ? (magnitude > 0.0 ? maximum / magnitude : 0.0) : 1.0;
    if (scale < 1.0)
    {
      internal.ClampedForces.fetch_add(1, std::memory_order_relaxed);
      asked = false;
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      value.Force[axis] = force[axis] * scale;
    }
  }
  if (internal.State.load(std::memory_order_acquire) != Connected)
  {
    const ForceValue zero = { { 0.0, 0.0, 0.0 } };
    internal.Commanded.Store(zero);
    return false;
  }
  internal.Commanded.Store(value);
  this->WriteForce(value.Force);
  return asked;
}

//------------------------------------------------------------------------------
void vtkHapticDevice::GetCommandedForce(double force[3]) const
{
  ForceValue value = { { 0.0, 0.0, 0.0 } };
  this->Internal->Commanded.Load(value);
  std::copy(value.Force, value.Force + 3, force);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticDevice::GetNumberOfRejectedForces() const
{
  return this->Internal->RejectedForces.load(std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticDevice::GetNumberOfClampedForces() const
{
  return this->Internal->ClampedForces.load(std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticDevice::GetNumberOfRejectedInputs() const
{
  return this->Internal->RejectedInputs.load(std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
void vtkHapticDevice::Synchronize(unsigned long long) {}

//------------------------------------------------------------------------------
void vtkHapticDevice::WriteForce(const double*) {}

//------------------------------------------------------------------------------
void vtkHapticDevice::SetErrorMessage(const char* message)
{
  this->Internal->ErrorMessage = message ? message : "";
}

//------------------------------------------------------------------------------
const char* vtkHapticDevice::GetLastErrorMessage() const
{
  return this->Internal->ErrorMessage.c_str();
}

//------------------------------------------------------------------------------
void vtkHapticDevice::PublishSample(const double position[3], const double orientation[4], unsigned int buttons)
{
  Internals& internal = *this->Internal;
  Sample sample;
  bool finite = true;
  for (int axis = 0; axis < 3; ++axis)
  {
    finite = finite && std::isfinite(position[axis]);
  }
  double norm2 = 0.0;
  for (int component = 0; component < 4; ++component)
  {
    finite = finite && std::isfinite(orientation[component]);
    norm2 += orientation[component] * orientation[component];
  }
  if (!finite || !(norm2 > 1e-12))
  {
    internal.RejectedInputs.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const double inverseNorm = 1.0 / std::sqrt(norm2);
  std::copy(position, position + 3, sample.Position);
  for (int component = 0; component < 4; ++component)
  {
    sample.Orientation[component] = orientation[component] * inverseNorm;
  }
  sample.Buttons = buttons;
  sample.Time = this->GetTimeSinceOpen();
  sample.Index = internal.SampleCount.load(std::memory_order_relaxed) + 1;
  internal.Latest.Store(sample);
  internal.SampleCount.store(sample.Index, std::memory_order_release);
}

//------------------------------------------------------------------------------
void vtkHapticDevice::PublishAbsence()
{
  Sample sample;
  this->Internal->Latest.Load(sample);
  sample.Present = false;
  sample.Time = this->GetTimeSinceOpen();
  this->Internal->Latest.Store(sample);
}

//------------------------------------------------------------------------------
void vtkHapticDevice::ReportLost(const char* reason)
{
  Internals& internal = *this->Internal;
  if (internal.State.load(std::memory_order_acquire) != Connected)
  {
    return;
  }
  std::strncpy(internal.LostReason, reason ? reason : "the device stopped answering", sizeof(internal.LostReason) - 1);
  internal.LostReason[sizeof(internal.LostReason) - 1] = '\0';
  const ForceValue zero = { { 0.0, 0.0, 0.0 } };
  internal.Commanded.Store(zero);
  internal.State.store(Lost, std::memory_order_release);
}

//------------------------------------------------------------------------------
void vtkHapticDevice::ReportRejectedInput()
{
  this->Internal->RejectedInputs.fetch_add(1, std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
double vtkHapticDevice::GetTimeSinceOpen() const
{
  const Clock::time_point opened{ Clock::duration(this->Internal->OpenTime.load(std::memory_order_acquire)) };
  return std::chrono::duration<double>(Clock::now() - opened).count();
}

//------------------------------------------------------------------------------
void vtkHapticDevice::ProcessConnectionEvents()
{
  Internals& internal = *this->Internal;
  const char* model = this->Capabilities->GetModelName();
  // What the other threads counted, reported once per batch.
  const unsigned long long rejectedInputs = internal.RejectedInputs.load(std::memory_order_relaxed);
  if (rejectedInputs != internal.ReportedRejectedInputs)
  {
    vtkWarningMacro("ProcessConnectionEvents: " << model << ": " << rejectedInputs - internal.ReportedRejectedInputs
                                                << " input frames or samples from the device made no sense and were dropped");
    internal.ReportedRejectedInputs = rejectedInputs;
  }
  const unsigned long long rejectedForces = internal.RejectedForces.load(std::memory_order_relaxed);
  if (rejectedForces != internal.ReportedRejectedForces)
  {
    vtkWarningMacro("ProcessConnectionEvents: " << model << ": " << rejectedForces - internal.ReportedRejectedForces
                                                << " force requests were not finite numbers; zero force was sent instead");
    internal.ReportedRejectedForces = rejectedForces;
  }
  const unsigned long long clampedForces = internal.ClampedForces.load(std::memory_order_relaxed);
  if (clampedForces != internal.ReportedClampedForces)
  {
    vtkWarningMacro("ProcessConnectionEvents: " << model << ": " << clampedForces - internal.ReportedClampedForces
                                                << " force requests exceeded the device's maximum of " << this->Capabilities->GetMaximumForce()
                                                << " N and were scaled down to it");
    internal.ReportedClampedForces = clampedForces;
  }

  const int state = internal.State.load(std::memory_order_acquire);
  if (state == Lost && internal.ReportedState != Lost)
  {
    this->CloseDevice();
    internal.ErrorMessage = internal.LostReason;
    vtkWarningMacro("ProcessConnectionEvents: " << model << " was lost (" << internal.LostReason << ")"
                                                << (this->AutoReconnect ? "; waiting for it to come back" : ""));
    internal.ReportedState = Lost;
    internal.LastAttempt = Clock::now();
    this->InvokeEvent(DeviceDisconnectedEvent);
    return;
  }
  if (state == Lost && this->AutoReconnect &&
    std::chrono::duration<double>(Clock::now() - internal.LastAttempt).count() >= this->ReconnectInterval)
  {
    internal.State.store(Closed, std::memory_order_release);
    if (this->OpenAndStart())
    {
      internal.ReportedState = Connected;
      this->InvokeEvent(DeviceConnectedEvent);
    }
    else
    {
      internal.State.store(Lost, std::memory_order_release);
    }
  }
}

//------------------------------------------------------------------------------
void vtkHapticDevice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  static const char* const stateNames[] = { "Closed", "Connected", "Lost" };
  os << indent << "ConnectionState: " << stateNames[this->GetConnectionState()] << "\n";
  os << indent << "AutoReconnect: " << (this->AutoReconnect ? "On" : "Off") << "\n";
  os << indent << "ReconnectInterval: " << this->ReconnectInterval << " s\n";
  os << indent << "NumberOfConnections: " << this->NumberOfConnections << "\n";
  os << indent << "NumberOfSamples: " << this->GetNumberOfSamples() << "\n";
  os << indent << "Capabilities:\n";
  this->Capabilities->PrintSelf(os, indent.GetNextIndent());
}
