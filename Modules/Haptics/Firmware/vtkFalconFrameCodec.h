// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkFalconFrameCodec
 * @brief   The Novint Falcon's 16-byte frames, as pure functions.
 *
 * With Novint's firmware loaded, host and device exchange 16-byte frames:
 * '<', 14 payload bytes, '>'. Every payload byte is a 4-bit value plus 0x41
 * ('A'), except the device's status byte, which carries 7 bits plus 0x41.
 *
 *  - host to device: three signed 16-bit motor commands, 4 nibbles each,
 *    least significant first (bytes 1-12), and a control byte (13): homing
 *    0x01, LEDs green 0x02, blue 0x04, red 0x08; byte 14 is 0.
 *  - device to host: three signed 16-bit encoder counts (bytes 1-12), and a
 *    status byte (13) with the grip buttons in its low 4 bits and the homed
 *    state of each axis in bits 4-6.
 *
 * Public reference for the layout: libnifalcon (firmware/FalconFirmwareNovintSDK).
 * Decoding never trusts the device: a frame of the wrong length, without its
 * delimiters or with a payload byte out of range is refused with a result
 * code saying which, and the stream is resynchronised on the next '<'.
 *
 * @sa vtkNovintFalconDevice vtkFalconKinematics
 */

#ifndef vtkFalconFrameCodec_h
#define vtkFalconFrameCodec_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkFalconFrameCodec : public vtkObject
{
public:
  static vtkFalconFrameCodec* New();
  vtkTypeMacro(vtkFalconFrameCodec, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Bytes in a frame, each way.
  static constexpr int FrameSize = 16;

  /// Bits of the host's control byte.
  enum ControlBits
  {
    Homing = 0x01,
    GreenLED = 0x02,
    BlueLED = 0x04,
    RedLED = 0x08
  };

  /// Results of decoding a frame.
  enum DecodeResults
  {
    FrameValid = 0,
    FrameWrongLength,
    FrameBadDelimiters,
    FrameBadPayload
  };

  /// What a result code means, for messages.
  static const char* GetDecodeResultAsString(int result);

  /// Host to device: motor commands and control bits (only the low 4 bits are sent).
  static void EncodeCommand(const short motors[3], int control, unsigned char frame[16]);

  /// Reads a host frame back (for fake devices and tests). Returns a DecodeResults code.
  static int DecodeCommand(const unsigned char* frame, int length, short motors[3], int& control);

  /// Device to host: encoder counts, grip buttons (4 bits) and homed axes (3 bits).
  static void EncodeStatus(const short encoders[3], int buttons, int homedAxes, unsigned char frame[16]);

  /**
   * Reads a device frame. Returns a DecodeResults code; the outputs are
   * written only for a valid frame.
   */
  static int DecodeStatus(const unsigned char* frame, int length, short encoders[3], int& buttons, int& homedAxes);

  /**
   * Where the first complete frame of a byte stream starts: the first '<'
   * followed 15 bytes later by '>' whose payload is in range. -1 if there is
   * none yet; bytes before a returned start are garbage to drop.
   */
  static int FindStatusFrame(const unsigned char* data, int length);

protected:
  vtkFalconFrameCodec() = default;
  ~vtkFalconFrameCodec() override = default;

private:
  vtkFalconFrameCodec(const vtkFalconFrameCodec&) = delete;
  void operator=(const vtkFalconFrameCodec&) = delete;
};

#endif
