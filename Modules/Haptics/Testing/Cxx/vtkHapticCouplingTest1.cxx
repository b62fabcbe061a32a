// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Forces forwarded: an instructor's and a trainee's haptic loop, each with a
// virtual device (the instructor's also as a replay), coupled over UDP on
// loopback with 0, 5 and 20 ms of injected one-way delay and 0 or 10 %
// loss. The loops tick in lockstep on this thread (RunTicks, 1 kHz of
// simulated time) and the hands are simulated: a handle of mass m moved by
// the device's force and the operator's (the instructor: a spring-damper
// arm following a path with a step; the trainee: a relaxed, lightly damped
// hand). The test books the work each device force did on its handle
// (force held over a tick times the handle's displacement), independently
// of the coupling's own observer.
//
// Criteria, at every tick of every case:
//  - no device force above the device's maximum (3.3 N here, a Touch's: the
//    instructor's step asks for more), none clamped by the device;
//  - passivity: the energy the coupling delivered to both handles, less
//    what the operators put into it, never exceeds the two tanks' initial
//    energy (2 mJ each) plus 0.5 mJ for the observer's one-tick lag;
//  - bounded: the trainee's handle stays within 40 mm of the instructor's;
//  - tracking: without delay or loss, the trainee's handle follows the
//    instructor's within 0.25 mm RMS over the smooth part of the path.
// Without the passivity layer, 20 ms of delay breaks the energy criterion:
// the check can fail. Garbled, replayed, foreign and stale packets are
// ignored; a peer that goes silent fades to no force within PeerTimeout +
// FadeTime (0.15 s).
#include "vtkHapticTestScene.h"
#include "vtkHapticTestWaiting.h"

#include "vtkHapticCoupling.h"
#include "vtkHapticCouplingTransport.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkHapticRecorder.h"
#include "vtkReplayHapticDevice.h"
#include "vtkVirtualHapticDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
constexpr double TimeStep = 1e-3;
constexpr double DeviceMaximumForce = 3.3;
constexpr double InitialEnergy = 2.0;
constexpr double ObserverLag = 0.05;
constexpr double Pi = 3.14159265358979323846;

/// The instructor's path (device mm): a slow figure, then a 12 mm step at 2 s.
void InstructorTarget(double time, double target[3])
{
  target[0] = 8.0 * std::sin(2.0 * Pi * 0.5 * time) + (time >= 2.0 ? 12.0 : 0.0);
  target[1] = 4.0 * std::sin(2.0 * Pi * 0.25 * time);
  target[2] = 0.0;
}

/// A handle and the hand on it.
struct Hand
{
  double Mass = 0.1;          ///< kg
  double Stiffness = 0.0;     ///< N/mm toward the target (0: relaxed)
  double Damping = 0.001;     ///< N s/mm
  bool FollowsPath = false;   ///< the instructor's target, else Hold
  double Hold[3] = { 0, 0, 0 };
  double Position[3] = { 0, 0, 0 };
  double Velocity[3] = { 0, 0, 0 };
  double Work = 0.0;          ///< mJ done on the handle by the device's forces

  /// The instructor's arm on its path: a 0.15 kg handle held with this stiffness and damping.
  void Instruct(double stiffness, double damping)
  {
    this->Mass = 0.15;
    this->Stiffness = stiffness;
    this->Damping = damping;
    this->FollowsPath = true;
  }

  /// One tick under the device force held over it (semi-implicit Euler); returns the displacement.
  void Step(double time, const double deviceForce[3], double displacement[3])
  {
    double target[3];
    if (this->FollowsPath)
    {
      InstructorTarget(time, target);
    }
    else
    {
      std::copy(this->Hold, this->Hold + 3, target);
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      const double hand = this->Stiffness * (target[axis] - this->Position[axis]) - this->Damping * this->Velocity[axis];
      // N / kg = m/s^2 = 1000 mm/s^2.
      this->Velocity[axis] += TimeStep * 1000.0 * (deviceForce[axis] + hand) / this->Mass;
      displacement[axis] = TimeStep * this->Velocity[axis];
      this->Position[axis] += displacement[axis];
    }
    this->Work += vtkMath::Dot(deviceForce, displacement);
  }
};

