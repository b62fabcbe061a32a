// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkSpaceMouseDevice.h"
#include "vtkHIDConnection.h"
#include "vtkHapticDeviceCapabilities.h"

#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>

vtkStandardNewMacro(vtkSpaceMouseDevice);

namespace
{
using Clock = std::chrono::steady_clock;

int ReadInt16(const unsigned char* bytes)
{
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(bytes[0] | (bytes[1] << 8)));
}

// Models known to speak the reports above (vendor, product): Logitech-era
// and 3Dconnexion IDs (spacenavd, PySpaceMouse, the project's device notes).
const int KnownIDs[][2] = { { 0x046d, 0xc626 }, { 0x046d, 0xc627 }, { 0x046d, 0xc628 }, { 0x046d, 0xc62b }, { 0x256f, 0xc62e },
  { 0x256f, 0xc631 }, { 0x256f, 0xc632 }, { 0x256f, 0xc633 }, { 0x256f, 0xc635 }, { 0x256f, 0xc638 }, { 0x256f, 0xc652 } };

/// Full deflection in counts.
constexpr double FullScale = 350.0;
} // namespace

struct vtkSpaceMouseDevice::Internals : public vtkHIDConnection::Listener
{
  vtkSpaceMouseDevice* Self = nullptr;
  vtkNew<vtkHIDConnection> Connection;
  // The reader thread's integration state.
  int Axes[6] = { 0, 0, 0, 0, 0, 0 };
  unsigned int Buttons = 0;
  double Position[3] = { 0.0, 0.0, 0.0 };
  double Orientation[4] = { 1.0, 0.0, 0.0, 0.0 };
  Clock::time_point Last;
  bool HasLast = false;
  std::atomic<bool> ResetRequested{ false };

  void ReportReceived(const unsigned char* report, int length) override
  {
    int axes[6];
    std::copy(this->Axes, this->Axes + 6, axes);
    unsigned int buttons = this->Buttons;
    const int contents = vtkSpaceMouseDevice::DecodeReport(report, length, axes, buttons);
    if (contents < 0)
    {
      this->Self->ReportRejectedInput();
      return;
    }
    if (contents == 0)
    {
      return;
    }
    const Clock::time_point now = Clock::now();
    // Integrate the rates held since the previous report (at most 50 ms:
    // a pause in the reports means the cap was at rest).
    const double dt = this->HasLast ? std::min(0.05, std::chrono::duration<double>(now - this->Last).count()) : 0.0;
    this->Last = now;
    this->HasLast = true;
    if (this->ResetRequested.exchange(false))
    {
      std::fill(this->Position, this->Position + 3, 0.0);
      this->Orientation[0] = 1.0;
      std::fill(this->Orientation + 1, this->Orientation + 4, 0.0);
    }
    const int deadZone = this->Self->DeadZone;
    auto rate = [deadZone](int counts) {
      if (std::abs(counts) <= deadZone)
      {
        return 0.0;
      }
      return std::max(-1.0, std::min(1.0, counts / FullScale));
    };
    for (int axis = 0; axis < 3; ++axis)
    {
      this->Position[axis] += rate(this->Axes[axis]) * this->Self->MaximumSpeed * dt;
    }
    // Rotation: the small turn of this step, composed on the right (body rates).
    const double turn[3] = { rate(this->Axes[3]) * this->Self->MaximumAngularSpeed * dt,
      rate(this->Axes[4]) * this->Self->MaximumAngularSpeed * dt, rate(this->Axes[5]) * this->Self->MaximumAngularSpeed * dt };
    const double angle = vtkMath::Norm(turn);
    if (angle > 0.0)
    {
      const double s = std::sin(0.5 * angle) / angle;
      const double step[4] = { std::cos(0.5 * angle), turn[0] * s, turn[1] * s, turn[2] * s };
      double turned[4];
      vtkMath::MultiplyQuaternion(this->Orientation, step, turned);
      std::copy(turned, turned + 4, this->Orientation);
    }
    std::copy(axes, axes + 6, this->Axes);
    this->Buttons = buttons;
    this->Self->PublishSample(this->Position, this->Orientation, this->Buttons);
  }

  void ConnectionFailed(const char* reason) override { this->Self->ReportLost(reason); }
};

