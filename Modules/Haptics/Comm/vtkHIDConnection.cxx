// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHIDConnection.h"

#include "vtkObjectFactory.h"

#include <hidapi/hidapi.h>

#include <atomic>
#include <cwchar>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkHIDConnection);

namespace
{
/// hidapi's wide-character messages, for ours.
std::string Narrow(const wchar_t* text)
{
  std::string result;
  for (; text && *text; ++text)
  {
    result += (*text >= 32 && *text < 127) ? static_cast<char>(*text) : '?';
  }
  return result;
}

std::string Hex4(int value)
{
  std::ostringstream text;
  text << std::hex;
  text.width(4);
  text.fill('0');
  text << value;
  return text.str();
}
} // namespace

struct vtkHIDConnection::Internals
{
  std::vector<std::pair<int, int>> IDs;
  Listener* Receiver = nullptr;
  hid_device* Device = nullptr;
  std::thread Reader;
  std::atomic<bool> Stop{ false };
  std::string OpenedPath;
  std::string Error;
};

//------------------------------------------------------------------------------
vtkHIDConnection::vtkHIDConnection()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkHIDConnection::~vtkHIDConnection()
{
  this->Close();
  this->SetDevicePath(nullptr);
}

//------------------------------------------------------------------------------
void vtkHIDConnection::SetListener(Listener* listener)
{
  this->Internal->Receiver = listener;
}

//------------------------------------------------------------------------------
void vtkHIDConnection::AddDeviceID(int vendorID, int productID)
{
  this->Internal->IDs.emplace_back(vendorID, productID);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkHIDConnection::RemoveAllDeviceIDs()
{
  this->Internal->IDs.clear();
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkHIDConnection::GetNumberOfDeviceIDs() const
{
  return static_cast<int>(this->Internal->IDs.size());
}

//------------------------------------------------------------------------------
bool vtkHIDConnection::IsOpen() const
{
  return this->Internal->Device != nullptr;
}

//------------------------------------------------------------------------------
const char* vtkHIDConnection::GetOpenedPath() const
{
  return this->Internal->OpenedPath.c_str();
}

//------------------------------------------------------------------------------
const char* vtkHIDConnection::GetErrorMessage() const
{
  return this->Internal->Error.c_str();
}

//------------------------------------------------------------------------------
bool vtkHIDConnection::Open()
{
  Internals& internal = *this->Internal;
  if (internal.Device)
  {
    return true;
  }
  internal.Error.clear();
  if (hid_init() != 0)
  {
    internal.Error = "hidapi could not be initialised: " + Narrow(hid_error(nullptr));
    return false;
  }
  std::string path = this->DevicePath ? this->DevicePath : "";
  if (path.empty())
  {
    // Enumerate once and take the first device of the list, in the list's order of IDs.
    hid_device_info* devices = hid_enumerate(0, 0);
    for (const auto& id : internal.IDs)
    {
      for (hid_device_info* info = devices; info && path.empty(); info = info->next)
      {
        if (info->vendor_id == id.first && info->product_id == id.second && info->path)
        {
          path = info->path;
          this->OpenedVendorID = id.first;
          this->OpenedProductID = id.second;
        }
      }
      if (!path.empty())
      {
        break;
      }
    }
    hid_free_enumeration(devices);
    if (path.empty())
    {
      std::ostringstream message;
      message << "no HID device with any of the IDs";
      for (const auto& id : internal.IDs)
      {
        message << " " << Hex4(id.first) << ":" << Hex4(id.second);
      }
      message << " is connected (or its hidraw node cannot be read: check the udev rules giving your user access)";
      internal.Error = message.str();
      return false;
    }
  }
  internal.Device = hid_open_path(path.c_str());
  if (!internal.Device)
  {
    internal.Error = "the HID device '" + path + "' could not be opened: " + Narrow(hid_error(nullptr));
    return false;
  }
  internal.OpenedPath = path;
  internal.Stop = false;
  const int timeout = this->ReadTimeout;
  hid_device* device = internal.Device;
  internal.Reader = std::thread([&internal, device, timeout]() {
    unsigned char report[256];
    while (!internal.Stop.load(std::memory_order_acquire))
    {
      const int length = timeout < 0 ? hid_read(device, report, sizeof(report)) : hid_read_timeout(device, report, sizeof(report), timeout);
      if (internal.Stop.load(std::memory_order_acquire))
      {
        break;
      }
      if (length < 0)
      {
        if (internal.Receiver)
        {
          const std::string reason = "reading from the HID device failed (" + Narrow(hid_error(device)) + "): unplugged?";
          internal.Receiver->ConnectionFailed(reason.c_str());
        }
        break;
      }
      if (length > 0 && internal.Receiver)
      {
        internal.Receiver->ReportReceived(report, length);
      }
    }
  });
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkHIDConnection::Close()
{
  Internals& internal = *this->Internal;
  internal.Stop = true;
  if (internal.Reader.joinable())
  {
    internal.Reader.join();
  }
  if (internal.Device)
  {
    hid_close(internal.Device);
    internal.Device = nullptr;
  }
}

//------------------------------------------------------------------------------
int vtkHIDConnection::Write(const unsigned char* data, int length)
{
  Internals& internal = *this->Internal;
  if (!internal.Device || !data || length <= 0)
  {
    internal.Error = "nothing to write, or the HID device is not open";
    return -1;
  }
  const int written = hid_write(internal.Device, data, static_cast<size_t>(length));
  if (written < 0)
  {
    internal.Error = "writing to the HID device failed: " + Narrow(hid_error(internal.Device));
  }
  return written;
}

//------------------------------------------------------------------------------
void vtkHIDConnection::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "DevicePath: " << (this->DevicePath ? this->DevicePath : "(search by IDs)") << "\n";
  os << indent << "DeviceIDs:";
  for (const auto& id : this->Internal->IDs)
  {
    os << " " << Hex4(id.first) << ":" << Hex4(id.second);
  }
  os << "\n";
  os << indent << "ReadTimeout: " << this->ReadTimeout << " ms\n";
  os << indent << "Open: " << (this->IsOpen() ? this->Internal->OpenedPath : std::string("no")) << "\n";
}
