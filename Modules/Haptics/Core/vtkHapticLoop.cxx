// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticLoop.h"
#include "vtkHapticCoupling.h"
#include "vtkHapticDevice.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticLatestValue.h"
#include "vtkHapticPendingCuts.h"
#include "vtkHapticRealTime.h"
#include "vtkHapticRecorder.h"
#include "vtkHapticRing.h"

#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutNerveMonitor.h"
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutTool.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>


vtkStandardNewMacro(vtkHapticLoop);

namespace
{
using Clock = vtkHapticRealTime::Clock;
using ThreadCounters = vtkHapticRealTime::Counters;

enum EventTypes
{
  CutEvent,
  DrillPressEvent,
  DrillReleaseEvent,
  LostEvent,
  ReturnEvent,
  FailedCutEvent
};

/// What the haptic thread reports to the main thread.
struct Event
{
  unsigned long long Tick;
  int Type;
  double P0[3];
  double P1[3];
};

/// What a tick asks the cutter to do with the field (see Cutting in the header), in order.
enum CutRequestTypes
{
  BeginStrokeRequest,
  SegmentRequest,
  EndStrokeRequest
};

struct CutRequest
{
  int Type;
  unsigned long long Tick;
  /// A segment's place among the segments queued since Start (1, 2, ...), 0 for a stroke's beginning or end.
  unsigned long long Sequence;
  /// When the tick queued it (the clock's count), for the cut's latency.
  Clock::rep Queued;
  double P0[3];
  double P1[3];
  double R0[3][3];
  double R1[3][3];
};

/// What the display reads.
struct Display
{
  double ToolToRAS[16];
  double Force[3];
  int Drilling;
  double ContactDepth;
};

unsigned short CountSince(long before, long after)
{
  return static_cast<unsigned short>(std::min(std::max(after - before, 0L), 65535L));
}

} // namespace

/// The nerve monitor's readings of one tick, as published for the display side.
struct NerveReadings
{
  int Count = -1;
  vtkVolumeCutNerveMonitor::Reading Values[vtkHapticLoop::MaximumNerveReadings];
};

