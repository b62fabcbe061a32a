// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkFalconFirmwareLoader
 * @brief   Uploads the Novint Falcon's firmware from a file the user supplies.
 *
 * The Falcon forgets its firmware at power-off. Novint's firmware binaries
 * are under a licence that forbids redistributing them: VolumeCutting does
 * not ship them; the user points FirmwareFileName at the file their Novint
 * driver or SDK installed. A missing or unreadable file stops the upload
 * with an error that says so and where to find it.
 *
 * The upload (public reference: libnifalcon's FalconCommLibUSB and
 * FalconFirmware): at 9600 baud, 8N1, DTR pulsed, the host sends
 * 0x0a 0x43 0x0d until the boot loader answers 0x0a 0x44 0x2c 0x0d; then at
 * about 140 kbaud with DTR low it sends 'A' and expects 'A' back; then the
 * file goes out in small blocks, each echoed back byte for byte (a
 * mismatch stops the upload); finally the link returns to normal mode
 * (latency 1 ms, the frame rate's baud rate).
 *
 * @sa vtkNovintFalconDevice vtkFTDIConnection
 */

#ifndef vtkFalconFirmwareLoader_h
#define vtkFalconFirmwareLoader_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <string> // For the error

class vtkFTDIConnection;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkFalconFirmwareLoader : public vtkObject
{
public:
  static vtkFalconFirmwareLoader* New();
  vtkTypeMacro(vtkFalconFirmwareLoader, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the firmware file (from the user's Novint installation). Default is none.
   */
  vtkSetStringMacro(FirmwareFileName);
  vtkGetStringMacro(FirmwareFileName);
  ///@}

  /**
   * Upload the firmware through an open link. False, with the reason in
   * GetErrorMessage(), if the file is missing or unreadable, the boot loader
   * does not answer, or an echo does not match.
   */
  bool Load(vtkFTDIConnection* link);

  /// Put the link in the normal (frame exchange) mode: 1 ms latency, the frame baud rate, buffers purged.
  static bool SetNormalMode(vtkFTDIConnection* link);

  /// Why the last Load failed.
  const char* GetErrorMessage() const { return this->ErrorMessage.c_str(); }

  /// Bytes of firmware the last Load sent.
  vtkGetMacro(NumberOfBytesLoaded, int);

  ///@{
  /// The wire facts, for the tests' fake devices.
  static constexpr int HandshakeBaudRateDivisor = 0x4138; // 9600 baud
  static constexpr int UploadBaudRateDivisor = 0x15;      // about 140 kbaud
  static constexpr int NormalBaudRateDivisor = 0x02;
  ///@}

protected:
  vtkFalconFirmwareLoader() = default;
  ~vtkFalconFirmwareLoader() override;

  /// Reads exactly length payload bytes (several packets) within the timeout per packet; false otherwise.
  bool ReadExactly(vtkFTDIConnection* link, unsigned char* data, int length, int timeoutMilliseconds);

  char* FirmwareFileName = nullptr;
  std::string ErrorMessage;
  int NumberOfBytesLoaded = 0;

private:
  vtkFalconFirmwareLoader(const vtkFalconFirmwareLoader&) = delete;
  void operator=(const vtkFalconFirmwareLoader&) = delete;
};

#endif