/// One side: device, force model, loop, coupling and its transport.
struct Side
{
  vtkSmartPointer<vtkHapticDevice> Device;
  vtkNew<vtkHapticForceModel> Model;
  vtkNew<vtkHapticLoop> Loop;
  vtkNew<vtkHapticCoupling> Coupling;
  vtkNew<vtkHapticCouplingTransport> Transport;
  Hand Operator;
  bool Simulated = true;
};

struct Figures
{
  double MaximumForce = 0.0;
  unsigned long long Clamped = 0;
  double WorstPassivityMargin = -1e300; ///< max over ticks of delivered - put in - initial (mJ)
  double MaximumSeparation = 0.0;
  double TrackingRMS = 0.0;
  bool Finite = true;
  /// The trainee's coupling force, tick by tick.
  std::vector<double> TraineeCouplingForce;
};

bool Configure(vtkHapticTestScene& scene, Side& side, double delay, double loss, unsigned long long seed, bool passivity)
{
  side.Device->GetCapabilities()->SetMaximumForce(DeviceMaximumForce);
  side.Model->SetAnatomy(scene.CT, scene.IJKToRAS);
  side.Model->SetSurfaceIsoValue(scene.IsoValue);
  side.Model->SetSphereRadius(2.0);
  // The tools meet nothing but air: the smallest shell keeps the test quick under the sanitizers.
  side.Model->SetNumberOfShellPoints(6);
  side.Loop->SetDevice(side.Device);
  side.Loop->SetForceModel(side.Model);
  vtkNew<vtkMatrix4x4> deviceToRAS;
  // Free space above the analytic bone: only the coupling pushes.
  deviceToRAS->SetElement(2, 3, scene.PlaneHeight + 10.0);
  side.Loop->SetDeviceToRAS(deviceToRAS);
  side.Loop->SetCoupling(side.Coupling);
  side.Loop->SetStatisticsCapacity(16);
  side.Coupling->SetTransport(side.Transport);
  side.Coupling->SetInitialEnergy(InitialEnergy);
  side.Coupling->SetPassivityControl(passivity);
  side.Transport->SetInjectedDelay(delay);
  side.Transport->SetInjectedLossRate(loss);
  side.Transport->SetInjectionSeed(seed);
  return side.Device->Open();
}

bool Link(Side& a, Side& b)
{
  return a.Transport->Open("127.0.0.1", 0, "127.0.0.1", 9) && b.Transport->Open("127.0.0.1", 0, "127.0.0.1", a.Transport->GetLocalPort()) &&
    a.Transport->Open("127.0.0.1", a.Transport->GetLocalPort(), "127.0.0.1", b.Transport->GetLocalPort());
}

/// Push a simulated hand's pose into its virtual device.
void Publish(Side& side)
{
  if (side.Simulated)
  {
    vtkVirtualHapticDevice::SafeDownCast(side.Device)->SetPose(side.Operator.Position, 0u);
  }
}

/// Ticks both loops in lockstep for a duration; the instructor is a, the trainee b.
bool Run(Side& a, Side& b, double start, double duration, Figures& figures, double trackingFrom = 1e300, double trackingTo = -1.0,
  bool instructorTicks = true)
{
  const int ticks = static_cast<int>(std::lround(duration / TimeStep));
  double squared = 0.0;
  int tracked = 0;
  for (int n = 0; n < ticks; ++n)
  {
    const double time = start + n * TimeStep;
    double held[3] = { 0, 0, 0 };
    for (Side* side : { &a, &b })
    {
      double force[3];
      side->Device->GetCommandedForce(force);
      figures.MaximumForce = std::max(figures.MaximumForce, vtkMath::Norm(force));
      if (side->Simulated)
      {
        double displacement[3];
        side->Operator.Step(time, force, displacement);
        Publish(*side);
      }
      else
      {
        std::copy(force, force + 3, held);
      }
    }
    if ((instructorTicks && !a.Loop->RunTicks(1)) || !b.Loop->RunTicks(1))
    {
      return false;
    }
    double coupling[3];
    b.Coupling->GetLatestForce(coupling);
    figures.TraineeCouplingForce.push_back(vtkMath::Norm(coupling));
    if (!a.Simulated)
    {
      // The replayed instructor is a position source: its handle moves as
      // recorded, and the force held over the step did this work on it.
      double after[3], step[3];
      a.Device->GetLatestPosition(after);
      vtkMath::Subtract(after, a.Operator.Position, step);
      a.Operator.Work += n > 0 ? vtkMath::Dot(held, step) : 0.0;
      std::copy(after, after + 3, a.Operator.Position);
    }
    const double delivered = a.Operator.Work + b.Operator.Work;
    figures.WorstPassivityMargin = std::max(figures.WorstPassivityMargin, delivered - 2.0 * InitialEnergy);
    const double separation = std::sqrt(vtkMath::Distance2BetweenPoints(a.Operator.Position, b.Operator.Position));
    figures.MaximumSeparation = std::max(figures.MaximumSeparation, separation);
    figures.Finite = figures.Finite && std::isfinite(separation) && std::isfinite(delivered);
    if (time >= trackingFrom && time < trackingTo)
    {
      squared += separation * separation;
      ++tracked;
    }
  }
  figures.Clamped = a.Device->GetNumberOfClampedForces() + b.Device->GetNumberOfClampedForces();
  if (tracked > 0)
  {
    figures.TrackingRMS = std::sqrt(squared / tracked);
  }
  return true;
}

