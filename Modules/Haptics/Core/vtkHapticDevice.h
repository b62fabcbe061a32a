// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticDevice
 * @brief   A haptic or 3D input device: its samples in, its forces out.
 *
 * The interface every backend implements (Novint Falcon over libusb,
 * SpaceMouse and foot switches over hidapi, the mouse-driven virtual device,
 * the replay of a recording), after libnifalcon's split of a device into
 * communication, firmware and kinematics and CHAI3D's capability data
 * (vtkHapticDeviceCapabilities): the product never asks which kind of device
 * it has, only what it can do.
 *
 * Threads. Open, Close and ProcessConnectionEvents belong to the thread that
 * owns the scene (the main thread). A backend's own I/O thread publishes
 * samples; any thread reads the latest one without a lock (a sequence lock
 * the reader gives up on rather than wait). SetForce is called by one
 * thread at a time, the haptic loop's while it runs; it never blocks. What
 * goes wrong on the I/O or haptic thread (garbage from the device, a
 * non-finite force, a device that stops answering or is unplugged) is
 * counted there and reported by ProcessConnectionEvents on the main thread.
 *
 * Hot-plug. A backend that loses its device says so (the state becomes Lost
 * and the force is dropped). ProcessConnectionEvents, called at display
 * rate, then closes it, invokes DeviceDisconnectedEvent, and tries to open
 * it again every ReconnectInterval seconds; when it succeeds it invokes
 * DeviceConnectedEvent. The haptic loop stops drilling while a device is not
 * connected and resumes when it is back.
 *
 * Frames. Positions are in millimetres in the device's frame, the origin at
 * the centre of its workspace; orientations are unit quaternions (w, x, y,
 * z); forces are in newtons in the same frame.
 *
 * @sa vtkHapticDeviceCapabilities vtkHapticLoop
 */

#ifndef vtkHapticDevice_h
#define vtkHapticDevice_h

