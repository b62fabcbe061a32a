// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticCoupling.h"
#include "vtkHapticCouplingTransport.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticLatestValue.h"

#include "vtkMath.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkHapticCoupling);

namespace
{
/// What other threads read of the latest tick.
struct Published
{
  double Force[3];
  double Tank;
  double EnergyIn;
  double EnergyOut;
  double Shipped;
  double Received;
  double Dissipated;
  double PeerPosition[3];
  int HavePeer;
  double Gain;
  double PeerAge;
};

/// Time constant (s) of the proxy velocity's low-pass: device quantisation
/// noise would otherwise reach the damper (about 50 Hz).
constexpr double VelocityTimeConstant = 0.003;

/// How far (device mm) a handle may move in one tick beyond the step its
/// velocity predicts: a 0.1 kg handle under the device's 3.3 N moves 0.017 mm
/// further in 1 ms; the passivity controller keeps the tank able to pay for it.
constexpr double DisplacementMargin = 0.02;
} // namespace

struct vtkHapticCoupling::Internals
{
  bool HaveLimits = false;
  // The local side.
  double Tank = 0.0;
  double EnergyIn = 0.0;
  double EnergyOut = 0.0;
  double Shipped = 0.0;
  double Received = 0.0;
  double Dissipated = 0.0;
  bool HaveLast = false;
  double LastTime = 0.0;
  double Period = 1e-3;
  bool HaveHandle = false;
  double PreviousHandle[3] = { 0, 0, 0 };
  double HandleVelocity[3] = { 0, 0, 0 };
  bool HaveProxy = false;
  double PreviousProxy[3] = { 0, 0, 0 };
  double ProxyVelocity[3] = { 0, 0, 0 };
  /// The force whose work the next tick books.
  double Applied[3] = { 0, 0, 0 };
  double Returned[3] = { 0, 0, 0 };
  // The peer.
  bool HavePeer = false;
  unsigned int PeerSession = 0;
  double PeerCredited = 0.0;
  double LastPacket = 0.0;
  double EngageStart = 0.0;
  vtkHapticCouplingTransport::State Peer;
  vtkHapticLatestValue<Published> Latest;
  // Statistics.
  std::vector<float> Durations;
  std::atomic<unsigned long long> Timed{ 0 };
};

//------------------------------------------------------------------------------
vtkHapticCoupling::vtkHapticCoupling()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkHapticCoupling::~vtkHapticCoupling() = default;

//------------------------------------------------------------------------------
void vtkHapticCoupling::SetTransport(vtkHapticCouplingTransport* transport)
{
  this->Transport = transport;
  this->Modified();
}

vtkHapticCouplingTransport* vtkHapticCoupling::GetTransport()
{
  return this->Transport;
}

//------------------------------------------------------------------------------
void vtkHapticCoupling::SetDeviceLimits(vtkHapticDeviceCapabilities* capabilities, double scale)
{
  Internals& internal = *this->Internal;
  internal.HaveLimits = capabilities != nullptr && std::isfinite(scale) && scale > 0.0;
  if (!internal.HaveLimits)
  {
    this->AppliedStiffness = this->AppliedDamping = this->AppliedMaximumForce = 0.0;
    return;
  }
  // A spring of k N per scene mm is k * scale N per device mm at the hand.
  this->AppliedStiffness = std::min(this->Stiffness, capabilities->GetMaximumStiffness() / scale);
  this->AppliedDamping = std::min(this->Damping, capabilities->GetMaximumDamping() / scale);
  const double deviceMaximum = capabilities->GetMaximumForce();
  this->AppliedMaximumForce = this->MaximumForce > 0.0 ? std::min(this->MaximumForce, deviceMaximum) : deviceMaximum;
}

