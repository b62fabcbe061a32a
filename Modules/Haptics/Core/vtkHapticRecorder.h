// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticRecorder
 * @brief   A haptic session, tick by tick: what the device gave and what it got.
 *
 * Attached to a vtkHapticLoop, it keeps for every tick the device's sample
 * (position, orientation, buttons; or that the device was not there), the
 * foot switch's buttons, the force sent, the proxy's position and whether
 * the drill ran and cut. Memory for Capacity ticks is taken by SetCapacity,
 * on the main thread; Record, on the haptic thread, only copies (ticks past
 * the capacity are counted, not kept). The session is saved as text
 * (WriteFile, full double precision) with the device's capabilities, read
 * back by ReadFile, and replayed by vtkReplayHapticDevice: tests, demos and
 * session review.
 *
 * @sa vtkReplayHapticDevice vtkHapticLoop
 */

#ifndef vtkHapticRecorder_h
#define vtkHapticRecorder_h

#include "vtkNew.h" // For the capabilities
#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <atomic> // For the count
#include <vector> // For the ticks

class vtkHapticDeviceCapabilities;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticRecorder : public vtkObject
{
public:
  static vtkHapticRecorder* New();
  vtkTypeMacro(vtkHapticRecorder, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

#ifndef __VTK_WRAP__
  /// One recorded tick.
  struct Tick
  {
    unsigned long long Index;
    /// Whether the device was connected and had a sample.
    bool Present;
    double Position[3];
    double Orientation[4];
    unsigned int Buttons;
    unsigned int SwitchButtons;
    double Force[3];
    double Proxy[3];
    bool Drilling;
    bool Cut;
  };
#endif

  /**
   * Room for this many ticks (memory taken now; what was recorded is
   * dropped). Main thread, while no loop records. Default capacity is 0.
   */
  void SetCapacity(int ticks);
  int GetCapacity() const { return static_cast<int>(this->Ticks.size()); }

  /// The loop's rate (Hz) when recorded, kept in the file. Default is 1000.
  vtkSetClampMacro(Rate, double, 1.0, 1.0e5);
  vtkGetMacro(Rate, double);

  /// The recorded device's capabilities (copied in by the loop at Start).
  vtkHapticDeviceCapabilities* GetCapabilities();

#ifndef __VTK_WRAP__
  /// Haptic thread: keep one tick (false, counted, when full).
  bool Record(const Tick& tick);

  /// Tick n (0 <= n < GetNumberOfTicks()).
  const Tick& GetTick(int n) const { return this->Ticks[n]; }
#endif

  /// Ticks recorded, and those that did not fit.
  int GetNumberOfTicks() const { return this->Count.load(std::memory_order_acquire); }
  int GetNumberOfDroppedTicks() const { return this->Dropped.load(std::memory_order_relaxed); }

  ///@{
  /// Parts of tick n, for Python and tests (false / zero outside the recording).
  bool GetTickPresent(int n) const;
  bool GetTickPosition(int n, double position[3]) const;
  bool GetTickForce(int n, double force[3]) const;
  bool GetTickProxy(int n, double position[3]) const;
  unsigned int GetTickButtons(int n) const;
  bool GetTickDrilling(int n) const;
  bool GetTickCut(int n) const;
  ///@}

  /// Forget the ticks, keeping the capacity.
  void Clear();

  /**
   * Save as text. False (and an error naming the file) if it cannot be written.
   */
  bool WriteFile(const char* fileName) const;

  /**
   * Read a recording WriteFile saved; the capacity becomes its length.
   * Missing, truncated or foreign files are refused with an error naming the
   * file and line, keeping what was here.
   */
  bool ReadFile(const char* fileName);

  /**
   * Add a tick from the main thread (building a recording by hand, for
   * demos and tests): the device's pose and buttons; the outputs are zero.
   * False when full.
   */
  bool AppendInput(const double position[3], const double orientation[4], unsigned int buttons, unsigned int switchButtons, bool present);

protected:
  vtkHapticRecorder();
  ~vtkHapticRecorder() override;

  std::vector<Tick> Ticks;
  std::atomic<int> Count{ 0 };
  std::atomic<int> Dropped{ 0 };
  double Rate = 1000.0;
  vtkNew<vtkHapticDeviceCapabilities> Capabilities;

private:
  vtkHapticRecorder(const vtkHapticRecorder&) = delete;
  void operator=(const vtkHapticRecorder&) = delete;
};

#endif
