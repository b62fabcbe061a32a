// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Shared by the haptics tests: a fake Novint Falcon in user space (umockdev
// test bed, run under libumockdev-preload). Its sysfs entry and descriptors
// let plain libusb enumerate, open and claim it; its usbfs node answers the
// URBs libusb submits and reaps: FTDI vendor control transfers (recorded,
// and the baud rate selects the boot loader, upload or frame mode), bulk
// OUT (probe, firmware bytes echoed, command frames decoded) and bulk IN
// (two modem-status bytes, then the boot loader's answers or one status
// frame per command frame, for the position the test sets through the
// delta kinematics).
#ifndef vtkHapticFakeFalcon_h
#define vtkHapticFakeFalcon_h

#include "vtkFalconFirmwareLoader.h"
#include "vtkFalconFrameCodec.h"
#include "vtkFalconKinematics.h"

#include <vtkNew.h>

#include <umockdev.h>

#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>

#include <glib/gstdio.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

class vtkHapticFakeFalcon
{
public:
  explicit vtkHapticFakeFalcon(UMockdevTestbed* bed)
    : Bed(bed)
  {
  }

  ~vtkHapticFakeFalcon()
  {
    this->Unplug();
    for (UMockdevIoctlBase* handler : this->Handlers)
    {
      g_object_unref(handler);
    }
    for (UMockdevIoctlData* urb : this->Completed)
    {
      g_object_unref(urb);
    }
  }

  /// Add the Falcon to the test bed (again after Unplug: a replug, powered
  /// on afresh, so without firmware unless keepFirmware).
  bool Plug(bool keepFirmware = false)
  {
    // Device, configuration, interface and the two bulk endpoints (bus-endian).
    unsigned char descriptors[] = {
      18, 1, 0x00, 0x02, 0, 0, 0, 64, 0x03, 0x04, 0x48, 0xcb, 0x00, 0x06, 1, 2, 3, 1, // device 0403:cb48
      9, 2, 32, 0, 1, 1, 0, 0x80, 50,                                                  // configuration
      9, 4, 0, 0, 2, 0xff, 0xff, 0xff, 2,                                              // interface 0, vendor class
      7, 5, 0x81, 2, 64, 0, 0,                                                         // bulk IN 0x81
      7, 5, 0x02, 2, 64, 0, 0                                                          // bulk OUT 0x02
    };
    gchar* usb = umockdev_testbed_add_device(this->Bed, "usb", "2-1", nullptr, "idVendor", "0403", "idProduct", "cb48", "busnum", "2",
      "devnum", "5", "speed", "12", "bConfigurationValue", "1", "manufacturer", "Novint", "product", "FALCON HAPTIC", nullptr, "DEVTYPE",
      "usb_device", "BUSNUM", "002", "DEVNUM", "005", "DEVNAME", "/dev/bus/usb/002/005", nullptr);
    if (!usb)
    {
      return false;
    }
    this->UsbPath = usb;
    umockdev_testbed_set_attribute_binary(this->Bed, usb, "descriptors", descriptors, sizeof(descriptors));
    g_free(usb);
    // The usbfs node the preload redirects to the handler's socket.
    gchar* root = umockdev_testbed_get_root_dir(this->Bed);
    this->NodeFile = std::string(root) + Node;
    g_free(root);
    gchar* folder = g_path_get_dirname(this->NodeFile.c_str());
    g_mkdir_with_parents(folder, 0755);
    g_free(folder);
    g_file_set_contents(this->NodeFile.c_str(), "", 0, nullptr);
    // A new handler per plug; the old ones live on for clients still connected.
    UMockdevIoctlBase* handler = umockdev_ioctl_base_new();
    this->Handlers.push_back(handler);
    g_signal_connect(handler, "handle-ioctl", G_CALLBACK(OnIoctl), this);
    GError* error = nullptr;
    const bool attached = umockdev_testbed_attach_ioctl(this->Bed, Node, handler, &error);
    if (error)
    {
      std::fprintf(stderr, "attaching the fake Falcon's usbfs node failed: %s\n", error->message);
      g_error_free(error);
    }
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Plugged = attached;
    this->FirmwareLoaded = keepFirmware && this->FirmwareLoaded;
    this->Mode = Idle;
    this->Pending.clear();
    return attached;
  }

  /// Unplugged: every transfer fails with ENODEV, and enumeration no longer finds it.
  void Unplug()
  {
    {
      std::lock_guard<std::mutex> lock(this->Mutex);
      if (!this->Plugged)
      {
        return;
      }
      this->Plugged = false;
    }
    umockdev_testbed_detach_ioctl(this->Bed, Node, nullptr);
    umockdev_testbed_remove_device(this->Bed, this->UsbPath.c_str());
    g_unlink(this->NodeFile.c_str());
  }

