// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkFTDIConnection.h"

#include "vtkObjectFactory.h"

#include <libusb.h>

#include <algorithm>
#include <cstring>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkFTDIConnection);

namespace
{
// FTDI vendor requests (libftdi's names) and their values.
constexpr int RequestReset = 0;
constexpr int RequestModemControl = 1;
constexpr int RequestFlowControl = 2;
constexpr int RequestBaudRate = 3;
constexpr int RequestData = 4;
constexpr int RequestLatencyTimer = 9;
constexpr int PurgeReceive = 1;
constexpr int PurgeTransmit = 2;
constexpr int DTRMask = 0x0100;
constexpr int RTSMask = 0x0200;
constexpr unsigned char EndpointOut = 0x02;
constexpr unsigned char EndpointIn = 0x81;
constexpr int PacketSize = 64;
constexpr int StatusBytes = 2;
} // namespace

struct vtkFTDIConnection::Internals
{
  libusb_context* Context = nullptr;
  libusb_device_handle* Handle = nullptr;
  std::string Error;
  bool Gone = false;

  void Fail(const std::string& what, int code)
  {
    this->Error = what + ": " + libusb_error_name(code);
    this->Gone = code == LIBUSB_ERROR_NO_DEVICE || code == LIBUSB_ERROR_IO || code == LIBUSB_ERROR_PIPE;
  }
};

