// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Forces forwarded between two drilling sessions on the same scan. The
// trainee's loop drills the analytic bone (vtkHapticTestScene: solid below
// the plane z = 0.3 mm) holding a protected cylinder; the instructor's loop
// holds its device over air in the same scan's RAS frame. The two devices
// are placed differently in the scan (device-to-RAS: other rotations, other
// offsets, the instructor's scaled 1.5 scene mm per device mm), so positions
// exchanged in device millimetres would pull toward the wrong places: the
// coupling exchanges the proxies in RAS and each loop maps the spring's
// force back into its own device's axes.
//
// The instructor's hand (a 0.3 N/mm arm) moves to a spot 1.8 mm inside the
// bone, at its own device's coordinates of that spot; the trainee's hand is
// relaxed, the drill on. Criteria, for one-way delays of 0, 5 and 20 ms with
// 10 % loss, ticked in lockstep at 1 kHz on loopback:
//  - the trainee's tool reaches the spot in RAS: within 0.5 mm after 3 s
//    (1 mm with 20 ms of delay, where the tanks run dry);
//  - it drilled there: removed volume > 0, and not one protected voxel removed;
//  - no device force above the device's maximum (3.3 N), none clamped;
//  - passivity: the net energy the coupling gave the two handles (its
//    observer's books: force applied times the handle's displacement) never
//    exceeds the tanks' initial 4 mJ plus 0.05 mJ;
// and a scan that differs (one sample changed) is refused: no packet
// accepted, no force, the mismatch counted with the peer's fingerprint.
#include "vtkHapticTestScene.h"

#include "vtkHapticCoupling.h"
#include "vtkHapticCouplingTransport.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkVirtualHapticDevice.h"

#include <vtkAddonTestingMacros.h>

#include <vtkFloatArray.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkTransform.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <utility>

namespace
{
constexpr double Period = 1e-3;
constexpr double ForceLimit = 3.3;
constexpr double TankStart = 2.0;
constexpr double OneTickLag = 0.05;
/// Where the instructor guides the trainee's tool (RAS mm): 1.8 mm inside the bone.
const double Spot[3] = { 0.5, 0.5, -1.5 };
/// The protected cylinder: along y, through x = 0.5, z = -5.5, radius 1.5 mm (0.5 mm below the burr at the spot).
constexpr double CylinderX = 0.5;
constexpr double CylinderZ = -5.5;
constexpr double CylinderRadius = 1.5;
/// Up to 5 ms of delay; with 20 ms the tanks run dry and the pull is what the operators' work pays for: 1 mm.
constexpr double SpotTolerance = 0.5;
constexpr double SlowLinkSpotTolerance = 1.0;

/// A handle of some mass, held by a hand that is a spring-damper toward a target (device mm).
struct Handle
{
  double Mass;
  double Stiffness;
  double Damping;
  double Target[3] = { 0, 0, 0 };
  double X[3] = { 0, 0, 0 };
  double V[3] = { 0, 0, 0 };

  void Advance(const double deviceForce[3])
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      const double push = deviceForce[axis] + this->Stiffness * (this->Target[axis] - this->X[axis]) - this->Damping * this->V[axis];
      this->V[axis] += Period * 1000.0 * push / this->Mass;
      this->X[axis] += Period * this->V[axis];
    }
  }
};

/// One session: a virtual device on a loop, its coupling and transport.
struct Session
{
  vtkNew<vtkVirtualHapticDevice> Device;
  vtkNew<vtkHapticForceModel> Model;
  vtkNew<vtkHapticLoop> Loop;
  vtkNew<vtkHapticCoupling> Coupling;
  vtkNew<vtkHapticCouplingTransport> Transport;
  vtkNew<vtkMatrix4x4> DeviceToRAS;
};

/// Device-to-RAS: translate, turn about an axis, scale.
void Place(vtkMatrix4x4* matrix, const double offset[3], double degrees, const double axis[3], double scale)
{
  vtkNew<vtkTransform> placement;
  placement->Translate(offset);
  placement->RotateWXYZ(degrees, axis);
  placement->Scale(scale, scale, scale);
  matrix->DeepCopy(placement->GetMatrix());
}

