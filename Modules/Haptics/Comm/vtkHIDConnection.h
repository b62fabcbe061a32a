// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHIDConnection
 * @brief   A HID device through hidapi (hidraw), with a thread that reads its reports.
 *
 * The communication part of the HID backends (SpaceMouse, foot switches),
 * as libnifalcon separates communication from the device. Open finds the
 * first device whose vendor and product IDs are in the list (or opens
 * DevicePath), then a reader thread hands every input report to the
 * listener, on that thread. A read that fails (the device was unplugged) is
 * reported to the listener once and ends the thread.
 *
 * Reads wait at most ReadTimeout milliseconds so that Close can stop the
 * thread; -1 makes them blocking, which the umockdev test bed needs (it never
 * signals a fake hidraw node as readable to poll): the device must then send
 * a report for Close to return.
 *
 * @sa vtkSpaceMouseDevice vtkFootSwitchDevice
 */

#ifndef vtkHIDConnection_h
#define vtkHIDConnection_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals
#include <string> // For the error

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHIDConnection : public vtkObject
{
public:
  static vtkHIDConnection* New();
  vtkTypeMacro(vtkHIDConnection, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

#ifndef __VTK_WRAP__
  /// Receives the reader thread's reports and its failure.
  class Listener
  {
  public:
    virtual ~Listener() = default;
    virtual void ReportReceived(const unsigned char* report, int length) = 0;
    virtual void ConnectionFailed(const char* reason) = 0;
  };

  /// Who receives the reports (set before Open; not owned).
  void SetListener(Listener* listener);
#endif

  ///@{
  /**
   * The devices to look for: vendor and product IDs (any of them), or a
   * hidraw path (when set, the IDs are not searched).
   */
  void AddDeviceID(int vendorID, int productID);
  void RemoveAllDeviceIDs();
  int GetNumberOfDeviceIDs() const;
  vtkSetStringMacro(DevicePath);
  vtkGetStringMacro(DevicePath);
  ///@}

  ///@{
  /**
   * Set/get the longest wait (ms) of one read; -1 for blocking reads. Default is 100.
   */
  vtkSetClampMacro(ReadTimeout, int, -1, 10000);
  vtkGetMacro(ReadTimeout, int);
  ///@}

  /**
   * Find and open the device and start reading. False, with the reason in
   * GetErrorMessage(), if no listed device is present or it cannot be opened.
   */
  bool Open();

  /// Stop reading and close the device.
  void Close();

  bool IsOpen() const;

  /// Send an output report (the first byte is the report ID). Bytes written, or -1.
  int Write(const unsigned char* data, int length);

  ///@{
  /// The opened device's IDs and path.
  vtkGetMacro(OpenedVendorID, int);
  vtkGetMacro(OpenedProductID, int);
  const char* GetOpenedPath() const;
  ///@}

  /// Why the last Open or Write failed.
  const char* GetErrorMessage() const;

protected:
  vtkHIDConnection();
  ~vtkHIDConnection() override;

  char* DevicePath = nullptr;
  int ReadTimeout = 100;
  int OpenedVendorID = 0;
  int OpenedProductID = 0;

private:
  struct Internals;
  std::unique_ptr<Internals> Internal;

  vtkHIDConnection(const vtkHIDConnection&) = delete;
  void operator=(const vtkHIDConnection&) = delete;
};

#endif
