// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticMachineCheck.h"

#include "vtkHapticRealTime.h"

#include "vtkDoubleArray.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

vtkStandardNewMacro(vtkHapticMachineCheck);

namespace
{
/// A chain of multiply-adds, each waiting for the one before: no memory, no
/// vectorisation, the same instructions every time. Returns the chain's end
/// so that the compiler keeps it.
#if defined(__GNUC__)
__attribute__((noinline))
#endif
double ConstantWork(long long iterations, double seed)
{
  double value = seed;
  for (long long n = 0; n < iterations; ++n)
  {
    value = value * 0.9999999 + 1e-7;
  }
  return value;
}

/// Iterations of ConstantWork per microsecond of the calling thread's processor time.
double IterationsPerMicrosecond(volatile double& sink)
{
  // The fastest of several runs: a run the machine slowed would give too few iterations.
  constexpr long long probe = 20000;
  double fastest = 0.0;
  for (int run = 0; run < 15; ++run)
  {
    const double start = vtkHapticRealTime::ThreadProcessorMicroseconds();
    sink = ConstantWork(probe, sink);
    const double elapsed = vtkHapticRealTime::ThreadProcessorMicroseconds() - start;
    if (elapsed > 0.0 && (fastest == 0.0 || elapsed < fastest))
    {
      fastest = elapsed;
    }
  }
  return probe / std::max(fastest, 1e-3);
}

/// What this many iterations take now, as the ticks will do them: the median of a few runs (us).
double MeasureWork(long long iterations, volatile double& sink)
{
  if (iterations <= 0)
  {
    return 0.0;
  }
  std::vector<double> runs;
  for (int run = 0; run < 9; ++run)
  {
    const double start = vtkHapticRealTime::ThreadProcessorMicroseconds();
    sink = ConstantWork(iterations, sink);
    runs.push_back(vtkHapticRealTime::ThreadProcessorMicroseconds() - start);
  }
  std::nth_element(runs.begin(), runs.begin() + runs.size() / 2, runs.end());
  return runs[runs.size() / 2];
}
} // namespace

struct vtkHapticMachineCheck::Internals
{
  std::vector<float> Durations;
  std::vector<float> ProcessorTimes;
  size_t Ticks = 0;
  /// Each tick's work (s), cycled: WorkTimes copied at Start, or WorkTime alone.
  std::vector<double> Work;
  vtkIdType Overruns = 0;
  vtkIdType LateWakeUpOverruns = 0;
  float MaximumWakeUpLateness = 0.0f;
  double CalibratedWork = 0.0;
  bool RealTime = false;
  std::string RealTimeStatus = "not run";
  volatile double Sink = 1.0;
  std::thread Thread;
  std::atomic<bool> Running{ false };
};

//------------------------------------------------------------------------------
vtkHapticMachineCheck::vtkHapticMachineCheck()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkHapticMachineCheck::~vtkHapticMachineCheck()
{
  this->Wait();
  this->SetWorkTimes(nullptr);
}

//------------------------------------------------------------------------------
vtkCxxSetObjectMacro(vtkHapticMachineCheck, WorkTimes, vtkDoubleArray);