//------------------------------------------------------------------------------
bool vtkHapticCoupling::Prepare()
{
  if (!this->Transport || !this->Transport->IsOpen())
  {
    vtkErrorMacro("Prepare: " << (this->Transport ? "open the transport first" : "no transport is set"));
    return false;
  }
  Internals& internal = *this->Internal;
  internal.Tank = this->InitialEnergy;
  internal.EnergyIn = internal.EnergyOut = internal.Shipped = internal.Received = internal.Dissipated = 0.0;
  internal.HaveLast = internal.HaveHandle = internal.HaveProxy = internal.HavePeer = false;
  internal.Period = 1e-3;
  std::fill(internal.Applied, internal.Applied + 3, 0.0);
  std::fill(internal.Returned, internal.Returned + 3, 0.0);
  std::fill(internal.ProxyVelocity, internal.ProxyVelocity + 3, 0.0);
  std::fill(internal.HandleVelocity, internal.HandleVelocity + 3, 0.0);
  internal.PeerCredited = 0.0;
  internal.Durations.assign(static_cast<size_t>(this->StatisticsCapacity), 0.0f);
  internal.Timed = 0;
  Published published{};
  published.Tank = internal.Tank;
  published.PeerAge = -1.0;
  internal.Latest.Store(published);
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticCoupling::Update(double time, const double proxy[3], const double handle[3], bool present, double force[3])
{
  const auto start = std::chrono::steady_clock::now();
  Internals& internal = *this->Internal;
  std::fill(force, force + 3, 0.0);
  if (internal.Durations.empty())
  {
    // Not prepared: no force, nothing sent.
    return;
  }
  if (internal.HaveLast && time > internal.LastTime)
  {
    internal.Period = time - internal.LastTime;
  }
  internal.HaveLast = true;
  internal.LastTime = time;
  const double period = internal.Period;

  // Passivity observer: the work the force held over the last tick did on the handle.
  if (present && internal.HaveHandle)
  {
    double displacement[3];
    vtkMath::Subtract(handle, internal.PreviousHandle, displacement);
    const double work = vtkMath::Dot(internal.Applied, displacement);
    internal.Tank -= work;
    (work > 0.0 ? internal.EnergyOut : internal.EnergyIn) += std::abs(work);
    for (int axis = 0; axis < 3; ++axis)
    {
      internal.HandleVelocity[axis] = displacement[axis] / period;
    }
  }
  else
  {
    std::fill(internal.HandleVelocity, internal.HandleVelocity + 3, 0.0);
  }
  internal.HaveHandle = present;
  if (present)
  {
    std::copy(handle, handle + 3, internal.PreviousHandle);
    const double blend = period / (period + VelocityTimeConstant);
    for (int axis = 0; axis < 3; ++axis)
    {
      const double raw = internal.HaveProxy ? (proxy[axis] - internal.PreviousProxy[axis]) / period : 0.0;
      internal.ProxyVelocity[axis] += blend * (raw - internal.ProxyVelocity[axis]);
      internal.PreviousProxy[axis] = proxy[axis];
    }
  }
  internal.HaveProxy = present;

  // The peer's latest state and the energy it shipped since the last one.
  vtkHapticCouplingTransport::State received;
  if (this->Transport && this->Transport->ReceiveLatest(time, received))
  {
    if (!internal.HavePeer || received.Session != internal.PeerSession)
    {
      internal.HavePeer = true;
      internal.PeerSession = received.Session;
      internal.PeerCredited = 0.0;
      internal.EngageStart = time;
    }
    const double credit = received.EnergySent - internal.PeerCredited;
    if (credit > 0.0)
    {
      internal.Tank += credit;
      internal.Received += credit;
      internal.PeerCredited = received.EnergySent;
    }
    internal.Peer = received;
    internal.LastPacket = time;
  }
  if (internal.Tank > this->MaximumEnergy)
  {
    internal.Dissipated += internal.Tank - this->MaximumEnergy;
    internal.Tank = this->MaximumEnergy;
  }

  // Transparency layer: the spring-damper toward the peer's proxy, ramped in and faded out.
  double gain = 0.0;
  const double age = internal.HavePeer ? time - internal.LastPacket : -1.0;
  if (internal.HavePeer && (internal.Peer.Flags & vtkHapticCouplingTransport::PresentFlag) != 0)
  {
    const double fade = age <= this->PeerTimeout
      ? 1.0
      : (this->FadeTime > 0.0 ? std::max(0.0, 1.0 - (age - this->PeerTimeout) / this->FadeTime) : 0.0);
    const double ramp = this->EngageTime > 0.0 ? std::min(1.0, (time - internal.EngageStart) / this->EngageTime) : 1.0;
    gain = fade * ramp;
  }
  if (present && gain > 0.0 && internal.HaveLimits)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      force[axis] = gain *
        (this->AppliedStiffness * (internal.Peer.Position[axis] - proxy[axis]) +
          this->AppliedDamping * (internal.Peer.Velocity[axis] - internal.ProxyVelocity[axis]));
    }
  }
  const auto limit = [this](double vector[3]) {
    const double norm = vtkMath::Norm(vector);
    if (norm > this->AppliedMaximumForce)
    {
      // A hair under the limit, so that rounding never makes the device clamp it.
      const double shrink = norm > 0.0 ? (1.0 - 1e-12) * this->AppliedMaximumForce / norm : 0.0;
      vtkMath::MultiplyScalar(vector, shrink);
    }
  };
  limit(force);

  // Passivity controller. First the tank must pay for the next tick's
  // predicted work: the part of the force along the handle's velocity that
  // it cannot pay for goes (a variable damper that stops at zero power: a
  // damper acting on a velocity one tick old, pushed past that, reverses a
  // light handle within the tick and does work instead of taking it).
  // Then the force is capped so that the tank also pays for the work of any
  // displacement the prediction misses: up to DisplacementMargin beyond the
  // predicted step, what the operator's hand and the tool's contacts (forces
  // the coupling does not know) can add in one tick. Without the cap, a hand
  // blocked by bone and pushed by its contacts goes where the prediction does
  // not expect it, and the misses add up to a tank deep in deficit. An empty
  // tank lets no force out. Shrinking a force only lowers the work it can do.
  if (this->PassivityControl && present)
  {
    const double tank = std::max(internal.Tank, 0.0);
    const double budget = tank / period;
    const double power = vtkMath::Dot(force, internal.HandleVelocity);
    const double speed2 = vtkMath::Dot(internal.HandleVelocity, internal.HandleVelocity);
    if (power > budget && speed2 > 1e-9)
    {
      const double damper = (power - budget) / speed2;
      for (int axis = 0; axis < 3; ++axis)
      {
        force[axis] -= damper * internal.HandleVelocity[axis];
      }
    }
    const double reach = std::sqrt(speed2) * period + DisplacementMargin;
    const double affordable = tank / reach;
    const double norm = vtkMath::Norm(force);
    if (norm > affordable)
    {
      vtkMath::MultiplyScalar(force, norm > 0.0 ? affordable / norm : 0.0);
    }
  }

  // Energy for the peer, and the local state.
  if (internal.HavePeer && gain > 0.0 && internal.Tank > 0.0)
  {
    const double share = this->EnergyShareRate * internal.Tank;
    internal.Tank -= share;
    internal.Shipped += share;
  }
  if (this->Transport)
  {
    vtkHapticCouplingTransport::State state;
    state.Time = time;
    if (present)
    {
      std::copy(proxy, proxy + 3, state.Position);
      std::copy(internal.ProxyVelocity, internal.ProxyVelocity + 3, state.Velocity);
    }
    state.EnergySent = internal.Shipped;
    state.Tank = internal.Tank;
    state.Flags = present ? vtkHapticCouplingTransport::PresentFlag : 0u;
    this->Transport->Send(state, time);
  }

  std::copy(force, force + 3, internal.Applied);
  std::copy(force, force + 3, internal.Returned);
  Published published;
  std::copy(force, force + 3, published.Force);
  published.Tank = internal.Tank;
  published.EnergyIn = internal.EnergyIn;
  published.EnergyOut = internal.EnergyOut;
  published.Shipped = internal.Shipped;
  published.Received = internal.Received;
  published.Dissipated = internal.Dissipated;
  std::copy(internal.Peer.Position, internal.Peer.Position + 3, published.PeerPosition);
  published.HavePeer = internal.HavePeer ? 1 : 0;
  published.Gain = gain;
  published.PeerAge = age;
  internal.Latest.Store(published);

  const unsigned long long timed = internal.Timed.load(std::memory_order_relaxed);
  internal.Durations[timed % internal.Durations.size()] =
    std::chrono::duration<float, std::micro>(std::chrono::steady_clock::now() - start).count();
  internal.Timed.store(timed + 1, std::memory_order_release);
}