struct vtkHapticLoop::Internals
{
  vtkSmartPointer<vtkHapticDevice> Device;
  vtkSmartPointer<vtkHapticDevice> Switch;
  vtkSmartPointer<vtkHapticForceModel> Model;
  vtkSmartPointer<vtkVolumeCutField> Field;
  vtkSmartPointer<vtkHapticRecorder> Recorder;
  vtkSmartPointer<vtkVolumeCutNerveMonitor> Monitor;
  vtkSmartPointer<vtkHapticCoupling> Coupling;
  vtkHapticLatestValue<NerveReadings> LatestNerve;
  double DeviceToRAS[4][4] = { { 1, 0, 0, 0 }, { 0, 1, 0, 0 }, { 0, 0, 1, 0 }, { 0, 0, 0, 1 } };
  double Scale = 1.0;
  double MapRotation[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  double ToolRotation[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };

  std::thread Thread;
  std::atomic<bool> StopRequested{ false };
  std::atomic<bool> Running{ false };
  bool Prepared = false;
  vtkHapticRing<Event> Events{ 8192 };
  vtkHapticLatestValue<Display> Latest;
  double LastSegment[2][3] = { { 0, 0, 0 }, { 0, 0, 0 } };

  // Haptic thread's state.
  std::atomic<unsigned long long> TickCount{ 0 };
  bool WasPresent = false;
  bool EverPresent = false;
  bool HaveSample = false;
  vtkHapticDevice::Sample PreviousSample;
  bool NeedsReset = true;
  bool StrokeOpen = false;
  bool LastCutValid = false;
  double LastCut[3] = { 0, 0, 0 };
  double LastCutRotation[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  vtkVolumeCutTool* Tool = nullptr;
  double Radius = 0.0;
  vtkNew<vtkMatrix4x4> Pose0;
  vtkNew<vtkMatrix4x4> Pose1;

  // Statistics: written by the haptic thread, read while stopped.
  std::vector<float> Durations;
  std::vector<float> ProcessorDurations;
  std::vector<float> Jitters;
  std::atomic<unsigned long long> Timed{ 0 };
  std::atomic<unsigned long long> Jittered{ 0 };
  std::atomic<unsigned long long> Overruns{ 0 };
  /// Overruns of ticks that the system woke later than the tick then took: the thread was asleep, not working.
  std::atomic<unsigned long long> LateWakeUpOverruns{ 0 };
  /// How long after its deadline the system woke the thread at worst (us); written by the haptic thread only.
  std::atomic<float> MaximumWakeUpLateness{ 0.0f };
  bool RealTime = false;
  /// What the haptic thread asked of the system and got (GetRealTimePriorityStatus), set before ThreadReady.
  std::string RealTimeStatus = "not started";
  std::atomic<bool> ThreadReady{ false };
  /// Per kept tick, in the same slot as its duration: the force model's,
  /// the cut stroke's and the nerve monitor's time, the shield bricks it
  /// built, the page faults it took and its preemptions.
  std::vector<float> ModelDurations;
  std::vector<float> CutDurations;
  std::vector<float> MonitorDurations;
  std::vector<unsigned short> ShieldBuilds;
  std::vector<unsigned short> PageFaults;
  std::vector<unsigned short> Preemptions;
  /// The force model's work in the kept ticks (see ProfileContacts).
  struct ModelWork
  {
    int Contacts, ProxySteps, Samples;
    float Immersion;
    int CutFieldSamples;
  };
  std::vector<ModelWork> Work;
  unsigned long long ShieldBricksInTicks = 0;

  // The cutter thread (see Cutting in the header).
  std::thread Cutter;
  std::atomic<bool> CutterStopRequested{ false };
  /// Whether the ticks cut themselves (RunTicks, no AsynchronousCutting) or queue their cuts for the cutter.
  bool CutInTicks = true;
  vtkHapticRing<CutRequest> CutRequests{ 8192 };
  /// The cutter's reports for the main thread: a ring of its own, as each ring has one producer.
  vtkHapticRing<Event> CutterEvents{ 8192 };
  /// The field's deepest contact as the cutter last left it, for the tick's display.
  std::atomic<double> CutterContactDepth{ 0.0 };
  /// A stroke's beginning or end that did not fit the queue: Stop closes the field's stroke.
  bool StrokeRequestLost = false;
  /// The segments queued and not cut yet, for the force model (FeelPendingCuts).
  vtkHapticPendingCuts Pending;
  /// RunTicks with ReplayCutterDelay: the first queued request not cut yet, taken off the queue.
  bool HoldingRequest = false;
  CutRequest HeldRequest{};
  // Cutter's statistics, read once it has stopped.
  std::vector<float> CutterDurations;
  unsigned long long CutterTimed = 0;
  float MaximumCutLatency = 0.0f;

  // The preparer thread (see Shield in the header).
  std::thread Preparer;
  std::atomic<bool> PreparerStopRequested{ false };
  /// The tool's reach around its pose (mm), set by Prepare.
  double ToolReach = 0.0;

  /// Haptic thread: keep a tick's times and what the system did meanwhile in its slot.
  void KeepTick(float duration, float processorTime, const ThreadCounters& before, const ThreadCounters& after)
  {
    const unsigned long long timed = this->Timed.load(std::memory_order_relaxed);
    const size_t slot = timed % this->Durations.size();
    this->Durations[slot] = duration;
    this->ProcessorDurations[slot] = processorTime;
    this->PageFaults[slot] = CountSince(before.PageFaults, after.PageFaults);
    this->Preemptions[slot] = CountSince(before.Preemptions, after.Preemptions);
    this->Timed.store(timed + 1, std::memory_order_release);
  }

  /// Haptic thread: a report for the main thread (counted, not kept, when the ring is full).
  void Push(unsigned long long tick, int type, const double p0[3] = nullptr, const double p1[3] = nullptr)
  {
    this->PushTo(this->Events, tick, type, p0, p1);
  }

  /// The writer's thread: cut the tool's sweep from pose 0 to pose 1 (centres and rotations).
  bool CutSegment(const double p0[3], const double p1[3], const double r0[3][3], const double r1[3][3])
  {
    if (!this->Tool)
    {
      return this->Field->CutCapsule(p0, p1, this->Radius);
    }
    for (int row = 0; row < 3; ++row)
    {
      for (int column = 0; column < 3; ++column)
      {
        this->Pose0->SetElement(row, column, r0[row][column]);
        this->Pose1->SetElement(row, column, r1[row][column]);
      }
      this->Pose0->SetElement(row, 3, p0[row]);
      this->Pose1->SetElement(row, 3, p1[row]);
    }
    return this->Field->CutToolSweep(this->Tool, this->Pose0, this->Pose1);
  }

  /// Haptic thread: queue a request for the cutter; false if the queue is full (the cutter is far behind).
  bool QueueCut(int type, unsigned long long tick, const double p0[3] = nullptr, const double p1[3] = nullptr,
    const double r0[3][3] = nullptr, const double r1[3][3] = nullptr)
  {
    CutRequest request{};
    request.Type = type;
    request.Tick = tick;
    request.Queued = Clock::now().time_since_epoch().count();
    request.Sequence = type == SegmentRequest ? this->Pending.GetNextSequence() : 0;
    if (p0 && p1 && r0 && r1)
    {
      std::copy(p0, p0 + 3, request.P0);
      std::copy(p1, p1 + 3, request.P1);
      std::copy(&r0[0][0], &r0[0][0] + 9, &request.R0[0][0]);
      std::copy(&r1[0][0], &r1[0][0] + 9, &request.R1[0][0]);
    }
    if (!this->CutRequests.Push(request))
    {
      return false;
    }
    if (type == SegmentRequest)
    {
      this->Pending.Add(request.Sequence, request.P0, request.P1);
    }
    return true;
  }

  /// RunTicks' cutter (ReplayCutterDelay): cut the requests the ticks before until queued, in order.
  void CutRequestsQueuedBefore(unsigned long long until)
  {
    while (this->HoldingRequest || this->CutRequests.Pop(this->HeldRequest))
    {
      this->HoldingRequest = this->HeldRequest.Tick >= until;
      if (this->HoldingRequest)
      {
        return;
      }
      this->ApplyCutRequest(this->HeldRequest);
    }
  }

  /// Haptic thread: the drill starts or stops, in the tick or through the cutter.
  void ChangeStroke(unsigned long long tick, bool open)
  {
    if (this->CutInTicks)
    {
      open ? this->Field->BeginStroke() : this->Field->EndStroke();
    }
    else if (!this->QueueCut(open ? BeginStrokeRequest : EndStrokeRequest, tick))
    {
      this->StrokeRequestLost = true;
      this->DroppedEvents.fetch_add(1, std::memory_order_relaxed);
    }
  }

  /// Cutter thread: carry out one request of the ticks.
  void ApplyCutRequest(const CutRequest& request)
  {
    if (request.Type != SegmentRequest)
    {
      request.Type == BeginStrokeRequest ? this->Field->BeginStroke() : this->Field->EndStroke();
      return;
    }
    const Clock::time_point start = Clock::now();
    const bool cut = this->CutSegment(request.P0, request.P1, request.R0, request.R1);
    // The field holds the segment: the force model need not count it any longer.
    this->Pending.MarkCut(request.Sequence);
    const Clock::time_point end = Clock::now();
    this->CutterDurations[this->CutterTimed % this->CutterDurations.size()] = std::chrono::duration<float, std::micro>(end - start).count();
    ++this->CutterTimed;
    const Clock::time_point queued{ Clock::duration(request.Queued) };
    this->MaximumCutLatency = std::max(this->MaximumCutLatency, std::chrono::duration<float, std::micro>(end - queued).count());
    this->CutterContactDepth.store(this->Field->GetMaximumContactDepth(), std::memory_order_relaxed);
    this->PushTo(this->CutterEvents, request.Tick, cut ? CutEvent : FailedCutEvent, request.P0, request.P1);
  }

  void PushTo(vtkHapticRing<Event>& ring, unsigned long long tick, int type, const double p0[3], const double p1[3])
  {
    Event event{};
    event.Tick = tick;
    event.Type = type;
    if (p0)
    {
      std::copy(p0, p0 + 3, event.P0);
    }
    if (p1)
    {
      std::copy(p1, p1 + 3, event.P1);
    }
    if (!ring.Push(event))
    {
      this->DroppedEvents.fetch_add(1, std::memory_order_relaxed);
    }
  }
  std::atomic<int> DroppedEvents{ 0 };
};

//------------------------------------------------------------------------------
vtkHapticLoop::vtkHapticLoop()
  : Internal(new Internals)
{
  Display display{};
  for (int n = 0; n < 16; ++n)
  {
    display.ToolToRAS[n] = (n % 5 == 0) ? 1.0 : 0.0;
  }
  this->Internal->Latest.Store(display);
}

//------------------------------------------------------------------------------
vtkHapticLoop::~vtkHapticLoop()
{
  this->Stop();
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetDevice(vtkHapticDevice* device)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetDevice: stop the loop first");
    return;
  }
  this->Internal->Device = device;
  this->Internal->Prepared = false;
  this->Modified();
}

vtkHapticDevice* vtkHapticLoop::GetDevice()
{
  return this->Internal->Device;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetSwitchDevice(vtkHapticDevice* device)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetSwitchDevice: stop the loop first");
    return;
  }
  this->Internal->Switch = device;
  this->Modified();
}

