// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticLoop
 * @brief   The haptic thread: device in, force out, cut strokes through the field.
 *
 * Start runs a thread that ticks at Rate (1 kHz by default, up to 4 kHz,
 * seed 003). Each tick it reads the device's latest sample (and the foot
 * switch's), maps it into the scene (DeviceToRAS), lets the force model
 * (vtkHapticForceModel) find the proxy, the force and the cut, cuts the
 * field along the way from the last cut (the tool's sweep, one undo step
 * per press of the drill), and sends the force.
 *
 * Cutting. With AsynchronousCutting (the default) the tick does not cut: it
 * queues the stroke's segments (and its beginning and end) for a third
 * thread, the cutter, which is then the field's single writer and cuts them
 * in order, as soon as they come. A segment of a fine field (a 4 mm burr on
 * 0.15 mm voxels) costs hundreds of microseconds, the first of a stroke a
 * millisecond and more: in the tick that would be half the period or an
 * overrun (GetMaximumCutLatency: from the tick to the cut made). The same
 * segments are cut as without it, the shield with them. The force model
 * counts the segments queued and not cut yet as removed (FeelPendingCuts),
 * so that the hand feels what cutting in the tick would have left.
 *
 * Real-time path: no allocation, no lock, nothing shared with the renderer
 * or MRML but lock-free exchanges (with the cutter too). The tick reads devices through their
 * sequence locks; it publishes the tool's pose and force through one for
 * the display, and its cut strokes, drill presses and device losses
 * through a single-producer single-consumer ring that the main thread
 * drains at display rate (ProcessEvents). While it runs, the cutter (or,
 * without AsynchronousCutting, the haptic thread) is the cut field's single
 * writer (readers, the renderers and the force model, read as they like);
 * the application must not cut, undo or restore meanwhile. The cut field's
 * writer allocates a brick the first time a tool reaches it and copies a
 * brick once per stroke for undo (on the cutter: not in a tick); everything
 * else in the tick is allocated by Start.
 *
 * Shield. Where structures are protected, the field's shield is built a
 * brick at a time where a tool first reaches it; built in a tick, a ring of
 * such bricks costs milliseconds. With PrepareShieldAhead (the default) a
 * second thread, the preparer, follows the tool's latest pose (the display
 * value, lock-free) and builds the shield within ShieldLookAhead of the
 * tool's reach before the tool gets there (vtkVolumeCutField::PrepareProtectionAhead);
 * the tick takes the prepared bricks without waiting and builds only what
 * was not prepared in time (counted: GetNumberOfShieldBricksBuiltInTicks).
 *
 * Safety. A device that is lost (unplugged, silent) or gives no sample
 * stops the drill at once: the open stroke is closed (every cut made stays,
 * as one undo step), the force is zero. When the device is back the proxy
 * starts again where the hand is, without sweeping from where it left.
 *
 * Timing. Ticks are scheduled on absolute deadlines; the thread sleeps
 * (clock_nanosleep to the deadline less SpinTime) and waits the rest
 * actively, which keeps the period's jitter well below 0.1 ms on an idle
 * core. Before its first tick the thread asks for real-time priority
 * (RequestRealTimePriority: SCHED_FIFO at RealTimePriorityLevel on Linux,
 * the cutter one level below; time-critical on Windows), a resident stack,
 * precise timer wake-ups and, if ProcessorIndex is set, one processor; the
 * system may refuse priority and processor (then the loop runs at normal
 * priority: GetRealTimePriorityStatus says why, in one line). Other
 * processes then preempt the haptic thread whenever the machine is busy.
 * Because the thread sleeps between its ticks, real-time priority cannot
 * starve the machine: the thread holds a processor only for a tick's work
 * and SpinTime. The process's memory is not locked (mlockall): in Slicer it
 * holds gigabytes of volumes, and a tick touches no new memory (its page
 * faults are counted, GetTickProfile). Tick durations and periods are kept
 * for the last StatisticsCapacity ticks.
 *
 * RunTicks performs the same ticks on the calling thread without waiting
 * between them, cutting in the tick (or with a cutter ReplayCutterDelay
 * ticks behind), for deterministic replays (vtkReplayHapticDevice) and tests.
 *
 * @sa vtkHapticDevice vtkHapticForceModel vtkHapticRecorder
 */