//------------------------------------------------------------------------------
vtkSpaceMouseDevice::vtkSpaceMouseDevice()
  : Internal(new Internals)
{
  this->Internal->Self = this;
  this->Internal->Connection->SetListener(this->Internal.get());
  for (const auto& id : KnownIDs)
  {
    this->Internal->Connection->AddDeviceID(id[0], id[1]);
  }
  vtkHapticDeviceCapabilities* capabilities = this->Capabilities;
  capabilities->SetModelName("3Dconnexion SpaceMouse");
  capabilities->SetManufacturer("3Dconnexion");
  capabilities->SetInputDegreesOfFreedom(6);
  capabilities->SetForceDegreesOfFreedom(0);
  capabilities->SetWorkspaceRadius(0.0);
  capabilities->SetNumberOfButtons(2);
  // Reports come at about 60 Hz while the cap moves.
  capabilities->SetUpdateRate(60.0);
}

//------------------------------------------------------------------------------
vtkSpaceMouseDevice::~vtkSpaceMouseDevice()
{
  this->Close();
}

//------------------------------------------------------------------------------
vtkHIDConnection* vtkSpaceMouseDevice::GetConnection()
{
  return this->Internal->Connection;
}

//------------------------------------------------------------------------------
int vtkSpaceMouseDevice::DecodeReport(const unsigned char* report, int length, int axes[6], unsigned int& buttons)
{
  if (!report || length < 1)
  {
    return -1;
  }
  switch (report[0])
  {
    case 1:
      if (length >= 13)
      {
        for (int axis = 0; axis < 6; ++axis)
        {
          axes[axis] = ReadInt16(report + 1 + 2 * axis);
        }
        return ReportTranslation | ReportRotation;
      }
      if (length >= 7)
      {
        for (int axis = 0; axis < 3; ++axis)
        {
          axes[axis] = ReadInt16(report + 1 + 2 * axis);
        }
        return ReportTranslation;
      }
      return -1;
    case 2:
      if (length >= 7)
      {
        for (int axis = 0; axis < 3; ++axis)
        {
          axes[3 + axis] = ReadInt16(report + 1 + 2 * axis);
        }
        return ReportRotation;
      }
      return -1;
    case 3:
    {
      if (length < 2)
      {
        return -1;
      }
      unsigned int mask = 0;
      for (int byte = 1; byte < std::min(length, 5); ++byte)
      {
        mask |= static_cast<unsigned int>(report[byte]) << (8 * (byte - 1));
      }
      buttons = mask;
      return ReportButtons;
    }
    default:
      // Battery level, receiver status and the like: not ours to decode.
      return 0;
  }
}

//------------------------------------------------------------------------------
bool vtkSpaceMouseDevice::OpenDevice()
{
  Internals& internal = *this->Internal;
  std::fill(internal.Axes, internal.Axes + 6, 0);
  internal.Buttons = 0;
  internal.HasLast = false;
  // A pose at once (where the integration stands), before the cap moves;
  // published before the reader thread starts, which owns it afterwards.
  this->PublishSample(internal.Position, internal.Orientation, internal.Buttons);
  if (!internal.Connection->Open())
  {
    this->SetErrorMessage((std::string("3Dconnexion SpaceMouse: ") + internal.Connection->GetErrorMessage()).c_str());
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkSpaceMouseDevice::CloseDevice()
{
  this->Internal->Connection->Close();
}

//------------------------------------------------------------------------------
bool vtkSpaceMouseDevice::SetLED(bool on)
{
  const unsigned char report[2] = { 0x04, static_cast<unsigned char>(on ? 1 : 0) };
  if (this->Internal->Connection->Write(report, 2) != 2)
  {
    vtkWarningMacro("SetLED: the SpaceMouse did not take the LED report: " << this->Internal->Connection->GetErrorMessage());
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkSpaceMouseDevice::ResetPose()
{
  this->Internal->ResetRequested = true;
}

//------------------------------------------------------------------------------
void vtkSpaceMouseDevice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "MaximumSpeed: " << this->MaximumSpeed << " mm/s\n";
  os << indent << "MaximumAngularSpeed: " << this->MaximumAngularSpeed << " rad/s\n";
  os << indent << "DeadZone: " << this->DeadZone << "\n";
  os << indent << "Connection:\n";
  this->Internal->Connection->PrintSelf(os, indent.GetNextIndent());
}
