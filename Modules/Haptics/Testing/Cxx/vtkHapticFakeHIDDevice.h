// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Shared by the haptics tests: a fake USB HID device in user space
// (umockdev test bed, run under libumockdev-preload): sysfs entries that
// hidapi's hidraw backend enumerates, and a /dev/hidrawN node whose ioctls,
// reads and writes this object answers. Reads are completed from a feeder
// thread with the queued reports, or the streaming report, as a device
// sends them; umockdev never signals the node readable to poll, so the
// backends are tested with blocking reads (vtkHIDConnection ReadTimeout -1).
#ifndef vtkHapticFakeHIDDevice_h
#define vtkHapticFakeHIDDevice_h

#include <umockdev.h>

#include <linux/hidraw.h>
#include <linux/input.h>
#include <sys/ioctl.h>

#include <atomic>
#include <glib/gstdio.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

class vtkHapticFakeHIDDevice
{
public:
  vtkHapticFakeHIDDevice(UMockdevTestbed* bed, int vendor, int product, int index, const std::vector<unsigned char>& descriptor)
    : Bed(bed)
    , Vendor(vendor)
    , Product(product)
    , Index(index)
    , Descriptor(descriptor)
  {
    this->Feeder = std::thread([this]() { this->Feed(); });
  }

  ~vtkHapticFakeHIDDevice()
  {
    this->Stop = true;
    this->Feeder.join();
    this->Unplug();
    for (UMockdevIoctlBase* handler : this->Handlers)
    {
      g_object_unref(handler);
    }
  }

  std::string DevNode() const { return "/dev/hidraw" + std::to_string(this->Index); }

  /// Add the device to the test bed (again after Unplug: a replug).
  bool Plug()
  {
    char vendor[8];
    char product[8];
    char hidId[32];
    char hidName[32];
    std::snprintf(vendor, sizeof(vendor), "%04x", this->Vendor);
    std::snprintf(product, sizeof(product), "%04x", this->Product);
    std::snprintf(hidId, sizeof(hidId), "0003:%08X:%08X", this->Vendor, this->Product);
    std::snprintf(hidName, sizeof(hidName), "0003:%04X:%04X.%04d", this->Vendor, this->Product, this->Index + 1);
    const std::string usbName = "1-" + std::to_string(this->Index + 1);
    const std::string node = this->DevNode();
    gchar* usb = umockdev_testbed_add_device(this->Bed, "usb", usbName.c_str(), nullptr, "idVendor", vendor, "idProduct", product,
      "manufacturer", "Fake", "product", "Fake HID", "bcdDevice", "0100", nullptr, "DEVTYPE", "usb_device", nullptr);
    gchar* intf = umockdev_testbed_add_device(
      this->Bed, "usb", (usbName + ":1.0").c_str(), usb, "bInterfaceNumber", "00", nullptr, "DEVTYPE", "usb_interface", nullptr);
    gchar* hid = umockdev_testbed_add_device(this->Bed, "hid", hidName, intf, nullptr, "HID_ID", hidId, "HID_NAME", "Fake HID", "HID_UNIQ", "",
      "HID_PHYS", "usb-fake/input0", nullptr);
    umockdev_testbed_set_attribute_binary(this->Bed, hid, "report_descriptor", this->Descriptor.data(), static_cast<gssize>(this->Descriptor.size()));
    gchar* raw = umockdev_testbed_add_device(
      this->Bed, "hidraw", ("hidraw" + std::to_string(this->Index)).c_str(), hid, nullptr, "DEVNAME", node.c_str(), nullptr);
    this->UsbPath = usb ? usb : "";
    // Children first when removed.
    this->Paths.clear();
    for (gchar* path : { raw, hid, intf, usb })
    {
      this->Paths.emplace_back(path ? path : "");
      g_free(path);
    }
    // The node the preload redirects /dev/hidrawN to (its ioctls, reads and
    // writes go to the handler's socket).
    gchar* root = umockdev_testbed_get_root_dir(this->Bed);
    this->NodeFile = std::string(root) + node;
    g_free(root);
    gchar* folder = g_path_get_dirname(this->NodeFile.c_str());
    g_mkdir_with_parents(folder, 0755);
    g_free(folder);
    g_file_set_contents(this->NodeFile.c_str(), "", 0, nullptr);
    // A new handler per plug; the old ones live on (a client still connected
    // to one must not lose its socket), released with this object.
    UMockdevIoctlBase* handler = umockdev_ioctl_base_new();
    this->Handlers.push_back(handler);
    g_signal_connect(handler, "handle-ioctl", G_CALLBACK(OnIoctl), this);
    g_signal_connect(handler, "handle-read", G_CALLBACK(OnRead), this);
    g_signal_connect(handler, "handle-write", G_CALLBACK(OnWrite), this);
    GError* error = nullptr;
    const bool attached = umockdev_testbed_attach_ioctl(this->Bed, node.c_str(), handler, &error);
    if (error)
    {
      std::fprintf(stderr, "attaching the fake hidraw node failed: %s\n", error->message);
      g_error_free(error);
    }
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Plugged = attached && !this->UsbPath.empty();
    return this->Plugged;
  }

