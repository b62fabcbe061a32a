// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkFootSwitchDevice.h"
#include "vtkHIDConnection.h"
#include "vtkHapticDeviceCapabilities.h"

#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <algorithm>

vtkStandardNewMacro(vtkFootSwitchDevice);

namespace
{
const int KnownIDs[][2] = { { 0x05f3, 0x00ff }, { 0x0c45, 0x7403 }, { 0x0c45, 0x7404 }, { 0x413d, 0x2107 }, { 0x1a86, 0xe026 } };
constexpr int VECReportLength = 2;
constexpr int KeyboardReportLength = 8;
/// Key codes that are not keys: none, and the keyboard's rollover error.
constexpr int NoKey = 0x00;
constexpr int RollOver = 0x01;
constexpr int MaximumPedals = 8;
} // namespace

struct vtkFootSwitchDevice::Internals : public vtkHIDConnection::Listener
{
  vtkFootSwitchDevice* Self = nullptr;
  vtkNew<vtkHIDConnection> Connection;
  int PedalKeys[MaximumPedals] = { 0x04, 0x05, 0x06, 0, 0, 0, 0, 0 };
  int NumberOfPedalKeys = 3;
  unsigned int Buttons = 0;

  void ReportReceived(const unsigned char* report, int length) override
  {
    if (!vtkFootSwitchDevice::DecodeReport(report, length, this->PedalKeys, this->NumberOfPedalKeys, this->Buttons))
    {
      this->Self->ReportRejectedInput();
      return;
    }
    const double origin[3] = { 0.0, 0.0, 0.0 };
    const double identity[4] = { 1.0, 0.0, 0.0, 0.0 };
    this->Self->PublishSample(origin, identity, this->Buttons);
  }

  void ConnectionFailed(const char* reason) override { this->Self->ReportLost(reason); }
};

//------------------------------------------------------------------------------
vtkFootSwitchDevice::vtkFootSwitchDevice()
  : Internal(new Internals)
{
  this->Internal->Self = this;
  this->Internal->Connection->SetListener(this->Internal.get());
  for (const auto& id : KnownIDs)
  {
    this->Internal->Connection->AddDeviceID(id[0], id[1]);
  }
  vtkHapticDeviceCapabilities* capabilities = this->Capabilities;
  capabilities->SetModelName("USB foot switch");
  capabilities->SetInputDegreesOfFreedom(0);
  capabilities->SetForceDegreesOfFreedom(0);
  capabilities->SetNumberOfButtons(3);
  capabilities->SetUpdateRate(125.0);
}

//------------------------------------------------------------------------------
vtkFootSwitchDevice::~vtkFootSwitchDevice()
{
  this->Close();
}

//------------------------------------------------------------------------------
vtkHIDConnection* vtkFootSwitchDevice::GetConnection()
{
  return this->Internal->Connection;
}

//------------------------------------------------------------------------------
void vtkFootSwitchDevice::SetPedalKeys(int key0, int key1, int key2)
{
  const int keys[3] = { key0, key1, key2 };
  std::copy(keys, keys + 3, this->Internal->PedalKeys);
  this->Internal->NumberOfPedalKeys = 3;
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkFootSwitchDevice::GetPedalKey(int pedal) const
{
  return pedal >= 0 && pedal < this->Internal->NumberOfPedalKeys ? this->Internal->PedalKeys[pedal] : 0;
}

//------------------------------------------------------------------------------
bool vtkFootSwitchDevice::DecodeReport(const unsigned char* report, int length, const int* pedalKeys, int numberOfPedalKeys, unsigned int& buttons)
{
  if (!report)
  {
    return false;
  }
  if (length == VECReportLength)
  {
    if (report[0] & ~0x07u)
    {
      return false; // bits no VEC pedal has
    }
    buttons = report[0] & 0x07u;
    return true;
  }
  if (length == KeyboardReportLength)
  {
    unsigned int pressed = report[0] != 0 ? 1u : 0u;
    for (int byte = 2; byte < KeyboardReportLength; ++byte)
    {
      const int key = report[byte];
      if (key == NoKey || key == RollOver)
      {
        continue;
      }
      int pedal = 0;
      for (int n = 0; n < std::min(numberOfPedalKeys, MaximumPedals); ++n)
      {
        if (pedalKeys[n] == key)
        {
          pedal = n;
          break;
        }
      }
      pressed |= 1u << pedal;
    }
    buttons = pressed;
    return true;
  }
  return false;
}

//------------------------------------------------------------------------------
bool vtkFootSwitchDevice::OpenDevice()
{
  Internals& internal = *this->Internal;
  internal.Buttons = 0;
  // Released until the pedal says otherwise; published before the reader starts.
  const double origin[3] = { 0.0, 0.0, 0.0 };
  const double identity[4] = { 1.0, 0.0, 0.0, 0.0 };
  this->PublishSample(origin, identity, 0u);
  if (!internal.Connection->Open())
  {
    this->SetErrorMessage((std::string("foot switch: ") + internal.Connection->GetErrorMessage()).c_str());
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkFootSwitchDevice::CloseDevice()
{
  this->Internal->Connection->Close();
}

//------------------------------------------------------------------------------
void vtkFootSwitchDevice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "PedalKeys:";
  for (int n = 0; n < this->Internal->NumberOfPedalKeys; ++n)
  {
    os << " " << this->Internal->PedalKeys[n];
  }
  os << "\n";
  os << indent << "Connection:\n";
  this->Internal->Connection->PrintSelf(os, indent.GetNextIndent());
}