#include "vtkCommand.h" // For the events
#include "vtkNew.h"     // For the capabilities
#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class vtkHapticDeviceCapabilities;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticDevice : public vtkObject
{
public:
  vtkTypeMacro(vtkHapticDevice, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Connection states.
  enum ConnectionStates
  {
    Closed = 0, ///< never opened, or closed by the application
    Connected,  ///< samples arrive and forces are sent
    Lost        ///< unplugged or silent; ProcessConnectionEvents reconnects
  };

  /// Events, invoked by ProcessConnectionEvents on the calling thread.
  enum Events
  {
    DeviceConnectedEvent = vtkCommand::UserEvent + 1310,
    DeviceDisconnectedEvent
  };

  /**
   * Open the device. Returns false and logs an error saying why (not found,
   * no permission, firmware file missing, ...) if it cannot; the device is
   * then Closed. Opening an open device does nothing and returns true.
   */
  bool Open();

  /// Close the device (stops its I/O thread, zero force first). Closed afterwards.
  void Close();

  /// The connection state (ConnectionStates), from any thread.
  int GetConnectionState() const;
  bool IsConnected() const { return this->GetConnectionState() == Connected; }

  /// What the device can do.
  vtkHapticDeviceCapabilities* GetCapabilities();

#ifndef __VTK_WRAP__
  /// One input sample.
  struct Sample
  {
    /// mm, device frame (origin at the workspace centre).
    double Position[3] = { 0.0, 0.0, 0.0 };
    /// Unit quaternion (w, x, y, z); identity for devices without rotation.
    double Orientation[4] = { 1.0, 0.0, 0.0, 0.0 };
    /// Bit n set while button n is pressed.
    unsigned int Buttons = 0;
    /// Seconds since Open.
    double Time = 0.0;
    /// 1 for the first sample after Open, then counting.
    unsigned long long Index = 0;
    /// False when the device said that nobody holds it or that it is
    /// absent for now (a recorded disconnection being replayed).
    bool Present = true;
  };

  /**
   * The latest sample, from any thread, without waiting. False if there is
   * none since the device was opened, or if the publishing thread was caught
   * half-way too often (then keep the previous sample). A sample whose
   * Present is false says the device has no pose for now.
   */
  bool GetLatestSample(Sample& sample) const;
#endif

  ///@{
  /**
   * Parts of the latest sample (see GetLatestSample), for Python and tests.
   * The first two return false, leaving the argument unchanged, without one.
   */
  bool GetLatestPosition(double position[3]) const;
  bool GetLatestOrientation(double orientation[4]) const;
  unsigned int GetLatestButtons() const;
  unsigned long long GetNumberOfSamples() const;
  ///@}

  /**
   * Ask the device for a force (N, device frame). A force that is not finite
   * is rejected (zero is sent instead); a larger one than the device's
   * maximum is scaled down to it, direction kept. Returns true if the force
   * was sent as asked, false if it was rejected, clamped, or the device is
   * not connected (nothing is sent then). Never blocks or allocates; call it
   * from one thread at a time.
   */
  bool SetForce(const double force[3]);

  /// The force the device was last asked for, after the limits (N).
  void GetCommandedForce(double force[3]) const;

  ///@{
  /**
   * Counts since Open of force requests rejected (not finite) or clamped
   * (above the maximum), and of input the device sent that was rejected
   * (garbage frames, non-finite positions).
   */
  unsigned long long GetNumberOfRejectedForces() const;
  unsigned long long GetNumberOfClampedForces() const;
  unsigned long long GetNumberOfRejectedInputs() const;
  ///@}

  /**
   * Called by the haptic loop once per tick, on its thread, before it reads
   * the latest sample: devices the loop steps (the replay of a recording)
   * publish the sample of that tick here. Others ignore it.
   */
  virtual void Synchronize(unsigned long long tick);

  /**
   * On the main thread, at display rate: reports what the I/O and haptic
   * threads counted (as warnings), closes a lost device and invokes
   * DeviceDisconnectedEvent, and tries to reopen it (AutoReconnect) every
   * ReconnectInterval seconds, invoking DeviceConnectedEvent when it is back.
   */
  void ProcessConnectionEvents();

  ///@{
  /**
   * Set/get whether ProcessConnectionEvents reopens a lost device. Default is true.
   */
  vtkSetMacro(AutoReconnect, bool);
  vtkGetMacro(AutoReconnect, bool);
  vtkBooleanMacro(AutoReconnect, bool);
  ///@}

  ///@{
  /**
   * Set/get the time (s) between two attempts to reopen a lost device. Default is 0.5.
   */
  vtkSetClampMacro(ReconnectInterval, double, 0.0, 3600.0);
  vtkGetMacro(ReconnectInterval, double);
  ///@}

  /// How many times the device was connected since it was created (opens and reconnections).
  vtkGetMacro(NumberOfConnections, int);

  /// Why the last open failed or the device was lost ("" if it never was).
  const char* GetLastErrorMessage() const;

protected:
  vtkHapticDevice();
  ~vtkHapticDevice() override;

  /**
   * Open the hardware and start publishing samples; on failure return false
   * having called SetErrorMessage with the reason (Open logs it; a
   * reconnection attempt does not). Main thread.
   */
  virtual bool OpenDevice() = 0;

  /// Stop publishing and release the hardware (join the I/O thread). Main thread.
  virtual void CloseDevice() = 0;

  /// Send a force that passed the limits (N, device frame). The caller's thread; must not block.
  virtual void WriteForce(const double force[3]);

  /// For backends, main thread: why opening failed.
  void SetErrorMessage(const char* message);

  /// For backends, their I/O thread: a new sample (a non-finite one is rejected and counted).
  void PublishSample(const double position[3], const double orientation[4], unsigned int buttons);

  /// For backends, their I/O thread: no sample for now (the last one's pose, marked absent).
  void PublishAbsence();

  /// For backends, their I/O thread: the device is gone or silent. The force is dropped.
  void ReportLost(const char* reason);

  /// For backends, their I/O thread: input that made no sense was dropped.
  void ReportRejectedInput();

  /// Seconds since the device was last opened (steady clock).
  double GetTimeSinceOpen() const;

  vtkNew<vtkHapticDeviceCapabilities> Capabilities;
  bool AutoReconnect = true;
  double ReconnectInterval = 0.5;
  int NumberOfConnections = 0;

private:
  /// Shared by Open and the reconnection attempts.
  bool OpenAndStart();

  struct Internals;
  std::unique_ptr<Internals> Internal;

  vtkHapticDevice(const vtkHapticDevice&) = delete;
  void operator=(const vtkHapticDevice&) = delete;
};

#endif