#ifndef vtkHapticLoop_h
#define vtkHapticLoop_h

#include "vtkObject.h"
#include "vtkSmartPointer.h"               // For the parts
#include "vtkWrappingHints.h"               // For VTK_WRAPEXCLUDE
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class vtkHapticCoupling;
class vtkHapticDevice;
class vtkHapticForceModel;
class vtkHapticRecorder;
class vtkMatrix4x4;
class vtkVolumeCutField;
class vtkVolumeCutNerveMonitor;
class vtkVolumeCutTool;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticLoop : public vtkObject
{
public:
  static vtkHapticLoop* New();
  vtkTypeMacro(vtkHapticLoop, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The parts, set while the loop is stopped: the device that moves the
   * tool, an optional second device whose buttons also run the drill (a
   * foot switch), the force model, the field that strokes cut (nullptr: no
   * cutting) and an optional recorder.
   */
  void SetDevice(vtkHapticDevice* device);
  vtkHapticDevice* GetDevice();
  void SetSwitchDevice(vtkHapticDevice* device);
  vtkHapticDevice* GetSwitchDevice();
  void SetForceModel(vtkHapticForceModel* model);
  vtkHapticForceModel* GetForceModel();
  void SetCutField(vtkVolumeCutField* field);
  vtkVolumeCutField* GetCutField();
  void SetRecorder(vtkHapticRecorder* recorder);
  vtkHapticRecorder* GetRecorder();
  ///@}

  ///@{
  /**
   * A nerve monitor (nullptr: none) that each tick reads with the tool's
   * pose, after its cut: lock-free, on the fields its builder published
   * (structures still being built read as not ready). The tick's readings
   * of the first MaximumNerveReadings structures are published for the
   * display side (GetLatestNerveReadings). Set while the loop is stopped.
   */
  void SetNerveMonitor(vtkVolumeCutNerveMonitor* monitor);
  vtkVolumeCutNerveMonitor* GetNerveMonitor();
  static constexpr int MaximumNerveReadings = 16;
  ///@}

  ///@{
  /**
   * Forces forwarded to and from a peer loop (vtkHapticCoupling, nullptr:
   * none). Each tick, the coupling gets the tick's time (tick count over
   * Rate), the proxy and the handle, and its force is added to the force
   * model's; the share of it the device applies (the sum is scaled down to
   * the device's maximum) is reported back to its passivity observer. While
   * the device has no pose the peer is told so and no force is added. Set
   * while the loop is stopped.
   */
  void SetCoupling(vtkHapticCoupling* coupling);
  vtkHapticCoupling* GetCoupling();
  ///@}

  ///@{
  /**
   * Set/get the tick rate (Hz), 1 to 4000. Default is 1000.
   */
  vtkSetClampMacro(Rate, double, 1.0, 4000.0);
  vtkGetMacro(Rate, double);
  ///@}

  /**
   * The device's frame in the scene: a rotation, a uniform scale (scene mm
   * per device mm) and a translation. Refused (false, with an error) if it
   * is not such a matrix. Default is the identity.
   */
  bool SetDeviceToRAS(vtkMatrix4x4* deviceToRAS);
  void GetDeviceToRAS(vtkMatrix4x4* deviceToRAS);

  /// The scale of DeviceToRAS.
  double GetDeviceScale() const;

  /**
   * The tool's orientation in the handle's frame: the tool-to-RAS rotation
   * is DeviceToRAS's rotation times the handle's orientation times this
   * (for devices that sense no rotation, the handle's is the identity).
   * Default is the identity.
   */
  void SetToolRotation(vtkMatrix4x4* rotation);

  ///@{
  /**
   * Set/get the buttons (a bit mask) of either device that run the drill. Default is 1.
   */
  vtkSetMacro(DrillButtons, unsigned int);
  vtkGetMacro(DrillButtons, unsigned int);
  ///@}

  ///@{
  /**
   * Set/get the time (s) before each tick that the thread waits actively
   * instead of sleeping. Default is 0.0002.
   */
  vtkSetClampMacro(SpinTime, double, 0.0, 0.01);
  vtkGetMacro(SpinTime, double);
  ///@}

  ///@{
  /**
   * Set/get whether a preparer thread builds the shield around the tool
   * ahead of the ticks (see Shield above), and how far beyond the tool's
   * reach (mm). Defaults: on, 3 mm. Set while stopped.
   */
  vtkSetMacro(PrepareShieldAhead, bool);
  vtkGetMacro(PrepareShieldAhead, bool);
  vtkBooleanMacro(PrepareShieldAhead, bool);
  vtkSetClampMacro(ShieldLookAhead, double, 0.0, 50.0);
  vtkGetMacro(ShieldLookAhead, double);
  ///@}

  ///@{
  /**
   * Set/get whether the cutter thread cuts the stroke's segments that the
   * ticks queue (see Cutting above) instead of the ticks themselves. Default
   * is on. Set while stopped; RunTicks cuts in the tick unless ReplayCutterDelay is set.
   */
  vtkSetMacro(AsynchronousCutting, bool);
  vtkGetMacro(AsynchronousCutting, bool);
  vtkBooleanMacro(AsynchronousCutting, bool);
  ///@}

  ///@{
  /**
   * Set/get whether, with AsynchronousCutting, each tick's force model counts
   * the segments queued and not cut yet as removed
   * (vtkHapticForceModel::AddPendingCut; the spherical burr's capsules), so
   * that the hand feels the bone as cutting in the tick would have left it
   * however far the cutter is behind. Off, the proxy meets the bone the
   * cutter has not reached yet. Default is on. Set while stopped.
   */
  vtkSetMacro(FeelPendingCuts, bool);
  vtkGetMacro(FeelPendingCuts, bool);
  vtkBooleanMacro(FeelPendingCuts, bool);
  ///@}

  ///@{
  /**
   * Set/get the delay (ticks) of a deterministic cutter for RunTicks: with
   * AsynchronousCutting and a delay of n > 0, RunTicks queues the ticks'
   * cuts as the thread does and cuts each one on the calling thread before
   * the tick n ticks after the one that queued it (Stop cuts the rest): the
   * asynchronous path replayed exactly, a cutter that far behind. Default is
   * 0 (RunTicks cuts in the tick). Set before the first RunTicks of a session.
   */
  vtkSetClampMacro(ReplayCutterDelay, int, 0, 1000);
  vtkGetMacro(ReplayCutterDelay, int);
  ///@}

  ///@{
  /**
   * Set/get whether the haptic thread asks the system for real-time
   * priority (see Timing above), and at which SCHED_FIFO level (1-99; the
   * cutter asks one below). Defaults: on, 80. Set while stopped.
   */
  vtkSetMacro(RequestRealTimePriority, bool);
  vtkGetMacro(RequestRealTimePriority, bool);
  vtkBooleanMacro(RequestRealTimePriority, bool);
  vtkSetClampMacro(RealTimePriorityLevel, int, 1, 99);
  vtkGetMacro(RealTimePriorityLevel, int);
  ///@}

  ///@{
  /**
   * Set/get the processor the thread asks to run on (-1: any). Default is -1.
   */
  vtkSetMacro(ProcessorIndex, int);
  vtkGetMacro(ProcessorIndex, int);
  ///@}

  ///@{
  /**
   * Set/get how many ticks' durations and periods are kept (memory taken at Start). Default is 100000.
   */
  vtkSetClampMacro(StatisticsCapacity, int, 16, 100000000);
  vtkGetMacro(StatisticsCapacity, int);
  ///@}

  /**
   * Check the parts (an open device, a force model that prepares), take the
   * memory the ticks need and start the thread. False, with an error
   * saying what is missing, otherwise.
   */
  bool Start();

  /// Stop the thread; the open stroke is closed on it, the force set to zero.
  void Stop();

  bool IsRunning() const;

  /**
   * Run count ticks on the calling thread, back to back (time step 1 /
   * Rate): deterministic replays and tests. Not while the thread runs.
   * The first call prepares as Start does; Stop ends the session.
   */
  bool RunTicks(int count);

  ///@{
  /**
   * The display side, for the main thread at display rate, lock-free: the
   * tool's latest pose (tool-to-RAS, the proxy's), the force sent (N,
   * device frame), whether the drill runs.
   */
  bool GetLatestToolPose(vtkMatrix4x4* toolToRAS) const;
  void GetLatestForce(double force[3]) const;
  bool GetDrilling() const;
  ///@}

  /**
   * The cut field's deepest contact with a protected structure (mm) as the
   * haptic thread last read it, after its cuts: the main thread must not
   * read the field's contact record while the loop writes it.
   */
  double GetLatestContactDepth() const;

  /**
   * The nerve monitor's readings of the latest tick (a
   * vtkVolumeCutNerveMonitor::Reading each, up to capacity), lock-free:
   * returns their number, -1 before any tick measured.
   */
  VTK_WRAPEXCLUDE int GetLatestNerveReadings(void* readings, int capacity) const;

  /**
   * Drain what the haptic thread reported since the last call (cut strokes,
   * drill presses and releases, device losses and returns, failed cuts) into
   * the counters below; returns the number of cut strokes among them. Main thread.
   */
  int ProcessEvents();

  ///@{
  /**
   * Counts since Start, as drained by ProcessEvents.
   */
  vtkGetMacro(NumberOfCutStrokes, int);
  vtkGetMacro(NumberOfDrillPresses, int);
  vtkGetMacro(NumberOfDrillReleases, int);
  vtkGetMacro(NumberOfDeviceLosses, int);
  vtkGetMacro(NumberOfDeviceReturns, int);
  vtkGetMacro(NumberOfFailedCuts, int);
  vtkGetMacro(NumberOfDroppedEvents, int);
  ///@}

  /// The last stroke segment cut (RAS, tool centres), valid after ProcessEvents counted one.
  void GetLastCutSegment(double p0[3], double p1[3]) const;

  ///@{
  /**
   * Timing of the ticks kept (see StatisticsCapacity), in microseconds:
   * percentiles (0-100) and maximum of a tick's duration (wall time), the
   * percentiles of the processor time the haptic thread spent in a tick
   * (its own CPU clock: the wall time less preemption by other threads),
   * and of the deviation of the period from 1 / Rate; ticks whose work took
   * longer than a period. Read them while stopped.
   */
  unsigned long long GetNumberOfTicks() const;
  double GetTickDurationPercentile(double percent) const;
  double GetTickProcessorTimePercentile(double percent) const;
  double GetMaximumTickDuration() const;
  double GetPeriodJitterPercentile(double percent) const;
  double GetMaximumPeriodJitter() const;
  unsigned long long GetNumberOfOverruns() const;
  ///@}

  ///@{
  /**
   * Overruns the thread slept through: ticks that the system woke later
   * after their deadline than the tick then took (the tick would have fit
   * had it started on time), and the latest such waking, in microseconds.
   * Ticks that start late because the previous one ended late are not
   * counted. On a virtual machine a sleeping processor is woken when the
   * host gets round to it: these are the system's, not the tick's work.
   */
  unsigned long long GetNumberOfLateWakeUpOverruns() const;
  double GetMaximumWakeUpLateness() const;
  ///@}

  ///@{
  /**
   * Whether the system granted the haptic thread real-time priority at its
   * last Start, and what the thread got, in one line: the policy and level,
   * or why it runs at normal priority (not requested, or the system's
   * refusal and what would permit it, e.g. CAP_SYS_NICE or RLIMIT_RTPRIO).
   */
  bool GetRealTimePriority() const;
  const char* GetRealTimePriorityStatus() const;
  ///@}

  ///@{
  /**
   * Where the ticks' time goes, over the ticks kept, in microseconds: the
   * percentiles of the cut stroke's part of a tick (0 in ticks that cut
   * nothing); the shield bricks the haptic thread built itself in its cut
   * strokes (none were prepared in time), the ticks that built any, and the
   * longest of those ticks (0 if none). Read them while stopped.
   */
  double GetCutDurationPercentile(double percent) const;
  unsigned long long GetNumberOfShieldBricksBuiltInTicks() const;
  unsigned long long GetNumberOfTicksBuildingShield() const;
  double GetMaximumTickDurationBuildingShield() const;
  void ResetStatistics();
  ///@}

  ///@{
  /**
   * The cutter's side (AsynchronousCutting), in microseconds, over the
   * segments it cut since Start (the last StatisticsCapacity): the
   * percentiles of one segment's cut, and the longest time from the tick
   * that queued a segment to the segment cut. 0 without a cutter. Read them while stopped.
   */
  double GetCutterDurationPercentile(double percent) const;
  double GetMaximumCutLatency() const;
  ///@}

  /// The parts of a tick's profile (GetTickProfile).
  enum TickProfileField
  {
    /// Wall time and the haptic thread's processor time of the tick (us).
    ProfileDuration,
    ProfileProcessorTime,
    /// The force model's step (contact, proxy, force) and the cut stroke (us).
    ProfileForceModel,
    ProfileCut,
    /// The nerve monitor's reading (us).
    ProfileNerveMonitor,
    /// Shield bricks the tick built itself (none had been prepared).
    ProfileShieldBricksBuilt,
    /// Page faults the haptic thread took in the tick (first touches of memory), and the times the system took the
    /// processor from it (involuntary context switches); 0 where the system does not count them per thread.
    ProfilePageFaults,
    ProfilePreemptions,
    /// The force model's work: shell points in material at its last contact test, its contact tests, the points of
    /// the anatomy all its tests looked up (traces included), and the deepest contact (mm) at the last test.
    ProfileContacts,
    ProfileProxySteps,
    ProfileSamples,
    ProfileImmersion,
    /// Of the points looked up, the cut field's (costlier: curvature-corrected distances).
    ProfileCutFieldSamples,
    NumberOfTickProfileFields
  };

  /**
   * What one of the ticks kept (see StatisticsCapacity) spent its time on, by
   * TickProfileField; index 0 is the oldest kept. Read while stopped. False
   * for an index beyond GetNumberOfKeptTicks. Overruns are told from the
   * machine's own noise by these: a slow tick with a fast processor time
   * and preemptions was the system's, one with page faults touched new memory,
   * one with many samples had the force model trace deep contacts.
   */
  bool GetTickProfile(int index, double profile[13]) const;
  int GetNumberOfKeptTicks() const;

protected:
  vtkHapticLoop();
  ~vtkHapticLoop() override;

  bool Prepare();
  void Run();
  /// The preparer thread's work (see Shield above).
  void PrepareShield();
  /// The cutter thread's work (see Cutting above).
  void CutQueuedSegments();
  void Tick(double timeStep);
  void SafeStop();
  void Finish();

  double Rate = 1000.0;
  unsigned int DrillButtons = 1u;
  double SpinTime = 0.0002;
  int ProcessorIndex = -1;
  bool RequestRealTimePriority = true;
  int RealTimePriorityLevel = 80;
  int StatisticsCapacity = 100000;
  bool PrepareShieldAhead = true;
  double ShieldLookAhead = 3.0;
  bool AsynchronousCutting = true;
  bool FeelPendingCuts = true;
  int ReplayCutterDelay = 0;
  int NumberOfCutStrokes = 0;
  int NumberOfDrillPresses = 0;
  int NumberOfDrillReleases = 0;
  int NumberOfDeviceLosses = 0;
  int NumberOfDeviceReturns = 0;
  int NumberOfFailedCuts = 0;
  int NumberOfDroppedEvents = 0;

  struct Internals;
  std::unique_ptr<Internals> Internal;

private:
  vtkHapticLoop(const vtkHapticLoop&) = delete;
  void operator=(const vtkHapticLoop&) = delete;
};

#endif