  /// Remove the device: a pending read fails as on a real unplug.
  void Unplug()
  {
    {
      std::lock_guard<std::mutex> lock(this->Mutex);
      if (!this->Plugged)
      {
        return;
      }
      this->Plugged = false;
      if (this->PendingRead)
      {
        umockdev_ioctl_client_complete(this->PendingRead, -1, ENODEV);
        g_object_unref(this->PendingRead);
        this->PendingRead = nullptr;
      }
    }
    umockdev_testbed_detach_ioctl(this->Bed, this->DevNode().c_str(), nullptr);
    for (const std::string& path : this->Paths)
    {
      if (!path.empty())
      {
        umockdev_testbed_remove_device(this->Bed, path.c_str());
      }
    }
    g_unlink(this->NodeFile.c_str());
  }

  /// A report to deliver at the next read.
  void Send(const std::vector<unsigned char>& report)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Queue.push_back(report);
  }

  /// The report delivered whenever nothing is queued (empty: none).
  void SetStream(const std::vector<unsigned char>& report)
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    this->Stream = report;
  }

  /// Whether every queued report was read.
  bool QueueEmpty()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    return this->Queue.empty();
  }

  std::vector<std::vector<unsigned char>> Written()
  {
    std::lock_guard<std::mutex> lock(this->Mutex);
    return this->Writes;
  }

private:
  static gboolean OnIoctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data)
  {
    vtkHapticFakeHIDDevice* self = static_cast<vtkHapticFakeHIDDevice*>(data);
    const gulong request = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    GError* error = nullptr;
    if (request == HIDIOCGRDESCSIZE)
    {
      UMockdevIoctlData* size = umockdev_ioctl_data_resolve(arg, 0, sizeof(int), &error);
      *reinterpret_cast<int*>(size->data) = static_cast<int>(self->Descriptor.size());
      umockdev_ioctl_client_complete(client, 0, 0);
    }
    else if (request == HIDIOCGRDESC)
    {
      UMockdevIoctlData* descriptor = umockdev_ioctl_data_resolve(arg, 0, sizeof(hidraw_report_descriptor), &error);
      hidraw_report_descriptor* value = reinterpret_cast<hidraw_report_descriptor*>(descriptor->data);
      value->size = static_cast<__u32>(self->Descriptor.size());
      std::memcpy(value->value, self->Descriptor.data(), self->Descriptor.size());
      umockdev_ioctl_client_complete(client, 0, 0);
    }
    else if (request == HIDIOCGRAWINFO)
    {
      UMockdevIoctlData* info = umockdev_ioctl_data_resolve(arg, 0, sizeof(hidraw_devinfo), &error);
      hidraw_devinfo* value = reinterpret_cast<hidraw_devinfo*>(info->data);
      value->bustype = BUS_USB;
      value->vendor = static_cast<__s16>(self->Vendor);
      value->product = static_cast<__s16>(self->Product);
      umockdev_ioctl_client_complete(client, 0, 0);
    }
    else
    {
      umockdev_ioctl_client_complete(client, -1, ENOTTY);
    }
    if (error)
    {
      g_error_free(error);
    }
    return TRUE;
  }

  static gboolean OnRead(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data)
  {
    vtkHapticFakeHIDDevice* self = static_cast<vtkHapticFakeHIDDevice*>(data);
    std::lock_guard<std::mutex> lock(self->Mutex);
    if (!self->Plugged)
    {
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return TRUE;
    }
    // Answered later, by the feeder, as a device answers when it has a report.
    self->PendingRead = UMOCKDEV_IOCTL_CLIENT(g_object_ref(client));
    return TRUE;
  }

  static gboolean OnWrite(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer data)
  {
    vtkHapticFakeHIDDevice* self = static_cast<vtkHapticFakeHIDDevice*>(data);
    UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
    std::lock_guard<std::mutex> lock(self->Mutex);
    if (!self->Plugged)
    {
      umockdev_ioctl_client_complete(client, -1, ENODEV);
      return TRUE;
    }
    self->Writes.emplace_back(arg->data, arg->data + arg->data_len);
    umockdev_ioctl_client_complete(client, arg->data_len, 0);
    return TRUE;
  }

  void Feed()
  {
    while (!this->Stop.load())
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      std::lock_guard<std::mutex> lock(this->Mutex);
      if (!this->PendingRead || !this->Plugged || (this->Queue.empty() && this->Stream.empty()))
      {
        continue;
      }
      const std::vector<unsigned char> report = this->Queue.empty() ? this->Stream : this->Queue.front();
      if (!this->Queue.empty())
      {
        this->Queue.pop_front();
      }
      UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(this->PendingRead);
      const int length = std::min(static_cast<int>(report.size()), arg->data_len);
      std::memcpy(arg->data, report.data(), static_cast<size_t>(length));
      umockdev_ioctl_client_complete(this->PendingRead, length, 0);
      g_object_unref(this->PendingRead);
      this->PendingRead = nullptr;
    }
  }

  UMockdevTestbed* Bed;
  int Vendor;
  int Product;
  int Index;
  std::vector<unsigned char> Descriptor;
  std::string UsbPath;
  std::vector<std::string> Paths;
  std::string NodeFile;
  std::vector<UMockdevIoctlBase*> Handlers;
  std::mutex Mutex;
  bool Plugged = false;
  UMockdevIoctlClient* PendingRead = nullptr;
  std::deque<std::vector<unsigned char>> Queue;
  std::vector<unsigned char> Stream;
  std::vector<std::vector<unsigned char>> Writes;
  std::thread Feeder;
  std::atomic<bool> Stop{ false };
};

#endif