/// (Returns EXIT_SUCCESS or EXIT_FAILURE, as the testing macros inside it do: a bool would read their failure as true.)
/// The trainee holds firm while the instructor pulls along the path; the
/// trainee's port is probed with bad packets, then the instructor goes silent.
int HeldCase(vtkHapticTestScene& scene)
{
  Side a, b;
  a.Device = vtkSmartPointer<vtkVirtualHapticDevice>::New();
  b.Device = vtkSmartPointer<vtkVirtualHapticDevice>::New();
  // Firm arms (2 N/mm) on both sides: in series with the coupling's spring,
  // the instructor's 20 mm excursion asks for 6.7 N.
  a.Operator.Instruct(2.0, 0.01);
  b.Operator.Stiffness = 2.0;
  b.Operator.Damping = 0.01;
  if (!Configure(scene, a, 0.005, 0.1, 5, true) || !Configure(scene, b, 0.005, 0.1, 7, true) || !Link(a, b))
  {
    return EXIT_FAILURE;
  }
  Publish(a);
  Publish(b);
  Figures engaged;
  CHECK_BOOL(Run(a, b, 0.0, 1.0, engaged), true);

  // Bad packets from this host: noise, a flipped bit, a replay of the
  // instructor's first packet, another session's packet, all placing the
  // peer 100 mm away. Sent while nothing is in flight from the instructor.
  vtkNew<vtkHapticCouplingTransport> probe;
  CHECK_BOOL(probe->Open("127.0.0.1", 0, "127.0.0.1", b.Transport->GetLocalPort()), true);
  unsigned long long noise = 12345;
  for (int n = 0; n < 50; ++n)
  {
    unsigned char bytes[200];
    const int size = (n % 2) ? vtkHapticCouplingTransport::PacketSize : 1 + n * 3;
    for (int k = 0; k < size; ++k)
    {
      noise = noise * 6364136223846793005ull + 1442695040888963407ull;
      bytes[k] = static_cast<unsigned char>(noise >> 56);
    }
    CHECK_BOOL(probe->SendRawDatagram(bytes, size), true);
  }
  vtkHapticCouplingTransport::State fake;
  fake.Session = a.Transport->GetSession();
  fake.Sequence = 1;
  fake.Time = 0.5;
  fake.Position[0] = fake.Position[1] = fake.Position[2] = 100.0;
  fake.EnergySent = 1000.0;
  fake.Flags = vtkHapticCouplingTransport::PresentFlag;
  unsigned char packet[vtkHapticCouplingTransport::PacketSize];
  vtkHapticCouplingTransport::EncodePacket(fake, packet);
  CHECK_BOOL(probe->SendRawDatagram(packet, vtkHapticCouplingTransport::PacketSize), true);
  fake.Sequence = 1000000000ull;
  vtkHapticCouplingTransport::EncodePacket(fake, packet);
  packet[40] ^= 0x10;
  CHECK_BOOL(probe->SendRawDatagram(packet, vtkHapticCouplingTransport::PacketSize), true);
  fake.Session = a.Transport->GetSession() + 2;
  vtkHapticCouplingTransport::EncodePacket(fake, packet);
  CHECK_BOOL(probe->SendRawDatagram(packet, vtkHapticCouplingTransport::PacketSize), true);
  const double receivedBefore = b.Coupling->GetEnergyReceived();
  Figures attacked;
  // 53 bad datagrams and the instructor's own: drained at most 32 a tick.
  CHECK_BOOL(Run(a, b, 1.0, 0.005, attacked), true);
  double peer[3];
  CHECK_BOOL(b.Coupling->GetLatestPeerPosition(peer), true);
  double instructorProxy[3];
  vtkNew<vtkMatrix4x4> pose;
  a.Loop->GetLatestToolPose(pose);
  for (int axis = 0; axis < 3; ++axis)
  {
    instructorProxy[axis] = pose->GetElement(axis, 3);
  }
  std::cout << "bad packets: garbled " << b.Transport->GetNumberOfGarbledPackets() << ", stale " << b.Transport->GetNumberOfStalePackets()
            << ", foreign session " << b.Transport->GetNumberOfForeignSessionPackets() << "; peer seen "
            << std::sqrt(vtkMath::Distance2BetweenPoints(peer, instructorProxy)) << " mm from the instructor's proxy" << std::endl;
  CHECK_BOOL(b.Transport->GetNumberOfGarbledPackets() >= 51, true);
  CHECK_BOOL(b.Transport->GetNumberOfStalePackets() >= 1, true);
  CHECK_BOOL(b.Transport->GetNumberOfForeignSessionPackets() >= 1, true);
  CHECK_BOOL(std::sqrt(vtkMath::Distance2BetweenPoints(peer, instructorProxy)) < 5.0, true);
  CHECK_BOOL(b.Coupling->GetEnergyReceived() - receivedBefore < 1.0, true);

  // The instructor pulls 20 mm away from the firm trainee: the spring asks for more than the device's 3.3 N.
  Figures pulled;
  CHECK_BOOL(Run(a, b, 1.005, 1.5, pulled), true);
  std::cout << "held trainee: max force " << pulled.MaximumForce << " N, passivity margin " << pulled.WorstPassivityMargin << " mJ" << std::endl;
  CHECK_BOOL(pulled.MaximumForce <= DeviceMaximumForce + 1e-9 && pulled.MaximumForce > 0.99 * DeviceMaximumForce, true);
  CHECK_BOOL(pulled.Clamped == 0, true);
  CHECK_BOOL(pulled.TraineeCouplingForce.back() > 1.0, true);

  // The instructor vanishes: its last packets are in flight for the 5 ms delay, then nothing.
  const double fadeBound = b.Coupling->GetPeerTimeout() + b.Coupling->GetFadeTime();
  Figures silent;
  CHECK_BOOL(Run(a, b, 2.505, 0.4, silent, 1e300, -1.0, false), true);
  size_t lastForce = 0;
  for (size_t n = 0; n < silent.TraineeCouplingForce.size(); ++n)
  {
    if (silent.TraineeCouplingForce[n] > 0.0)
    {
      lastForce = n + 1;
    }
  }
  const double zeroAfter = lastForce * TimeStep - a.Transport->GetInjectedDelay();
  std::cout << "silent instructor: the trainee's coupling force is zero " << 1000.0 * zeroAfter
            << " ms after the instructor's last packet (bound " << 1000.0 * fadeBound << " ms)" << std::endl;
  CHECK_BOOL(zeroAfter <= fadeBound + 2.0 * TimeStep, true);
  CHECK_BOOL(zeroAfter > b.Coupling->GetPeerTimeout() - 2.0 * TimeStep, true);
  return EXIT_SUCCESS;
}