bool Prepare(Session& side, vtkImageData* anatomy, vtkMatrix4x4* ijkToRAS, double isoValue, vtkVolumeCutField* field,
  unsigned long long frame, double delay, double loss, unsigned long long seed)
{
  side.Device->GetCapabilities()->SetMaximumForce(ForceLimit);
  side.Model->SetAnatomy(anatomy, ijkToRAS);
  side.Model->SetSurfaceIsoValue(isoValue);
  side.Model->SetSphereRadius(2.0);
  side.Loop->SetDevice(side.Device);
  side.Loop->SetForceModel(side.Model);
  side.Loop->SetCutField(field);
  side.Loop->SetStatisticsCapacity(16);
  side.Coupling->SetStatisticsCapacity(16);
  side.Coupling->SetTransport(side.Transport);
  side.Coupling->SetInitialEnergy(TankStart);
  side.Transport->SetFrameFingerprint(frame);
  side.Transport->SetInjectedDelay(delay);
  side.Transport->SetInjectedLossRate(loss);
  side.Transport->SetInjectionSeed(seed);
  side.Loop->SetCoupling(side.Coupling);
  return side.Loop->SetDeviceToRAS(side.DeviceToRAS) && side.Device->Open();
}

bool Connect(Session& trainee, Session& instructor)
{
  // The trainee waits (remote port 0), the instructor joins it.
  return trainee.Transport->Open("127.0.0.1", 0, "127.0.0.1", 0) &&
    instructor.Transport->Open("127.0.0.1", 0, "127.0.0.1", trainee.Transport->GetLocalPort());
}

/// RAS of a device position through a session's placement.
void ToRAS(const Session& side, const double device[3], double ras[3])
{
  const double point[4] = { device[0], device[1], device[2], 1.0 };
  double mapped[4];
  side.DeviceToRAS->MultiplyPoint(point, mapped);
  std::copy(mapped, mapped + 3, ras);
}

/// The device position of a RAS point through a session's placement.
void ToDevice(const Session& side, const double ras[3], double device[3])
{
  vtkNew<vtkMatrix4x4> inverse;
  vtkMatrix4x4::Invert(side.DeviceToRAS, inverse);
  const double point[4] = { ras[0], ras[1], ras[2], 1.0 };
  double mapped[4];
  inverse->MultiplyPoint(point, mapped);
  std::copy(mapped, mapped + 3, device);
}

struct Outcome
{
  double MaximumForce = 0.0;
  unsigned long long Clamped = 0;
  double WorstEnergy = -1e300; ///< most net energy given to the handles less the tanks' initial energy (mJ)
  double SpotError = 1e300;    ///< the trainee's tool to the spot at the end (RAS mm)
  double InstructorError = 1e300;
  double Removed = 0.0;        ///< mm^3
  int ProtectedRemoved = -1;
  unsigned long long Accepted[2] = { 0, 0 };
  unsigned long long Mismatches[2] = { 0, 0 };
  unsigned long long RefusedFrame[2] = { 0, 0 };
  double LargestTraineeCoupling = 0.0;
  bool Finite = true;
};

