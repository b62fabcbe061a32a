// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticCoupling
 * @brief   Forces forwarded: a spring-damper between two haptic loops' proxies, kept passive.
 *
 * An instructor's and a trainee's haptic loops (vtkHapticLoop, 1 kHz each,
 * possibly on two machines) each own one of these, linked by a
 * vtkHapticCouplingTransport. Every tick the loop hands in its proxy (the
 * tool where it is drawn, scene mm) and its handle's position (device mm in
 * scene axes: where the force acts); the coupling sends that state, takes
 * the peer's latest, and returns a force pulling the local proxy toward the
 * peer's: Stiffness times their distance plus Damping times their relative
 * velocity. The instructor's hand feels the trainee's tool and, pulling,
 * guides it; the trainee feels the pull.
 *
 * Passivity: the two-layer approach with energy tanks (Franken, Stramigioli,
 * Misra, Secchi, Macchelli, "Bilateral telemanipulation with time delays: a
 * two-layer approach combining passivity and transparency", IEEE Trans.
 * Robotics 27(4), 2011), whose passivity layer is a time-domain passivity
 * observer and controller (Hannaford and Ryu, "Time-domain passivity
 * control of haptic interfaces", IEEE Trans. Robotics and Automation 18(1),
 * 2002). The spring-damper above is only the transparency layer's wish.
 * Each side keeps a tank of energy (mJ = N mm). The observer books, each
 * tick, the work the force applied during the last tick did on the handle
 * (force times the handle's displacement, exact for a force held over the
 * tick): work done by the operator on the coupling fills the tank, work the
 * coupling does on the operator empties it. The controller lets a force out
 * only if the tank pays for its predicted work over the next tick; if not,
 * it removes the part along the handle's velocity (a variable damper, the
 * TDPA controller), and with an empty tank only dissipative force remains.
 * Each tick a share of the tank (EnergyShareRate) is shipped to the peer as a
 * cumulative count in the packet: a lost packet loses no energy (the next
 * carries the sum), a delayed one only arrives later, a stale, replayed or
 * garbled one is dropped by the transport, and energy is never received
 * twice. So, whatever the delay and loss, the energy the two handles
 * receive never exceeds what the operators put in plus the tanks' initial
 * energy (InitialEnergy on each side), up to the observer's one-tick lag
 * (a tank may dip below zero by the misprediction of one tick; the next
 * ticks dissipate it). MaximumEnergy caps a tank so that energy stored long
 * ago cannot be released at once (the excess is dissipated).
 *
 * Limits: stiffness and damping at the hand stay within the device's
 * (SetDeviceLimits, as the force model's), the force within MaximumForce
 * (the device's maximum by default). The coupling ramps in over EngageTime
 * when a peer appears, and fades out: once no packet came for PeerTimeout
 * (or the peer says its device has no pose) the force falls linearly to
 * zero within FadeTime.
 *
 * Threads: configure and Prepare on the main thread while the loop is
 * stopped; Update and ReportAppliedForce on the haptic thread (no
 * allocation, no lock, no blocking); the Get*Latest* values from any thread.
 *
 * @sa vtkHapticCouplingTransport vtkHapticLoop vtkHapticForceModel
 */

#ifndef vtkHapticCoupling_h
#define vtkHapticCoupling_h

#include "vtkObject.h"
#include "vtkSmartPointer.h"               // For the transport
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <memory> // For the internals

class vtkHapticCouplingTransport;
class vtkHapticDeviceCapabilities;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticCoupling : public vtkObject
{
public:
  static vtkHapticCoupling* New();
  vtkTypeMacro(vtkHapticCoupling, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The link to the peer (opened by the caller). Set while the loop is stopped.
  void SetTransport(vtkHapticCouplingTransport* transport);
  vtkHapticCouplingTransport* GetTransport();

  ///@{
  /**
   * Set/get the spring (N per scene mm between the proxies) and the damper
   * (N s per scene mm) that the transparency layer asks for. Defaults 0.5 and 0.002.
   */
  vtkSetClampMacro(Stiffness, double, 0.0, 100.0);
  vtkGetMacro(Stiffness, double);
  vtkSetClampMacro(Damping, double, 0.0, 10.0);
  vtkGetMacro(Damping, double);
  ///@}

  ///@{
  /**
   * Set/get the largest coupling force (N); 0 (default): the device's maximum.
   */
  vtkSetClampMacro(MaximumForce, double, 0.0, 1000.0);
  vtkGetMacro(MaximumForce, double);
  ///@}

  ///@{
  /**
   * Set/get the tank's energy at Prepare and its cap (mJ). Defaults 2 and 20.
   */
  vtkSetClampMacro(InitialEnergy, double, 0.0, 1.0e4);
  vtkGetMacro(InitialEnergy, double);
  vtkSetClampMacro(MaximumEnergy, double, 0.0, 1.0e4);
  vtkGetMacro(MaximumEnergy, double);
  ///@}

  ///@{
  /**
   * Set/get the share of the tank shipped to the peer each tick (0 to 1). Default 0.02.
   */
  vtkSetClampMacro(EnergyShareRate, double, 0.0, 1.0);
  vtkGetMacro(EnergyShareRate, double);
  ///@}

  ///@{
  /**
   * Set/get the ramps (s): in after a peer appears (EngageTime), out after
   * PeerTimeout without packets (FadeTime). Defaults 0.25, 0.05 and 0.1: a
   * vanished peer's pull is gone 0.15 s after its last packet.
   */
  vtkSetClampMacro(EngageTime, double, 0.0, 10.0);
  vtkGetMacro(EngageTime, double);
  vtkSetClampMacro(PeerTimeout, double, 0.0, 10.0);
  vtkGetMacro(PeerTimeout, double);
  vtkSetClampMacro(FadeTime, double, 0.0, 10.0);
  vtkGetMacro(FadeTime, double);
  ///@}

  ///@{
  /**
   * Set/get whether the passivity layer acts. Default on; off only to show,
   * in tests, what the spring-damper alone does under delay.
   */
  vtkSetMacro(PassivityControl, bool);
  vtkGetMacro(PassivityControl, bool);
  vtkBooleanMacro(PassivityControl, bool);
  ///@}

  /**
   * The device's limits (maximum force, stiffness, damping) and the scale
   * of its frame in the scene (scene mm per device mm); the loop sets them
   * at Start. Without a call the coupling asks for no force.
   */
  void SetDeviceLimits(vtkHapticDeviceCapabilities* capabilities, double scale);

  /// The stiffness (N per scene mm), damping (N s per scene mm) and force limit (N) used, after the device's limits.
  vtkGetMacro(AppliedStiffness, double);
  vtkGetMacro(AppliedDamping, double);
  vtkGetMacro(AppliedMaximumForce, double);

  /**
   * Reset the tank, the peer and the statistics (allocated here, capacity
   * StatisticsCapacity ticks). The loop calls it at Start. False, with an
   * error, without an open transport.
   */
  bool Prepare();

  ///@{
  /**
   * Set/get how many ticks' update times are kept. Default 100000.
   */
  vtkSetClampMacro(StatisticsCapacity, int, 16, 100000000);
  vtkGetMacro(StatisticsCapacity, int);
  ///@}

  /**
   * One tick, haptic thread: the local clock (s), the proxy (scene mm), the
   * handle (device mm in scene axes) and whether the device has a pose
   * (false: the peer is told, nothing is booked, no force). Writes the
   * coupling force (N, scene axes), limits and passivity applied.
   */
  void Update(double time, const double proxy[3], const double handle[3], bool present, double force[3]);

  /**
   * The part of the force the device really applied this tick (the loop
   * scales the sum of all forces down to the device's maximum); without a
   * call, all of it. The observer books the work of this force.
   */
  void ReportAppliedForce(const double force[3]);

  ///@{
  /**
   * The latest tick's figures, from any thread: the force returned (N),
   * the tank (mJ), the energies (mJ) the operator put in and the coupling
   * gave out at this side's handle, shipped to and received from the peer,
   * dissipated by the controller and the cap, the peer's proxy as last
   * received, the gain (0 to 1: ramps and fading) and the time since the
   * last packet (s; negative: none yet).
   */
  void GetLatestForce(double force[3]) const;
  double GetLatestTank() const;
  double GetEnergyIn() const;
  double GetEnergyOut() const;
  double GetEnergyShipped() const;
  double GetEnergyReceived() const;
  double GetEnergyDissipated() const;
  bool GetLatestPeerPosition(double position[3]) const;
  double GetLatestGain() const;
  double GetLatestPeerAge() const;
  ///@}

  ///@{
  /**
   * Percentiles (0-100) of the time Update took (us), over the ticks kept, and their number. Read while stopped.
   */
  double GetUpdateDurationPercentile(double percent) const;
  unsigned long long GetNumberOfUpdates() const;
  ///@}

protected:
  vtkHapticCoupling();
  ~vtkHapticCoupling() override;

  double Stiffness = 0.5;
  double Damping = 0.002;
  double MaximumForce = 0.0;
  double InitialEnergy = 2.0;
  double MaximumEnergy = 20.0;
  double EnergyShareRate = 0.02;
  double EngageTime = 0.25;
  double PeerTimeout = 0.05;
  double FadeTime = 0.1;
  bool PassivityControl = true;
  int StatisticsCapacity = 100000;
  double AppliedStiffness = 0.0;
  double AppliedDamping = 0.0;
  double AppliedMaximumForce = 0.0;

  vtkSmartPointer<vtkHapticCouplingTransport> Transport;

  struct Internals;
  std::unique_ptr<Internals> Internal;

private:
  vtkHapticCoupling(const vtkHapticCoupling&) = delete;
  void operator=(const vtkHapticCoupling&) = delete;
};

#endif