//------------------------------------------------------------------------------
void vtkHapticCoupling::ReportAppliedForce(const double force[3])
{
  Internals& internal = *this->Internal;
  for (int axis = 0; axis < 3; ++axis)
  {
    internal.Applied[axis] = std::isfinite(force[axis]) ? force[axis] : 0.0;
  }
}

//------------------------------------------------------------------------------
void vtkHapticCoupling::GetLatestForce(double force[3]) const
{
  Published published{};
  this->Internal->Latest.Load(published);
  std::copy(published.Force, published.Force + 3, force);
}

namespace
{
template <typename Member>
double LatestField(const vtkHapticLatestValue<Published>& latest, Member member)
{
  Published published{};
  latest.Load(published);
  return published.*member;
}
} // namespace

double vtkHapticCoupling::GetLatestTank() const
{
  return LatestField(this->Internal->Latest, &Published::Tank);
}

double vtkHapticCoupling::GetEnergyIn() const
{
  return LatestField(this->Internal->Latest, &Published::EnergyIn);
}

double vtkHapticCoupling::GetEnergyOut() const
{
  return LatestField(this->Internal->Latest, &Published::EnergyOut);
}

double vtkHapticCoupling::GetEnergyShipped() const
{
  return LatestField(this->Internal->Latest, &Published::Shipped);
}

