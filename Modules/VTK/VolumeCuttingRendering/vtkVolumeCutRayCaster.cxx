// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutRayCaster.h"

#include "vtkVolumeCutField.h"

#include <vtkColorTransferFunction.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkMath.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>
#include <vtkPointData.h>
#include <vtkSMPTools.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutRayCaster);

namespace
{
constexpr int MaximumCutFields = 8;
constexpr int BlockSize = 8;
constexpr int MaximumLayers = 8;
constexpr int ObjectBisections = 22;
constexpr int CutBisections = 22;
constexpr int TransferTableSize = 4096;
constexpr int MaximumRefinements = 4;
constexpr int MaximumFractions = 16;
constexpr float OpaqueAlpha = 0.995f;

struct SegmentStyle
{
  float Color[3] = { 1.f, 1.f, 1.f };
  float Opacity = 0.f;
  float Iso = 0.f;
  bool Shape = false; // the surface is the label's own indicator at 0.5
  bool Defined = false;
};

struct CutEntry
{
  vtkSmartPointer<vtkVolumeCutField> Field;
  bool Usable = false;
  bool Reported = false;
  vtkTypeUInt64 RenderedStamp = 0;
};

// One point of a ray and what is there.
struct Sample
{
  double T = 0.0;
  double Index[3] = { 0.0, 0.0, 0.0 };
  int Object = 0;
  float Value = 0.f;
  bool CutsKnown = false;
  double Distance[MaximumCutFields];
};

// A border between two samples: where it is and which volume forms it.
struct Border
{
  double T;
  int Source; // vtkVolumeCutRayCaster::SurfaceSources (SourceCutField + k for cut k)
};

void Multiply4(const double m[16], const double in[4], double out[4])
{
  for (int row = 0; row < 4; ++row)
  {
    out[row] = m[4 * row] * in[0] + m[4 * row + 1] * in[1] + m[4 * row + 2] * in[2] + m[4 * row + 3] * in[3];
  }
}

void TransformPoint(const double m[16], const double in[3], double out[3])
{
  const double h[4] = { in[0], in[1], in[2], 1.0 };
  double r[4];
  Multiply4(m, h, r);
  out[0] = r[0];
  out[1] = r[1];
  out[2] = r[2];
}

void TransformVector(const double m[16], const double in[3], double out[3])
{
  for (int row = 0; row < 3; ++row)
  {
    out[row] = m[4 * row] * in[0] + m[4 * row + 1] * in[1] + m[4 * row + 2] * in[2];
  }
}

/// vtkSMPTools::For over [0, end) with at most maximumThreads threads (0: all
/// cores). The VTK wheels start on the Sequential backend, which would leave a
/// CPU reference that is meant to be multithreaded on one core: there the
/// standard-thread backend is used for these loops only. Slicer's own build
/// runs TBB and keeps it.
template <typename Work>
void ParallelFor(int maximumThreads, vtkIdType end, Work&& work)
{
  if (maximumThreads == 1)
  {
    work(vtkIdType(0), end);
    return;
  }
  vtkSMPTools::Config config; // the active backend
  if (std::strcmp(vtkSMPTools::GetBackend(), "Sequential") == 0)
  {
    config.Backend = "STDThread";
  }
  config.MaxNumberOfThreads = maximumThreads;
  vtkSMPTools::LocalScope(config, [&] { vtkSMPTools::For(0, end, work); });
}
}

//------------------------------------------------------------------------------
struct vtkVolumeCutRayCaster::Internals
{
  // Anatomy
  vtkSmartPointer<vtkImageData> Anatomy;
  vtkSmartPointer<vtkMatrix4x4> AnatomyMatrix;
  vtkMTimeType AnatomyCopyTime = 0;
  std::vector<float> Values;
  int Dimensions[3] = { 0, 0, 0 };
  double IJKToWorld[16];
  double WorldToIJK[16];

  // Segments
  vtkSmartPointer<vtkImageData> LabelMap;
  vtkMTimeType LabelCopyTime = 0;
  std::vector<uint16_t> Labels;
  std::vector<SegmentStyle> Styles;
  bool DefaultStyles = true;

  // Fractional labelmaps: per segment, the fraction (0..1) of each voxel.
  struct FractionInput
  {
    vtkSmartPointer<vtkImageData> Image;
    double ValueAtZero = 0.0;
    double ValueAtOne = 1.0;
  };
  std::map<int, FractionInput> FractionInputs;
  struct FractionVolume
  {
    int Label = 0;
    std::vector<float> Values;
  };
  std::vector<FractionVolume> Fractions;
  vtkMTimeType FractionCopyTime = 0;

  bool HasSegments() const { return !this->Labels.empty() || !this->Fractions.empty(); }

  std::vector<CutEntry> Cuts;
  vtkSmartPointer<vtkPlaneCollection> Planes;
  vtkSmartPointer<vtkColorTransferFunction> ColorFunction;
  vtkSmartPointer<vtkPiecewiseFunction> OpacityFunction;
  std::vector<float> ColorTable;   // 3 per entry
  std::vector<float> OpacityTable; // per entry, per ScalarOpacityUnitDistance
  double TableRange[2] = { 0.0, 1.0 };

  // Empty-space skipping: blocks of BlockSize^3 cells that may hold a visible object.
  int BlockDimensions[3] = { 0, 0, 0 };
  std::vector<uint8_t> BlockOccupied;
  std::vector<float> BlockLipschitz; // bound of the CT's gradient (per voxel) in the block
  bool AnyIsoSegment = false;
  double MinimumIso = 0.0;
  vtkMTimeType BlockTime = 0;
  vtkMTimeType SceneVersion = 1;
  vtkMTimeType LabelVersion = 1; // changes when the label map or fractions are copied or dropped

  // Last image, for localized updates.
  int Width = 0;
  int Height = 0;
  double WorldToNDC[16];
  double NDCToWorld[16];
  vtkMTimeType SceneTime = 0;
  std::vector<float> OpaqueDepth;
  bool HadOpaqueDepth = false;
  std::vector<float> Color;
  std::vector<float> Depth;
  std::vector<float> Normal;
  std::vector<int> Source;
  bool ImageValid = false;

  // Per-frame constants copied from the caster so rays read plain members.
  int BlendMode = 0;
  double SampleDistance = 0.5;
  double GradientStep = 0.3;
  double UnitDistance = 1.0;
  bool ThinBone = false;
  double ThinBoneThickness = 1.0;
  double Ambient = 0.25, Diffuse = 0.7, Specular = 0.2, SpecularPower = 20.0;
  std::vector<int> ActiveCuts; // indices into Cuts of usable, non-empty fields
  struct PlaneEquation
  {
    double Normal[3];
    double Offset;
  };
  std::vector<PlaneEquation> PlaneEquations;