vtkHapticDevice* vtkHapticLoop::GetSwitchDevice()
{
  return this->Internal->Switch;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetForceModel(vtkHapticForceModel* model)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetForceModel: stop the loop first");
    return;
  }
  this->Internal->Model = model;
  this->Internal->Prepared = false;
  this->Modified();
}

vtkHapticForceModel* vtkHapticLoop::GetForceModel()
{
  return this->Internal->Model;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetCutField(vtkVolumeCutField* field)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetCutField: stop the loop first");
    return;
  }
  this->Internal->Field = field;
  this->Internal->Prepared = false;
  this->Modified();
}

vtkVolumeCutField* vtkHapticLoop::GetCutField()
{
  return this->Internal->Field;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetRecorder(vtkHapticRecorder* recorder)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetRecorder: stop the loop first");
    return;
  }
  this->Internal->Recorder = recorder;
  this->Modified();
}

vtkHapticRecorder* vtkHapticLoop::GetRecorder()
{
  return this->Internal->Recorder;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetNerveMonitor(vtkVolumeCutNerveMonitor* monitor)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetNerveMonitor: stop the loop first");
    return;
  }
  this->Internal->Monitor = monitor;
  this->Modified();
}

vtkVolumeCutNerveMonitor* vtkHapticLoop::GetNerveMonitor()
{
  return this->Internal->Monitor;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetCoupling(vtkHapticCoupling* coupling)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetCoupling: stop the loop first");
    return;
  }
  this->Internal->Coupling = coupling;
  this->Modified();
}

vtkHapticCoupling* vtkHapticLoop::GetCoupling()
{
  return this->Internal->Coupling;
}

