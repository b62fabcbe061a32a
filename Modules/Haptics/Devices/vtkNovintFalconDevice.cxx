// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkNovintFalconDevice.h"
#include "vtkFTDIConnection.h"
#include "vtkFalconFirmwareLoader.h"
#include "vtkFalconFrameCodec.h"
#include "vtkFalconKinematics.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticLatestValue.h"

#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>

vtkStandardNewMacro(vtkNovintFalconDevice);

namespace
{
using Clock = std::chrono::steady_clock;

struct ForceValue
{
  double Force[3];
};

constexpr int AllAxesHomed = 0x7;
constexpr int TransferTimeoutMilliseconds = 10;
/// Bytes kept between frames: a frame and a half is plenty to resynchronise.
constexpr int StreamCapacity = 256;
} // namespace

struct vtkNovintFalconDevice::Internals
{
  vtkNew<vtkFTDIConnection> Link;
  vtkNew<vtkFalconFirmwareLoader> Loader;
  vtkNew<vtkFalconKinematics> Kinematics;
  std::thread IO;
  std::atomic<bool> Stop{ false };
  vtkHapticLatestValue<ForceValue> Force;
  std::atomic<int> LEDs{ vtkFalconFrameCodec::GreenLED };
  std::atomic<int> HomedAxes{ 0 };

  // The I/O thread's state.
  double Position[3] = { 0.0, 0.0, 0.0 };
  bool HasPosition = false;
  unsigned char Stream[StreamCapacity];
  int StreamLength = 0;

  /// One command frame for the latest force.
  void Command(unsigned char frame[16])
  {
    ForceValue force = { { 0.0, 0.0, 0.0 } };
    this->Force.Load(force);
    short motors[3] = { 0, 0, 0 };
    const int homed = this->HomedAxes.load(std::memory_order_relaxed);
    if (homed == AllAxesHomed && this->HasPosition)
    {
      bool saturated = false;
      this->Kinematics->ForceToMotorCommands(this->Position, force.Force, motors, saturated);
    }
    const int control = this->LEDs.load(std::memory_order_relaxed) | (homed == AllAxesHomed ? 0 : vtkFalconFrameCodec::Homing);
    vtkFalconFrameCodec::EncodeCommand(motors, control, frame);
  }
};

//------------------------------------------------------------------------------
vtkNovintFalconDevice::vtkNovintFalconDevice()
  : Internal(new Internals)
{
  vtkHapticDeviceCapabilities* capabilities = this->Capabilities;
  capabilities->SetModelName("Novint Falcon");
  capabilities->SetManufacturer("Novint Technologies");
  capabilities->SetInputDegreesOfFreedom(3);
  capabilities->SetForceDegreesOfFreedom(3);
  capabilities->SetWorkspaceRadius(40.0);
  capabilities->SetMaximumForce(8.0);
  capabilities->SetMaximumStiffness(3.0);
  capabilities->SetMaximumDamping(0.02);
  capabilities->SetNumberOfButtons(4);
  capabilities->SetUpdateRate(1000.0);
  const ForceValue zero = { { 0.0, 0.0, 0.0 } };
  this->Internal->Force.Store(zero);
}

//------------------------------------------------------------------------------
vtkNovintFalconDevice::~vtkNovintFalconDevice()
{
  this->Close();
}

//------------------------------------------------------------------------------
void vtkNovintFalconDevice::SetFirmwareFileName(const char* fileName)
{
  this->Internal->Loader->SetFirmwareFileName(fileName);
  this->Modified();
}

const char* vtkNovintFalconDevice::GetFirmwareFileName()
{
  return this->Internal->Loader->GetFirmwareFileName();
}

vtkFTDIConnection* vtkNovintFalconDevice::GetConnection()
{
  return this->Internal->Link;
}

vtkFalconFirmwareLoader* vtkNovintFalconDevice::GetFirmwareLoader()
{
  return this->Internal->Loader;
}