  ///@{ What the test controls.
  void SetPosition(const double position[3])
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    std::memcpy(this->Position, position, sizeof(this->Position));
  }
  void SetButtons(int buttons)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Buttons = buttons;
  }
  /// Frames needed in homing mode before the axes report homed.
  void SetHomingFrames(int frames)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->HomingFrames = frames;
  }
  /// Bytes sent before the next status frame (garbage).
  void InjectGarbage(const std::vector<unsigned char>& bytes)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Garbage = bytes;
  }
  /// A silent device sends no frames (modem bytes only).
  void SetSilent(bool silent)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Silent = silent;
  }
  ///@}

  ///@{ What the test checks.
  bool GetFirmwareLoaded()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    return this->FirmwareLoaded;
  }
  std::vector<unsigned char> GetFirmware()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    return this->Firmware;
  }
  /// (request, value) of every vendor control transfer.
  std::vector<std::pair<int, int>> GetControls()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    return this->Controls;
  }
  int GetNumberOfCommandFrames()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    return this->CommandFrames;
  }
  void GetLastMotors(short motors[3], int& control)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    std::memcpy(motors, this->Motors, sizeof(this->Motors));
    control = this->Control;
  }
  ///@}

private:
  enum Modes
  {
    Idle,
    BootLoader,
    Upload,
    Frames
  };

  static gboolean OnIoctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data)
  {
    vtkHapticFakeFalcon* self = static_cast<vtkHapticFakeFalcon*>(data);
    const gulong request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    GError* error = nullptr;
    std::lock_guard<std::mutex> lock(self->Mutex);
    if (!self->Plugged)
    {
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return TRUE;
    }
    if (request == USBDEVFS_GET_CAPABILITIES)
    {
      UMockdevIoctlData* capabilities = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), &error);
      *reinterpret_cast<guint32*>(capabilities->data) = 0;
      umockdev_ioctl_client_complete(client, 0, 0);
    }
    else if (request == USBDEVFS_CLAIMINTERFACE || request == USBDEVFS_RELEASEINTERFACE || request == USBDEVFS_SETINTERFACE ||
      request == USBDEVFS_CLEAR_HALT || request == USBDEVFS_RESETEP || request == USBDEVFS_DISCONNECT_CLAIM)
    {
      umockdev_ioctl_client_complete(client, 0, 0);
    }
    else if (request == USBDEVFS_SUBMITURB)
    {
      UMockdevIoctlData* urbData = umockdev_ioctl_data_resolve(arg, 0, sizeof(usbdevfs_urb), &error);
      usbdevfs_urb* urb = reinterpret_cast<usbdevfs_urb*>(urbData->data);
      UMockdevIoctlData* buffer = urb->buffer_length > 0
        ? umockdev_ioctl_data_resolve(urbData, offsetof(usbdevfs_urb, buffer), static_cast<gsize>(urb->buffer_length), &error)
        : nullptr;
      self->Transfer(urb, buffer ? buffer->data : nullptr);
      // Completed at once; libusb reaps it next.
      self->Completed.push_back(UMOCKDEV_IOCTL_DATA(g_object_ref(urbData)));
      umockdev_ioctl_client_complete(client, 0, 0);
    }
    else if (request == USBDEVFS_REAPURB || request == USBDEVFS_REAPURBNDELAY)
    {
      if (self->Completed.empty())
      {
        umockdev_ioctl_client_complete(client, -1, EAGAIN);
      }
      else
      {
        UMockdevIoctlData* urbData = self->Completed.front();
        self->Completed.pop_front();
        // The argument points at the client's pointer: make that point at its URB.
        UMockdevIoctlData* slot = umockdev_ioctl_data_resolve(arg, 0, sizeof(void*), &error);
        umockdev_ioctl_data_set_ptr(slot, 0, urbData);
        g_object_unref(urbData);
        umockdev_ioctl_client_complete(client, 0, 0);
      }
    }
    else if (request == USBDEVFS_GETDRIVER || request == USBDEVFS_IOCTL)
    {
      // No kernel driver holds the interface.
      umockdev_ioctl_client_complete(client, -1, ENODATA);
    }
    else
    {
      std::fprintf(stderr, "fake Falcon: unexpected ioctl 0x%lx\n", request);
      umockdev_ioctl_client_complete(client, -1, ENOTTY);
    }
    if (error)
    {
      std::fprintf(stderr, "fake Falcon: %s\n", error->message);
      g_error_free(error);
    }
    return TRUE;
  }

  /// One URB's effect (called with the mutex held).
  void Transfer(usbdevfs_urb* urb, guint8* buffer)
  {
    urb->status = 0;
    urb->actual_length = 0;
    if (urb->type == USBDEVFS_URB_TYPE_CONTROL && buffer)
    {
      const int request = buffer[1];
      const int value = buffer[2] | (buffer[3] << 8);
      this->Controls.emplace_back(request, value);
      if (request == 3) // baud rate: which of the Falcon's modes the host wants
      {
        if (value == vtkFalconFirmwareLoader::HandshakeBaudRateDivisor)
        {
          this->Mode = BootLoader;
        }
        else if (value == vtkFalconFirmwareLoader::UploadBaudRateDivisor)
        {
          this->Mode = Upload;
          this->Firmware.clear();
          this->UploadStarted = false;
        }
        else if (value == vtkFalconFirmwareLoader::NormalBaudRateDivisor)
        {
          this->FirmwareLoaded = this->FirmwareLoaded || (this->Mode == Upload && this->Firmware.size() > 0);
          this->Mode = Frames;
        }
      }
      if (request == 0 && value == 1)
      {
        this->Pending.clear(); // receive buffer purged
      }
      return;
    }
    if (urb->type != USBDEVFS_URB_TYPE_BULK || !buffer)
    {
      urb->status = -EINVAL;
      return;
    }
    if (urb->endpoint == 0x02)
    {
      this->Received(buffer, urb->buffer_length);
      urb->actual_length = urb->buffer_length;
      return;
    }
    // Bulk IN: the FTDI's two modem-status bytes, then what is pending.
    const int room = std::max(0, urb->buffer_length - 2);
    const int count = std::min(room, static_cast<int>(this->Pending.size()));
    buffer[0] = 0x31;
    buffer[1] = 0x60;
    for (int n = 0; n < count; ++n)
    {
      buffer[2 + n] = this->Pending.front();
      this->Pending.pop_front();
    }
    urb->actual_length = 2 + count;
  }

  void Received(const guint8* data, int length)
  {
    if (this->Mode == BootLoader && !this->FirmwareLoaded)
    {
      if (length == 3 && data[0] == 0x0a && data[1] == 0x43 && data[2] == 0x0d)
      {
        for (unsigned char byte : { 0x0a, 0x44, 0x2c, 0x0d })
        {
          this->Pending.push_back(byte);
        }
      }
      return;
    }
    if (this->Mode == Upload)
    {
      // 'A' first, then the firmware; everything is echoed.
      for (int n = 0; n < length; ++n)
      {
        this->Pending.push_back(data[n]);
        if (this->UploadStarted)
        {
          this->Firmware.push_back(data[n]);
        }
      }
      this->UploadStarted = true;
      return;
    }
    if (this->Mode != Frames || !this->FirmwareLoaded)
    {
      return; // no firmware: nothing answers frames
    }
    short motors[3];
    int control = 0;
    if (length != 16 || vtkFalconFrameCodec::DecodeCommand(data, length, motors, control) != vtkFalconFrameCodec::FrameValid)
    {
      return;
    }
    ++this->CommandFrames;
    std::memcpy(this->Motors, motors, sizeof(motors));
    this->Control = control;
    if ((control & vtkFalconFrameCodec::Homing) && this->HomingFrames > 0)
    {
      --this->HomingFrames;
    }
    if (this->Silent)
    {
      return;
    }
    for (unsigned char byte : this->Garbage)
    {
      this->Pending.push_back(byte);
    }
    this->Garbage.clear();
    double angles[3] = { 0.0, 0.0, 0.0 };
    this->Kinematics->InverseKinematics(this->Position, angles);
    const short encoders[3] = { static_cast<short>(vtkFalconKinematics::AngleToEncoder(angles[0])),
      static_cast<short>(vtkFalconKinematics::AngleToEncoder(angles[1])), static_cast<short>(vtkFalconKinematics::AngleToEncoder(angles[2])) };
    unsigned char status[16];
    vtkFalconFrameCodec::EncodeStatus(encoders, this->Buttons, this->HomingFrames > 0 ? 0 : 0x7, status);
    this->Pending.insert(this->Pending.end(), status, status + 16);
  }

  static constexpr const char* Node = "/dev/bus/usb/002/005";
  UMockdevTestbed* Bed;
  std::string UsbPath;
  std::string NodeFile;
  std::vector<UMockdevIoctlBase*> Handlers;
  std::mutex Mutex;
  bool Plugged = false;
  int Mode = Idle;
  bool FirmwareLoaded = false;
  bool UploadStarted = false;
  bool Silent = false;
  std::vector<unsigned char> Firmware;
  std::vector<unsigned char> Garbage;
  std::deque<unsigned char> Pending;
  std::deque<UMockdevIoctlData*> Completed;
  std::vector<std::pair<int, int>> Controls;
  int CommandFrames = 0;
  short Motors[3] = { 0, 0, 0 };
  int Control = 0;
  int HomingFrames = 0;
  int Buttons = 0;
  double Position[3] = { 0.0, 0.0, 0.0 };
  vtkNew<vtkFalconKinematics> Kinematics;
};

#endif