//------------------------------------------------------------------------------
int vtkHapticLoop::GetLatestNerveReadings(void* readings, int capacity) const
{
  NerveReadings latest;
  if (!this->Internal->LatestNerve.Load(latest) || latest.Count < 0)
  {
    return -1;
  }
  const int count = std::min({ latest.Count, capacity, MaximumNerveReadings });
  std::copy(latest.Values, latest.Values + std::max(count, 0), static_cast<vtkVolumeCutNerveMonitor::Reading*>(readings));
  return count;
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::SetDeviceToRAS(vtkMatrix4x4* deviceToRAS)
{
  if (!deviceToRAS || this->IsRunning())
  {
    vtkErrorMacro("SetDeviceToRAS: " << (deviceToRAS ? "stop the loop first" : "a matrix is required"));
    return false;
  }
  double columns[3][3];
  double scale = 0.0;
  for (int column = 0; column < 3; ++column)
  {
    for (int row = 0; row < 3; ++row)
    {
      columns[column][row] = deviceToRAS->GetElement(row, column);
    }
    scale += vtkMath::Norm(columns[column]) / 3.0;
  }
  bool valid = std::isfinite(scale) && scale > 0.0 && deviceToRAS->GetElement(3, 0) == 0.0 && deviceToRAS->GetElement(3, 1) == 0.0 &&
    deviceToRAS->GetElement(3, 2) == 0.0 && deviceToRAS->GetElement(3, 3) == 1.0;
  for (int a = 0; a < 3 && valid; ++a)
  {
    valid = std::isfinite(deviceToRAS->GetElement(a, 3));
    for (int b = 0; b < 3 && valid; ++b)
    {
      const double dot = vtkMath::Dot(columns[a], columns[b]) / (scale * scale);
      valid = std::abs(dot - (a == b ? 1.0 : 0.0)) < 1e-6;
    }
  }
  if (!valid || deviceToRAS->Determinant() <= 0.0)
  {
    vtkErrorMacro("SetDeviceToRAS: the matrix must be a rotation times a uniform scale plus a translation; the previous one is kept");
    return false;
  }
  Internals& internal = *this->Internal;
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      internal.DeviceToRAS[row][column] = deviceToRAS->GetElement(row, column);
    }
  }
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      internal.MapRotation[row][column] = internal.DeviceToRAS[row][column] / scale;
    }
  }
  internal.Scale = scale;
  internal.Prepared = false;
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::GetDeviceToRAS(vtkMatrix4x4* deviceToRAS)
{
  if (deviceToRAS)
  {
    deviceToRAS->DeepCopy(&this->Internal->DeviceToRAS[0][0]);
  }
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetDeviceScale() const
{
  return this->Internal->Scale;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SetToolRotation(vtkMatrix4x4* rotation)
{
  if (!rotation || this->IsRunning())
  {
    vtkErrorMacro("SetToolRotation: " << (rotation ? "stop the loop first" : "a matrix is required"));
    return;
  }
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      this->Internal->ToolRotation[row][column] = rotation->GetElement(row, column);
    }
  }
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::IsRunning() const
{
  return this->Internal->Running.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::Prepare()
{
  Internals& internal = *this->Internal;
  if (!internal.Device || !internal.Device->IsConnected())
  {
    vtkErrorMacro("Start: " << (internal.Device ? "the device is not connected; open it first" : "no device is set"));
    return false;
  }
  if (!internal.Model)
  {
    vtkErrorMacro("Start: no force model is set");
    return false;
  }
  vtkHapticDeviceCapabilities* capabilities = internal.Device->GetCapabilities();
  internal.Model->SetDeviceLimits(capabilities, internal.Scale);
  // Four samples a period at least: what the loop and the device can render.
  internal.Model->SetMaximumVibrationFrequency(0.25 * std::min(this->Rate, capabilities->GetUpdateRate()));
  if (internal.Field)
  {
    internal.Model->SetCutField(internal.Field);
  }
  if (!internal.Model->Prepare())
  {
    vtkErrorMacro("Start: the force model could not be prepared (see the error above)");
    return false;
  }
  internal.Tool = internal.Model->GetTool();
  internal.Radius = internal.Model->GetSphereRadius();
  internal.ToolReach = internal.Tool ? internal.Tool->GetBoundingRadius() : internal.Radius;
  // The monitor's points on a tool of another shape are placed here, not in a tick.
  if (internal.Monitor && internal.Tool && !internal.Monitor->PrepareTool(internal.Tool))
  {
    vtkErrorMacro("Start: the nerve monitor could not place points on the tool (see the error above)");
    return false;
  }
  if (internal.Coupling)
  {
    internal.Coupling->SetDeviceLimits(capabilities, internal.Scale);
    if (!internal.Coupling->Prepare())
    {
      vtkErrorMacro("Start: the coupling to the peer could not be prepared (see the error above)");
      return false;
    }
  }
  if (internal.Recorder)
  {
    internal.Recorder->GetCapabilities()->DeepCopy(capabilities);
    internal.Recorder->SetRate(this->Rate);
  }
  internal.Durations.assign(static_cast<size_t>(this->StatisticsCapacity), 0.0f);
  internal.ProcessorDurations.assign(static_cast<size_t>(this->StatisticsCapacity), 0.0f);
  internal.Jitters.assign(static_cast<size_t>(this->StatisticsCapacity), 0.0f);
  const size_t capacity = static_cast<size_t>(this->StatisticsCapacity);
  internal.ModelDurations.assign(capacity, 0.0f);
  internal.CutDurations.assign(capacity, 0.0f);
  internal.MonitorDurations.assign(capacity, 0.0f);
  internal.ShieldBuilds.assign(capacity, 0);
  internal.PageFaults.assign(capacity, 0);
  internal.Preemptions.assign(capacity, 0);
  internal.Work.assign(capacity, Internals::ModelWork{});
  internal.ShieldBricksInTicks = 0;
  internal.CutterDurations.assign(capacity, 0.0f);
  internal.CutterTimed = 0;
  internal.MaximumCutLatency = 0.0f;
  internal.CutInTicks = true;
  internal.StrokeRequestLost = false;
  internal.Pending.Reset();
  internal.HoldingRequest = false;
  internal.Model->ClearPendingCuts();
  internal.CutterContactDepth = internal.Field ? internal.Field->GetMaximumContactDepth() : 0.0;
  internal.Timed = 0;
  internal.Jittered = 0;
  internal.Overruns = 0;
  internal.LateWakeUpOverruns = 0;
  internal.MaximumWakeUpLateness = 0.0f;
  internal.TickCount = 0;
  internal.WasPresent = internal.EverPresent = internal.HaveSample = false;
  internal.NeedsReset = true;
  internal.StrokeOpen = false;
  internal.LastCutValid = false;
  this->NumberOfCutStrokes = this->NumberOfDrillPresses = this->NumberOfDrillReleases = this->NumberOfDeviceLosses = 0;
  this->NumberOfDeviceReturns = this->NumberOfFailedCuts = this->NumberOfDroppedEvents = 0;
  internal.DroppedEvents = 0;
  Event stale;
  while (internal.Events.Pop(stale) || internal.CutterEvents.Pop(stale))
  {
  }
  CutRequest unused;
  while (internal.CutRequests.Pop(unused))
  {
  }
  internal.Prepared = true;
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::Start()
{
  Internals& internal = *this->Internal;
  if (this->IsRunning())
  {
    return true;
  }
  if (!this->Prepare())
  {
    return false;
  }
  internal.StopRequested = false;
  internal.RealTime = false;
  internal.ThreadReady = false;
  internal.Running = true;
  internal.CutInTicks = !(this->AsynchronousCutting && internal.Field);
  if (!internal.CutInTicks)
  {
    internal.CutterStopRequested = false;
    internal.Cutter = std::thread([this]() { this->CutQueuedSegments(); });
  }
  internal.Thread = std::thread([this]() { this->Run(); });
  if (this->PrepareShieldAhead && internal.Field && internal.Field->GetProtection()->HasShieldedLabels())
  {
    internal.PreparerStopRequested = false;
    internal.Preparer = std::thread([this]() { this->PrepareShield(); });
  }
  // The thread asks for its priority and processor before its first tick; Start reports what it got.
  while (!internal.ThreadReady.load(std::memory_order_acquire))
  {
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::Stop()
{
  Internals& internal = *this->Internal;
  if (internal.Preparer.joinable())
  {
    internal.PreparerStopRequested = true;
    internal.Preparer.join();
  }
  if (internal.Thread.joinable())
  {
    internal.StopRequested = true;
    internal.Thread.join();
  }
  else if (internal.Prepared)
  {
    this->Finish();
    // RunTicks' delayed cutter cuts what the ticks queued (the stroke's end too); cutting in the ticks queued nothing.
    internal.CutRequestsQueuedBefore(~0ull);
  }
  // The haptic thread has queued its last cuts (and the stroke's end): the cutter cuts them all, then stops.
  if (internal.Cutter.joinable())
  {
    internal.CutterStopRequested = true;
    internal.Cutter.join();
    if (internal.StrokeRequestLost && internal.Field->IsStrokeOpen())
    {
      internal.Field->EndStroke();
    }
  }
  internal.Running = false;
  internal.Prepared = false;
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::RunTicks(int count)
{
  Internals& internal = *this->Internal;
  if (this->IsRunning())
  {
    vtkErrorMacro("RunTicks: the loop's thread is running; stop it first");
    return false;
  }
  if (!internal.Prepared)
  {
    if (!this->Prepare())
    {
      return false;
    }
    internal.CutInTicks = !(this->AsynchronousCutting && this->ReplayCutterDelay > 0 && internal.Field);
  }
  const double timeStep = 1.0 / this->Rate;
  for (int n = 0; n < count; ++n)
  {
    if (!internal.CutInTicks)
    {
      // The cutter of a replay: before this tick, it cuts what the ticks up to ReplayCutterDelay ticks ago queued.
      const unsigned long long tick = internal.TickCount.load(std::memory_order_relaxed) + 1;
      internal.CutRequestsQueuedBefore(tick > static_cast<unsigned long long>(this->ReplayCutterDelay) ? tick - this->ReplayCutterDelay : 0);
    }
    const Clock::time_point start = Clock::now();
    const ThreadCounters countersBefore = vtkHapticRealTime::ReadCounters();
    const double processorStart = vtkHapticRealTime::ThreadProcessorMicroseconds();
    this->Tick(timeStep);
    const double processorEnd = vtkHapticRealTime::ThreadProcessorMicroseconds();
    const ThreadCounters countersAfter = vtkHapticRealTime::ReadCounters();
    internal.KeepTick(std::chrono::duration<float, std::micro>(Clock::now() - start).count(),
      static_cast<float>(processorEnd - processorStart), countersBefore, countersAfter);
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::Run()
{
  Internals& internal = *this->Internal;
  internal.RealTime = vtkHapticRealTime::SetUpServoThread(
    this->RequestRealTimePriority, this->RealTimePriorityLevel, this->ProcessorIndex, internal.RealTimeStatus);
  internal.ThreadReady.store(true, std::memory_order_release);
  const Clock::duration period =
    std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / this->Rate));
  const Clock::duration spin = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(this->SpinTime));
  const double nominal = 1e6 / this->Rate;
  const double timeStep = 1.0 / this->Rate;
  Clock::time_point deadline = Clock::now() + period;
  Clock::time_point previousStart;
  bool hasPrevious = false;
  while (!internal.StopRequested.load(std::memory_order_acquire))
  {
    const bool waited = vtkHapticRealTime::WaitUntil(deadline, spin);
    const Clock::time_point start = Clock::now();
    // Woken late: the time from the deadline slept to, where the thread did wait for it.
    const float lateness = waited ? std::chrono::duration<float, std::micro>(start - deadline).count() : 0.0f;
    if (lateness > internal.MaximumWakeUpLateness.load(std::memory_order_relaxed))
    {
      internal.MaximumWakeUpLateness.store(lateness, std::memory_order_relaxed);
    }
    const size_t capacity = internal.Durations.size();
    if (hasPrevious)
    {
      const unsigned long long jittered = internal.Jittered.load(std::memory_order_relaxed);
      internal.Jitters[jittered % capacity] =
        static_cast<float>(std::abs(std::chrono::duration<double, std::micro>(start - previousStart).count() - nominal));
      internal.Jittered.store(jittered + 1, std::memory_order_release);
    }
    previousStart = start;
    hasPrevious = true;
    // The processor time is read inside the wall-clock interval, so that a
    // tick's processor time never exceeds its wall time.
    const ThreadCounters countersBefore = vtkHapticRealTime::ReadCounters();
    const double processorStart = vtkHapticRealTime::ThreadProcessorMicroseconds();
    this->Tick(timeStep);
    const double processorEnd = vtkHapticRealTime::ThreadProcessorMicroseconds();
    const ThreadCounters countersAfter = vtkHapticRealTime::ReadCounters();
    const Clock::time_point end = Clock::now();
    const float duration = std::chrono::duration<float, std::micro>(end - start).count();
    internal.KeepTick(duration, static_cast<float>(processorEnd - processorStart), countersBefore, countersAfter);
    deadline += period;
    if (end > deadline)
    {
      internal.Overruns.fetch_add(1, std::memory_order_relaxed);
      if (lateness > duration)
      {
        internal.LateWakeUpOverruns.fetch_add(1, std::memory_order_relaxed);
      }
      // Late by more than a tick: start afresh rather than burst to catch up.
      if (end > deadline + period)
      {
        deadline = end + period;
      }
    }
  }
  this->Finish();
}

//------------------------------------------------------------------------------
void vtkHapticLoop::PrepareShield()
{
  Internals& internal = *this->Internal;
  const double reach = internal.ToolReach + this->ShieldLookAhead;
  // Prepare again once the tool has used a quarter of the look-ahead.
  const double step = std::max(0.1, 0.25 * this->ShieldLookAhead);
  // Before the first tick the tool is at the device's workspace centre.
  double last[3] = { internal.DeviceToRAS[0][3], internal.DeviceToRAS[1][3], internal.DeviceToRAS[2][3] };
  internal.Field->PrepareProtectionAhead(last, reach);
  while (!internal.PreparerStopRequested.load(std::memory_order_acquire))
  {
    Display display;
    if (internal.Latest.Load(display))
    {
      const double position[3] = { display.ToolToRAS[3], display.ToolToRAS[7], display.ToolToRAS[11] };
      if (vtkMath::Distance2BetweenPoints(position, last) > step * step)
      {
        internal.Field->PrepareProtectionAhead(position, reach);
        std::copy(position, position + 3, last);
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

//------------------------------------------------------------------------------
void vtkHapticLoop::CutQueuedSegments()
{
  Internals& internal = *this->Internal;
  if (this->RequestRealTimePriority)
  {
    // Just below the haptic thread, above everything else: the force reads
    // the field as the cutter left it, so the cut must not wait for the
    // machine's other work (its work is bounded: what the ticks queue).
    std::string status;
    vtkHapticRealTime::RequestPriority(std::max(1, this->RealTimePriorityLevel - 1), status);
  }
  for (;;)
  {
    // Read before draining: whatever the ticks queued before the stop request is cut too.
    const bool stopping = internal.CutterStopRequested.load(std::memory_order_acquire);
    bool cutAny = false;
    CutRequest request;
    while (internal.CutRequests.Pop(request))
    {
      internal.ApplyCutRequest(request);
      cutAny = true;
    }
    if (stopping)
    {
      return;
    }
    if (!cutAny)
    {
      // A fraction of a tick: the cut follows the tick that queued it closely.
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
}

//------------------------------------------------------------------------------
void vtkHapticLoop::SafeStop()
{
  Internals& internal = *this->Internal;
  const unsigned long long tick = internal.TickCount.load(std::memory_order_relaxed);
  if (internal.StrokeOpen && internal.Field)
  {
    // Everything cut so far stays, as one undo step.
    internal.ChangeStroke(tick, false);
    internal.Push(tick, DrillReleaseEvent);
  }
  internal.StrokeOpen = false;
  internal.LastCutValid = false;
  const double zero[3] = { 0.0, 0.0, 0.0 };
  if (internal.Device)
  {
    internal.Device->SetForce(zero);
  }
  Display display{};
  internal.Latest.Load(display);
  std::fill(display.Force, display.Force + 3, 0.0);
  display.Drilling = 0;
  internal.Latest.Store(display);
}

//------------------------------------------------------------------------------
void vtkHapticLoop::Finish()
{
  this->SafeStop();
  this->Internal->Running.store(false, std::memory_order_release);
}

//------------------------------------------------------------------------------
void vtkHapticLoop::Tick(double timeStep)
{
  Internals& internal = *this->Internal;
  const unsigned long long tick = internal.TickCount.load(std::memory_order_relaxed);
  internal.TickCount.store(tick + 1, std::memory_order_release);
  // This tick's slot in the statistics: the one its duration goes to.
  const size_t slot = internal.Timed.load(std::memory_order_relaxed) % internal.Durations.size();
  internal.ModelDurations[slot] = 0.0f;
  internal.CutDurations[slot] = 0.0f;
  internal.MonitorDurations[slot] = 0.0f;
  internal.ShieldBuilds[slot] = 0;
  internal.Work[slot] = Internals::ModelWork{};
  vtkHapticDevice* device = internal.Device;
  device->Synchronize(tick);
  if (internal.Switch)
  {
    internal.Switch->Synchronize(tick);
  }

  vtkHapticDevice::Sample sample;
  const bool connected = device->IsConnected();
  const bool read = connected && device->GetLatestSample(sample);
  bool present = read && sample.Present;
  if (connected && !read && internal.HaveSample)
  {
    // The device's thread was caught publishing: this tick uses the last sample.
    sample = internal.PreviousSample;
    present = true;
  }
  vtkHapticRecorder::Tick record{};
  record.Index = tick;
  record.Present = present;
  const double time = static_cast<double>(tick) * timeStep;
  if (!present)
  {
    if (internal.Coupling)
    {
      const double nowhere[3] = { 0.0, 0.0, 0.0 };
      double none[3];
      internal.Coupling->Update(time, nowhere, nowhere, false, none);
    }
    if (internal.WasPresent)
    {
      this->SafeStop();
      internal.Push(tick, LostEvent);
    }
    internal.WasPresent = false;
    internal.HaveSample = false;
    if (internal.Recorder)
    {
      internal.Recorder->Record(record);
    }
    return;
  }
  if (!internal.WasPresent)
  {
    if (internal.EverPresent)
    {
      internal.Push(tick, ReturnEvent);
    }
    internal.EverPresent = internal.WasPresent = true;
    internal.NeedsReset = true;
  }
  internal.HaveSample = true;
  internal.PreviousSample = sample;

  // The tool's pose in the scene.
  const double (*m)[4] = internal.DeviceToRAS;
  double position[3];
  for (int row = 0; row < 3; ++row)
  {
    position[row] = m[row][0] * sample.Position[0] + m[row][1] * sample.Position[1] + m[row][2] * sample.Position[2] + m[row][3];
  }
  double handle[3][3];
  vtkMath::QuaternionToMatrix3x3(sample.Orientation, handle);
  double turned[3][3];
  double rotation[3][3];
  vtkMath::Multiply3x3(internal.MapRotation, handle, turned);
  vtkMath::Multiply3x3(turned, internal.ToolRotation, rotation);
  if (internal.NeedsReset)
  {
    internal.Model->Reset(position);
    internal.LastCutValid = false;
    internal.NeedsReset = false;
  }

  unsigned int switchButtons = 0;
  if (internal.Switch && internal.Switch->IsConnected())
  {
    vtkHapticDevice::Sample pedal;
    if (internal.Switch->GetLatestSample(pedal) && pedal.Present)
    {
      switchButtons = pedal.Buttons;
    }
  }
  const bool drilling = internal.Field && ((sample.Buttons | switchButtons) & this->DrillButtons) != 0;
  if (drilling != internal.StrokeOpen)
  {
    internal.ChangeStroke(tick, drilling);
    internal.Push(tick, drilling ? DrillPressEvent : DrillReleaseEvent);
    internal.StrokeOpen = drilling;
    internal.LastCutValid = false;
  }

  vtkHapticForceModel::Result result;
  const Clock::time_point modelStart = Clock::now();
  if (!internal.CutInTicks && this->FeelPendingCuts)
  {
    internal.Pending.ShowTo(internal.Model);
  }
  internal.Model->Update(position, rotation, timeStep, drilling, result);
  internal.ModelDurations[slot] = std::chrono::duration<float, std::micro>(Clock::now() - modelStart).count();
  internal.Work[slot] = { result.NumberOfContacts, result.NumberOfProxySteps, result.NumberOfSamples, static_cast<float>(result.Immersion),
    result.NumberOfCutFieldSamples };

  bool cut = false;
  if (drilling && result.Cut)
  {
    const Clock::time_point cutStart = Clock::now();
    const double* p1 = result.CutPosition;
    const double* p0 = internal.LastCutValid ? internal.LastCut : p1;
    // A jump longer than the field accepts (the proxy is limited per tick,
    // so only after a glitch) starts a new segment instead of an error here.
    if (std::sqrt(vtkMath::Distance2BetweenPoints(p0, p1)) > internal.Field->GetMaximumStrokeLength())
    {
      p0 = p1;
    }
    const double (*r0)[3] = internal.LastCutValid ? internal.LastCutRotation : rotation;
    if (internal.CutInTicks)
    {
      vtkVolumeCutProtection* protection = internal.Field->GetProtection();
      const vtkIdType shieldBefore = protection->GetNumberOfBricksBuiltOnDemand();
      cut = internal.CutSegment(p0, p1, r0, rotation);
      const vtkIdType shieldBuilt = protection->GetNumberOfBricksBuiltOnDemand() - shieldBefore;
      internal.ShieldBuilds[slot] = static_cast<unsigned short>(std::min<vtkIdType>(std::max<vtkIdType>(shieldBuilt, 0), 65535));
      internal.ShieldBricksInTicks += static_cast<unsigned long long>(std::max<vtkIdType>(shieldBuilt, 0));
      internal.Push(tick, cut ? CutEvent : FailedCutEvent, p0, p1);
    }
    else
    {
      // The cutter reports the cut; a full queue (a cutter far behind) loses this segment, told as a failed cut.
      cut = internal.QueueCut(SegmentRequest, tick, p0, p1, r0, rotation);
      if (!cut)
      {
        internal.Push(tick, FailedCutEvent, p0, p1);
      }
    }
    internal.CutDurations[slot] = std::chrono::duration<float, std::micro>(Clock::now() - cutStart).count();
    if (cut)
    {
      std::copy(p1, p1 + 3, internal.LastCut);
      std::copy(&rotation[0][0], &rotation[0][0] + 9, &internal.LastCutRotation[0][0]);
    }
  }
  internal.LastCutValid = cut;

  double total[3] = { result.Force[0], result.Force[1], result.Force[2] };
  double coupling[3] = { 0.0, 0.0, 0.0 };
  if (internal.Coupling)
  {
    // The handle in device millimetres along the scene's axes: where the
    // coupling's force does its work, whatever the scene's scale.
    double handle[3];
    vtkMath::Multiply3x3(internal.MapRotation, sample.Position, handle);
    internal.Coupling->Update(time, result.ProxyPosition, handle, true, coupling);
    vtkMath::Add(total, coupling, total);
  }

  // The force in the device's frame (forces do not scale with positions).
  double force[3];
  for (int row = 0; row < 3; ++row)
  {
    force[row] = internal.MapRotation[0][row] * total[0] + internal.MapRotation[1][row] * total[1] +
      internal.MapRotation[2][row] * total[2];
  }
  device->SetForce(force);
  if (internal.Coupling)
  {
    // The device scales a sum above its maximum down, direction kept: so much of the coupling's force is felt.
    const double norm = vtkMath::Norm(total);
    const double maximum = device->GetCapabilities()->GetMaximumForce();
    const double felt = (device->IsConnected() && std::isfinite(norm)) ? (norm > maximum ? maximum / norm : 1.0) : 0.0;
    vtkMath::MultiplyScalar(coupling, felt);
    internal.Coupling->ReportAppliedForce(coupling);
  }
  double sent[3];
  device->GetCommandedForce(sent);

  Display display;
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      display.ToolToRAS[4 * row + column] = rotation[row][column];
    }
    display.ToolToRAS[4 * row + 3] = result.ProxyPosition[row];
  }
  display.ToolToRAS[12] = display.ToolToRAS[13] = display.ToolToRAS[14] = 0.0;
  display.ToolToRAS[15] = 1.0;
  std::copy(sent, sent + 3, display.Force);
  display.Drilling = drilling ? 1 : 0;
  display.ContactDepth = !internal.Field ? 0.0
    : internal.CutInTicks               ? internal.Field->GetMaximumContactDepth()
                                        : internal.CutterContactDepth.load(std::memory_order_relaxed);
  internal.Latest.Store(display);

  if (internal.Monitor)
  {
    const Clock::time_point monitorStart = Clock::now();
    NerveReadings readings;
    readings.Count = internal.Tool ? internal.Monitor->MeasureTool(display.ToolToRAS, readings.Values, MaximumNerveReadings)
                                   : internal.Monitor->Measure(result.ProxyPosition, internal.Radius, readings.Values, MaximumNerveReadings);
    readings.Count = std::min(readings.Count, static_cast<int>(MaximumNerveReadings));
    internal.LatestNerve.Store(readings);
    internal.MonitorDurations[slot] = std::chrono::duration<float, std::micro>(Clock::now() - monitorStart).count();
  }

  if (internal.Recorder)
  {
    std::copy(sample.Position, sample.Position + 3, record.Position);
    std::copy(sample.Orientation, sample.Orientation + 4, record.Orientation);
    record.Buttons = sample.Buttons;
    record.SwitchButtons = switchButtons;
    std::copy(sent, sent + 3, record.Force);
    std::copy(result.ProxyPosition, result.ProxyPosition + 3, record.Proxy);
    record.Drilling = drilling;
    record.Cut = cut;
    internal.Recorder->Record(record);
  }
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::GetLatestToolPose(vtkMatrix4x4* toolToRAS) const
{
  Display display;
  if (!toolToRAS || !this->Internal->Latest.Load(display))
  {
    return false;
  }
  toolToRAS->DeepCopy(display.ToolToRAS);
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::GetLatestForce(double force[3]) const
{
  Display display{};
  this->Internal->Latest.Load(display);
  std::copy(display.Force, display.Force + 3, force);
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::GetDrilling() const
{
  Display display{};
  this->Internal->Latest.Load(display);
  return display.Drilling != 0;
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetLatestContactDepth() const
{
  Display display{};
  this->Internal->Latest.Load(display);
  return display.ContactDepth;
}

//------------------------------------------------------------------------------
int vtkHapticLoop::ProcessEvents()
{
  Internals& internal = *this->Internal;
  int cuts = 0;
  Event event;
  while (internal.Events.Pop(event) || internal.CutterEvents.Pop(event))
  {
    switch (event.Type)
    {
      case CutEvent:
        ++cuts;
        std::copy(event.P0, event.P0 + 3, internal.LastSegment[0]);
        std::copy(event.P1, event.P1 + 3, internal.LastSegment[1]);
        break;
      case DrillPressEvent:
        ++this->NumberOfDrillPresses;
        break;
      case DrillReleaseEvent:
        ++this->NumberOfDrillReleases;
        break;
      case LostEvent:
        ++this->NumberOfDeviceLosses;
        break;
      case ReturnEvent:
        ++this->NumberOfDeviceReturns;
        break;
      case FailedCutEvent:
        ++this->NumberOfFailedCuts;
        break;
      default:
        break;
    }
  }
  this->NumberOfCutStrokes += cuts;
  const int dropped = internal.DroppedEvents.exchange(0, std::memory_order_relaxed);
  if (dropped > 0)
  {
    this->NumberOfDroppedEvents += dropped;
    vtkWarningMacro("ProcessEvents: " << dropped << " reports of the haptic thread did not fit its queue (call ProcessEvents more often)");
  }
  return cuts;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::GetLastCutSegment(double p0[3], double p1[3]) const
{
  std::copy(this->Internal->LastSegment[0], this->Internal->LastSegment[0] + 3, p0);
  std::copy(this->Internal->LastSegment[1], this->Internal->LastSegment[1] + 3, p1);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticLoop::GetNumberOfTicks() const
{
  return this->Internal->TickCount.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetTickDurationPercentile(double percent) const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.Timed.load(std::memory_order_acquire), internal.Durations.size());
  return vtkHapticRealTime::Percentile(std::vector<float>(internal.Durations.begin(), internal.Durations.begin() + count), percent);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetTickProcessorTimePercentile(double percent) const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.Timed.load(std::memory_order_acquire), internal.ProcessorDurations.size());
  return vtkHapticRealTime::Percentile(std::vector<float>(internal.ProcessorDurations.begin(), internal.ProcessorDurations.begin() + count), percent);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetMaximumTickDuration() const
{
  return this->GetTickDurationPercentile(100.0);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetPeriodJitterPercentile(double percent) const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.Jittered.load(std::memory_order_acquire), internal.Jitters.size());
  return vtkHapticRealTime::Percentile(std::vector<float>(internal.Jitters.begin(), internal.Jitters.begin() + count), percent);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetMaximumPeriodJitter() const
{
  return this->GetPeriodJitterPercentile(100.0);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticLoop::GetNumberOfOverruns() const
{
  return this->Internal->Overruns.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticLoop::GetNumberOfLateWakeUpOverruns() const
{
  return this->Internal->LateWakeUpOverruns.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetMaximumWakeUpLateness() const
{
  return this->Internal->MaximumWakeUpLateness.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetCutDurationPercentile(double percent) const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.Timed.load(std::memory_order_acquire), internal.CutDurations.size());
  return vtkHapticRealTime::Percentile(std::vector<float>(internal.CutDurations.begin(), internal.CutDurations.begin() + count), percent);
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticLoop::GetNumberOfShieldBricksBuiltInTicks() const
{
  return this->Internal->ShieldBricksInTicks;
}

//------------------------------------------------------------------------------
unsigned long long vtkHapticLoop::GetNumberOfTicksBuildingShield() const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.Timed.load(std::memory_order_acquire), internal.ShieldBuilds.size());
  return static_cast<unsigned long long>(
    std::count_if(internal.ShieldBuilds.begin(), internal.ShieldBuilds.begin() + count, [](unsigned short built) { return built > 0; }));
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetMaximumTickDurationBuildingShield() const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.Timed.load(std::memory_order_acquire), internal.ShieldBuilds.size());
  float longest = 0.0f;
  for (size_t n = 0; n < count; ++n)
  {
    if (internal.ShieldBuilds[n] > 0)
    {
      longest = std::max(longest, internal.Durations[n]);
    }
  }
  return longest;
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetCutterDurationPercentile(double percent) const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.CutterTimed, internal.CutterDurations.size());
  return vtkHapticRealTime::Percentile(std::vector<float>(internal.CutterDurations.begin(), internal.CutterDurations.begin() + count), percent);
}

//------------------------------------------------------------------------------
double vtkHapticLoop::GetMaximumCutLatency() const
{
  return this->Internal->MaximumCutLatency;
}

//------------------------------------------------------------------------------
int vtkHapticLoop::GetNumberOfKeptTicks() const
{
  const Internals& internal = *this->Internal;
  return static_cast<int>(std::min<size_t>(internal.Timed.load(std::memory_order_acquire), internal.Durations.size()));
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::GetTickProfile(int index, double profile[13]) const
{
  static_assert(NumberOfTickProfileFields == 13, "the profile's array holds every field");
  const Internals& internal = *this->Internal;
  if (index < 0 || index >= this->GetNumberOfKeptTicks())
  {
    return false;
  }
  // Once the statistics have wrapped around, the oldest kept tick is in the slot after the newest.
  const unsigned long long timed = internal.Timed.load(std::memory_order_acquire);
  const size_t capacity = internal.Durations.size();
  const size_t slot = timed > capacity ? (timed + static_cast<unsigned long long>(index)) % capacity : static_cast<size_t>(index);
  profile[ProfileDuration] = internal.Durations[slot];
  profile[ProfileProcessorTime] = internal.ProcessorDurations[slot];
  profile[ProfileForceModel] = internal.ModelDurations[slot];
  profile[ProfileCut] = internal.CutDurations[slot];
  profile[ProfileNerveMonitor] = internal.MonitorDurations[slot];
  profile[ProfileShieldBricksBuilt] = internal.ShieldBuilds[slot];
  profile[ProfilePageFaults] = internal.PageFaults[slot];
  profile[ProfilePreemptions] = internal.Preemptions[slot];
  const Internals::ModelWork& work = internal.Work[slot];
  profile[ProfileContacts] = work.Contacts;
  profile[ProfileProxySteps] = work.ProxySteps;
  profile[ProfileSamples] = work.Samples;
  profile[ProfileImmersion] = work.Immersion;
  profile[ProfileCutFieldSamples] = work.CutFieldSamples;
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticLoop::GetRealTimePriority() const
{
  return this->Internal->RealTime;
}

//------------------------------------------------------------------------------
const char* vtkHapticLoop::GetRealTimePriorityStatus() const
{
  return this->Internal->RealTimeStatus.c_str();
}

//------------------------------------------------------------------------------
void vtkHapticLoop::ResetStatistics()
{
  if (this->IsRunning())
  {
    vtkErrorMacro("ResetStatistics: stop the loop first");
    return;
  }
  this->Internal->Timed = 0;
  this->Internal->Jittered = 0;
  this->Internal->Overruns = 0;
  this->Internal->LateWakeUpOverruns = 0;
  this->Internal->MaximumWakeUpLateness = 0.0f;
  this->Internal->ShieldBricksInTicks = 0;
}

//------------------------------------------------------------------------------
void vtkHapticLoop::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Rate: " << this->Rate << " Hz\n";
  os << indent << "DrillButtons: " << this->DrillButtons << "\n";
  os << indent << "SpinTime: " << this->SpinTime << " s\n";
  os << indent << "ProcessorIndex: " << this->ProcessorIndex << "\n";
  os << indent << "RequestRealTimePriority: " << (this->RequestRealTimePriority ? "on" : "off") << " (level "
     << this->RealTimePriorityLevel << "): " << this->Internal->RealTimeStatus << "\n";
  os << indent << "StatisticsCapacity: " << this->StatisticsCapacity << "\n";
  os << indent << "Running: " << (this->IsRunning() ? "yes" : "no") << "\n";
  os << indent << "NumberOfTicks: " << this->GetNumberOfTicks() << "\n";
  os << indent << "NumberOfCutStrokes: " << this->NumberOfCutStrokes << "\n";
  os << indent << "PrepareShieldAhead: " << (this->PrepareShieldAhead ? "on" : "off") << "\n";
  os << indent << "ShieldLookAhead: " << this->ShieldLookAhead << " mm\n";
  os << indent << "AsynchronousCutting: " << (this->AsynchronousCutting ? "on" : "off") << "\n";
  os << indent << "FeelPendingCuts: " << (this->FeelPendingCuts ? "on" : "off") << "\n";
  os << indent << "ReplayCutterDelay: " << this->ReplayCutterDelay << " ticks\n";
  os << indent << "DeviceScale: " << this->GetDeviceScale() << "\n";
}
