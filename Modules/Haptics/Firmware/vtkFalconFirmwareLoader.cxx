// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkFalconFirmwareLoader.h"
#include "vtkFTDIConnection.h"

#include "vtkObjectFactory.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

vtkStandardNewMacro(vtkFalconFirmwareLoader);

namespace
{
const unsigned char Probe[3] = { 0x0a, 0x43, 0x0d };
const unsigned char BootLoaderAnswer[4] = { 0x0a, 0x44, 0x2c, 0x0d };
constexpr unsigned char Ready = 'A';
// Blocks small enough that block and echo each fit one USB packet.
constexpr int BlockSize = 58;
constexpr int HandshakeAttempts = 50;
constexpr int TimeoutMilliseconds = 1000;
} // namespace

//------------------------------------------------------------------------------
vtkFalconFirmwareLoader::~vtkFalconFirmwareLoader()
{
  this->SetFirmwareFileName(nullptr);
}

//------------------------------------------------------------------------------
bool vtkFalconFirmwareLoader::SetNormalMode(vtkFTDIConnection* link)
{
  return link && link->SetLatencyTimer(1) && link->SetBaudRateDivisor(NormalBaudRateDivisor) && link->Purge(true, true);
}

//------------------------------------------------------------------------------
bool vtkFalconFirmwareLoader::ReadExactly(vtkFTDIConnection* link, unsigned char* data, int length, int timeoutMilliseconds)
{
  int received = 0;
  int silentReads = 0;
  unsigned char packet[64];
  while (received < length)
  {
    const int count = link->Read(packet, sizeof(packet), timeoutMilliseconds);
    if (count < 0)
    {
      return false;
    }
    if (count == 0 && ++silentReads > 50)
    {
      return false;
    }
    const int used = std::min(count, length - received);
    std::memcpy(data + received, packet, static_cast<size_t>(used));
    received += used;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkFalconFirmwareLoader::Load(vtkFTDIConnection* link)
{
  this->ErrorMessage.clear();
  this->NumberOfBytesLoaded = 0;
  const std::string fileName = this->FirmwareFileName ? this->FirmwareFileName : "";
  if (fileName.empty())
  {
    this->ErrorMessage = "the Novint Falcon needs its firmware uploaded after every power-on, and no firmware file is set. VolumeCutting "
                         "does not ship Novint's firmware (its licence forbids redistribution): set the firmware file name to the file "
                         "your Novint driver or SDK installed (for example nvent_firmware.bin)";
    return false;
  }
  std::ifstream file(fileName, std::ios::binary);
  if (!file)
  {
    this->ErrorMessage = "the Novint Falcon firmware file '" + fileName + "' cannot be read (" + std::strerror(errno) +
      "). VolumeCutting does not ship Novint's firmware: point the firmware file name at the file your Novint driver or SDK installed";
    return false;
  }
  const std::vector<unsigned char> firmware((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (firmware.empty())
  {
    this->ErrorMessage = "the Novint Falcon firmware file '" + fileName + "' is empty";
    return false;
  }
  if (!link || !link->IsOpen())
  {
    this->ErrorMessage = "the Falcon's USB link is not open";
    return false;
  }
  auto linkError = [this, link](const char* step) {
    this->ErrorMessage = std::string("uploading the Falcon's firmware failed while ") + step + ": " + link->GetErrorMessage();
    return false;
  };
  // The boot loader listens at 9600 baud, 8N1, after a DTR pulse.
  if (!link->Purge(true, true) || !link->SetLatencyTimer(16) || !link->SetBaudRateDivisor(HandshakeBaudRateDivisor) ||
    !link->SetLineProperties8N1() || !link->DisableFlowControl() || !link->SetRTS(false) || !link->SetDTR(false) || !link->SetDTR(true))
  {
    return linkError("setting the link up");
  }
  bool answered = false;
  for (int attempt = 0; attempt < HandshakeAttempts && !answered; ++attempt)
  {
    if (link->Write(Probe, 3, TimeoutMilliseconds) != 3)
    {
      return linkError("probing the boot loader");
    }
    unsigned char reply[64];
    const int count = link->Read(reply, sizeof(reply), TimeoutMilliseconds);
    if (count < 0)
    {
      return linkError("waiting for the boot loader");
    }
    // Some hosts see a leading zero byte too: the answer ends the reply.
    answered = count >= 4 && std::memcmp(reply + count - 4, BootLoaderAnswer, 4) == 0;
  }
  if (!answered)
  {
    this->ErrorMessage = "the Falcon's boot loader did not answer (is it powered, and its firmware not loaded already?)";
    return false;
  }
  if (!link->SetDTR(false) || !link->SetBaudRateDivisor(UploadBaudRateDivisor))
  {
    return linkError("switching to the upload speed");
  }
  unsigned char ready = Ready;
  unsigned char echo = 0;
  if (link->Write(&ready, 1, TimeoutMilliseconds) != 1 || !this->ReadExactly(link, &echo, 1, TimeoutMilliseconds) || echo != Ready)
  {
    this->ErrorMessage = "the Falcon's boot loader did not confirm the upload speed";
    return false;
  }
  std::vector<unsigned char> echoed(BlockSize);
  for (size_t offset = 0; offset < firmware.size(); offset += BlockSize)
  {
    const int length = static_cast<int>(std::min<size_t>(BlockSize, firmware.size() - offset));
    if (link->Write(firmware.data() + offset, length, TimeoutMilliseconds) != length)
    {
      return linkError("sending the firmware");
    }
    if (!this->ReadExactly(link, echoed.data(), length, TimeoutMilliseconds))
    {
      this->ErrorMessage = "the Falcon stopped echoing the firmware at byte " + std::to_string(offset);
      return false;
    }
    for (int n = 0; n < length; ++n)
    {
      if (echoed[n] != firmware[offset + n])
      {
        this->ErrorMessage = "the Falcon echoed firmware byte " + std::to_string(offset + n) + " wrongly: the upload is corrupt (try again)";
        return false;
      }
    }
    this->NumberOfBytesLoaded += length;
  }
  if (!SetNormalMode(link))
  {
    return linkError("returning to normal mode");
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkFalconFirmwareLoader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FirmwareFileName: " << (this->FirmwareFileName ? this->FirmwareFileName : "(none)") << "\n";
  os << indent << "NumberOfBytesLoaded: " << this->NumberOfBytesLoaded << "\n";
}