  // ---- field evaluation -------------------------------------------------
  // The cell holding p (clamped to the volume) and p's offsets in it.
  void CellOf(const double p[3], int base[3], double f[3]) const
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      const double x = std::min(std::max(p[axis], 0.0), double(this->Dimensions[axis] - 1));
      base[axis] = std::min(static_cast<int>(x), this->Dimensions[axis] - 2);
      f[axis] = x - base[axis];
    }
  }

  float Interpolate(const double p[3]) const { return this->InterpolateArray(this->Values.data(), p); }

  float InterpolateArray(const float* values, const double p[3]) const
  {
    int base[3];
    double f[3];
    this->CellOf(p, base, f);
    const vtkIdType sx = 1;
    const vtkIdType sy = this->Dimensions[0];
    const vtkIdType sz = static_cast<vtkIdType>(this->Dimensions[0]) * this->Dimensions[1];
    const float* v = values + base[0] + base[1] * sy + base[2] * sz;
    const double c00 = v[0] + f[0] * (v[sx] - v[0]);
    const double c10 = v[sy] + f[0] * (v[sy + sx] - v[sy]);
    const double c01 = v[sz] + f[0] * (v[sz + sx] - v[sz]);
    const double c11 = v[sz + sy] + f[0] * (v[sz + sy + sx] - v[sz + sy]);
    const double c0 = c00 + f[1] * (c10 - c00);
    const double c1 = c01 + f[1] * (c11 - c01);
    return static_cast<float>(c0 + f[2] * (c1 - c0));
  }

  // The segment label with the largest trilinear weight among the cell's
  // corners (hidden segments included, background not), and that weight (the
  // label's interpolated indicator). Where two segments meet, their border is
  // where their weights are equal, a smooth surface; where a segment meets
  // the background, the CT's iso-surface (or the indicator at 0.5) decides.
  int DominantLabel(const double p[3], double& weight) const
  {
    int base[3];
    double f[3];
    this->CellOf(p, base, f);
    int labels[8 + MaximumFractions];
    double weights[8 + MaximumFractions];
    int count = 0;
    double unlabelledBright = 0.0;
    for (int corner = 0; corner < 8 && !this->Labels.empty(); ++corner)
    {
      const int c[3] = { base[0] + (corner & 1), base[1] + ((corner >> 1) & 1), base[2] + ((corner >> 2) & 1) };
      const vtkIdType voxel = c[0] + static_cast<vtkIdType>(this->Dimensions[0]) * (c[1] + static_cast<vtkIdType>(this->Dimensions[1]) * c[2]);
      const int label = this->Labels[voxel];
      const double w =
        ((corner & 1) ? f[0] : 1.0 - f[0]) * (((corner >> 1) & 1) ? f[1] : 1.0 - f[1]) * (((corner >> 2) & 1) ? f[2] : 1.0 - f[2]);
      if (label == 0)
      {
        // Material above the surface value that no shown segment claims
        // competes like a segment: its border with a shown one is smooth,
        // not the cell faces where a labelled voxel first counts.
        if (this->AnyIsoSegment && this->Values[voxel] >= this->MinimumIso)
        {
          unlabelledBright += w;
        }
        continue;
      }
      int slot = 0;
      while (slot < count && labels[slot] != label)
      {
        ++slot;
      }
      if (slot == count)
      {
        labels[count] = label;
        weights[count++] = 0.0;
      }
      weights[slot] += w;
    }
    // A segment with a fractional labelmap weighs its interpolated fraction
    // (the label map's indicator is its binary special case).
    for (const FractionVolume& fraction : this->Fractions)
    {
      const double w = this->InterpolateArray(fraction.Values.data(), p);
      int slot = 0;
      while (slot < count && labels[slot] != fraction.Label)
      {
        ++slot;
      }
      if (slot == count)
      {
        labels[count++] = fraction.Label;
      }
      weights[slot] = w;
    }
    int best = 0;
    weight = 0.0;
    for (int slot = 0; slot < count; ++slot)
    {
      // Ties go to the lower label so that every path decides the same way.
      if (weights[slot] > weight || (weights[slot] == weight && weight > 0.0 && labels[slot] < best))
      {
        best = labels[slot];
        weight = weights[slot];
      }
    }
    if (unlabelledBright > weight)
    {
      return 0;
    }
    return best;
  }

  // Interpolated indicator of one label (for shape-defined segments' normals).
  double Indicator(int label, const double p[3]) const
  {
    for (const FractionVolume& fraction : this->Fractions)
    {
      if (fraction.Label == label)
      {
        return this->InterpolateArray(fraction.Values.data(), p);
      }
    }
    if (this->Labels.empty())
    {
      return 0.0;
    }
    int base[3];
    double f[3];
    this->CellOf(p, base, f);
    double value = 0.0;
    for (int corner = 0; corner < 8; ++corner)
    {
      const int c[3] = { base[0] + (corner & 1), base[1] + ((corner >> 1) & 1), base[2] + ((corner >> 2) & 1) };
      if (this->Labels[c[0] + static_cast<vtkIdType>(this->Dimensions[0]) * (c[1] + static_cast<vtkIdType>(this->Dimensions[1]) * c[2])] ==
        label)
      {
        value += ((corner & 1) ? f[0] : 1.0 - f[0]) * (((corner >> 1) & 1) ? f[1] : 1.0 - f[1]) * (((corner >> 2) & 1) ? f[2] : 1.0 - f[2]);
      }
    }
    return value;
  }

  // Which visible object is at p (0 for none), and the CT value there.
  int ObjectAt(const double p[3], float& value) const
  {
    value = this->Interpolate(p);
    if (!this->HasSegments())
    {
      const SegmentStyle& style = this->Styles[1];
      return (style.Opacity > 0.f && value >= style.Iso) ? 1 : 0;
    }
    double weight = 0.0;
    const int label = this->DominantLabel(p, weight);
    if (label == 0 || label >= static_cast<int>(this->Styles.size()) || this->Styles[label].Opacity <= 0.f)
    {
      return 0; // background, or a hidden segment
    }
    const SegmentStyle& style = this->Styles[label];
    const bool inside = style.Shape ? weight >= 0.5 : value >= style.Iso;
    return inside ? label : 0;
  }

  void EvaluateObject(Sample& s) const { s.Object = this->ObjectAt(s.Index, s.Value); }

  void WorldPoint(const double index[3], double world[3]) const { TransformPoint(this->IJKToWorld, index, world); }

  void EvaluateCuts(Sample& s) const
  {
    if (s.CutsKnown)
    {
      return;
    }
    double world[3];
    this->WorldPoint(s.Index, world);
    for (size_t n = 0; n < this->ActiveCuts.size(); ++n)
    {
      s.Distance[n] = this->Cuts[this->ActiveCuts[n]].Field->GetSignedDistance(world);
    }
    s.CutsKnown = true;
  }

  bool Removed(const Sample& s) const
  {
    for (size_t n = 0; n < this->ActiveCuts.size(); ++n)
    {
      if (s.Distance[n] < 0.0)
      {
        return true;
      }
    }
    return false;
  }

  bool Visible(Sample& s) const
  {
    if (s.Object == 0)
    {
      return false;
    }
    this->EvaluateCuts(s);
    return !this->Removed(s);
  }

  // ---- normals (world, unit, pointing out of the visible material) ----
  void ObjectNormal(int object, const double p[3], double normal[3]) const
  {
    const double h = this->GradientStep;
    double gradient[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      double plus[3] = { p[0], p[1], p[2] };
      double minus[3] = { p[0], p[1], p[2] };
      plus[axis] += h;
      minus[axis] -= h;
      if (this->HasSegments() && this->Styles[object].Shape)
      {
        gradient[axis] = this->Indicator(object, plus) - this->Indicator(object, minus);
      }
      else
      {
        gradient[axis] = double(this->Interpolate(plus)) - double(this->Interpolate(minus));
      }
    }
    // Outward: against the gradient of the inside-positive field.
    TransformVector(this->NormalMatrix4(), gradient, normal);
    for (int axis = 0; axis < 3; ++axis)
    {
      normal[axis] = -normal[axis];
    }
    vtkMath::Normalize(normal);
  }

  void CutNormal(int n, const double world[3], double normal[3]) const
  {
    const vtkVolumeCutField* field = this->Cuts[this->ActiveCuts[n]].Field;
    double spacing[3];
    field->GetSubVoxelSpacing(spacing);
    const double h = 0.25 * std::min({ spacing[0], spacing[1], spacing[2] });
    for (int axis = 0; axis < 3; ++axis)
    {
      double plus[3] = { world[0], world[1], world[2] };
      double minus[3] = { world[0], world[1], world[2] };
      plus[axis] += h;
      minus[axis] -= h;
      // The material's outward normal points into the removed region, where
      // the distance decreases.
      normal[axis] = field->GetSignedDistance(minus) - field->GetSignedDistance(plus);
    }
    vtkMath::Normalize(normal);
  }

  // Inverse transpose of IJK-to-world's linear part (4x4, row-major): maps
  // IJK gradients to world normals.
  double NormalMatrix4Storage[16];
  const double* NormalMatrix4() const { return this->NormalMatrix4Storage; }

  // ---- borders --------------------------------------------------------
  Sample At(const double origin[3], const double direction[3], double t) const
  {
    Sample s;
    s.T = t;
    for (int axis = 0; axis < 3; ++axis)
    {
      s.Index[axis] = origin[axis] + t * direction[axis];
    }
    return s;
  }

  double BisectObject(const double o[3], const double d[3], const Sample& a, const Sample& b) const
  {
    double lo = a.T;
    double hi = b.T;
    for (int iteration = 0; iteration < ObjectBisections; ++iteration)
    {
      Sample mid = this->At(o, d, 0.5 * (lo + hi));
      this->EvaluateObject(mid);
      (mid.Object == a.Object ? lo : hi) = mid.T;
    }
    return 0.5 * (lo + hi);
  }

  double BisectCut(int n, const double o[3], const double d[3], const Sample& a, const Sample& b) const
  {
    const vtkVolumeCutField* field = this->Cuts[this->ActiveCuts[n]].Field;
    double lo = a.T;
    double hi = b.T;
    const bool loRemoved = a.Distance[n] < 0.0;
    for (int iteration = 0; iteration < CutBisections; ++iteration)
    {
      const double t = 0.5 * (lo + hi);
      double index[3];
      double world[3];
      for (int axis = 0; axis < 3; ++axis)
      {
        index[axis] = o[axis] + t * d[axis];
      }
      this->WorldPoint(index, world);
      ((field->GetSignedDistance(world) < 0.0) == loRemoved ? lo : hi) = t;
    }
    return 0.5 * (lo + hi);
  }

  // ---- transfer functions ---------------------------------------------
  void LookUp(float value, float color[3], float& opacity) const
  {
    const double span = this->TableRange[1] - this->TableRange[0];
    double x = span > 0.0 ? (value - this->TableRange[0]) / span * (TransferTableSize - 1) : 0.0;
    x = std::min(std::max(x, 0.0), double(TransferTableSize - 1));
    const int i = std::min(static_cast<int>(x), TransferTableSize - 2);
    const float f = static_cast<float>(x - i);
    for (int c = 0; c < 3; ++c)
    {
      color[c] = this->ColorTable[3 * i + c] * (1.f - f) + this->ColorTable[3 * (i + 1) + c] * f;
    }
    opacity = this->OpacityTable[i] * (1.f - f) + this->OpacityTable[i + 1] * f;
  }

  bool BlockEmpty(const double p[3]) const
  {
    int b[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      b[axis] = std::min(std::max(static_cast<int>(p[axis]) / BlockSize, 0), this->BlockDimensions[axis] - 1);
    }
    return !this->BlockOccupied[b[0] + this->BlockDimensions[0] * (b[1] + this->BlockDimensions[1] * b[2])];
  }

  // Ray parameter where the ray leaves the block holding p.
  double BlockExit(const double p[3], const double d[3], double t) const
  {
    double exit = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis)
    {
      if (std::abs(d[axis]) < 1e-12)
      {
        continue;
      }
      const int b = std::min(std::max(static_cast<int>(p[axis]) / BlockSize, 0), this->BlockDimensions[axis] - 1);
      const double wall = d[axis] > 0.0 ? double((b + 1) * BlockSize) : double(b * BlockSize);
      exit = std::min(exit, t + (wall - p[axis]) / d[axis]);
    }
    return exit;
  }

  float BlockValue(const std::vector<float>& values, const double p[3]) const
  {
    int b[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      b[axis] = std::min(std::max(static_cast<int>(p[axis]) / BlockSize, 0), this->BlockDimensions[axis] - 1);
    }
    return values[b[0] + this->BlockDimensions[0] * (b[1] + this->BlockDimensions[1] * b[2])];
  }

  // Whether a border could lie between two samples without showing at them:
  // bounds from the CT's largest gradient in the blocks (voxels) and from the
  // cut fields being distances (1 mm per mm).
  bool MayHideBorders(const Sample& a, const Sample& b, double lengthVoxels, double lengthMillimetres) const
  {
    if (a.Object == 0 && b.Object == 0)
    {
      if (!this->AnyIsoSegment)
      {
        return false;
      }
      const double slope = std::max(this->BlockValue(this->BlockLipschitz, a.Index), this->BlockValue(this->BlockLipschitz, b.Index));
      return 0.5 * (double(a.Value) + double(b.Value) + slope * lengthVoxels) >= this->MinimumIso;
    }
    if (!a.CutsKnown || !b.CutsKnown)
    {
      return false;
    }
    for (size_t n = 0; n < this->ActiveCuts.size(); ++n)
    {
      const double da = a.Distance[n];
      const double db = b.Distance[n];
      if ((da >= 0.0) == (db >= 0.0) && std::abs(da) + std::abs(db) < lengthMillimetres)
      {
        return true;
      }
    }
    return false;
  }

  void Shade(const float color[3], const double normal[3], const double view[3], float out[3]) const
  {
    // Headlight: the light comes from the eye, so the half vector is the view.
    const double cosine = std::abs(vtkMath::Dot(normal, view));
    const double specular = this->Specular * std::pow(cosine, this->SpecularPower);
    for (int c = 0; c < 3; ++c)
    {
      out[c] = static_cast<float>(std::min(1.0, color[c] * (this->Ambient + this->Diffuse * cosine) + specular));
    }
  }

  double MeasureThickness(const double index[3], const double normalWorld[3]) const;
  void CastRay(int x, int y, const double* opaqueLimit);
};

