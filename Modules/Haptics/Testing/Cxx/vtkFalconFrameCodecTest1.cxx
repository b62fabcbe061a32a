// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The Falcon's 16-byte frames against byte-level fixtures written out by
// hand from the layout (nibble + 'A', least significant nibble first), and
// every kind of garbage a device could send.
#include "vtkFalconFrameCodec.h"

#include <vtkAddonTestingMacros.h>

#include <vtkNew.h>

#include <cstring>
#include <iostream>
#include <vector>

int vtkFalconFrameCodecTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  // Host to device: motors 0x1234, -2 (0xFFFE), 0x7FFF; homing and red LED.
  // 0x1234 -> nibbles 4,3,2,1 -> 'E','D','C','B'; 0xFFFE -> 'O','P','P','P';
  // 0x7FFF -> 'P','P','P','H'; control 0x09 -> 'J'; byte 14 'A'.
  const unsigned char expectedCommand[16] = { '<', 'E', 'D', 'C', 'B', 'O', 'P', 'P', 'P', 'P', 'P', 'P', 'H', 'J', 'A', '>' };
  const short motors[3] = { 0x1234, -2, 0x7FFF };
  unsigned char frame[16];
  vtkFalconFrameCodec::EncodeCommand(motors, vtkFalconFrameCodec::Homing | vtkFalconFrameCodec::RedLED, frame);
  CHECK_BOOL(std::memcmp(frame, expectedCommand, 16) == 0, true);
  short decodedMotors[3] = { 0, 0, 0 };
  int control = -1;
  CHECK_INT(vtkFalconFrameCodec::DecodeCommand(frame, 16, decodedMotors, control), vtkFalconFrameCodec::FrameValid);
  CHECK_INT(decodedMotors[0], 0x1234);
  CHECK_INT(decodedMotors[1], -2);
  CHECK_INT(decodedMotors[2], 0x7FFF);
  CHECK_INT(control, 0x09);

  // Device to host: encoders -32768 (0x8000), 0, 258 (0x0102); grip buttons
  // 0b0101, axes 0 and 2 homed (0b101): status 0x55 -> 0x96.
  const unsigned char status[16] = { '<', 'A', 'A', 'A', 'I', 'A', 'A', 'A', 'A', 'C', 'A', 'B', 'A', 0x96, 'A', '>' };
  short encoders[3] = { 1, 1, 1 };
  int buttons = -1;
  int homed = -1;
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(status, 16, encoders, buttons, homed), vtkFalconFrameCodec::FrameValid);
  CHECK_INT(encoders[0], -32768);
  CHECK_INT(encoders[1], 0);
  CHECK_INT(encoders[2], 258);
  CHECK_INT(buttons, 5);
  CHECK_INT(homed, 5);
  unsigned char reencoded[16];
  vtkFalconFrameCodec::EncodeStatus(encoders, buttons, homed, reencoded);
  CHECK_BOOL(std::memcmp(reencoded, status, 16) == 0, true);

  // Every 16-bit value survives the round trip both ways.
  for (int value = -32768; value <= 32767; value += 7)
  {
    const short words[3] = { static_cast<short>(value), static_cast<short>(-value - 1), static_cast<short>(value / 3) };
    short back[3];
    int bits = 0;
    int axes = 0;
    vtkFalconFrameCodec::EncodeStatus(words, 0xA, 0x3, frame);
    if (vtkFalconFrameCodec::DecodeStatus(frame, 16, back, bits, axes) != vtkFalconFrameCodec::FrameValid || back[0] != words[0] ||
      back[1] != words[1] || back[2] != words[2] || bits != 0xA || axes != 0x3)
    {
      std::cerr << "status round trip failed at " << value << std::endl;
      return EXIT_FAILURE;
    }
  }

  // Garbage: each is refused with its reason and the outputs stay untouched.
  encoders[0] = encoders[1] = encoders[2] = 77;
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(status, 15, encoders, buttons, homed), vtkFalconFrameCodec::FrameWrongLength);
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(status, 17, encoders, buttons, homed), vtkFalconFrameCodec::FrameWrongLength);
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(nullptr, 16, encoders, buttons, homed), vtkFalconFrameCodec::FrameWrongLength);
  unsigned char broken[16];
  std::memcpy(broken, status, 16);
  broken[0] = '[';
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(broken, 16, encoders, buttons, homed), vtkFalconFrameCodec::FrameBadDelimiters);
  std::memcpy(broken, status, 16);
  broken[15] = 0;
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(broken, 16, encoders, buttons, homed), vtkFalconFrameCodec::FrameBadDelimiters);
  std::memcpy(broken, status, 16);
  broken[5] = 'Q'; // one past the largest nibble
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(broken, 16, encoders, buttons, homed), vtkFalconFrameCodec::FrameBadPayload);
  std::memcpy(broken, status, 16);
  broken[2] = '@'; // one below the smallest
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(broken, 16, encoders, buttons, homed), vtkFalconFrameCodec::FrameBadPayload);
  std::memcpy(broken, status, 16);
  broken[13] = 0x41 + 0x80; // a status bit the firmware never sets
  CHECK_INT(vtkFalconFrameCodec::DecodeStatus(broken, 16, encoders, buttons, homed), vtkFalconFrameCodec::FrameBadPayload);
  CHECK_INT(encoders[0], 77);
  // A host frame's control byte is a nibble: the status byte's range is refused there.
  CHECK_INT(vtkFalconFrameCodec::DecodeCommand(status, 16, decodedMotors, control), vtkFalconFrameCodec::FrameBadPayload);
  CHECK_STRING(vtkFalconFrameCodec::GetDecodeResultAsString(vtkFalconFrameCodec::FrameBadDelimiters), "missing '<' or '>'");

  // Resynchronisation in a stream: noise, a frame cut short, then a whole one.
  std::vector<unsigned char> stream = { 0x00, 0x41, '>', '<', 'A', 'B' };
  const size_t validStart = stream.size() + 7;
  const unsigned char noise[7] = { '<', 'P', 'P', 'P', '<', 'A', 0xFF };
  stream.insert(stream.end(), noise, noise + 7);
  stream.insert(stream.end(), status, status + 16);
  CHECK_INT(vtkFalconFrameCodec::FindStatusFrame(stream.data(), static_cast<int>(stream.size())), static_cast<int>(validStart));
  CHECK_INT(vtkFalconFrameCodec::FindStatusFrame(stream.data(), static_cast<int>(validStart) + 15), -1);
  CHECK_INT(vtkFalconFrameCodec::FindStatusFrame(nullptr, 40), -1);

  vtkNew<vtkFalconFrameCodec> codec;
  codec->Print(std::cout);
  return EXIT_SUCCESS;
}