vtkFalconKinematics* vtkNovintFalconDevice::GetKinematics()
{
  return this->Internal->Kinematics;
}

void vtkNovintFalconDevice::SetLEDs(int leds)
{
  this->Internal->LEDs = leds & (vtkFalconFrameCodec::GreenLED | vtkFalconFrameCodec::BlueLED | vtkFalconFrameCodec::RedLED);
}

int vtkNovintFalconDevice::GetLEDs() const
{
  return this->Internal->LEDs.load();
}

int vtkNovintFalconDevice::GetHomedAxes() const
{
  return this->Internal->HomedAxes.load();
}

//------------------------------------------------------------------------------
void vtkNovintFalconDevice::WriteForce(const double force[3])
{
  ForceValue value = { { force[0], force[1], force[2] } };
  this->Internal->Force.Store(value);
}

//------------------------------------------------------------------------------
bool vtkNovintFalconDevice::AnswersFrames()
{
  Internals& internal = *this->Internal;
  unsigned char frame[16];
  unsigned char received[64];
  unsigned char stream[StreamCapacity];
  int length = 0;
  for (int attempt = 0; attempt < 20; ++attempt)
  {
    internal.Command(frame);
    if (internal.Link->Write(frame, 16, TransferTimeoutMilliseconds) != 16)
    {
      return false;
    }
    const int count = internal.Link->Read(received, sizeof(received), TransferTimeoutMilliseconds);
    if (count < 0)
    {
      return false;
    }
    if (length + count > StreamCapacity)
    {
      length = 0;
    }
    std::memcpy(stream + length, received, static_cast<size_t>(count));
    length += count;
    if (vtkFalconFrameCodec::FindStatusFrame(stream, length) >= 0)
    {
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
bool vtkNovintFalconDevice::OpenDevice()
{
  Internals& internal = *this->Internal;
  this->FirmwareUploaded = false;
  internal.HasPosition = false;
  internal.StreamLength = 0;
  internal.HomedAxes = 0;
  const ForceValue zero = { { 0.0, 0.0, 0.0 } };
  internal.Force.Store(zero);
  auto fail = [this, &internal](const std::string& why) {
    this->SetErrorMessage(("Novint Falcon: " + why).c_str());
    internal.Link->Close();
    return false;
  };
  if (!internal.Link->Open())
  {
    return fail(internal.Link->GetErrorMessage());
  }
  if (!vtkFalconFirmwareLoader::SetNormalMode(internal.Link))
  {
    return fail(internal.Link->GetErrorMessage());
  }
  if (!this->AnswersFrames())
  {
    // No firmware (the Falcon was powered since the last upload): load it.
    if (!internal.Loader->Load(internal.Link))
    {
      return fail(internal.Loader->GetErrorMessage());
    }
    this->FirmwareUploaded = true;
    if (!this->AnswersFrames())
    {
      return fail("the firmware was uploaded but the Falcon does not answer frames");
    }
  }
  internal.Stop = false;
  internal.IO = std::thread([this]() { this->RunIO(); });
  return true;
}

//------------------------------------------------------------------------------
void vtkNovintFalconDevice::CloseDevice()
{
  Internals& internal = *this->Internal;
  internal.Stop = true;
  if (internal.IO.joinable())
  {
    internal.IO.join();
  }
  internal.Link->Close();
}

//------------------------------------------------------------------------------
void vtkNovintFalconDevice::RunIO()
{
  Internals& internal = *this->Internal;
  const Clock::duration period = std::chrono::milliseconds(1);
  const Clock::duration silence = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(this->SilenceTimeout));
  Clock::time_point deadline = Clock::now();
  Clock::time_point lastValid = deadline;
  const double identity[4] = { 1.0, 0.0, 0.0, 0.0 };
  unsigned char frame[16];
  unsigned char received[64];
  while (!internal.Stop.load(std::memory_order_acquire))
  {
    internal.Command(frame);
    const int written = internal.Link->Write(frame, 16, TransferTimeoutMilliseconds);
    const int count = written == 16 ? internal.Link->Read(received, sizeof(received), TransferTimeoutMilliseconds) : -1;
    if (written < 0 || count < 0)
    {
      if (internal.Link->IsDeviceGone())
      {
        this->ReportLost((std::string("its USB transfers failed, unplugged? (") + internal.Link->GetErrorMessage() + ")").c_str());
        return;
      }
    }
    else
    {
      if (internal.StreamLength + count > StreamCapacity)
      {
        // Far more bytes than frames: drop what is there.
        internal.StreamLength = 0;
        this->ReportRejectedInput();
      }
      std::memcpy(internal.Stream + internal.StreamLength, received, static_cast<size_t>(count));
      internal.StreamLength += count;
    }
    // Every complete frame in the stream; garbage before one is dropped.
    for (;;)
    {
      const int start = vtkFalconFrameCodec::FindStatusFrame(internal.Stream, internal.StreamLength);
      if (start < 0)
      {
        // Keep at most a frame's worth: a frame may still be arriving.
        const int keep = std::min(internal.StreamLength, vtkFalconFrameCodec::FrameSize - 1);
        if (internal.StreamLength > keep)
        {
          this->ReportRejectedInput();
          std::memmove(internal.Stream, internal.Stream + internal.StreamLength - keep, static_cast<size_t>(keep));
          internal.StreamLength = keep;
        }
        break;
      }
      if (start > 0)
      {
        this->ReportRejectedInput();
      }
      short encoders[3];
      int buttons = 0;
      int homed = 0;
      vtkFalconFrameCodec::DecodeStatus(internal.Stream + start, vtkFalconFrameCodec::FrameSize, encoders, buttons, homed);
      const int consumed = start + vtkFalconFrameCodec::FrameSize;
      std::memmove(internal.Stream, internal.Stream + consumed, static_cast<size_t>(internal.StreamLength - consumed));
      internal.StreamLength -= consumed;
      lastValid = Clock::now();
      internal.HomedAxes.store(homed, std::memory_order_relaxed);
      if (homed != AllAxesHomed)
      {
        this->PublishAbsence();
        continue;
      }
      const int counts[3] = { encoders[0], encoders[1], encoders[2] };
      double position[3];
      if (internal.Kinematics->EncodersToPosition(counts, position, internal.HasPosition ? internal.Position : nullptr))
      {
        std::copy(position, position + 3, internal.Position);
        internal.HasPosition = true;
        this->PublishSample(position, identity, static_cast<unsigned int>(buttons));
      }
      else
      {
        this->ReportRejectedInput();
      }
    }
    if (Clock::now() - lastValid > silence)
    {
      this->ReportLost("it sent no valid frame for too long (stopped answering)");
      return;
    }
    deadline += period;
    const Clock::time_point now = Clock::now();
    if (deadline > now)
    {
      std::this_thread::sleep_until(deadline);
    }
    else
    {
      deadline = now;
    }
  }
  // Leaving: the motors get no force.
  const ForceValue zero = { { 0.0, 0.0, 0.0 } };
  internal.Force.Store(zero);
  internal.Command(frame);
  internal.Link->Write(frame, 16, TransferTimeoutMilliseconds);
}

//------------------------------------------------------------------------------
void vtkNovintFalconDevice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FirmwareFileName: " << (this->GetFirmwareFileName() ? this->GetFirmwareFileName() : "(none)") << "\n";
  os << indent << "LEDs: " << this->GetLEDs() << "\n";
  os << indent << "HomedAxes: " << this->GetHomedAxes() << "\n";
  os << indent << "SilenceTimeout: " << this->SilenceTimeout << " s\n";
  os << indent << "FirmwareUploaded: " << (this->FirmwareUploaded ? "yes" : "no") << "\n";
}