//------------------------------------------------------------------------------
bool vtkHapticMachineCheck::Start()
{
  Internals& internal = *this->Internal;
  if (this->IsRunning())
  {
    vtkErrorMacro("Start: a check is running; Wait for it first");
    return false;
  }
  this->Wait(); // the thread of a check that has ended
  internal.Durations.clear();
  internal.ProcessorTimes.clear();
  internal.Overruns = 0;
  internal.LateWakeUpOverruns = 0;
  internal.MaximumWakeUpLateness = 0.0f;
  internal.CalibratedWork = 0.0;
  internal.RealTime = false;
  internal.RealTimeStatus = "not run";
  internal.Work.assign(1, this->WorkTime);
  if (this->WorkTimes && this->WorkTimes->GetNumberOfTuples() > 0)
  {
    internal.Work.resize(static_cast<size_t>(this->WorkTimes->GetNumberOfTuples()));
    for (vtkIdType n = 0; n < this->WorkTimes->GetNumberOfTuples(); ++n)
    {
      internal.Work[n] = this->WorkTimes->GetValue(n);
    }
  }
  for (const double work : internal.Work)
  {
    if (!(work >= 0.0 && work <= 0.9 / this->Rate))
    {
      vtkErrorMacro("Start: " << work * 1e6 << " us of work does not fit in a period of " << 1e6 / this->Rate
                              << " us (0 to 0.9 of it)");
      internal.Work.clear();
      return false;
    }
  }
  internal.Ticks = static_cast<size_t>(this->Duration * this->Rate + 0.5);
  // Allocated here: the ticks only store into it.
  internal.Durations.reserve(internal.Ticks);
  internal.ProcessorTimes.reserve(internal.Ticks);
  internal.Running.store(true, std::memory_order_release);
  try
  {
    internal.Thread = std::thread([this]() {
      this->Measure();
      this->Internal->Running.store(false, std::memory_order_release);
    });
  }
  catch (const std::system_error& error)
  {
    internal.Running.store(false, std::memory_order_release);
    vtkErrorMacro("Start: the check's thread could not start: " << error.what());
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkHapticMachineCheck::IsRunning() const
{
  return this->Internal->Running.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
void vtkHapticMachineCheck::Wait()
{
  if (this->Internal->Thread.joinable())
  {
    this->Internal->Thread.join();
  }
}

//------------------------------------------------------------------------------
bool vtkHapticMachineCheck::Run()
{
  if (!this->Start())
  {
    return false;
  }
  this->Wait();
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticMachineCheck::Measure()
{
  using Clock = vtkHapticRealTime::Clock;
  Internals& internal = *this->Internal;
  internal.RealTime = vtkHapticRealTime::SetUpServoThread(
    this->RequestRealTimePriority, this->RealTimePriorityLevel, this->ProcessorIndex, internal.RealTimeStatus);
  // Calibrated where the ticks run: same thread, same priority, same processor.
  const double perMicrosecond = IterationsPerMicrosecond(internal.Sink);
  std::vector<long long> iterations(internal.Work.size());
  double total = 0.0;
  for (size_t n = 0; n < iterations.size(); ++n)
  {
    iterations[n] = static_cast<long long>(internal.Work[n] * 1e6 * perMicrosecond + 0.5);
    total += iterations[n];
  }
  internal.CalibratedWork = MeasureWork(static_cast<long long>(total / iterations.size() + 0.5), internal.Sink);
  const Clock::duration period =
    std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / this->Rate));
  const Clock::duration spin = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(this->SpinTime));
  Clock::time_point deadline = Clock::now() + period;
  for (size_t tick = 0; tick < internal.Ticks; ++tick)
  {
    const bool waited = vtkHapticRealTime::WaitUntil(deadline, spin);
    // As the loop measures a tick: processor time read inside the wall-clock interval.
    const Clock::time_point start = Clock::now();
    const float lateness = waited ? std::chrono::duration<float, std::micro>(start - deadline).count() : 0.0f;
    internal.MaximumWakeUpLateness = std::max(internal.MaximumWakeUpLateness, lateness);
    const double processorStart = vtkHapticRealTime::ThreadProcessorMicroseconds();
    internal.Sink = ConstantWork(iterations[tick % iterations.size()], internal.Sink);
    const double processorEnd = vtkHapticRealTime::ThreadProcessorMicroseconds();
    const Clock::time_point end = Clock::now();
    const float duration = std::chrono::duration<float, std::micro>(end - start).count();
    internal.Durations.push_back(duration);
    internal.ProcessorTimes.push_back(static_cast<float>(processorEnd - processorStart));
    deadline += period;
    if (end > deadline)
    {
      ++internal.Overruns;
      internal.LateWakeUpOverruns += lateness > duration;
      if (end > deadline + period)
      {
        deadline = end + period;
      }
    }
  }
}

//------------------------------------------------------------------------------
vtkIdType vtkHapticMachineCheck::GetNumberOfTicks() const
{
  return this->IsRunning() ? 0 : static_cast<vtkIdType>(this->Internal->Durations.size());
}

//------------------------------------------------------------------------------
double vtkHapticMachineCheck::GetTickDurationPercentile(double percent) const
{
  return this->IsRunning() ? 0.0 : vtkHapticRealTime::Percentile(this->Internal->Durations, percent);
}

//------------------------------------------------------------------------------
double vtkHapticMachineCheck::GetTickProcessorTimePercentile(double percent) const
{
  return this->IsRunning() ? 0.0 : vtkHapticRealTime::Percentile(this->Internal->ProcessorTimes, percent);
}

//------------------------------------------------------------------------------
vtkIdType vtkHapticMachineCheck::GetNumberOfOverruns() const
{
  return this->IsRunning() ? 0 : this->Internal->Overruns;
}

//------------------------------------------------------------------------------
vtkIdType vtkHapticMachineCheck::GetNumberOfLateWakeUpOverruns() const
{
  return this->IsRunning() ? 0 : this->Internal->LateWakeUpOverruns;
}

//------------------------------------------------------------------------------
double vtkHapticMachineCheck::GetMaximumWakeUpLateness() const
{
  return this->IsRunning() ? 0.0 : this->Internal->MaximumWakeUpLateness;
}

//------------------------------------------------------------------------------
vtkIdType vtkHapticMachineCheck::GetNumberOfSlowTicks() const
{
  if (this->IsRunning())
  {
    return 0;
  }
  const float slow = static_cast<float>(this->SlowTickTime * 1e6);
  return std::count_if(this->Internal->Durations.begin(), this->Internal->Durations.end(), [slow](float d) { return d > slow; });
}

//------------------------------------------------------------------------------
vtkIdType vtkHapticMachineCheck::GetNumberOfProcessorBoundSlowTicks() const
{
  if (this->IsRunning())
  {
    return 0;
  }
  const float slow = static_cast<float>(this->SlowTickTime * 1e6);
  const Internals& internal = *this->Internal;
  vtkIdType count = 0;
  for (size_t n = 0; n < internal.Durations.size(); ++n)
  {
    count += internal.Durations[n] > slow && internal.ProcessorTimes[n] > slow;
  }
  return count;
}

//------------------------------------------------------------------------------
double vtkHapticMachineCheck::GetCalibratedWorkTime() const
{
  return this->IsRunning() ? 0.0 : this->Internal->CalibratedWork;
}

//------------------------------------------------------------------------------
bool vtkHapticMachineCheck::GetRealTimePriority() const
{
  return !this->IsRunning() && this->Internal->RealTime;
}

//------------------------------------------------------------------------------
const char* vtkHapticMachineCheck::GetRealTimePriorityStatus() const
{
  return this->IsRunning() ? "running" : this->Internal->RealTimeStatus.c_str();
}

//------------------------------------------------------------------------------
void vtkHapticMachineCheck::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Rate: " << this->Rate << " Hz\n";
  os << indent << "Duration: " << this->Duration << " s\n";
  os << indent << "WorkTime: " << this->WorkTime << " s (calibrated: " << this->GetCalibratedWorkTime() << " us)\n";
  os << indent << "WorkTimes: " << (this->WorkTimes ? this->WorkTimes->GetNumberOfTuples() : 0) << " ticks\n";
  os << indent << "SlowTickTime: " << this->SlowTickTime << " s\n";
  os << indent << "RequestRealTimePriority: " << (this->RequestRealTimePriority ? "on" : "off") << " (level "
     << this->RealTimePriorityLevel << "): " << this->Internal->RealTimeStatus << "\n";
  os << indent << "SpinTime: " << this->SpinTime << " s\n";
  os << indent << "ProcessorIndex: " << this->ProcessorIndex << "\n";
  os << indent << "NumberOfTicks: " << this->GetNumberOfTicks() << "\n";
  os << indent << "NumberOfOverruns: " << this->GetNumberOfOverruns() << " (late wake-ups "
     << this->GetNumberOfLateWakeUpOverruns() << ")\n";
  os << indent << "MaximumWakeUpLateness: " << this->GetMaximumWakeUpLateness() << " us\n";
  os << indent << "NumberOfSlowTicks: " << this->GetNumberOfSlowTicks() << " (processor-bound "
     << this->GetNumberOfProcessorBoundSlowTicks() << ")\n";
}
