// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkFTDIConnection
 * @brief   An FTDI USB serial chip driven through plain libusb.
 *
 * The Novint Falcon talks through an FTDI chip (0403:cb48). No FTDI driver
 * is needed: its serial settings are vendor control transfers (request type
 * 0x40: 0 reset and purge, 1 modem control, 2 flow control, 3 baud rate
 * divisor, 4 data format, 9 latency timer) on interface 0, data goes out on
 * bulk endpoint 0x02 and comes in on 0x81, where every USB packet starts
 * with two modem-status bytes that Read removes. Public reference:
 * libnifalcon's FalconCommLibUSB.
 *
 * Used by one thread at a time (the device's I/O thread once it runs).
 *
 * @sa vtkNovintFalconDevice vtkFalconFirmwareLoader
 */

#ifndef vtkFTDIConnection_h
#define vtkFTDIConnection_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkFTDIConnection : public vtkObject
{
public:
  static vtkFTDIConnection* New();
  vtkTypeMacro(vtkFTDIConnection, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the device to open: IDs and which of several (0: the first).
   * Defaults are the Novint Falcon's 0403:cb48, index 0.
   */
  vtkSetMacro(VendorID, int);
  vtkGetMacro(VendorID, int);
  vtkSetMacro(ProductID, int);
  vtkGetMacro(ProductID, int);
  vtkSetClampMacro(DeviceIndex, int, 0, 127);
  vtkGetMacro(DeviceIndex, int);
  ///@}

  /// Open and claim interface 0. False, with the reason in GetErrorMessage(), otherwise.
  bool Open();
  void Close();
  bool IsOpen() const;

  ///@{
  /**
   * FTDI settings, as vendor control transfers. False (reason in
   * GetErrorMessage()) if the device refused or is gone.
   */
  bool Purge(bool receive, bool transmit);
  bool SetLatencyTimer(int milliseconds);
  bool SetBaudRateDivisor(int divisor);
  bool SetLineProperties8N1();
  bool DisableFlowControl();
  bool SetDTR(bool high);
  bool SetRTS(bool high);
  ///@}

  /// Send bytes on the bulk OUT endpoint. Bytes sent, or -1.
  int Write(const unsigned char* data, int length, int timeoutMilliseconds);

  /**
   * Receive up to capacity payload bytes (the modem-status bytes of each
   * packet removed). Bytes received (0 if the chip had nothing), or -1 on
   * a USB error: see IsDeviceGone().
   */
  int Read(unsigned char* data, int capacity, int timeoutMilliseconds);

  /// Whether the last failure means the device is no longer there (unplugged).
  bool IsDeviceGone() const;

  /// What the last failure was.
  const char* GetErrorMessage() const;

protected:
  vtkFTDIConnection();
  ~vtkFTDIConnection() override;

  bool Control(int request, int value, const char* what);

  int VendorID = 0x0403;
  int ProductID = 0xcb48;
  int DeviceIndex = 0;

private:
  struct Internals;
  std::unique_ptr<Internals> Internal;

  vtkFTDIConnection(const vtkFTDIConnection&) = delete;
  void operator=(const vtkFTDIConnection&) = delete;
};

#endif