//------------------------------------------------------------------------------
double vtkVolumeCutRayCaster::Internals::MeasureThickness(const double index[3], const double normalWorld[3]) const
{
  // March inward (against the outward normal) until the visible material
  // ends, in steps of a quarter voxel, up to the threshold.
  double inward[3] = { -normalWorld[0], -normalWorld[1], -normalWorld[2] };
  double inwardIndex[3];
  TransformVector(this->WorldToIJK, inward, inwardIndex);
  const double voxelsPerMillimetre = vtkMath::Norm(inwardIndex);
  if (voxelsPerMillimetre <= 0.0)
  {
    return this->ThinBoneThickness;
  }
  const double step = 0.25 / voxelsPerMillimetre;
  for (double travelled = step; travelled < this->ThinBoneThickness; travelled += step)
  {
    Sample s;
    for (int axis = 0; axis < 3; ++axis)
    {
      s.Index[axis] = index[axis] + travelled * inwardIndex[axis];
      if (s.Index[axis] < 0.0 || s.Index[axis] > this->Dimensions[axis] - 1)
      {
        return this->ThinBoneThickness;
      }
    }
    // Bone is bone whatever its segment (cortical over trabecular): the wall
    // ends where no visible material is left.
    this->EvaluateObject(s);
    if (!this->Visible(s))
    {
      return travelled;
    }
  }
  return this->ThinBoneThickness;
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::Internals::CastRay(int x, int y, const double* opaqueLimit)
{
  const vtkIdType pixel = static_cast<vtkIdType>(y) * this->Width + x;
  float* color = &this->Color[4 * pixel];
  std::fill(color, color + 4, 0.f);
  this->Depth[pixel] = 1.f;
  std::fill(&this->Normal[3 * pixel], &this->Normal[3 * pixel] + 3, 0.f);
  this->Source[pixel] = SourceNone;

  // The ray through the pixel's centre, from the near to the far plane.
  const double ndcX = 2.0 * (x + 0.5) / this->Width - 1.0;
  const double ndcY = 2.0 * (y + 0.5) / this->Height - 1.0;
  const double nearH[4] = { ndcX, ndcY, -1.0, 1.0 };
  const double farH[4] = { ndcX, ndcY, 1.0, 1.0 };
  double nearW[4];
  double farW[4];
  Multiply4(this->NDCToWorld, nearH, nearW);
  Multiply4(this->NDCToWorld, farH, farW);
  double originWorld[3];
  double directionWorld[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    originWorld[axis] = nearW[axis] / nearW[3];
    directionWorld[axis] = farW[axis] / farW[3] - originWorld[axis];
  }
  double tEnd = vtkMath::Normalize(directionWorld);
  if (opaqueLimit)
  {
    tEnd = std::min(tEnd, *opaqueLimit);
  }
  const double view[3] = { -directionWorld[0], -directionWorld[1], -directionWorld[2] };

  double o[3];
  double d[3];
  TransformPoint(this->WorldToIJK, originWorld, o);
  TransformVector(this->WorldToIJK, directionWorld, d);

  // Entry and exit: the volume's box (sample domain), then the clip planes.
  double tStart = 0.0;
  int entrySource = SourceClipPlane; // the near plane, when the eye is inside
  double entryNormal[3] = { view[0], view[1], view[2] };
  for (int axis = 0; axis < 3; ++axis)
  {
    const double lo = 0.0;
    const double hi = this->Dimensions[axis] - 1.0;
    if (std::abs(d[axis]) < 1e-15)
    {
      if (o[axis] < lo || o[axis] > hi)
      {
        return;
      }
      continue;
    }
    double t0 = (lo - o[axis]) / d[axis];
    double t1 = (hi - o[axis]) / d[axis];
    const bool forward = t0 < t1;
    if (!forward)
    {
      std::swap(t0, t1);
    }
    if (t0 > tStart)
    {
      tStart = t0;
      entrySource = SourceVolumeBox;
      double faceNormal[3] = { 0.0, 0.0, 0.0 };
      faceNormal[axis] = forward ? -1.0 : 1.0;
      TransformVector(this->NormalMatrix4(), faceNormal, entryNormal);
      vtkMath::Normalize(entryNormal);
    }
    tEnd = std::min(tEnd, t1);
  }
  for (const PlaneEquation& plane : this->PlaneEquations)
  {
    const double f0 = vtkMath::Dot(plane.Normal, originWorld) + plane.Offset;
    const double fd = vtkMath::Dot(plane.Normal, directionWorld);
    if (std::abs(fd) < 1e-15)
    {
      if (f0 < 0.0)
      {
        return;
      }
      continue;
    }
    const double t = -f0 / fd;
    if (fd > 0.0)
    {
      if (t > tStart)
      {
        tStart = t;
        entrySource = SourceClipPlane;
        for (int axis = 0; axis < 3; ++axis)
        {
          entryNormal[axis] = -plane.Normal[axis];
        }
        vtkMath::Normalize(entryNormal);
      }
    }
    else
    {
      tEnd = std::min(tEnd, t);
    }
  }
  if (!(tStart < tEnd))
  {
    return;
  }

  // World length of one voxel step along this ray.
  const double voxelsPerMillimetre = vtkMath::Norm(d);
  const double step = this->SampleDistance / voxelsPerMillimetre;
  const bool composite = this->BlendMode == CompositeBlend;

  int layers = 0;
  bool first = true;
  auto record = [&](double t, int source, const double normal[3], const float rgb[3], float alpha, float minimumAlpha) {
    const float remaining = 1.f - color[3];
    for (int c = 0; c < 3; ++c)
    {
      color[c] += remaining * alpha * rgb[c];
    }
    color[3] += remaining * alpha;
    if (first && alpha >= minimumAlpha)
    {
      first = false;
      double world[4] = { originWorld[0] + t * directionWorld[0], originWorld[1] + t * directionWorld[1],
        originWorld[2] + t * directionWorld[2], 1.0 };
      double clip[4];
      Multiply4(this->WorldToNDC, world, clip);
      this->Depth[pixel] = static_cast<float>(std::min(1.0, std::max(0.0, 0.5 * clip[2] / clip[3] + 0.5)));
      for (int axis = 0; axis < 3; ++axis)
      {
        this->Normal[3 * pixel + axis] = static_cast<float>(normal[axis]);
      }
      this->Source[pixel] = source;
    }
  };

  // A visible piece starts at a border: shade it with that border's normal.
  auto enter = [&](const Sample& piece, double t, int source) -> bool {
    double normal[3];
    double index[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      index[axis] = o[axis] + t * d[axis];
    }
    if (source == SourceObject)
    {
      this->ObjectNormal(piece.Object, index, normal);
    }
    else if (source >= SourceCutField)
    {
      double world[3];
      this->WorldPoint(index, world);
      this->CutNormal(source - SourceCutField, world, normal);
    }
    else
    {
      std::copy(entryNormal, entryNormal + 3, normal);
    }
    if (vtkMath::Dot(normal, view) < 0.0)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        normal[axis] = -normal[axis];
      }
    }
    const SegmentStyle& style = this->Styles[piece.Object];
    float rgb[3];
    this->Shade(style.Color, normal, view, rgb);
    float alpha = style.Opacity;
    if (this->ThinBone)
    {
      const double thickness = this->MeasureThickness(index, normal);
      if (thickness < this->ThinBoneThickness)
      {
        const float f = static_cast<float>(thickness / this->ThinBoneThickness);
        const float red[3] = { 1.f, 0.12f, 0.08f };
        for (int c = 0; c < 3; ++c)
        {
          rgb[c] = red[c] * (1.f - f) + rgb[c] * f;
        }
        alpha *= 0.3f + 0.7f * f;
      }
    }
    record(t, source, normal, rgb, alpha, 0.f);
    return color[3] >= OpaqueAlpha || ++layers >= MaximumLayers;
  };

  // Iso-surface mode: the borders between two samples, found one volume at a
  // time, and the first visible piece between them. Where a border could
  // hide between the samples (a grazing ray through a thin sliver of an
  // object or of a cut), the interval is halved first.
  // Every border of every volume between two samples, in ray order: the
  // object's (iso-surface mode) and each cut field's.
  auto findBorders = [&](const Sample& a, const Sample& b, bool withObject, Border* borders) -> int {
    int count = 0;
    if (withObject && a.Object != b.Object)
    {
      borders[count++] = { this->BisectObject(o, d, a, b), SourceObject };
    }
    if (a.CutsKnown && b.CutsKnown)
    {
      for (size_t n = 0; n < this->ActiveCuts.size(); ++n)
      {
        if ((a.Distance[n] < 0.0) != (b.Distance[n] < 0.0))
        {
          borders[count++] = { this->BisectCut(static_cast<int>(n), o, d, a, b), SourceCutField + static_cast<int>(n) };
        }
      }
    }
    std::sort(borders, borders + count, [](const Border& l, const Border& r) { return l.T < r.T; });
    return count;
  };

  bool insideVisible = false;
  auto surfaceInterval = [&](auto& self, Sample& a, Sample& b, int depth) -> bool {
    if (a.Object != 0 || b.Object != 0)
    {
      this->EvaluateCuts(a);
      this->EvaluateCuts(b);
    }
    if (depth == 0 && this->MayHideBorders(a, b, (b.T - a.T) * voxelsPerMillimetre, b.T - a.T))
    {
      // Sub-steps of 1/2^MaximumRefinements of the interval, as the GPU does.
      constexpr int parts = 1 << MaximumRefinements;
      Sample from = a;
      for (int part = 1; part <= parts; ++part)
      {
        Sample to = part == parts ? b : this->At(o, d, a.T + (b.T - a.T) * part / parts);
        if (part < parts)
        {
          this->EvaluateObject(to);
        }
        if (self(self, from, to, 1))
        {
          return true;
        }
        from = to;
      }
      b = from;
      return false;
    }
    Border borders[MaximumCutFields + 1];
    const int count = findBorders(a, b, true, borders);
    for (int border = 0; border < count; ++border)
    {
      const double end = border + 1 < count ? borders[border + 1].T : b.T;
      Sample mid = this->At(o, d, 0.5 * (borders[border].T + end));
      this->EvaluateObject(mid);
      const bool visible = this->Visible(mid);
      if (visible && !insideVisible && enter(mid, borders[border].T, borders[border].Source))
      {
        return true;
      }
      insideVisible = visible;
    }
    return false;
  };

  Sample a = this->At(o, d, tStart);
  this->EvaluateObject(a);
  if (composite)
  {
    this->EvaluateCuts(a);
  }
  insideVisible = !composite && this->Visible(a);
  if (insideVisible && enter(a, tStart, entrySource))
  {
    return;
  }
  int lastCutBorder = -1; // composite: the cut whose border a piece starts at

  while (a.T < tEnd)
  {
    if (a.Object == 0 && !composite && this->BlockEmpty(a.Index))
    {
      // Nothing visible in this block: jump to where the ray leaves it.
      const double exit = std::min(this->BlockExit(a.Index, d, a.T) + 1e-9, tEnd);
      if (exit > a.T + step)
      {
        a = this->At(o, d, exit);
        this->EvaluateObject(a);
        insideVisible = this->Visible(a);
        if (insideVisible && enter(a, a.T, SourceObject))
        {
          return;
        }
        continue;
      }
    }
    else if (composite && this->BlockEmpty(a.Index))
    {
      const double exit = std::min(this->BlockExit(a.Index, d, a.T) + 1e-9, tEnd);
      if (exit > a.T + step)
      {
        a = this->At(o, d, exit);
        this->EvaluateObject(a);
        this->EvaluateCuts(a);
        lastCutBorder = -1;
        continue;
      }
    }

    Sample b = this->At(o, d, std::min(a.T + step, tEnd));
    this->EvaluateObject(b);
    if (!composite)
    {
      if (surfaceInterval(surfaceInterval, a, b, 0))
      {
        return;
      }
      a = b;
      continue;
    }
    this->EvaluateCuts(a);
    this->EvaluateCuts(b);

    // Every cut's border between a and b.
    Border borders[MaximumCutFields + 1];
    const int count = findBorders(a, b, false, borders);

    // Front-to-back compositing of the pieces outside every cut.
    double start = a.T;
    for (int piece = 0; piece <= count; ++piece)
    {
      const double end = piece < count ? borders[piece].T : b.T;
      if (end > start)
      {
        Sample mid = this->At(o, d, 0.5 * (start + end));
        this->EvaluateObject(mid);
        this->EvaluateCuts(mid);
        if (!this->Removed(mid))
        {
          float rgb[3];
          float opacity;
          this->LookUp(mid.Value, rgb, opacity);
          if (opacity > 0.f)
          {
            const float alpha = 1.f - std::pow(1.f - std::min(opacity, 0.9999f), static_cast<float>((end - start) / this->UnitDistance));
            double normal[3];
            int source = SourceObject;
            if (lastCutBorder >= 0)
            {
              // The first piece after a cut border shows the cut surface.
              double world[3];
              this->WorldPoint(mid.Index, world);
              this->CutNormal(lastCutBorder, world, normal);
              source = SourceCutField + lastCutBorder;
            }
            else
            {
              // Composite mode shades with the CT's gradient whatever the labels.
              double gradient[3];
              for (int axis = 0; axis < 3; ++axis)
              {
                double plus[3] = { mid.Index[0], mid.Index[1], mid.Index[2] };
                double minus[3] = { mid.Index[0], mid.Index[1], mid.Index[2] };
                plus[axis] += this->GradientStep;
                minus[axis] -= this->GradientStep;
                gradient[axis] = double(this->Interpolate(minus)) - double(this->Interpolate(plus));
              }
              TransformVector(this->NormalMatrix4(), gradient, normal);
              vtkMath::Normalize(normal);
            }
            float shaded[3];
            this->Shade(rgb, normal, view, shaded);
            // Depth and normal belong to the first piece that clearly shows.
            // (a cut surface is a surface: its first piece always counts).
            record(start, source, normal, shaded, alpha, lastCutBorder >= 0 ? 0.f : 0.02f);
            if (color[3] >= OpaqueAlpha)
            {
              return;
            }
          }
          lastCutBorder = -1;
        }
      }
      if (piece < count)
      {
        lastCutBorder = borders[piece].Source >= SourceCutField ? borders[piece].Source - SourceCutField : -1;
      }
      start = end;
    }
    a = b;
  }
}

