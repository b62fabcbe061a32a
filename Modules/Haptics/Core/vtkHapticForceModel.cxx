// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkHapticForceModel.h"
#include "vtkHapticDeviceCapabilities.h"
#include "vtkHapticPointShell.h"
#include "vtkHapticVibration.h"

#include "vtkBinaryVoxelCutter.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutTool.h"

#include <algorithm>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkHapticForceModel);

namespace
{
/// The renderer's trilinear interpolation (vtkVolumeCutRayCaster keeps the
/// CT as float and blends in double): the same arithmetic, the same surface.
template <typename T>
double InterpolateCT(const void* data, const int dims[3], const double ijk[3])
{
  int base[3];
  double f[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    const double x = std::min(std::max(ijk[axis], 0.0), double(dims[axis] - 1));
    base[axis] = std::min(static_cast<int>(x), std::max(dims[axis] - 2, 0));
    f[axis] = x - base[axis];
  }
  const vtkIdType sx = dims[0] > 1 ? 1 : 0;
  const vtkIdType sy = dims[1] > 1 ? dims[0] : 0;
  const vtkIdType sz = dims[2] > 1 ? static_cast<vtkIdType>(dims[0]) * dims[1] : 0;
  const T* v = static_cast<const T*>(data) + base[0] + base[1] * static_cast<vtkIdType>(dims[0]) +
    base[2] * static_cast<vtkIdType>(dims[0]) * dims[1];
  auto at = [v](vtkIdType offset) { return static_cast<double>(static_cast<float>(v[offset])); };
  const double c00 = at(0) + f[0] * (at(sx) - at(0));
  const double c10 = at(sy) + f[0] * (at(sy + sx) - at(sy));
  const double c01 = at(sz) + f[0] * (at(sz + sx) - at(sz));
  const double c11 = at(sz + sy) + f[0] * (at(sz + sy + sx) - at(sz + sy));
  const double c0 = c00 + f[1] * (c10 - c00);
  const double c1 = c01 + f[1] * (c11 - c01);
  return static_cast<float>(c0 + f[2] * (c1 - c0));
}

/// The nearest voxel's value (the whole-voxel baseline).
template <typename T>
double NearestCT(const void* data, const int dims[3], const double ijk[3])
{
  vtkIdType index = 0;
  vtkIdType stride = 1;
  for (int axis = 0; axis < 3; ++axis)
  {
    const int i = std::min(std::max(static_cast<int>(std::lround(ijk[axis])), 0), dims[axis] - 1);
    index += i * stride;
    stride *= dims[axis];
  }
  return static_cast<const T*>(data)[index];
}

using Sampler = double (*)(const void*, const int[3], const double[3]);

double Norm(const double v[3])
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}
} // namespace

struct vtkHapticForceModel::Internals
{
  bool Prepared = false;
  const void* Scalars = nullptr;
  int Dimensions[3] = { 0, 0, 0 };
  Sampler Interpolate = nullptr;
  Sampler Nearest = nullptr;
  double RASToIJK[3][4];
  std::vector<double> Shell;
  int ShellCount = 0;
  /// The last contact test's push directions (unit), three values a contact, for the proxy's step.
  std::vector<double> ContactDirections;
  /// The last contact test's points in the cut: offset from the centre and cut-field distance, four values a point.
  std::vector<double> Clearances;
  int NumberOfClearances = 0;
  /// Steps of the trace toward the centre, and the longest proxy step (mm).
  double TraceStep = 0.1;
  double ProxyStep = 0.5;
  // Proxy state.
  bool HasState = false;
  double Proxy[3] = { 0.0, 0.0, 0.0 };
  double PreviousDevice[3] = { 0.0, 0.0, 0.0 };
  double PreviousProxy[3] = { 0.0, 0.0, 0.0 };
  double RelativeVelocity[3] = { 0.0, 0.0, 0.0 };
  vtkHapticForceModel::Result Last = {};
  /// Pending cuts (AddPendingCut): p0 and p1, six values a cut.
  double Pending[vtkHapticForceModel::MaximumPendingCuts][6];
  int PendingCount = 0;
  /// Those near the proxy in this Update: p0, p1 - p0 and 1 / |p1 - p0|^2 (0 for a point).
  double Near[vtkHapticForceModel::MaximumPendingCuts][7];
  int NearCount = 0;
  /// Whether the cut field shields structures (a pending cut keeps their voxels), for this Update.
  bool Shielded = false;
};