double vtkHapticCoupling::GetEnergyReceived() const
{
  return LatestField(this->Internal->Latest, &Published::Received);
}

double vtkHapticCoupling::GetEnergyDissipated() const
{
  return LatestField(this->Internal->Latest, &Published::Dissipated);
}

double vtkHapticCoupling::GetLatestGain() const
{
  return LatestField(this->Internal->Latest, &Published::Gain);
}

double vtkHapticCoupling::GetLatestPeerAge() const
{
  Published published{};
  return this->Internal->Latest.Load(published) ? published.PeerAge : -1.0;
}

//------------------------------------------------------------------------------
bool vtkHapticCoupling::GetLatestPeerPosition(double position[3]) const
{
  Published published{};
  if (!this->Internal->Latest.Load(published) || !published.HavePeer)
  {
    return false;
  }
  std::copy(published.PeerPosition, published.PeerPosition + 3, position);
  return true;
}

//------------------------------------------------------------------------------
double vtkHapticCoupling::GetUpdateDurationPercentile(double percent) const
{
  const Internals& internal = *this->Internal;
  const size_t count = std::min<size_t>(internal.Timed.load(std::memory_order_acquire), internal.Durations.size());
  if (count == 0)
  {
    return 0.0;
  }
  std::vector<float> kept(internal.Durations.begin(), internal.Durations.begin() + count);
  std::sort(kept.begin(), kept.end());
  const double rank = std::min(std::max(percent, 0.0), 100.0) / 100.0 * static_cast<double>(count - 1);
  return kept[static_cast<size_t>(std::lround(rank))];
}

unsigned long long vtkHapticCoupling::GetNumberOfUpdates() const
{
  return this->Internal->Timed.load(std::memory_order_acquire);
}

//------------------------------------------------------------------------------
void vtkHapticCoupling::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Stiffness: " << this->Stiffness << " N/mm (applied " << this->AppliedStiffness << ")\n";
  os << indent << "Damping: " << this->Damping << " N s/mm (applied " << this->AppliedDamping << ")\n";
  os << indent << "MaximumForce: " << this->MaximumForce << " N (applied " << this->AppliedMaximumForce << ")\n";
  os << indent << "InitialEnergy: " << this->InitialEnergy << " mJ\n";
  os << indent << "MaximumEnergy: " << this->MaximumEnergy << " mJ\n";
  os << indent << "EnergyShareRate: " << this->EnergyShareRate << "\n";
  os << indent << "EngageTime: " << this->EngageTime << " s\n";
  os << indent << "PeerTimeout: " << this->PeerTimeout << " s\n";
  os << indent << "FadeTime: " << this->FadeTime << " s\n";
  os << indent << "PassivityControl: " << (this->PassivityControl ? "on" : "off") << "\n";
  os << indent << "Transport: " << this->Transport.GetPointer() << "\n";
}