/// The guided drilling for `seconds`; the instructor loaded `instructorScan` (the trainee's scene.CT, or another).
bool Guide(vtkHapticTestScene& scene, vtkImageData* instructorScan, double delay, double loss, double seconds, Outcome& outcome)
{
  Session trainee, instructor;
  // Each side registers its own device in the scan: the trainee's turned 90 degrees about S, its centre 4 mm over the
  // bone; the instructor's turned 40 degrees about an oblique axis and scaled 1.5, its centre elsewhere over the bone.
  const double traineeOffset[3] = { 2.0, -1.0, 4.0 }, upright[3] = { 0.0, 0.0, 1.0 };
  const double instructorOffset[3] = { -1.0, 1.0, 5.0 }, oblique[3] = { 1.0, 1.0, 0.0 };
  Place(trainee.DeviceToRAS, traineeOffset, 90.0, upright, 1.0);
  Place(instructor.DeviceToRAS, instructorOffset, 40.0, oblique, 1.5);

  vtkNew<vtkVolumeCutField> field;
  const int dims[3] = { scene.Size, scene.Size, scene.Size };
  field->Initialize(dims, scene.IJKToRAS, 2);
  vtkNew<vtkImageData> labels;
  const vtkIdType cylinder = scene.MakeLabels(labels, [](const double ras[3]) {
    const double dx = ras[0] - CylinderX, dz = ras[2] - CylinderZ;
    return dx * dx + dz * dz <= CylinderRadius * CylinderRadius;
  });
  if (cylinder == 0 || !field->SetProtectedLabels(labels))
  {
    return false;
  }
  // The instructor's tool touches nothing but the trainee's (its loop has no field and an all-air copy of the grid);
  // only its fingerprint says which scan it loaded.
  vtkNew<vtkImageData> air;
  air->DeepCopy(scene.CT);
  vtkFloatArray::SafeDownCast(air->GetPointData()->GetScalars())->Fill(-1000.0);
  const unsigned long long traineeFrame = vtkHapticCouplingTransport::ComputeFrameFingerprint(scene.CT, scene.IJKToRAS);
  const unsigned long long instructorFrame = vtkHapticCouplingTransport::ComputeFrameFingerprint(instructorScan, scene.IJKToRAS);
  if (!Prepare(trainee, scene.CT, scene.IJKToRAS, scene.IsoValue, field, traineeFrame, delay, loss, 31) ||
    !Prepare(instructor, air, scene.IJKToRAS, scene.IsoValue, nullptr, instructorFrame, delay, loss, 47) ||
    !Connect(trainee, instructor))
  {
    return false;
  }

  Handle traineeHand{ 0.1, 0.0, 0.002 };
  Handle instructorHand{ 0.15, 0.3, 0.004 };
  double spotOnInstructorDevice[3];
  ToDevice(instructor, Spot, spotOnInstructorDevice);
  const unsigned int drill = 1u;
  trainee.Device->SetPose(traineeHand.X, drill);
  instructor.Device->SetPose(instructorHand.X, 0u);
  const double initial = 2.0 * TankStart;
  const int ticks = static_cast<int>(std::lround(seconds / Period));
  for (int n = 0; n < ticks; ++n)
  {
    // The instructor's hand moves to the spot over the first second, then holds it.
    const double reach = std::min(1.0, n * Period / 1.0);
    for (int axis = 0; axis < 3; ++axis)
    {
      instructorHand.Target[axis] = reach * spotOnInstructorDevice[axis];
    }
    for (auto pair : { std::make_pair(&trainee, &traineeHand), std::make_pair(&instructor, &instructorHand) })
    {
      double force[3];
      pair.first->Device->GetCommandedForce(force);
      outcome.MaximumForce = std::max(outcome.MaximumForce, vtkMath::Norm(force));
      pair.second->Advance(force);
    }
    trainee.Device->SetPose(traineeHand.X, drill);
    instructor.Device->SetPose(instructorHand.X, 0u);
    if (!instructor.Loop->RunTicks(1) || !trainee.Loop->RunTicks(1))
    {
      return false;
    }
    double net = 0.0;
    for (Session* side : { &trainee, &instructor })
    {
      net += side->Coupling->GetEnergyOut() - side->Coupling->GetEnergyIn();
    }
    outcome.WorstEnergy = std::max(outcome.WorstEnergy, net - initial);
    double coupling[3];
    trainee.Coupling->GetLatestForce(coupling);
    outcome.LargestTraineeCoupling = std::max(outcome.LargestTraineeCoupling, vtkMath::Norm(coupling));
    outcome.Finite = outcome.Finite && std::isfinite(net) && std::isfinite(traineeHand.X[0]) && std::isfinite(instructorHand.X[0]);
  }
  vtkNew<vtkMatrix4x4> pose;
  double tool[3];
  if (trainee.Loop->GetLatestToolPose(pose))
  {
    for (int row = 0; row < 3; ++row)
    {
      tool[row] = pose->GetElement(row, 3);
    }
    outcome.SpotError = std::sqrt(vtkMath::Distance2BetweenPoints(tool, Spot));
  }
  double instructorTool[3];
  ToRAS(instructor, instructorHand.X, instructorTool);
  outcome.InstructorError = std::sqrt(vtkMath::Distance2BetweenPoints(instructorTool, Spot));
  outcome.Clamped = trainee.Device->GetNumberOfClampedForces() + instructor.Device->GetNumberOfClampedForces();
  trainee.Loop->Stop();
  instructor.Loop->Stop();
  outcome.Removed = field->ComputeRemovedVolume();
  outcome.ProtectedRemoved = scene.CountRemovedLabelled(labels, field);
  int index = 0;
  for (Session* side : { &trainee, &instructor })
  {
    outcome.Accepted[index] = side->Transport->GetNumberOfPacketsAccepted();
    outcome.Mismatches[index] = side->Transport->GetNumberOfFrameMismatches();
    outcome.RefusedFrame[index] = side->Transport->GetLastRefusedFrame();
    ++index;
  }
  return true;
}
} // namespace

int vtkHapticCouplingDrillingTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkHapticTestScene scene;

  // The fingerprint: the same scan gives the same value, any change another; no scan gives 0.
  const unsigned long long frame = vtkHapticCouplingTransport::ComputeFrameFingerprint(scene.CT, scene.IJKToRAS);
  CHECK_BOOL(frame != 0, true);
  vtkNew<vtkImageData> copy;
  copy->DeepCopy(scene.CT);
  CHECK_BOOL(vtkHapticCouplingTransport::ComputeFrameFingerprint(copy, scene.IJKToRAS) == frame, true);
  vtkNew<vtkMatrix4x4> shifted;
  shifted->DeepCopy(scene.IJKToRAS);
  shifted->SetElement(2, 3, shifted->GetElement(2, 3) + 0.5);
  CHECK_BOOL(vtkHapticCouplingTransport::ComputeFrameFingerprint(scene.CT, shifted) != frame, true);
  vtkNew<vtkImageData> other;
  other->DeepCopy(scene.CT);
  vtkFloatArray* samples = vtkFloatArray::SafeDownCast(other->GetPointData()->GetScalars());
  samples->SetValue(1234, samples->GetValue(1234) + 1.0f);
  const unsigned long long otherFrame = vtkHapticCouplingTransport::ComputeFrameFingerprint(other, scene.IJKToRAS);
  CHECK_BOOL(otherFrame != frame && otherFrame != 0, true);
  CHECK_BOOL(vtkHapticCouplingTransport::ComputeFrameFingerprint(nullptr, scene.IJKToRAS) == 0, true);

  // The frame travels in the packet (and a flipped bit in it fails the checksum like any other).
  {
    vtkHapticCouplingTransport::State state;
    state.Session = 3;
    state.Sequence = 1;
    state.Frame = frame;
    unsigned char packet[vtkHapticCouplingTransport::PacketSize];
    vtkHapticCouplingTransport::EncodePacket(state, packet);
    vtkHapticCouplingTransport::State decoded;
    CHECK_BOOL(vtkHapticCouplingTransport::DecodePacket(packet, vtkHapticCouplingTransport::PacketSize, decoded), true);
    CHECK_BOOL(decoded.Frame == frame, true);
  }

  // Guided drilling on the same scan: delay x loss.
  const double links[3][2] = { { 0.0, 0.1 }, { 0.005, 0.1 }, { 0.020, 0.1 } };
  for (const auto& link : links)
  {
    Outcome outcome;
    CHECK_BOOL(Guide(scene, scene.CT, link[0], link[1], 3.0, outcome), true);
    std::cout << "same scan, delay " << 1000.0 * link[0] << " ms, loss " << 100.0 * link[1] << " %: trainee's tool "
              << outcome.SpotError << " mm from the spot (instructor's " << outcome.InstructorError << " mm), removed "
              << outcome.Removed << " mm3, protected voxels removed " << outcome.ProtectedRemoved << ", max device force "
              << outcome.MaximumForce << " N, net coupling energy - tanks " << outcome.WorstEnergy << " mJ" << std::endl;
    CHECK_BOOL(outcome.Finite, true);
    CHECK_BOOL(outcome.Accepted[0] > 0 && outcome.Accepted[1] > 0, true);
    CHECK_BOOL(outcome.SpotError < (link[0] > 0.01 ? SlowLinkSpotTolerance : SpotTolerance), true);
    CHECK_BOOL(outcome.Removed > 0.0, true);
    CHECK_INT(outcome.ProtectedRemoved, 0);
    CHECK_BOOL(outcome.MaximumForce <= ForceLimit + 1e-9, true);
    CHECK_BOOL(outcome.Clamped == 0, true);
    CHECK_BOOL(outcome.WorstEnergy <= OneTickLag, true);
  }

  // The instructor loaded another scan: refused on both sides, nothing coupled, the trainee drills alone.
  {
    Outcome outcome;
    CHECK_BOOL(Guide(scene, other, 0.0, 0.0, 0.5, outcome), true);
    std::cout << "another scan: accepted " << outcome.Accepted[0] << "/" << outcome.Accepted[1] << ", refused "
              << outcome.Mismatches[0] << "/" << outcome.Mismatches[1] << std::endl;
    CHECK_BOOL(outcome.Accepted[0] == 0 && outcome.Accepted[1] == 0, true);
    CHECK_BOOL(outcome.Mismatches[0] > 0 && outcome.Mismatches[1] > 0, true);
    CHECK_BOOL(outcome.RefusedFrame[0] == otherFrame && outcome.RefusedFrame[1] == frame, true);
    CHECK_BOOL(outcome.LargestTraineeCoupling == 0.0, true);
  }
  return EXIT_SUCCESS;
}