//------------------------------------------------------------------------------
vtkFTDIConnection::vtkFTDIConnection()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkFTDIConnection::~vtkFTDIConnection()
{
  this->Close();
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::IsOpen() const
{
  return this->Internal->Handle != nullptr;
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::IsDeviceGone() const
{
  return this->Internal->Gone;
}

//------------------------------------------------------------------------------
const char* vtkFTDIConnection::GetErrorMessage() const
{
  return this->Internal->Error.c_str();
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::Open()
{
  Internals& internal = *this->Internal;
  if (internal.Handle)
  {
    return true;
  }
  internal.Error.clear();
  internal.Gone = false;
  int result = libusb_init(&internal.Context);
  if (result < 0)
  {
    internal.Fail("libusb could not be initialised", result);
    internal.Context = nullptr;
    return false;
  }
  libusb_device** devices = nullptr;
  const ssize_t count = libusb_get_device_list(internal.Context, &devices);
  libusb_device* found = nullptr;
  int seen = 0;
  for (ssize_t n = 0; n < count; ++n)
  {
    libusb_device_descriptor descriptor;
    if (libusb_get_device_descriptor(devices[n], &descriptor) == 0 && descriptor.idVendor == this->VendorID &&
      descriptor.idProduct == this->ProductID && seen++ == this->DeviceIndex)
    {
      found = devices[n];
      break;
    }
  }
  if (found)
  {
    result = libusb_open(found, &internal.Handle);
  }
  if (devices)
  {
    libusb_free_device_list(devices, 1);
  }
  std::ostringstream id;
  id << std::hex;
  id.fill('0');
  id.width(4);
  id << this->VendorID << ":";
  id.width(4);
  id << this->ProductID;
  if (!found)
  {
    internal.Error = "no USB device " + id.str() + (this->DeviceIndex > 0 ? " with that index" : "") +
      " is connected (or it cannot be accessed: check the udev rules giving your user access to it)";
    this->Close();
    return false;
  }
  if (!internal.Handle)
  {
    internal.Fail("the USB device " + id.str() + " could not be opened", result);
    internal.Handle = nullptr;
    this->Close();
    return false;
  }
  // A kernel serial driver (ftdi_sio) may hold the interface: let libusb
  // detach it while we use the device.
  libusb_set_auto_detach_kernel_driver(internal.Handle, 1);
  result = libusb_claim_interface(internal.Handle, 0);
  if (result < 0)
  {
    internal.Fail("interface 0 of the USB device " + id.str() + " could not be claimed (another program uses it?)", result);
    this->Close();
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkFTDIConnection::Close()
{
  Internals& internal = *this->Internal;
  if (internal.Handle)
  {
    libusb_release_interface(internal.Handle, 0);
    libusb_close(internal.Handle);
    internal.Handle = nullptr;
  }
  if (internal.Context)
  {
    libusb_exit(internal.Context);
    internal.Context = nullptr;
  }
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::Control(int request, int value, const char* what)
{
  Internals& internal = *this->Internal;
  if (!internal.Handle)
  {
    internal.Error = std::string(what) + ": the device is not open";
    return false;
  }
  const int result = libusb_control_transfer(internal.Handle, LIBUSB_REQUEST_TYPE_VENDOR | LIBUSB_RECIPIENT_DEVICE | LIBUSB_ENDPOINT_OUT,
    static_cast<uint8_t>(request), static_cast<uint16_t>(value), 0, nullptr, 0, 1000);
  if (result < 0)
  {
    internal.Fail(what, result);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::Purge(bool receive, bool transmit)
{
  return (!receive || this->Control(RequestReset, PurgeReceive, "purging the FTDI receive buffer")) &&
    (!transmit || this->Control(RequestReset, PurgeTransmit, "purging the FTDI transmit buffer"));
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::SetLatencyTimer(int milliseconds)
{
  return this->Control(RequestLatencyTimer, std::max(1, std::min(255, milliseconds)), "setting the FTDI latency timer");
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::SetBaudRateDivisor(int divisor)
{
  return this->Control(RequestBaudRate, divisor, "setting the FTDI baud rate");
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::SetLineProperties8N1()
{
  // 8 data bits, no parity (bits 8-10 zero), one stop bit (bits 11-12 zero).
  return this->Control(RequestData, 8, "setting the FTDI data format");
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::DisableFlowControl()
{
  return this->Control(RequestFlowControl, 0, "disabling FTDI flow control");
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::SetDTR(bool high)
{
  return this->Control(RequestModemControl, DTRMask | (high ? 1 : 0), "setting the FTDI DTR line");
}

//------------------------------------------------------------------------------
bool vtkFTDIConnection::SetRTS(bool high)
{
  return this->Control(RequestModemControl, RTSMask | (high ? 2 : 0), "setting the FTDI RTS line");
}

//------------------------------------------------------------------------------
int vtkFTDIConnection::Write(const unsigned char* data, int length, int timeoutMilliseconds)
{
  Internals& internal = *this->Internal;
  if (!internal.Handle)
  {
    internal.Error = "writing: the device is not open";
    return -1;
  }
  int sent = 0;
  const int result = libusb_bulk_transfer(
    internal.Handle, EndpointOut, const_cast<unsigned char*>(data), length, &sent, static_cast<unsigned int>(std::max(0, timeoutMilliseconds)));
  if (result < 0 && result != LIBUSB_ERROR_TIMEOUT)
  {
    internal.Fail("writing to the FTDI chip", result);
    return -1;
  }
  return sent;
}

//------------------------------------------------------------------------------
int vtkFTDIConnection::Read(unsigned char* data, int capacity, int timeoutMilliseconds)
{
  Internals& internal = *this->Internal;
  if (!internal.Handle)
  {
    internal.Error = "reading: the device is not open";
    return -1;
  }
  // One packet at a time: each begins with the chip's two status bytes.
  unsigned char packet[PacketSize];
  int received = 0;
  const int result = libusb_bulk_transfer(
    internal.Handle, EndpointIn, packet, PacketSize, &received, static_cast<unsigned int>(std::max(0, timeoutMilliseconds)));
  if (result < 0 && result != LIBUSB_ERROR_TIMEOUT)
  {
    internal.Fail("reading from the FTDI chip", result);
    return -1;
  }
  const int payload = std::max(0, std::min(received - StatusBytes, capacity));
  if (payload > 0)
  {
    std::memcpy(data, packet + StatusBytes, static_cast<size_t>(payload));
  }
  return payload;
}

//------------------------------------------------------------------------------
void vtkFTDIConnection::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "VendorID: 0x" << std::hex << this->VendorID << "\n";
  os << indent << "ProductID: 0x" << this->ProductID << std::dec << "\n";
  os << indent << "DeviceIndex: " << this->DeviceIndex << "\n";
  os << indent << "Open: " << (this->IsOpen() ? "yes" : "no") << "\n";
}