//------------------------------------------------------------------------------
vtkVolumeCutRayCaster::vtkVolumeCutRayCaster()
  : Impl(new Internals)
{
  this->Impl->Styles.resize(2);
}

//------------------------------------------------------------------------------
vtkVolumeCutRayCaster::~vtkVolumeCutRayCaster() = default;

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::SetAnatomy(vtkImageData* intensities, vtkMatrix4x4* ijkToWorld)
{
  this->Impl->Anatomy = intensities;
  if (ijkToWorld)
  {
    this->Impl->AnatomyMatrix = vtkSmartPointer<vtkMatrix4x4>::New();
    this->Impl->AnatomyMatrix->DeepCopy(ijkToWorld);
  }
  else
  {
    this->Impl->AnatomyMatrix = nullptr;
  }
  this->Impl->AnatomyCopyTime = 0;
  this->Modified();
}

//------------------------------------------------------------------------------
vtkImageData* vtkVolumeCutRayCaster::GetAnatomy()
{
  return this->Impl->Anatomy;
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::SetLabelMap(vtkImageData* labels)
{
  this->Impl->LabelMap = labels;
  this->Impl->LabelCopyTime = 0;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::SetSegmentFraction(int label, vtkImageData* fraction, double valueAtZero, double valueAtOne)
{
  if (label < 1 || label > 65535 || !(std::abs(valueAtOne - valueAtZero) > 0.0) || !std::isfinite(valueAtZero) ||
    !std::isfinite(valueAtOne))
  {
    vtkErrorMacro("SetSegmentFraction: needs a label in 1..65535 and two different finite values for fractions 0 and 1");
    return;
  }
  if (!fraction)
  {
    if (this->Impl->FractionInputs.erase(label) == 0)
    {
      return; // nothing to remove: the image stays valid for localized updates
    }
  }
  else if (this->Impl->FractionInputs.size() >= MaximumFractions && !this->Impl->FractionInputs.count(label))
  {
    vtkErrorMacro("SetSegmentFraction: at most " << MaximumFractions << " segments can have fractional labelmaps");
    return;
  }
  else
  {
    this->Impl->FractionInputs[label] = { fraction, valueAtZero, valueAtOne };
  }
  this->Impl->FractionCopyTime = 0;
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkVolumeCutRayCaster::GetNumberOfSegmentFractions() const
{
  return static_cast<int>(this->Impl->FractionInputs.size());
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::SetSegmentAppearance(int label, const double color[3], double opacity, double isoValue)
{
  if (label < 1 || label > 65535 || !color)
  {
    vtkErrorMacro("SetSegmentAppearance: label " << label << " is not in 1..65535");
    return;
  }
  if (this->Impl->DefaultStyles)
  {
    this->Impl->Styles.assign(2, SegmentStyle());
    this->Impl->DefaultStyles = false;
  }
  if (static_cast<int>(this->Impl->Styles.size()) <= label)
  {
    this->Impl->Styles.resize(label + 1);
  }
  SegmentStyle& style = this->Impl->Styles[label];
  for (int c = 0; c < 3; ++c)
  {
    style.Color[c] = static_cast<float>(std::min(1.0, std::max(0.0, color[c])));
  }
  style.Opacity = std::isfinite(opacity) ? static_cast<float>(std::min(1.0, std::max(0.0, opacity))) : 0.f;
  style.Shape = std::isnan(isoValue);
  style.Iso = style.Shape ? 0.f : static_cast<float>(isoValue);
  style.Defined = true;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::RemoveAllSegmentAppearances()
{
  this->Impl->Styles.assign(2, SegmentStyle());
  this->Impl->DefaultStyles = true;
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkVolumeCutRayCaster::GetNumberOfSegmentAppearances() const
{
  return static_cast<int>(
    std::count_if(this->Impl->Styles.begin(), this->Impl->Styles.end(), [](const SegmentStyle& style) { return style.Defined; }));
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::AddCutField(vtkVolumeCutField* field)
{
  if (!field)
  {
    return;
  }
  if (static_cast<int>(this->Impl->Cuts.size()) >= MaximumCutFields)
  {
    vtkErrorMacro("AddCutField: at most " << MaximumCutFields << " cut fields can be rendered together");
    return;
  }
  CutEntry entry;
  entry.Field = field;
  this->Impl->Cuts.push_back(entry);
  this->Impl->ImageValid = false;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::RemoveAllCutFields()
{
  this->Impl->Cuts.clear();
  this->Impl->ImageValid = false;
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkVolumeCutRayCaster::GetNumberOfCutFields() const
{
  return static_cast<int>(this->Impl->Cuts.size());
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::SetClippingPlanes(vtkPlaneCollection* planes)
{
  this->Impl->Planes = planes;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::SetTransferFunctions(vtkColorTransferFunction* color, vtkPiecewiseFunction* opacity)
{
  this->Impl->ColorFunction = color;
  this->Impl->OpacityFunction = opacity;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::InvalidateImage()
{
  this->Impl->ImageValid = false;
}

//------------------------------------------------------------------------------
const float* vtkVolumeCutRayCaster::GetColorBuffer() const
{
  return this->Impl->Color.empty() ? nullptr : this->Impl->Color.data();
}
const float* vtkVolumeCutRayCaster::GetDepthBuffer() const
{
  return this->Impl->Depth.empty() ? nullptr : this->Impl->Depth.data();
}
const float* vtkVolumeCutRayCaster::GetNormalBuffer() const
{
  return this->Impl->Normal.empty() ? nullptr : this->Impl->Normal.data();
}
const int* vtkVolumeCutRayCaster::GetSourceBuffer() const
{
  return this->Impl->Source.empty() ? nullptr : this->Impl->Source.data();
}

namespace
{
template <typename ArrayType, typename ValueType>
void FillImage(vtkImageData* image, int width, int height, int components, const std::vector<ValueType>& values)
{
  if (!image)
  {
    return;
  }
  image->Initialize();
  image->SetDimensions(std::max(width, 0), std::max(height, 0), 1);
  vtkNew<ArrayType> array;
  array->SetNumberOfComponents(components);
  array->SetNumberOfTuples(static_cast<vtkIdType>(values.size()) / components);
  std::copy(values.begin(), values.end(), array->GetPointer(0));
  image->GetPointData()->SetScalars(array);
}
}

void vtkVolumeCutRayCaster::GetColorImage(vtkImageData* image) const
{
  FillImage<vtkFloatArray>(image, this->Impl->Width, this->Impl->Height, 4, this->Impl->Color);
}
void vtkVolumeCutRayCaster::GetDepthImage(vtkImageData* image) const
{
  FillImage<vtkFloatArray>(image, this->Impl->Width, this->Impl->Height, 1, this->Impl->Depth);
}
void vtkVolumeCutRayCaster::GetNormalImage(vtkImageData* image) const
{
  FillImage<vtkFloatArray>(image, this->Impl->Width, this->Impl->Height, 3, this->Impl->Normal);
}
void vtkVolumeCutRayCaster::GetSourceImage(vtkImageData* image) const
{
  FillImage<vtkIntArray>(image, this->Impl->Width, this->Impl->Height, 1, this->Impl->Source);
}

namespace
{
template <typename T>
void CopyFirstComponent(const T* in, int stride, vtkIdType count, float* out)
{
  for (vtkIdType n = 0; n < count; ++n)
  {
    out[n] = static_cast<float>(in[n * stride]);
  }
}

bool SameGeometry(vtkImageData* a, vtkImageData* b)
{
  int da[3];
  int db[3];
  a->GetDimensions(da);
  b->GetDimensions(db);
  return da[0] == db[0] && da[1] == db[1] && da[2] == db[2];
}
}

//------------------------------------------------------------------------------
bool vtkVolumeCutRayCaster::PrepareScene(bool& sceneChanged)
{
  Internals& impl = *this->Impl;
  vtkImageData* anatomy = impl.Anatomy;
  vtkDataArray* scalars = anatomy ? anatomy->GetPointData()->GetScalars() : nullptr;
  if (!scalars)
  {
    vtkErrorMacro("Render: no anatomy intensities");
    return false;
  }
  int dims[3];
  anatomy->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
  {
    vtkErrorMacro("Render: the anatomy needs at least 2 voxels along each axis, not " << dims[0] << " x " << dims[1] << " x " << dims[2]);
    return false;
  }

  // Geometry and intensities, copied when they change.
  sceneChanged = false;
  if (impl.AnatomyCopyTime < anatomy->GetMTime() || impl.AnatomyCopyTime < scalars->GetMTime() ||
    (impl.AnatomyMatrix && impl.AnatomyCopyTime < impl.AnatomyMatrix->GetMTime()))
  {
    vtkNew<vtkMatrix4x4> ijkToWorld;
    if (impl.AnatomyMatrix)
    {
      ijkToWorld->DeepCopy(impl.AnatomyMatrix);
    }
    else
    {
      ijkToWorld->DeepCopy(anatomy->GetIndexToPhysicalMatrix());
    }
    if (!(std::abs(ijkToWorld->Determinant()) > 1e-12))
    {
      vtkErrorMacro("Render: the anatomy's IJK-to-world matrix is not invertible");
      return false;
    }
    vtkNew<vtkMatrix4x4> worldToIJK;
    vtkMatrix4x4::Invert(ijkToWorld, worldToIJK);
    std::copy(&ijkToWorld->Element[0][0], &ijkToWorld->Element[0][0] + 16, impl.IJKToWorld);
    std::copy(&worldToIJK->Element[0][0], &worldToIJK->Element[0][0] + 16, impl.WorldToIJK);
    // Normals: the transpose of world-to-IJK's linear part maps IJK gradients to world.
    std::fill(impl.NormalMatrix4Storage, impl.NormalMatrix4Storage + 16, 0.0);
    for (int row = 0; row < 3; ++row)
    {
      for (int column = 0; column < 3; ++column)
      {
        impl.NormalMatrix4Storage[4 * row + column] = worldToIJK->GetElement(column, row);
      }
    }
    impl.NormalMatrix4Storage[15] = 1.0;
    const vtkIdType count = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
    impl.Values.resize(count);
    const int stride = scalars->GetNumberOfComponents();
    switch (scalars->GetDataType())
    {
      vtkTemplateMacro(CopyFirstComponent(static_cast<const VTK_TT*>(scalars->GetVoidPointer(0)), stride, count, impl.Values.data()));
      default:
        vtkErrorMacro("Render: unsupported anatomy scalar type");
        return false;
    }
    std::copy(dims, dims + 3, impl.Dimensions);
    impl.AnatomyCopyTime = std::max({ anatomy->GetMTime(), scalars->GetMTime(), impl.AnatomyMatrix ? impl.AnatomyMatrix->GetMTime() : 0 });
    impl.LabelCopyTime = 0;
    impl.BlockTime = 0;
    for (CutEntry& entry : impl.Cuts)
    {
      entry.Reported = false;
    }
    sceneChanged = true;
  }

  vtkImageData* labelMap = impl.LabelMap;
  if (!labelMap)
  {
    if (!impl.Labels.empty())
    {
      impl.Labels.clear();
      ++impl.LabelVersion;
      sceneChanged = true;
      impl.BlockTime = 0;
    }
  }
  else if (impl.LabelCopyTime < labelMap->GetMTime() || !labelMap->GetPointData()->GetScalars() ||
    impl.LabelCopyTime < labelMap->GetPointData()->GetScalars()->GetMTime())
  {
    vtkDataArray* labelScalars = labelMap->GetPointData()->GetScalars();
    if (!labelScalars || !SameGeometry(labelMap, anatomy))
    {
      vtkErrorMacro("Render: the label map must have the anatomy's dimensions; rendering without labels");
      impl.Labels.clear();
    }
    else
    {
      const vtkIdType count = labelScalars->GetNumberOfTuples();
      impl.Labels.resize(count);
      bool outOfRange = false;
      for (vtkIdType n = 0; n < count; ++n)
      {
        const double label = labelScalars->GetComponent(n, 0);
        outOfRange |= !(label >= 0.0 && label <= 65535.0);
        impl.Labels[n] = static_cast<uint16_t>(std::min(65535.0, std::max(0.0, std::isfinite(label) ? label : 0.0)));
      }
      if (outOfRange)
      {
        vtkWarningMacro("Render: label values outside 0..65535 were clamped");
      }
    }
    impl.LabelCopyTime = std::max(labelMap->GetMTime(), labelScalars ? labelScalars->GetMTime() : 0);
    ++impl.LabelVersion;
    impl.BlockTime = 0;
    sceneChanged = true;
  }

  // Fractional labelmaps, copied to floats 0..1 when any of them changed.
  vtkMTimeType fractionTime = 0;
  for (const auto& entry : impl.FractionInputs)
  {
    vtkImageData* image = entry.second.Image;
    fractionTime = std::max({ fractionTime, image->GetMTime(),
      image->GetPointData()->GetScalars() ? image->GetPointData()->GetScalars()->GetMTime() : vtkMTimeType(0) });
  }
  if (fractionTime > impl.FractionCopyTime || impl.FractionInputs.size() != impl.Fractions.size() || sceneChanged)
  {
    impl.Fractions.clear();
    for (const auto& entry : impl.FractionInputs)
    {
      vtkImageData* image = entry.second.Image;
      vtkDataArray* values = image->GetPointData()->GetScalars();
      if (!values || !SameGeometry(image, anatomy))
      {
        vtkErrorMacro("Render: the fractional labelmap of segment " << entry.first << " must have the anatomy's dimensions; it is not shown");
        continue;
      }
      Internals::FractionVolume fraction;
      fraction.Label = entry.first;
      fraction.Values.resize(values->GetNumberOfTuples());
      const double v0 = entry.second.ValueAtZero;
      const double scale = 1.0 / (entry.second.ValueAtOne - entry.second.ValueAtZero);
      for (vtkIdType n = 0; n < values->GetNumberOfTuples(); ++n)
      {
        const double f = (values->GetComponent(n, 0) - v0) * scale;
        fraction.Values[n] = std::isfinite(f) ? static_cast<float>(std::min(1.0, std::max(0.0, f))) : 0.f;
      }
      impl.Fractions.push_back(std::move(fraction));
    }
    impl.FractionCopyTime = std::max(fractionTime, vtkMTimeType(1));
    ++impl.LabelVersion;
    impl.BlockTime = 0;
    sceneChanged = true;
  }

  // Segment 1 follows IsoValue until appearances are given.
  if (impl.DefaultStyles)
  {
    SegmentStyle& bone = impl.Styles[1];
    bone.Color[0] = 0.95f;
    bone.Color[1] = 0.92f;
    bone.Color[2] = 0.84f;
    bone.Opacity = 1.f;
    bone.Iso = static_cast<float>(this->IsoValue);
    bone.Shape = false;
  }
  if (impl.Styles.size() < 2)
  {
    impl.Styles.resize(2);
  }

  // Transfer functions (composite mode).
  if (this->BlendMode == CompositeBlend)
  {
    if (!impl.ColorFunction || !impl.OpacityFunction)
    {
      vtkErrorMacro("Render: the composite mode needs colour and opacity transfer functions");
      return false;
    }
    double range[2];
    impl.OpacityFunction->GetRange(range);
    double colorRange[2];
    impl.ColorFunction->GetRange(colorRange);
    impl.TableRange[0] = std::min(range[0], colorRange[0]);
    impl.TableRange[1] = std::max(range[1], colorRange[1]);
    impl.ColorTable.resize(3 * TransferTableSize);
    impl.OpacityTable.resize(TransferTableSize);
    impl.ColorFunction->GetTable(impl.TableRange[0], impl.TableRange[1], TransferTableSize, impl.ColorTable.data());
    impl.OpacityFunction->GetTable(impl.TableRange[0], impl.TableRange[1], TransferTableSize, impl.OpacityTable.data());
  }

  impl.AnyIsoSegment = false;
  impl.MinimumIso = std::numeric_limits<double>::infinity();
  for (size_t label = 1; label < impl.Styles.size(); ++label)
  {
    const SegmentStyle& style = impl.Styles[label];
    if (style.Opacity > 0.f && !style.Shape && (label == 1 || impl.HasSegments()))
    {
      impl.AnyIsoSegment = true;
      impl.MinimumIso = std::min(impl.MinimumIso, double(style.Iso));
    }
  }

  // What the scene's look depends on besides the cuts.
  vtkMTimeType sceneTime = this->GetMTime();
  if (impl.Planes)
  {
    sceneTime = std::max(sceneTime, impl.Planes->GetMTime());
    impl.Planes->InitTraversal();
    while (vtkPlane* plane = impl.Planes->GetNextItem())
    {
      sceneTime = std::max(sceneTime, plane->GetMTime());
    }
  }
  if (this->BlendMode == CompositeBlend)
  {
    sceneTime = std::max({ sceneTime, impl.ColorFunction->GetMTime(), impl.OpacityFunction->GetMTime() });
  }
  sceneChanged |= sceneTime != impl.SceneTime;
  impl.SceneTime = sceneTime;

  // Empty-space blocks.
  if (impl.BlockTime == 0 || sceneChanged)
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      impl.BlockDimensions[axis] = (dims[axis] - 1 + BlockSize - 1) / BlockSize;
    }
    const vtkIdType blockCount = static_cast<vtkIdType>(impl.BlockDimensions[0]) * impl.BlockDimensions[1] * impl.BlockDimensions[2];
    impl.BlockOccupied.assign(blockCount, 0);
    impl.BlockLipschitz.assign(blockCount, 0.f);
    const bool composite = this->BlendMode == CompositeBlend;
    ParallelFor(this->MaximumNumberOfThreads, impl.BlockDimensions[2], [&](vtkIdType beginZ, vtkIdType endZ) {
      for (vtkIdType bz = beginZ; bz < endZ; ++bz)
      {
        for (int by = 0; by < impl.BlockDimensions[1]; ++by)
        {
          for (int bx = 0; bx < impl.BlockDimensions[0]; ++bx)
          {
            const vtkIdType block = bx + impl.BlockDimensions[0] * (by + static_cast<vtkIdType>(impl.BlockDimensions[1]) * bz);
            float lo = std::numeric_limits<float>::infinity();
            float hi = -std::numeric_limits<float>::infinity();
            bool occupied = false;
            float slope[3] = { 0.f, 0.f, 0.f };
            // Cells of the block and their far corners (one voxel of apron).
            for (int k = int(bz) * BlockSize; k <= std::min((int(bz) + 1) * BlockSize, dims[2] - 1); ++k)
            {
              for (int j = by * BlockSize; j <= std::min((by + 1) * BlockSize, dims[1] - 1); ++j)
              {
                const vtkIdType row = static_cast<vtkIdType>(dims[0]) * (j + static_cast<vtkIdType>(dims[1]) * k);
                for (int i = bx * BlockSize; i <= std::min((bx + 1) * BlockSize, dims[0] - 1); ++i)
                {
                  const float v = impl.Values[row + i];
                  lo = v < lo ? v : lo;
                  hi = v > hi ? v : hi;
                  // Largest change to a neighbour along each axis bounds the
                  // trilinear gradient's components.
                  if (i + 1 < dims[0])
                  {
                    slope[0] = std::max(slope[0], std::abs(impl.Values[row + i + 1] - v));
                  }
                  if (j + 1 < dims[1])
                  {
                    slope[1] = std::max(slope[1], std::abs(impl.Values[row + dims[0] + i] - v));
                  }
                  if (k + 1 < dims[2])
                  {
                    slope[2] = std::max(slope[2], std::abs(impl.Values[row + static_cast<vtkIdType>(dims[0]) * dims[1] + i] - v));
                  }
                }
              }
            }
            // Labels: a visible segment whose surface could lie in the block.
            if (!composite && !impl.Labels.empty())
            {
              for (int k = int(bz) * BlockSize; k <= std::min((int(bz) + 1) * BlockSize, dims[2] - 1) && !occupied; ++k)
              {
                for (int j = by * BlockSize; j <= std::min((by + 1) * BlockSize, dims[1] - 1) && !occupied; ++j)
                {
                  const vtkIdType row = static_cast<vtkIdType>(dims[0]) * (j + static_cast<vtkIdType>(dims[1]) * k);
                  for (int i = bx * BlockSize; i <= std::min((bx + 1) * BlockSize, dims[0] - 1); ++i)
                  {
                    const int label = impl.Labels[row + i];
                    if (label > 0 && label < static_cast<int>(impl.Styles.size()))
                    {
                      const SegmentStyle& style = impl.Styles[label];
                      if (style.Opacity > 0.f && (style.Shape || hi >= style.Iso))
                      {
                        occupied = true;
                        break;
                      }
                    }
                  }
                }
              }
            }
            if (!composite && !occupied)
            {
              // Fractional segments: any voxel of the block partly inside a shown one.
              for (const Internals::FractionVolume& fraction : impl.Fractions)
              {
                const SegmentStyle& style =
                  fraction.Label < static_cast<int>(impl.Styles.size()) ? impl.Styles[fraction.Label] : impl.Styles[0];
                if (occupied || style.Opacity <= 0.f || (!style.Shape && hi < style.Iso))
                {
                  continue;
                }
                for (int k = int(bz) * BlockSize; k <= std::min((int(bz) + 1) * BlockSize, dims[2] - 1) && !occupied; ++k)
                {
                  for (int j = by * BlockSize; j <= std::min((by + 1) * BlockSize, dims[1] - 1) && !occupied; ++j)
                  {
                    const vtkIdType row = static_cast<vtkIdType>(dims[0]) * (j + static_cast<vtkIdType>(dims[1]) * k);
                    for (int i = bx * BlockSize; i <= std::min((bx + 1) * BlockSize, dims[0] - 1) && !occupied; ++i)
                    {
                      occupied = fraction.Values[row + i] > 0.f;
                    }
                  }
                }
              }
            }
            if (!composite && !impl.HasSegments())
            {
              occupied = impl.Styles[1].Opacity > 0.f && hi >= impl.Styles[1].Iso;
            }
            else if (composite)
            {
              // Any opacity over the block's value range.
              const double span = impl.TableRange[1] - impl.TableRange[0];
              const int first = span > 0.0
                ? std::max(0, static_cast<int>(std::floor((lo - impl.TableRange[0]) / span * (TransferTableSize - 1))))
                : 0;
              const int last = span > 0.0
                ? std::min(TransferTableSize - 1, static_cast<int>(std::ceil((hi - impl.TableRange[0]) / span * (TransferTableSize - 1))))
                : TransferTableSize - 1;
              for (int n = std::min(first, TransferTableSize - 1); n <= last && !occupied; ++n)
              {
                occupied = impl.OpacityTable[n] > 0.f;
              }
            }
            impl.BlockOccupied[block] = occupied ? 1 : 0;
            // NaN voxels make the bound infinite: such blocks are always refined.
            const float lipschitz = std::sqrt(slope[0] * slope[0] + slope[1] * slope[1] + slope[2] * slope[2]);
            impl.BlockLipschitz[block] = std::isfinite(lipschitz) ? lipschitz : std::numeric_limits<float>::infinity();
          }
        }
      }
    });
    impl.BlockTime = sceneTime;
  }

  // Cut fields: usable when initialised on the anatomy's grid.
  impl.ActiveCuts.clear();
  for (size_t n = 0; n < impl.Cuts.size(); ++n)
  {
    CutEntry& entry = impl.Cuts[n];
    vtkVolumeCutField* field = entry.Field;
    const int factor = field->GetSubVoxelFactor();
    bool usable = factor > 0;
    if (usable)
    {
      const int* fieldDims = field->GetDimensions();
      usable = fieldDims[0] == dims[0] * factor && fieldDims[1] == dims[1] * factor && fieldDims[2] == dims[2] * factor;
    }
    if (usable)
    {
      vtkNew<vtkMatrix4x4> subToWorld;
      field->GetSubVoxelIJKToRAS(subToWorld);
      // Sub-voxel s lies at anatomy index (s + 0.5) / f - 0.5.
      double tolerance = 0.0;
      for (int axis = 0; axis < 3; ++axis)
      {
        double column[3];
        const double unit[3] = { axis == 0 ? 1.0 : 0.0, axis == 1 ? 1.0 : 0.0, axis == 2 ? 1.0 : 0.0 };
        TransformVector(impl.IJKToWorld, unit, column);
        tolerance = std::max(tolerance, 1e-4 * vtkMath::Norm(column));
      }
      for (int corner = 0; corner < 4 && usable; ++corner)
      {
        const double sub[3] = { corner == 1 ? 10.0 : 0.0, corner == 2 ? 10.0 : 0.0, corner == 3 ? 10.0 : 0.0 };
        double h[4] = { sub[0], sub[1], sub[2], 1.0 };
        double viaField[4];
        subToWorld->MultiplyPoint(h, viaField);
        double anatomyIndex[3];
        for (int axis = 0; axis < 3; ++axis)
        {
          anatomyIndex[axis] = (sub[axis] + 0.5) / factor - 0.5;
        }
        double viaAnatomy[3];
        TransformPoint(impl.IJKToWorld, anatomyIndex, viaAnatomy);
        for (int axis = 0; axis < 3; ++axis)
        {
          usable &= std::abs(viaField[axis] - viaAnatomy[axis]) <= tolerance;
        }
      }
    }
    if (!usable && !entry.Reported)
    {
      vtkErrorMacro("Render: cut field " << n << " was not made on the anatomy's voxel grid; it is not shown");
    }
    entry.Reported = !usable;
    if (usable != entry.Usable)
    {
      sceneChanged = true;
    }
    entry.Usable = usable;
    if (usable && field->GetNumberOfAllocatedBricks() > 0)
    {
      impl.ActiveCuts.push_back(static_cast<int>(n));
    }
  }

  impl.PlaneEquations.clear();
  if (impl.Planes)
  {
    impl.Planes->InitTraversal();
    while (vtkPlane* plane = impl.Planes->GetNextItem())
    {
      Internals::PlaneEquation equation;
      plane->GetNormal(equation.Normal);
      if (vtkMath::Normalize(equation.Normal) <= 0.0)
      {
        continue;
      }
      double origin[3];
      plane->GetOrigin(origin);
      equation.Offset = -vtkMath::Dot(equation.Normal, origin);
      impl.PlaneEquations.push_back(equation);
    }
  }

  impl.BlendMode = this->BlendMode;
  impl.SampleDistance = this->SampleDistance;
  impl.GradientStep = this->GradientStep;
  impl.UnitDistance = this->ScalarOpacityUnitDistance;
  impl.ThinBone = this->ThinBoneShading;
  impl.ThinBoneThickness = this->ThinBoneThickness;
  impl.Ambient = this->Ambient;
  impl.Diffuse = this->Diffuse;
  impl.Specular = this->Specular;
  impl.SpecularPower = this->SpecularPower;
  if (sceneChanged)
  {
    ++impl.SceneVersion;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutRayCaster::UpdateScene(SceneView& view)
{
  bool sceneChanged = false;
  if (!this->PrepareScene(sceneChanged))
  {
    return false;
  }
  const Internals& impl = *this->Impl;
  view.Version = impl.SceneVersion;
  view.AnatomyVersion = impl.AnatomyCopyTime;
  view.LabelVersion = impl.LabelVersion;
  view.Values = impl.Values.data();
  std::copy(impl.Dimensions, impl.Dimensions + 3, view.Dimensions);
  std::copy(impl.IJKToWorld, impl.IJKToWorld + 16, view.IJKToWorld);
  std::copy(impl.WorldToIJK, impl.WorldToIJK + 16, view.WorldToIJK);
  std::copy(impl.NormalMatrix4Storage, impl.NormalMatrix4Storage + 16, view.NormalMatrix);
  view.Labels = impl.Labels.empty() ? nullptr : impl.Labels.data();
  view.Fractions.clear();
  for (const Internals::FractionVolume& fraction : impl.Fractions)
  {
    view.Fractions.emplace_back(fraction.Label, fraction.Values.data());
  }
  view.Styles.clear();
  for (const SegmentStyle& style : impl.Styles)
  {
    view.Styles.push_back({ style.Color[0], style.Color[1], style.Color[2], style.Opacity, style.Iso, style.Shape ? 1.f : 0.f, 0.f, 0.f });
  }
  std::copy(impl.BlockDimensions, impl.BlockDimensions + 3, view.BlockDimensions);
  view.BlockOccupied = impl.BlockOccupied.data();
  view.BlockLipschitz = impl.BlockLipschitz.data();
  view.AnyIsoSegment = impl.AnyIsoSegment;
  view.MinimumIso = impl.MinimumIso;
  view.CutFields.clear();
  for (int index : impl.ActiveCuts)
  {
    view.CutFields.push_back(impl.Cuts[index].Field);
  }
  view.Planes.clear();
  for (const Internals::PlaneEquation& plane : impl.PlaneEquations)
  {
    view.Planes.push_back({ plane.Normal[0], plane.Normal[1], plane.Normal[2], plane.Offset });
  }
  view.ColorTable = impl.ColorTable.empty() ? nullptr : impl.ColorTable.data();
  view.OpacityTable = impl.OpacityTable.empty() ? nullptr : impl.OpacityTable.data();
  view.TableSize = TransferTableSize;
  view.TableRange[0] = impl.TableRange[0];
  view.TableRange[1] = impl.TableRange[1];
  view.MaximumRefinements = MaximumRefinements;
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutRayCaster::Render(vtkMatrix4x4* worldToNDC, int width, int height, const float* opaqueDepth)
{
  Internals& impl = *this->Impl;
  this->NumberOfRaysCast = 0;
  this->LastRenderWasLocalized = false;
  if (!worldToNDC || width < 1 || height < 1 || width > 16384 || height > 16384)
  {
    vtkErrorMacro("Render: needs a camera matrix and an image of 1 to 16384 pixels a side");
    return false;
  }
  // The counters first, before the scene decides which fields have bricks
  // (the active cuts): a brick stamped after this is listed next time, and
  // one allocated before it is in the scene.
  std::vector<vtkTypeUInt64> currentStamps;
  for (CutEntry& entry : impl.Cuts)
  {
    currentStamps.push_back(entry.Field->GetCurrentStamp());
  }
  bool sceneChanged = false;
  if (!this->PrepareScene(sceneChanged))
  {
    return false;
  }

  // Camera.
  double matrix[16];
  std::copy(&worldToNDC->Element[0][0], &worldToNDC->Element[0][0] + 16, matrix);
  const bool sameCamera = std::equal(matrix, matrix + 16, impl.WorldToNDC) && width == impl.Width && height == impl.Height;
  const vtkIdType pixels = static_cast<vtkIdType>(width) * height;
  bool sameOpaque = (opaqueDepth != nullptr) == impl.HadOpaqueDepth;
  if (sameOpaque && opaqueDepth)
  {
    sameOpaque = impl.OpaqueDepth.size() == static_cast<size_t>(pixels) &&
      std::memcmp(opaqueDepth, impl.OpaqueDepth.data(), pixels * sizeof(float)) == 0;
  }
  const bool localized = impl.ImageValid && sameCamera && sameOpaque && !sceneChanged;

  std::copy(matrix, matrix + 16, impl.WorldToNDC);
  vtkNew<vtkMatrix4x4> inverse;
  vtkMatrix4x4::Invert(worldToNDC, inverse);
  std::copy(&inverse->Element[0][0], &inverse->Element[0][0] + 16, impl.NDCToWorld);
  impl.Width = width;
  impl.Height = height;
  impl.HadOpaqueDepth = opaqueDepth != nullptr;
  if (opaqueDepth)
  {
    impl.OpaqueDepth.assign(opaqueDepth, opaqueDepth + pixels);
  }
  if (!localized)
  {
    impl.Color.assign(4 * pixels, 0.f);
    impl.Depth.assign(pixels, 1.f);
    impl.Normal.assign(3 * pixels, 0.f);
    impl.Source.assign(pixels, SourceNone);
  }

  // Which pixels to cast: all, or those covering bricks changed since the last image.
  std::vector<uint8_t> mask;
  if (localized)
  {
    mask.assign(pixels, 0);
    this->UpdatedRegion[0] = width;
    this->UpdatedRegion[1] = height;
    this->UpdatedRegion[2] = -1;
    this->UpdatedRegion[3] = -1;
    vtkNew<vtkIdList> bricks;
    for (int index : impl.ActiveCuts)
    {
      CutEntry& entry = impl.Cuts[index];
      entry.Field->GetBricksModifiedSince(entry.RenderedStamp, bricks);
      const int* brickDims = entry.Field->GetBrickDimensions();
      vtkNew<vtkMatrix4x4> subToWorld;
      entry.Field->GetSubVoxelIJKToRAS(subToWorld);
      for (vtkIdType n = 0; n < bricks->GetNumberOfIds(); ++n)
      {
        const vtkIdType id = bricks->GetId(n);
        const int b[3] = { static_cast<int>(id % brickDims[0]), static_cast<int>((id / brickDims[0]) % brickDims[1]),
          static_cast<int>(id / (static_cast<vtkIdType>(brickDims[0]) * brickDims[1])) };
        // A brick's samples reach two sub-voxels beyond it (interpolation and
        // its curvature correction).
        double lo[2] = { 1e300, 1e300 };
        double hi[2] = { -1e300, -1e300 };
        bool behind = false;
        for (int corner = 0; corner < 8; ++corner)
        {
          double sub[4] = { b[0] * 8.0 + ((corner & 1) ? 10.0 : -3.0), b[1] * 8.0 + ((corner & 2) ? 10.0 : -3.0),
            b[2] * 8.0 + ((corner & 4) ? 10.0 : -3.0), 1.0 };
          double world[4];
          subToWorld->MultiplyPoint(sub, world);
          double clip[4];
          Multiply4(matrix, world, clip);
          if (clip[3] <= 1e-12)
          {
            behind = true;
            break;
          }
          for (int axis = 0; axis < 2; ++axis)
          {
            const double ndc = clip[axis] / clip[3];
            const double pixel = (ndc + 1.0) * 0.5 * (axis == 0 ? width : height);
            lo[axis] = std::min(lo[axis], pixel);
            hi[axis] = std::max(hi[axis], pixel);
          }
        }
        if (behind)
        {
          lo[0] = lo[1] = 0.0;
          hi[0] = width;
          hi[1] = height;
        }
        const int x0 = std::max(0, static_cast<int>(std::floor(lo[0])) - 1);
        const int x1 = std::min(width - 1, static_cast<int>(std::ceil(hi[0])) + 1);
        const int y0 = std::max(0, static_cast<int>(std::floor(lo[1])) - 1);
        const int y1 = std::min(height - 1, static_cast<int>(std::ceil(hi[1])) + 1);
        for (int y = y0; y <= y1; ++y)
        {
          std::fill(mask.begin() + static_cast<vtkIdType>(y) * width + x0, mask.begin() + static_cast<vtkIdType>(y) * width + x1 + 1, 1);
        }
        if (x0 <= x1 && y0 <= y1)
        {
          this->UpdatedRegion[0] = std::min(this->UpdatedRegion[0], x0);
          this->UpdatedRegion[1] = std::min(this->UpdatedRegion[1], y0);
          this->UpdatedRegion[2] = std::max(this->UpdatedRegion[2], x1);
          this->UpdatedRegion[3] = std::max(this->UpdatedRegion[3], y1);
        }
      }
    }
  }
  for (size_t n = 0; n < impl.Cuts.size(); ++n)
  {
    // Taken before casting: a brick the writer changes while rays are cast is
    // recast next time.
    impl.Cuts[n].RenderedStamp = currentStamps[n];
  }

  std::vector<double> limits;
  if (opaqueDepth)
  {
    // Ray length to the opaque geometry in each pixel.
    limits.resize(pixels);
    ParallelFor(this->MaximumNumberOfThreads, height, [&](vtkIdType begin, vtkIdType end) {
      for (vtkIdType y = begin; y < end; ++y)
      {
        for (int x = 0; x < width; ++x)
        {
          const vtkIdType p = y * width + x;
          const double ndcX = 2.0 * (x + 0.5) / width - 1.0;
          const double ndcY = 2.0 * (y + 0.5) / height - 1.0;
          const double nearH[4] = { ndcX, ndcY, -1.0, 1.0 };
          const double hitH[4] = { ndcX, ndcY, 2.0 * opaqueDepth[p] - 1.0, 1.0 };
          double nearW[4];
          double hitW[4];
          Multiply4(impl.NDCToWorld, nearH, nearW);
          Multiply4(impl.NDCToWorld, hitH, hitW);
          double length = 0.0;
          for (int axis = 0; axis < 3; ++axis)
          {
            const double delta = hitW[axis] / hitW[3] - nearW[axis] / nearW[3];
            length += delta * delta;
          }
          limits[p] = opaqueDepth[p] >= 1.f ? std::numeric_limits<double>::infinity() : std::sqrt(length);
        }
      }
    });
  }

  // The rectangle of pixels this call changes (the union of the bricks' rectangles).
  if (!localized)
  {
    this->UpdatedRegion[0] = 0;
    this->UpdatedRegion[1] = 0;
    this->UpdatedRegion[2] = width - 1;
    this->UpdatedRegion[3] = height - 1;
  }

  std::atomic<vtkIdType> cast(0);
  ParallelFor(this->MaximumNumberOfThreads, height, [&](vtkIdType begin, vtkIdType end) {
    vtkIdType local = 0;
    for (vtkIdType y = begin; y < end; ++y)
    {
      for (int x = 0; x < width; ++x)
      {
        const vtkIdType p = y * width + x;
        if (localized && !mask[p])
        {
          continue;
        }
        impl.CastRay(x, static_cast<int>(y), limits.empty() ? nullptr : &limits[p]);
        ++local;
      }
    }
    cast += local;
  });
  this->NumberOfRaysCast = cast.load();
  this->LastRenderWasLocalized = localized;
  impl.ImageValid = true;
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "BlendMode: " << (this->BlendMode == IsoSurfaceBlend ? "IsoSurface" : "Composite") << "\n";
  os << indent << "IsoValue: " << this->IsoValue << "\n";
  os << indent << "SampleDistance: " << this->SampleDistance << "\n";
  os << indent << "GradientStep: " << this->GradientStep << "\n";
  os << indent << "ScalarOpacityUnitDistance: " << this->ScalarOpacityUnitDistance << "\n";
  os << indent << "ThinBoneShading: " << this->ThinBoneShading << " (" << this->ThinBoneThickness << " mm)\n";
  os << indent << "Lighting: ambient " << this->Ambient << ", diffuse " << this->Diffuse << ", specular " << this->Specular << "^"
     << this->SpecularPower << "\n";
  os << indent << "MaximumNumberOfThreads: " << this->MaximumNumberOfThreads << "\n";
  os << indent << "Anatomy: " << this->Impl->Anatomy.GetPointer() << "\n";
  os << indent << "LabelMap: " << this->Impl->LabelMap.GetPointer() << "\n";
  os << indent << "SegmentAppearances: " << this->GetNumberOfSegmentAppearances() << "\n";
  os << indent << "CutFields: " << this->Impl->Cuts.size() << "\n";
  os << indent << "NumberOfRaysCast: " << this->NumberOfRaysCast << (this->LastRenderWasLocalized ? " (localized)" : "") << "\n";
}