/// Listening (the trainee's side): the first sender becomes the peer and gets the replies; another address is
/// foreign while the peer is alive, and takes its place once it has been silent for the session timeout.
int ListenCase()
{
  vtkNew<vtkHapticCouplingTransport> listener;
  listener->SetSessionTimeout(0.5);
  CHECK_BOOL(listener->Open("127.0.0.1", 0, "0.0.0.0", 0), true);
  CHECK_BOOL(listener->IsListening(), true);
  CHECK_BOOL(listener->GetPeerAddress().empty(), true);
  vtkNew<vtkHapticCouplingTransport> first;
  vtkNew<vtkHapticCouplingTransport> second;
  CHECK_BOOL(first->Open("127.0.0.1", 0, "127.0.0.1", listener->GetLocalPort()), true);
  CHECK_BOOL(second->Open("127.0.0.1", 0, "127.0.0.1", listener->GetLocalPort()), true);
  CHECK_BOOL(first->IsListening(), false);
  vtkHapticCouplingTransport::State state;
  vtkHapticCouplingTransport::State latest;
  state.Flags = vtkHapticCouplingTransport::PresentFlag;
  CHECK_BOOL(listener->Send(state, 0.5), false); // nobody joined: nowhere to send
  CHECK_BOOL(first->Send(state, 1.0), true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return listener->ReceiveLatest(1.0, latest); }), true);
  const std::string firstAddress = "127.0.0.1:" + std::to_string(first->GetLocalPort());
  CHECK_STD_STRING(listener->GetPeerAddress(), firstAddress);
  CHECK_BOOL(latest.Session == first->GetSession(), true);
  CHECK_BOOL(listener->Send(state, 1.0), true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return first->ReceiveLatest(1.0, latest); }), true);
  CHECK_BOOL(latest.Session == listener->GetSession(), true);

  CHECK_BOOL(second->Send(state, 1.1), true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() {
    listener->ReceiveLatest(1.1, latest);
    return listener->GetNumberOfForeignHostPackets() == 1;
  }), true);
  CHECK_STD_STRING(listener->GetPeerAddress(), firstAddress);

  CHECK_BOOL(second->Send(state, 2.0), true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return listener->ReceiveLatest(2.0, latest); }), true);
  CHECK_STD_STRING(listener->GetPeerAddress(), "127.0.0.1:" + std::to_string(second->GetLocalPort()));
  CHECK_BOOL(latest.Session == second->GetSession(), true);
  CHECK_BOOL(listener->Send(state, 2.0), true);
  CHECK_BOOL(vtkHapticTestWaitFor([&]() { return second->ReceiveLatest(2.0, latest); }), true);
  return EXIT_SUCCESS;
}

