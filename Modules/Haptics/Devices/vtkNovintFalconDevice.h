// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkNovintFalconDevice
 * @brief   The Novint Falcon over plain libusb: 3-DOF position, 3-DOF force, about 1 kHz.
 *
 * Composed as libnifalcon composes a FalconDevice: communication
 * (vtkFTDIConnection), firmware (vtkFalconFirmwareLoader and the frame
 * codec vtkFalconFrameCodec) and kinematics (vtkFalconKinematics).
 *
 * Open claims the FTDI chip, and if the Falcon does not answer frames
 * (its firmware is lost at every power-off) uploads the firmware from
 * FirmwareFileName, which the user supplies (it is never shipped); then an
 * I/O thread exchanges a command frame for a status frame every
 * millisecond: the latest force becomes motor commands at the handle's
 * position (J^T F, scaled into the 16-bit range), encoders become the
 * handle's position by forward kinematics. Until all three axes are homed
 * (move the handle out and back in), samples are published as absent and
 * the homing bit is sent.
 *
 * Bad input: garbage bytes between frames are dropped and counted; a
 * Falcon that sends no valid frame for SilenceTimeout seconds, or whose
 * transfers fail because it was unplugged, is reported lost (the force is
 * zero from then on) and reopened by ProcessConnectionEvents when it is
 * back.
 *
 * Figures (CHAI3D's for the Falcon): 8 N, 3 N/mm, 0.02 N s/mm, a workspace
 * of 40 mm radius, 4 grip buttons.
 *
 * @sa vtkHapticDevice vtkFalconKinematics vtkFalconFrameCodec
 */

#ifndef vtkNovintFalconDevice_h
#define vtkNovintFalconDevice_h

#include "vtkHapticDevice.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class vtkFTDIConnection;
class vtkFalconFirmwareLoader;
class vtkFalconKinematics;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkNovintFalconDevice : public vtkHapticDevice
{
public:
  static vtkNovintFalconDevice* New();
  vtkTypeMacro(vtkNovintFalconDevice, vtkHapticDevice);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the firmware file from the user's Novint installation (used
   * only when the Falcon has none loaded). Default is none.
   */
  void SetFirmwareFileName(const char* fileName);
  const char* GetFirmwareFileName();
  ///@}

  /// The parts: USB link (IDs, which Falcon), firmware loader, kinematics.
  vtkFTDIConnection* GetConnection();
  vtkFalconFirmwareLoader* GetFirmwareLoader();
  vtkFalconKinematics* GetKinematics();

  ///@{
  /**
   * Set/get the LEDs to light (vtkFalconFrameCodec::GreenLED | BlueLED |
   * RedLED); any thread. Default is green.
   */
  void SetLEDs(int leds);
  int GetLEDs() const;
  ///@}

  /// The homed axes (bit n: axis n) the Falcon last reported.
  int GetHomedAxes() const;

  ///@{
  /**
   * Set/get how long (s) the Falcon may send no valid frame before it is
   * reported lost (set while closed). Default is 0.1.
   */
  vtkSetClampMacro(SilenceTimeout, double, 0.005, 60.0);
  vtkGetMacro(SilenceTimeout, double);
  ///@}

  /// Whether the last Open had to upload the firmware.
  vtkGetMacro(FirmwareUploaded, bool);

protected:
  vtkNovintFalconDevice();
  ~vtkNovintFalconDevice() override;

  bool OpenDevice() override;
  void CloseDevice() override;
  void WriteForce(const double force[3]) override;

  /// Whether the Falcon answers command frames with status frames now.
  bool AnswersFrames();

  double SilenceTimeout = 0.1;
  bool FirmwareUploaded = false;

private:
  void RunIO();

  struct Internals;
  std::unique_ptr<Internals> Internal;

  vtkNovintFalconDevice(const vtkNovintFalconDevice&) = delete;
  void operator=(const vtkNovintFalconDevice&) = delete;
};

#endif
