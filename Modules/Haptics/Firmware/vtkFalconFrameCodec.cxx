// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkFalconFrameCodec.h"

#include "vtkObjectFactory.h"

#include <cstdint>

vtkStandardNewMacro(vtkFalconFrameCodec);

namespace
{
constexpr unsigned char Start = '<';
constexpr unsigned char End = '>';
constexpr unsigned char Offset = 0x41;

void EncodeWords(const short values[3], unsigned char frame[16])
{
  for (int word = 0; word < 3; ++word)
  {
    const std::uint16_t bits = static_cast<std::uint16_t>(values[word]);
    for (int nibble = 0; nibble < 4; ++nibble)
    {
      frame[1 + 4 * word + nibble] = static_cast<unsigned char>(((bits >> (4 * nibble)) & 0xF) + Offset);
    }
  }
}

bool IsNibble(unsigned char byte)
{
  return byte >= Offset && byte <= Offset + 0xF;
}

void DecodeWords(const unsigned char* frame, short values[3])
{
  for (int word = 0; word < 3; ++word)
  {
    std::uint16_t bits = 0;
    for (int nibble = 0; nibble < 4; ++nibble)
    {
      bits = static_cast<std::uint16_t>(bits | ((frame[1 + 4 * word + nibble] - Offset) & 0xF) << (4 * nibble));
    }
    values[word] = static_cast<short>(static_cast<std::int16_t>(bits));
  }
}

/// Checks what both directions share; statusByteBits: how many bits byte 13 may carry.
int CheckFrame(const unsigned char* frame, int length, int statusByteBits)
{
  if (!frame || length != vtkFalconFrameCodec::FrameSize)
  {
    return vtkFalconFrameCodec::FrameWrongLength;
  }
  if (frame[0] != Start || frame[15] != End)
  {
    return vtkFalconFrameCodec::FrameBadDelimiters;
  }
  for (int n = 1; n <= 14; ++n)
  {
    if (n == 13)
    {
      if (frame[n] < Offset || frame[n] - Offset >= (1 << statusByteBits))
      {
        return vtkFalconFrameCodec::FrameBadPayload;
      }
    }
    else if (!IsNibble(frame[n]))
    {
      return vtkFalconFrameCodec::FrameBadPayload;
    }
  }
  return vtkFalconFrameCodec::FrameValid;
}
} // namespace

//------------------------------------------------------------------------------
const char* vtkFalconFrameCodec::GetDecodeResultAsString(int result)
{
  switch (result)
  {
    case FrameValid:
      return "valid";
    case FrameWrongLength:
      return "wrong length";
    case FrameBadDelimiters:
      return "missing '<' or '>'";
    case FrameBadPayload:
      return "payload byte out of range";
    default:
      return "unknown";
  }
}

//------------------------------------------------------------------------------
void vtkFalconFrameCodec::EncodeCommand(const short motors[3], int control, unsigned char frame[16])
{
  frame[0] = Start;
  EncodeWords(motors, frame);
  frame[13] = static_cast<unsigned char>((control & 0xF) + Offset);
  frame[14] = Offset;
  frame[15] = End;
}

//------------------------------------------------------------------------------
int vtkFalconFrameCodec::DecodeCommand(const unsigned char* frame, int length, short motors[3], int& control)
{
  const int result = CheckFrame(frame, length, 4);
  if (result == FrameValid)
  {
    DecodeWords(frame, motors);
    control = frame[13] - Offset;
  }
  return result;
}

//------------------------------------------------------------------------------
void vtkFalconFrameCodec::EncodeStatus(const short encoders[3], int buttons, int homedAxes, unsigned char frame[16])
{
  frame[0] = Start;
  EncodeWords(encoders, frame);
  frame[13] = static_cast<unsigned char>(((buttons & 0xF) | ((homedAxes & 0x7) << 4)) + Offset);
  frame[14] = Offset;
  frame[15] = End;
}

//------------------------------------------------------------------------------
int vtkFalconFrameCodec::DecodeStatus(const unsigned char* frame, int length, short encoders[3], int& buttons, int& homedAxes)
{
  const int result = CheckFrame(frame, length, 7);
  if (result == FrameValid)
  {
    DecodeWords(frame, encoders);
    const int status = frame[13] - Offset;
    buttons = status & 0xF;
    homedAxes = (status >> 4) & 0x7;
  }
  return result;
}

//------------------------------------------------------------------------------
int vtkFalconFrameCodec::FindStatusFrame(const unsigned char* data, int length)
{
  for (int start = 0; data && start + FrameSize <= length; ++start)
  {
    if (data[start] == Start && CheckFrame(data + start, FrameSize, 7) == FrameValid)
    {
      return start;
    }
  }
  return -1;
}

//------------------------------------------------------------------------------
void vtkFalconFrameCodec::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FrameSize: " << FrameSize << "\n";
}