/// One stability case with two virtual devices (or a replayed instructor).
bool StabilityCase(vtkHapticTestScene& scene, double delay, double loss, bool passivity, bool replayInstructor, Figures& figures)
{
  Side a, b;
  vtkNew<vtkHapticRecorder> recording;
  if (replayInstructor)
  {
    // The instructor's path, recorded as a stiff hand would move it.
    recording->SetCapacity(4000);
    const double identity[4] = { 1, 0, 0, 0 };
    for (int n = 0; n < 4000; ++n)
    {
      double target[3];
      InstructorTarget(n * TimeStep, target);
      recording->AppendInput(target, identity, 0u, 0u, true);
    }
    recording->GetCapabilities()->SetMaximumForce(DeviceMaximumForce);
    recording->GetCapabilities()->SetMaximumStiffness(3.0);
    recording->GetCapabilities()->SetMaximumDamping(0.02);
    vtkNew<vtkReplayHapticDevice> replay;
    replay->SetRecording(recording);
    a.Device = replay;
    a.Simulated = false;
  }
  else
  {
    a.Device = vtkSmartPointer<vtkVirtualHapticDevice>::New();
  }
  b.Device = vtkSmartPointer<vtkVirtualHapticDevice>::New();
  // The instructor: a firm arm (0.3 N/mm) on the path; the trainee: a relaxed hand, 3 mm off.
  a.Operator.Instruct(0.3, 0.004);
  b.Operator.Position[0] = 3.0;
  b.Operator.Position[1] = -2.0;
  if (!Configure(scene, a, delay, loss, 11, passivity) || !Configure(scene, b, delay, loss, 23, passivity) || !Link(a, b))
  {
    std::cerr << "the pair could not be set up" << std::endl;
    return false;
  }
  Publish(a);
  Publish(b);
  return Run(a, b, 0.0, 3.0, figures, 0.5, 2.0);
}
} // namespace

int vtkHapticCouplingTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkHapticTestScene scene;

  // The packet: round trip, and every single flipped bit refused.
  {
    vtkHapticCouplingTransport::State state;
    state.Session = 77;
    state.Sequence = 5;
    state.Time = 1.25;
    state.Position[1] = -3.5;
    state.Velocity[2] = 40.0;
    state.EnergySent = 2.5;
    state.Flags = vtkHapticCouplingTransport::PresentFlag;
    unsigned char packet[vtkHapticCouplingTransport::PacketSize];
    vtkHapticCouplingTransport::EncodePacket(state, packet);
    vtkHapticCouplingTransport::State decoded;
    CHECK_BOOL(vtkHapticCouplingTransport::DecodePacket(packet, vtkHapticCouplingTransport::PacketSize, decoded), true);
    CHECK_BOOL(decoded.Sequence == 5 && decoded.Position[1] == -3.5 && decoded.Velocity[2] == 40.0 && decoded.EnergySent == 2.5, true);
    int refused = 0;
    for (int bit = 0; bit < 8 * vtkHapticCouplingTransport::PacketSize; ++bit)
    {
      packet[bit / 8] ^= static_cast<unsigned char>(1u << (bit % 8));
      refused += vtkHapticCouplingTransport::DecodePacket(packet, vtkHapticCouplingTransport::PacketSize, decoded) ? 0 : 1;
      packet[bit / 8] ^= static_cast<unsigned char>(1u << (bit % 8));
    }
    CHECK_INT(refused, 8 * vtkHapticCouplingTransport::PacketSize);
    CHECK_BOOL(vtkHapticCouplingTransport::DecodePacket(packet, vtkHapticCouplingTransport::PacketSize - 1, decoded), false);
  }

  // Stability: delay x loss, two virtual devices.
  for (double delay : { 0.0, 0.005, 0.020 })
  {
    for (double loss : { 0.0, 0.1 })
    {
      Figures figures;
      CHECK_BOOL(StabilityCase(scene, delay, loss, true, false, figures), true);
      std::cout << "delay " << 1000.0 * delay << " ms, loss " << 100.0 * loss << " %: max force " << figures.MaximumForce
                << " N, passivity margin " << figures.WorstPassivityMargin << " mJ, max separation " << figures.MaximumSeparation
                << " mm, tracking RMS " << figures.TrackingRMS << " mm" << std::endl;
      CHECK_BOOL(figures.Finite, true);
      CHECK_BOOL(figures.MaximumForce <= DeviceMaximumForce + 1e-9, true);
      CHECK_BOOL(figures.Clamped == 0, true);
      CHECK_BOOL(figures.WorstPassivityMargin <= ObserverLag, true);
      CHECK_BOOL(figures.MaximumSeparation < 40.0, true);
      if (delay == 0.0 && loss == 0.0)
      {
        CHECK_BOOL(figures.TrackingRMS < 0.25, true);
      }
    }
  }

  // The instructor as a replayed recording (a position source), the worst link.
  {
    Figures figures;
    CHECK_BOOL(StabilityCase(scene, 0.020, 0.1, true, true, figures), true);
    std::cout << "replayed instructor, 20 ms, 10 %: max force " << figures.MaximumForce << " N, passivity margin "
              << figures.WorstPassivityMargin << " mJ, max separation " << figures.MaximumSeparation << " mm" << std::endl;
    CHECK_BOOL(figures.Finite, true);
    CHECK_BOOL(figures.MaximumForce <= DeviceMaximumForce + 1e-9, true);
    CHECK_BOOL(figures.MaximumSeparation < 40.0, true);
  }

  CHECK_EXIT_SUCCESS(HeldCase(scene));
  CHECK_EXIT_SUCCESS(ListenCase());

  // Without the passivity layer, 20 ms of delay breaks the criterion.
  {
    Figures figures;
    CHECK_BOOL(StabilityCase(scene, 0.020, 0.0, false, false, figures), true);
    std::cout << "no passivity layer, 20 ms: passivity margin " << figures.WorstPassivityMargin << " mJ, max separation "
              << figures.MaximumSeparation << " mm" << std::endl;
    CHECK_BOOL(figures.WorstPassivityMargin > ObserverLag, true);
  }

  return EXIT_SUCCESS;
}
