// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkReplayHapticDevice.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticRecorder.h"

#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <algorithm>

vtkStandardNewMacro(vtkReplayHapticDevice);

//------------------------------------------------------------------------------
vtkReplayHapticDevice::vtkReplayHapticDevice()
{
  this->Capabilities->SetModelName("Replay");
}

//------------------------------------------------------------------------------
vtkReplayHapticDevice::~vtkReplayHapticDevice()
{
  this->Close();
  this->SetRecording(nullptr);
}

//------------------------------------------------------------------------------
void vtkReplayHapticDevice::SetRecording(vtkHapticRecorder* recording)
{
  if (recording == this->Recording)
  {
    return;
  }
  if (this->Recording)
  {
    this->Recording->UnRegister(this);
  }
  this->Recording = recording;
  if (this->Recording)
  {
    this->Recording->Register(this);
    this->Capabilities->DeepCopy(this->Recording->GetCapabilities());
  }
  this->Rewind();
  this->Modified();
}

//------------------------------------------------------------------------------
vtkHapticRecorder* vtkReplayHapticDevice::GetRecording()
{
  return this->Recording;
}

//------------------------------------------------------------------------------
bool vtkReplayHapticDevice::ReadFile(const char* fileName)
{
  vtkNew<vtkHapticRecorder> recording;
  if (!recording->ReadFile(fileName))
  {
    return false;
  }
  this->SetRecording(recording);
  return true;
}

//------------------------------------------------------------------------------
void vtkReplayHapticDevice::Rewind()
{
  this->Cursor.store(0, std::memory_order_release);
  std::fill(this->LastPosition, this->LastPosition + 3, 0.0);
  this->LastOrientation[0] = 1.0;
  std::fill(this->LastOrientation + 1, this->LastOrientation + 4, 0.0);
}

//------------------------------------------------------------------------------
bool vtkReplayHapticDevice::IsFinished() const
{
  return !this->Recording || this->GetNumberOfTicksPlayed() >= this->Recording->GetNumberOfTicks();
}

//------------------------------------------------------------------------------
bool vtkReplayHapticDevice::OpenDevice()
{
  if (!this->Recording || this->Recording->GetNumberOfTicks() == 0)
  {
    this->SetErrorMessage("there is no recording to replay (SetRecording or ReadFile first)");
    return false;
  }
  this->Rewind();
  return true;
}

//------------------------------------------------------------------------------
void vtkReplayHapticDevice::CloseDevice() {}

//------------------------------------------------------------------------------
void vtkReplayHapticDevice::Synchronize(unsigned long long)
{
  if (!this->Recording || !this->IsConnected())
  {
    return;
  }
  const int cursor = this->Cursor.load(std::memory_order_relaxed);
  if (cursor >= this->Recording->GetNumberOfTicks())
  {
    this->PublishSample(this->LastPosition, this->LastOrientation, 0u);
    return;
  }
  const vtkHapticRecorder::Tick& tick = this->Recording->GetTick(cursor);
  if (tick.Present)
  {
    std::copy(tick.Position, tick.Position + 3, this->LastPosition);
    std::copy(tick.Orientation, tick.Orientation + 4, this->LastOrientation);
    this->PublishSample(tick.Position, tick.Orientation, tick.Buttons | tick.SwitchButtons);
  }
  else
  {
    this->PublishAbsence();
  }
  this->Cursor.store(cursor + 1, std::memory_order_release);
}

//------------------------------------------------------------------------------
void vtkReplayHapticDevice::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Recording: " << this->Recording << "\n";
  os << indent << "NumberOfTicksPlayed: " << this->GetNumberOfTicksPlayed() << "\n";
}