//------------------------------------------------------------------------------
vtkHapticForceModel::vtkHapticForceModel()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkHapticForceModel::~vtkHapticForceModel()
{
  delete this->Internal;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::SetAnatomy(vtkImageData* intensities, vtkMatrix4x4* ijkToRAS)
{
  this->Anatomy = intensities;
  this->AnatomyIJKToRAS = ijkToRAS;
  this->Internal->Prepared = false;
  this->Modified();
}

//------------------------------------------------------------------------------
vtkImageData* vtkHapticForceModel::GetAnatomy()
{
  return this->Anatomy;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::SetCutField(vtkVolumeCutField* field)
{
  this->CutField = field;
  this->Internal->Prepared = false;
  this->Modified();
}

//------------------------------------------------------------------------------
vtkVolumeCutField* vtkHapticForceModel::GetCutField()
{
  return this->CutField;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::SetTool(vtkVolumeCutTool* tool)
{
  this->Tool = tool;
  this->Internal->Prepared = false;
  this->Modified();
}

//------------------------------------------------------------------------------
vtkVolumeCutTool* vtkHapticForceModel::GetTool()
{
  return this->Tool;
}

//------------------------------------------------------------------------------
vtkHapticPointShell* vtkHapticForceModel::GetPointShell()
{
  return this->PointShell;
}

//------------------------------------------------------------------------------
vtkHapticVibration* vtkHapticForceModel::GetVibration()
{
  return this->Vibration;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::SetDeviceLimits(vtkHapticDeviceCapabilities* capabilities, double scale)
{
  if (!capabilities || !(scale > 0.0) || !std::isfinite(scale))
  {
    if (capabilities)
    {
      vtkErrorMacro("SetDeviceLimits: the device-to-scene scale (" << scale << ") must be a positive number; no force will be rendered");
    }
    this->DeviceMaximumForce = this->DeviceMaximumStiffness = this->DeviceMaximumDamping = 0.0;
    this->DeviceScale = 1.0;
  }
  else
  {
    const bool rendersForce = capabilities->GetRendersForce();
    this->DeviceMaximumForce = rendersForce ? capabilities->GetMaximumForce() : 0.0;
    this->DeviceMaximumStiffness = rendersForce ? capabilities->GetMaximumStiffness() : 0.0;
    this->DeviceMaximumDamping = rendersForce ? capabilities->GetMaximumDamping() : 0.0;
    this->DeviceScale = scale;
  }
  this->Internal->Prepared = false;
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkHapticForceModel::SetGuideAxis(const double point[3], const double direction[3])
{
  const double length = Norm(direction);
  if (!point || !std::isfinite(point[0]) || !std::isfinite(point[1]) || !std::isfinite(point[2]) || !(length > 1e-9) ||
    !std::isfinite(length))
  {
    vtkErrorMacro("SetGuideAxis: the guide needs a finite point and a direction of non-zero length; the previous guide is kept");
    return false;
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    this->GuidePoint[axis] = point[axis];
    this->GuideDirection[axis] = direction[axis] / length;
  }
  this->GuideEnabled = true;
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::RemoveGuide()
{
  this->GuideEnabled = false;
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkHapticForceModel::Prepare()
{
  Internals& internal = *this->Internal;
  internal.Prepared = false;
  if (!this->Anatomy || !this->AnatomyIJKToRAS || !this->Anatomy->GetPointData() || !this->Anatomy->GetScalarPointer())
  {
    vtkErrorMacro("Prepare: no anatomy (CT image and IJK-to-RAS matrix) is set; nothing can be touched");
    return false;
  }
  if (this->Anatomy->GetNumberOfScalarComponents() != 1)
  {
    vtkErrorMacro("Prepare: the anatomy has " << this->Anatomy->GetNumberOfScalarComponents() << " components per voxel; one (intensities) is needed");
    return false;
  }
  this->Anatomy->GetDimensions(internal.Dimensions);
  switch (this->Anatomy->GetScalarType())
  {
    vtkTemplateMacro(internal.Interpolate = &InterpolateCT<VTK_TT>; internal.Nearest = &NearestCT<VTK_TT>);
    default:
      vtkErrorMacro("Prepare: the anatomy's scalar type " << this->Anatomy->GetScalarTypeAsString() << " is not supported");
      return false;
  }
  internal.Scalars = this->Anatomy->GetScalarPointer();
  vtkNew<vtkMatrix4x4> rasToIJK;
  if (this->AnatomyIJKToRAS->Determinant() == 0.0)
  {
    vtkErrorMacro("Prepare: the anatomy's IJK-to-RAS matrix is not invertible");
    return false;
  }
  vtkMatrix4x4::Invert(this->AnatomyIJKToRAS, rasToIJK);
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      internal.RASToIJK[row][column] = rasToIJK->GetElement(row, column);
    }
  }
  // Tool and shell.
  this->PointShell->SetNumberOfPointsToBuild(this->NumberOfShellPoints);
  const bool built = this->Tool ? this->PointShell->BuildTool(this->Tool) : this->PointShell->BuildSphere(this->SphereRadius);
  if (!built)
  {
    vtkErrorMacro("Prepare: the tool's point shell could not be built");
    return false;
  }
  internal.ShellCount = this->PointShell->GetNumberOfPoints();
  internal.Shell.assign(this->PointShell->GetPointData(), this->PointShell->GetPointData() + 3 * internal.ShellCount);
  internal.ContactDirections.assign(3 * internal.ShellCount, 0.0);
  internal.Clearances.assign(4 * internal.ShellCount, 0.0);
  internal.NumberOfClearances = 0;
  // Traces step half the finest spacing of the CT and the cut field: no
  // feature of either hides between two steps and bisection finds the rest.
  double finest = 1e300;
  for (int column = 0; column < 3; ++column)
  {
    const double spacing[3] = { this->AnatomyIJKToRAS->GetElement(0, column), this->AnatomyIJKToRAS->GetElement(1, column),
      this->AnatomyIJKToRAS->GetElement(2, column) };
    finest = std::min(finest, Norm(spacing));
  }
  if (this->CutField && this->CutField->GetSubVoxelFactor() > 0)
  {
    double subSpacing[3];
    this->CutField->GetSubVoxelSpacing(subSpacing);
    finest = std::min({ finest, subSpacing[0], subSpacing[1], subSpacing[2] });
  }
  internal.TraceStep = 0.5 * finest;
  const double shellSpacing = this->PointShell->GetLargestSpacing();
  internal.ProxyStep = std::max(1e-3, std::min(0.5 * shellSpacing, 1.0));
  // What the hand feels, within the device's limits.
  this->MaximumForce = this->DeviceMaximumForce;
  const double stiffnessLimit = this->DeviceMaximumStiffness / this->DeviceScale;
  const double dampingLimit = this->DeviceMaximumDamping / this->DeviceScale;
  this->AppliedCouplingStiffness = std::min(this->CouplingStiffness, stiffnessLimit);
  this->AppliedGuideStiffness = std::min(this->GuideStiffness, stiffnessLimit);
  this->AppliedDamping = std::min(this->Damping, dampingLimit);
  this->Vibration->Reset();
  internal.HasState = false;
  internal.Prepared = true;
  return true;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::Reset(const double position[3])
{
  Internals& internal = *this->Internal;
  for (int axis = 0; axis < 3; ++axis)
  {
    internal.Proxy[axis] = internal.PreviousProxy[axis] = internal.PreviousDevice[axis] = position[axis];
    internal.RelativeVelocity[axis] = 0.0;
  }
  internal.HasState = true;
  this->Vibration->Reset();
}

//------------------------------------------------------------------------------
bool vtkHapticForceModel::IsSolid(const double ras[3]) const
{
  if (!this->Internal->Prepared)
  {
    return false;
  }
  Margins margins;
  this->Measure(ras, margins);
  return margins.IsSolid();
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::Measure(const double ras[3], Margins& margins, bool withCut, bool pending) const
{
  const Internals& internal = *this->Internal;
  margins.Anatomy = -1.0;
  margins.Removal = VTK_DOUBLE_MAX;
  margins.InBox = false;
  margins.CutLookedUp = false;
  double ijk[3];
  for (int row = 0; row < 3; ++row)
  {
    ijk[row] = internal.RASToIJK[row][0] * ras[0] + internal.RASToIJK[row][1] * ras[1] + internal.RASToIJK[row][2] * ras[2] +
      internal.RASToIJK[row][3];
    // Outside the volume's box there is nothing to touch (the renderer stops there too).
    if (!(ijk[row] >= 0.0 && ijk[row] <= internal.Dimensions[row] - 1.0))
    {
      return;
    }
  }
  margins.InBox = true;
  margins.Anatomy = internal.Interpolate(internal.Scalars, internal.Dimensions, ijk) - this->SurfaceIsoValue;
  // The cut field costs several times the CT's lookup: only where the CT is solid.
  if (withCut && (this->CutField || pending) && !(margins.Anatomy < 0.0))
  {
    margins.Removal = this->RemovalDistance(ras, pending);
    margins.CutLookedUp = this->CutField != nullptr;
  }
}

//------------------------------------------------------------------------------
double vtkHapticForceModel::RemovalDistance(const double ras[3], bool pending) const
{
  const Internals& internal = *this->Internal;
  double removal = this->CutField ? this->CutField->GetSignedDistance(ras) : VTK_DOUBLE_MAX;
  if (!pending)
  {
    return removal;
  }
  // The union of the removed region and the pending capsules: the smaller
  // distance, as the field will hold once the cutter has cut them.
  double nearest = VTK_DOUBLE_MAX;
  for (int n = 0; n < internal.NearCount; ++n)
  {
    const double* cut = internal.Near[n];
    const double w[3] = { ras[0] - cut[0], ras[1] - cut[1], ras[2] - cut[2] };
    const double along = std::min(std::max((w[0] * cut[3] + w[1] * cut[4] + w[2] * cut[5]) * cut[6], 0.0), 1.0);
    const double d[3] = { w[0] - along * cut[3], w[1] - along * cut[4], w[2] - along * cut[5] };
    nearest = std::min(nearest, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  }
  const double capsule = std::sqrt(nearest) - this->SphereRadius;
  if (!(capsule < removal))
  {
    return removal;
  }
  if (internal.Shielded)
  {
    // The cutter keeps shielded voxels: a pending cut removes nothing there.
    int voxel[3];
    for (int row = 0; row < 3; ++row)
    {
      voxel[row] = static_cast<int>(std::lround(internal.RASToIJK[row][0] * ras[0] + internal.RASToIJK[row][1] * ras[1] +
        internal.RASToIJK[row][2] * ras[2] + internal.RASToIJK[row][3]));
    }
    if (this->CutField->GetProtection()->GetShieldLabel(voxel[0], voxel[1], voxel[2]) != 0)
    {
      return removal;
    }
  }
  return capsule;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::ClearPendingCuts()
{
  this->Internal->PendingCount = 0;
}

//------------------------------------------------------------------------------
bool vtkHapticForceModel::AddPendingCut(const double p0[3], const double p1[3])
{
  Internals& internal = *this->Internal;
  if (this->Tool || internal.PendingCount >= MaximumPendingCuts || !p0 || !p1 || !std::isfinite(p0[0] + p0[1] + p0[2] + p1[0] + p1[1] + p1[2]))
  {
    return false;
  }
  double* cut = internal.Pending[internal.PendingCount++];
  std::copy(p0, p0 + 3, cut);
  std::copy(p1, p1 + 3, cut + 3);
  return true;
}

//------------------------------------------------------------------------------
int vtkHapticForceModel::GetNumberOfPendingCuts() const
{
  return this->Internal->PendingCount;
}

namespace
{
/// Where margin(t) falls below zero between a (margin >= 0) and b (margin <
/// 0), to within tolerance: Illinois regula falsi. Both margins (CT less the
/// iso-value, the cut field's distance) are smooth across the half-voxel
/// bracket, so this takes 2-4 evaluations where halving takes 8.
template <typename Margin>
double FindBorder(Margin&& margin, double a, double marginA, double b, double marginB, double tolerance)
{
  int keptSide = 0;
  for (int iteration = 0; iteration < 16 && b - a > tolerance; ++iteration)
  {
    const double slope = (marginA - marginB) / (b - a);
    double t = a + marginA / slope;
    if (!(t > a && t < b))
    {
      t = 0.5 * (a + b);
    }
    const double value = margin(t);
    // Where the margin is this small, the border is within half the
    // tolerance of t along the bracket's slope.
    if (std::abs(value) <= 0.5 * tolerance * slope)
    {
      return t;
    }
    if (!(value < 0.0))
    {
      a = t;
      marginA = value;
      if (keptSide == 1)
      {
        marginB *= 0.5;
      }
      keptSide = 1;
    }
    else
    {
      b = t;
      marginB = value;
      if (keptSide == -1)
      {
        marginA *= 0.5;
      }
      keptSide = -1;
    }
  }
  return 0.5 * (a + b);
}
} // namespace

//------------------------------------------------------------------------------
double vtkHapticForceModel::ExitDistance(const double p[3], const double u[3], double length, const Margins& atStart, int& samples,
  int& cutSamples, bool pending) const
{
  const double step = this->Internal->TraceStep;
  // 1/256 of a step (a step is half a voxel): far inside the 0.1 voxel the
  // force must agree with the picture.
  const double tolerance = step / 256.0;
  // Every point the trace places is looked up: counting them counts its work.
  auto at = [p, u, &samples](double s, double point[3]) {
    ++samples;
    for (int axis = 0; axis < 3; ++axis)
    {
      point[axis] = p[axis] + s * u[axis];
    }
  };
  // The cut field is a distance (mm) and changes by no more than about a
  // millimetre per millimetre along the trace (0.9 leaves room for its
  // interpolation): closer than 0.9 of its value at p, no cut ends the
  // material and only the CT is sampled. Just beyond its value is where a
  // trace facing the cut surface leaves (as in the burr's own cavity): the
  // first sample there brackets that border with one lookup.
  const bool cut = this->CutField != nullptr || pending;
  const double cutFree = cut ? 0.9 * atStart.Removal : VTK_DOUBLE_MAX;
  const double guess = cut ? std::max(1.05 * atStart.Removal + tolerance, tolerance) : VTK_DOUBLE_MAX;
  double inside = 0.0;
  double insideAnatomy = atStart.Anatomy;
  // The last solid sample where the cut field was measured.
  double measured = 0.0;
  double measuredRemoval = atStart.Removal;
  for (double t = std::min({ step, guess, length });;)
  {
    double q[3];
    at(t, q);
    Margins here;
    this->Measure(q, here, t >= cutFree, pending);
    cutSamples += here.CutLookedUp;
    if (!here.IsSolid())
    {
      if (!here.InBox)
      {
        // Left the volume's box (convex, so between the two samples only
        // once): halve on the classification itself.
        double outside = t;
        for (int halving = 0; halving < 8; ++halving)
        {
          const double middle = 0.5 * (inside + outside);
          double m[3];
          at(middle, m);
          Margins margins;
          this->Measure(m, margins, true, pending);
          cutSamples += margins.CutLookedUp;
          (margins.IsSolid() ? inside : outside) = middle;
        }
        return 0.5 * (inside + outside);
      }
      double end = t;
      if (here.Anatomy < 0.0)
      {
        const double exit = FindBorder(
          [&](double s) {
            double m[3];
            at(s, m);
            Margins margins;
            this->Measure(m, margins, false);
            return margins.Anatomy;
          },
          inside, insideAnatomy, t, here.Anatomy, tolerance);
        if (exit - tolerance < cutFree)
        {
          return exit;
        }
        // The cut may end the material before the CT does.
        double m[3];
        at(exit - tolerance, m);
        here.Removal = this->RemovalDistance(m, pending);
        cutSamples += this->CutField != nullptr;
        if (!(here.Removal < 0.0))
        {
          return exit;
        }
        end = exit - tolerance;
      }
      if (!(end > measured))
      {
        return measured;
      }
      return FindBorder(
        [&](double s) {
          double m[3];
          at(s, m);
          cutSamples += this->CutField != nullptr;
          return this->RemovalDistance(m, pending);
        },
        measured, measuredRemoval, end, here.Removal, tolerance);
    }
    inside = t;
    insideAnatomy = here.Anatomy;
    if (t >= cutFree)
    {
      measured = t;
      measuredRemoval = here.Removal;
    }
    if (t >= length)
    {
      return length;
    }
    // A step on, stopping at the guess on the way.
    const double next = t < guess ? std::min(t + step, guess) : t + step;
    t = std::min(next, length);
  }
}

//------------------------------------------------------------------------------
int vtkHapticForceModel::Contact(const double position[3], const double rotation[3][3], double force[3], bool record, ContactWork* work) const
{
  int looked = 0;
  int cutLooked = 0;
  double deepest = 0.0;
  const Internals& internal = *this->Internal;
  // Only the haptic thread's Update records: ComputeContactForce stays a pure read.
  Internals* recording = record ? this->Internal : nullptr;
  force[0] = force[1] = force[2] = 0.0;
  int contacts = 0;
  if (recording)
  {
    recording->NumberOfClearances = 0;
  }
  const bool pending = recording && internal.NearCount > 0;
  for (int n = 0; n < internal.ShellCount; ++n)
  {
    const double* local = &internal.Shell[3 * n];
    double offset[3];
    for (int row = 0; row < 3; ++row)
    {
      offset[row] = rotation[row][0] * local[0] + rotation[row][1] * local[1] + rotation[row][2] * local[2];
    }
    const double p[3] = { position[0] + offset[0], position[1] + offset[1], position[2] + offset[2] };
    Margins margins;
    this->Measure(p, margins, true, pending);
    ++looked;
    cutLooked += margins.CutLookedUp;
    if (!margins.IsSolid())
    {
      // A point in the cut is at least the cut field's distance from the
      // cut's surface, and so from the material beyond it.
      if (recording && margins.Removal < 0.0)
      {
        double* clearance = &recording->Clearances[4 * recording->NumberOfClearances++];
        std::copy(offset, offset + 3, clearance);
        clearance[3] = -margins.Removal;
      }
      continue;
    }
    // Seed 003: trace from the immersed point toward the tool's centre; the
    // material between the point and its exit pushes the tool out that way.
    const double length = Norm(offset);
    if (!(length > 0.0))
    {
      continue;
    }
    const double u[3] = { -offset[0] / length, -offset[1] / length, -offset[2] / length };
    const double depth = this->ExitDistance(p, u, length, margins, looked, cutLooked, pending);
    deepest = std::max(deepest, depth);
    for (int axis = 0; axis < 3; ++axis)
    {
      force[axis] += this->ContactStiffness * depth * u[axis];
    }
    if (recording)
    {
      std::copy(u, u + 3, &recording->ContactDirections[3 * contacts]);
    }
    ++contacts;
  }
  if (work)
  {
    work->Samples += looked;
    work->CutFieldSamples += cutLooked;
    work->Deepest = deepest;
  }
  return contacts;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::ProxyMove(const double proxy[3], const double hand[3], int contacts, const double contact[3], double move[3]) const
{
  // Along the net force on the proxy (coupling pull plus the contacts'
  // push), as far as the stiffness in that direction says: the coupling's
  // plus each contact's share, kc (u . d)^2, as a plane facing its push
  // would resist. Counting every contact at full stiffness, whatever its
  // direction, stepped a third of the way back from a stroke into bone.
  const Internals& internal = *this->Internal;
  const double k = this->CouplingStiffness;
  double net[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    net[axis] = k * (hand[axis] - proxy[axis]) + contact[axis];
  }
  const double magnitude = Norm(net);
  if (!(magnitude > 0.0))
  {
    move[0] = move[1] = move[2] = 0.0;
    return;
  }
  const double d[3] = { net[0] / magnitude, net[1] / magnitude, net[2] / magnitude };
  double stiffness = k;
  const double* directions = internal.ContactDirections.data();
  for (int n = 0; n < contacts; ++n)
  {
    const double along = vtkMath::Dot(directions + 3 * n, d);
    stiffness += this->ContactStiffness * along * along;
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    move[axis] = magnitude / stiffness * d[axis];
  }
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::Update(const double position[3], const double rotation[3][3], double timeStep, bool drilling, Result& result)
{
  Internals& internal = *this->Internal;
  result = Result{};
  if (!internal.Prepared || !std::isfinite(position[0]) || !std::isfinite(position[1]) || !std::isfinite(position[2]))
  {
    // Nothing to render from: no force, the proxy stays where it was.
    std::copy(internal.Proxy, internal.Proxy + 3, result.ProxyPosition);
    std::copy(internal.Proxy, internal.Proxy + 3, result.CutPosition);
    internal.Last = result;
    return;
  }
  if (!internal.HasState)
  {
    this->Reset(position);
  }
  const double dt = (timeStep > 0.0 && std::isfinite(timeStep)) ? timeStep : 1e-3;

  // The pending cuts this tick's contact tests can reach: the shell's points
  // lie within the radius of the proxy, which moves at most ProxyIterations
  // steps.
  internal.NearCount = 0;
  internal.Shielded = false;
  if (internal.PendingCount > 0)
  {
    const double reach = 2.0 * this->SphereRadius + this->ProxyIterations * internal.ProxyStep;
    for (int n = 0; n < internal.PendingCount; ++n)
    {
      const double* p0 = internal.Pending[n];
      const double* p1 = p0 + 3;
      double* near = internal.Near[internal.NearCount];
      const double d[3] = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] };
      const double length2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const double w[3] = { internal.Proxy[0] - p0[0], internal.Proxy[1] - p0[1], internal.Proxy[2] - p0[2] };
      const double along = length2 > 0.0 ? std::min(std::max(vtkMath::Dot(w, d) / length2, 0.0), 1.0) : 0.0;
      const double gap[3] = { w[0] - along * d[0], w[1] - along * d[1], w[2] - along * d[2] };
      if (vtkMath::Dot(gap, gap) <= reach * reach)
      {
        std::copy(p0, p0 + 3, near);
        std::copy(d, d + 3, near + 3);
        near[6] = length2 > 0.0 ? 1.0 / length2 : 0.0;
        ++internal.NearCount;
      }
    }
    internal.Shielded = internal.NearCount > 0 && this->CutField && this->CutField->GetProtection()->HasShieldedLabels();
  }

  // Proxy: toward the hand until the coupling balances the contacts.
  double* x = internal.Proxy;
  const double k = this->CouplingStiffness;
  double contact[3] = { 0.0, 0.0, 0.0 };
  int contacts = 0;
  for (int iteration = 0; iteration < this->ProxyIterations; ++iteration)
  {
    ContactWork work;
    contacts = this->Contact(x, rotation, contact, true, &work);
    result.NumberOfSamples += work.Samples;
    result.NumberOfCutFieldSamples += work.CutFieldSamples;
    result.Immersion = work.Deepest;
    ++result.NumberOfProxySteps;
    double move[3];
    this->ProxyMove(x, position, contacts, contact, move);
    const double length = Norm(move);
    // God-object: the proxy stops where the material ahead of it in the cut
    // begins (just past, so that the next test finds the contact it settles
    // on) instead of a full step into bone that the next tests must undo. A
    // point in the cut is its cut-field distance from the cut's wall. The
    // points facing the move (within 45 degrees) bound it: in a cavity the
    // tool cut, their wall ahead lies along their outward normal, which the
    // move approaches at the cosine of its angle to it (points beside the
    // move are nearest to walls it runs along, and would stall it).
    double limit = internal.ProxyStep;
    for (int n = 0; n < internal.NumberOfClearances; ++n)
    {
      const double* record = &internal.Clearances[4 * n];
      const double approach = vtkMath::Dot(record, move) / (Norm(record) * length);
      if (approach > 0.7)
      {
        limit = std::min(limit, record[3] / approach + std::max(this->ProxyTolerance, 1e-6));
      }
    }
    const double scale = length > limit ? limit / length : 1.0;
    for (int axis = 0; axis < 3; ++axis)
    {
      x[axis] += scale * move[axis];
    }
    // Settled: a further contact test would move the proxy, and the
    // coupling force, by less than what the next tick corrects anyway.
    if (length < std::max(this->ProxyTolerance, 1e-9))
    {
      break;
    }
  }

  // The hand: coupling spring and damping relative to the proxy (filtered
  // at about 100 Hz: finite differences of encoder positions are noisy),
  // then the guide.
  const double filter = dt / (dt + 1.0 / (2.0 * vtkMath::Pi() * 100.0));
  double force[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    const double relative = ((position[axis] - internal.PreviousDevice[axis]) - (x[axis] - internal.PreviousProxy[axis])) / dt;
    internal.RelativeVelocity[axis] += filter * (relative - internal.RelativeVelocity[axis]);
    force[axis] = this->AppliedCouplingStiffness * (x[axis] - position[axis]) - this->AppliedDamping * internal.RelativeVelocity[axis];
    internal.PreviousDevice[axis] = position[axis];
    internal.PreviousProxy[axis] = x[axis];
  }
  if (this->GuideEnabled)
  {
    const double w[3] = { position[0] - this->GuidePoint[0], position[1] - this->GuidePoint[1], position[2] - this->GuidePoint[2] };
    const double along = vtkMath::Dot(w, this->GuideDirection);
    for (int axis = 0; axis < 3; ++axis)
    {
      force[axis] -= this->AppliedGuideStiffness * (w[axis] - along * this->GuideDirection[axis]);
    }
  }
  double magnitude = Norm(force);
  if (magnitude > this->MaximumForce)
  {
    const double scale = this->MaximumForce > 0.0 && magnitude > 0.0 ? this->MaximumForce / magnitude : 0.0;
    for (double& component : force)
    {
      component *= scale;
    }
    magnitude = this->MaximumForce;
  }
  const double contactMagnitude = Norm(contact);
  if (drilling && this->VibrationEnabled)
  {
    // Along the tool's axis (its local z), within what the force leaves.
    result.Vibration = this->Vibration->Evaluate(contactMagnitude, dt, this->MaximumVibrationFrequency, this->MaximumForce - magnitude);
    for (int axis = 0; axis < 3; ++axis)
    {
      force[axis] += result.Vibration * rotation[axis][2];
    }
  }
  std::copy(force, force + 3, result.Force);
  std::copy(x, x + 3, result.ProxyPosition);
  result.NumberOfContacts = contacts;
  result.ContactForce = contactMagnitude;

  // Drilling: a bite ahead of the proxy toward the hand, as deep as the push allows.
  std::copy(x, x + 3, result.CutPosition);
  if (drilling && contacts > 0)
  {
    double push[3] = { position[0] - x[0], position[1] - x[1], position[2] - x[2] };
    const double pushLength = Norm(push);
    const double pushForce = k * pushLength;
    const double bite = std::min(this->FeedRatePerNewton * pushForce, this->MaximumFeedRate) * dt;
    if (pushLength > 1e-9 && bite > 0.0)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        result.CutPosition[axis] = x[axis] + bite * push[axis] / pushLength;
      }
    }
    result.Cut = true;
  }
  internal.Last = result;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::SetToolRotation(vtkMatrix4x4* toolToRAS)
{
  if (!toolToRAS)
  {
    return;
  }
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      this->ToolRotation[row][column] = toolToRAS->GetElement(row, column);
    }
  }
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::Step(const double position[3], double timeStep, bool drilling)
{
  Result result;
  this->Update(position, this->ToolRotation, timeStep, drilling, result);
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::GetForce(double force[3]) const
{
  std::copy(this->Internal->Last.Force, this->Internal->Last.Force + 3, force);
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::GetProxyPosition(double position[3]) const
{
  std::copy(this->Internal->Last.ProxyPosition, this->Internal->Last.ProxyPosition + 3, position);
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::GetCutPosition(double position[3]) const
{
  std::copy(this->Internal->Last.CutPosition, this->Internal->Last.CutPosition + 3, position);
}

//------------------------------------------------------------------------------
bool vtkHapticForceModel::GetLastStepCut() const
{
  return this->Internal->Last.Cut;
}

//------------------------------------------------------------------------------
int vtkHapticForceModel::GetNumberOfContacts() const
{
  return this->Internal->Last.NumberOfContacts;
}

//------------------------------------------------------------------------------
int vtkHapticForceModel::GetNumberOfProxySteps() const
{
  return this->Internal->Last.NumberOfProxySteps;
}

//------------------------------------------------------------------------------
int vtkHapticForceModel::ComputeContactForce(const double position[3], double force[3])
{
  if (!this->Internal->Prepared)
  {
    vtkErrorMacro("ComputeContactForce: call Prepare first");
    force[0] = force[1] = force[2] = 0.0;
    return 0;
  }
  return this->Contact(position, this->ToolRotation, force);
}

//------------------------------------------------------------------------------
int vtkHapticForceModel::CountWholeVoxelContacts(const double position[3], vtkBinaryVoxelCutter* removed)
{
  const Internals& internal = *this->Internal;
  if (!internal.Prepared)
  {
    vtkErrorMacro("CountWholeVoxelContacts: call Prepare first");
    return 0;
  }
  int contacts = 0;
  for (int n = 0; n < internal.ShellCount; ++n)
  {
    const double* local = &internal.Shell[3 * n];
    double p[3];
    double ijk[3];
    for (int row = 0; row < 3; ++row)
    {
      p[row] = position[row] + this->ToolRotation[row][0] * local[0] + this->ToolRotation[row][1] * local[1] + this->ToolRotation[row][2] * local[2];
    }
    bool inside = true;
    for (int row = 0; row < 3; ++row)
    {
      ijk[row] = internal.RASToIJK[row][0] * p[0] + internal.RASToIJK[row][1] * p[1] + internal.RASToIJK[row][2] * p[2] + internal.RASToIJK[row][3];
      inside = inside && ijk[row] > -0.5 && ijk[row] < internal.Dimensions[row] - 0.5;
    }
    if (inside && internal.Nearest(internal.Scalars, internal.Dimensions, ijk) >= this->SurfaceIsoValue && !(removed && removed->IsRemoved(p)))
    {
      ++contacts;
    }
  }
  return contacts;
}

//------------------------------------------------------------------------------
void vtkHapticForceModel::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SurfaceIsoValue: " << this->SurfaceIsoValue << "\n";
  os << indent << "SphereRadius: " << this->SphereRadius << " mm\n";
  os << indent << "Tool: " << (this->Tool ? this->Tool->GetClassName() : "(sphere)") << "\n";
  os << indent << "NumberOfShellPoints: " << this->NumberOfShellPoints << "\n";
  os << indent << "ContactStiffness: " << this->ContactStiffness << " N/mm\n";
  os << indent << "CouplingStiffness: " << this->CouplingStiffness << " N/mm (applied " << this->AppliedCouplingStiffness << ")\n";
  os << indent << "Damping: " << this->Damping << " N s/mm (applied " << this->AppliedDamping << ")\n";
  os << indent << "MaximumForce: " << this->MaximumForce << " N\n";
  os << indent << "ProxyIterations: " << this->ProxyIterations << "\n";
  os << indent << "ProxyTolerance: " << this->ProxyTolerance << " mm\n";
  os << indent << "FeedRatePerNewton: " << this->FeedRatePerNewton << " mm/s/N\n";
  os << indent << "MaximumFeedRate: " << this->MaximumFeedRate << " mm/s\n";
  os << indent << "GuideEnabled: " << (this->GuideEnabled ? "On" : "Off") << "\n";
  os << indent << "GuideStiffness: " << this->GuideStiffness << " N/mm\n";
  os << indent << "VibrationEnabled: " << (this->VibrationEnabled ? "On" : "Off") << "\n";
  os << indent << "MaximumVibrationFrequency: " << this->MaximumVibrationFrequency << " Hz\n";
}
