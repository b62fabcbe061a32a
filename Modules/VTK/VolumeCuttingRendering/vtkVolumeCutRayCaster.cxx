// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutRayCaster.h"

// The stages of adaptive sampling along one ray are vtkVolumeCutRayMarcher's;
// the inputs become the scene it reads through vtkVolumeCutSceneInputs.
#include "vtkVolumeCutBorderLocator.h"
#include "vtkVolumeCutEmptySpace.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutLabelSmoothing.h"
#include "vtkVolumeCutPartialVolumeLabels.h"
#include "vtkVolumeCutLocalizedUpdate.h"
#include "vtkVolumeCutParallelFor.h"
#include "vtkVolumeCutRayMarcher.h"
#include "vtkVolumeCutRayResult.h"
#include "vtkVolumeCutRayScene.h"
#include "vtkVolumeCutSceneInputs.h"

#include <vtkColorTransferFunction.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkTimerLog.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <map>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutRayCaster);

using vtkVolumeCutRayMath::Multiply4;

namespace
{
constexpr int MaximumCutFields = vtkVolumeCutRayScene::MaximumCutFields;
constexpr int MaximumFractions = vtkVolumeCutRayScene::MaximumFractions;
constexpr int TransferTableSize = vtkVolumeCutRayScene::TransferTableSize;
using SegmentStyle = vtkVolumeCutRayScene::SegmentStyle;

struct CutEntry
{
  vtkSmartPointer<vtkVolumeCutField> Field;
  bool Usable = false;
  bool Reported = false;
  vtkTypeUInt64 RenderedStamp = 0;
};
}

//------------------------------------------------------------------------------
struct vtkVolumeCutRayCaster::Internals
{
  // Inputs, and when each was last copied into the scene.
  vtkSmartPointer<vtkImageData> Anatomy;
  vtkSmartPointer<vtkMatrix4x4> AnatomyMatrix;
  vtkMTimeType AnatomyCopyTime = 0;
  vtkSmartPointer<vtkImageData> LabelMap;
  vtkMTimeType LabelCopyTime = 0;
  /// The label map as given; Scene.Labels is it resolved against the CT
  /// and the styles (vtkVolumeCutPartialVolumeLabels), made again when the
  /// labels, the CT or what the styles show change.
  std::vector<uint16_t> GivenLabels;
  std::vector<float> ResolvedStyles; // per label: shown, shape, iso
  bool LabelsResolved = false;
  bool DefaultStyles = true;
  struct FractionInput
  {
    vtkSmartPointer<vtkImageData> Image;
    double ValueAtZero = 0.0;
    double ValueAtOne = 1.0;
  };
  std::map<int, FractionInput> FractionInputs;
  vtkMTimeType FractionCopyTime = 0;
  size_t CopiedFractionInputs = 0;
  size_t GivenFractions = 0; // Scene.Fractions: the given ones first, then the smoothed ones
  std::vector<int> SmoothedLabels;
  double SmoothedSigma = 0.0;
  /// GivenLabelVersion when the smoothed fractions were made: a shown
  /// segment keeps its given voxels in Scene.Labels, so its smoothed
  /// fraction stays valid while the given labels and the sigma do.
  vtkMTimeType SmoothedLabelVersion = 0;
  vtkMTimeType GivenLabelVersion = 1; // changes when GivenLabels is copied or dropped
  /// Smoothed fractions set aside while the scene's fractions are rebuilt.
  std::map<int, vtkVolumeCutRayScene::FractionVolume> SmoothedSetAside;
  vtkTypeInt64 LabelSmoothings = 0;
  std::vector<CutEntry> Cuts;
  std::vector<int> ActiveCuts; // indices into Cuts of the scene's cut fields
  vtkSmartPointer<vtkPlaneCollection> Planes;
  vtkSmartPointer<vtkColorTransferFunction> ColorFunction;
  vtkSmartPointer<vtkPiecewiseFunction> OpacityFunction;
  vtkMTimeType BlockTime = 0;
  vtkMTimeType SceneVersion = 1;
  vtkMTimeType LabelVersion = 1; // changes when the label map or fractions are copied or dropped

  /// What the rays read.
  vtkVolumeCutRayScene Scene;

  // Last image, for localized updates.
  int Width = 0;
  int Height = 0;
  double WorldToNDC[16];
  double NDCToWorld[16];
  vtkMTimeType SceneTime = 0;
  bool LastDraftQuality = false;
  std::vector<float> OpaqueDepth;
  bool HadOpaqueDepth = false;
  std::vector<float> Color;
  std::vector<float> Depth;
  std::vector<float> Normal;
  std::vector<int> Source;
  std::vector<int> Segment;
  bool ImageValid = false;

  void CastRay(int x, int y, const double* opaqueLimit);
};

//------------------------------------------------------------------------------
// One ray, from the eye through the pixel's centre, into its pixel (cleared first).
void vtkVolumeCutRayCaster::Internals::CastRay(int x, int y, const double* opaqueLimit)
{
  const vtkIdType pixel = static_cast<vtkIdType>(y) * this->Width + x;
  vtkVolumeCutRayResult result;
  result.Color = &this->Color[4 * pixel];
  result.Depth = &this->Depth[pixel];
  result.Normal = &this->Normal[3 * pixel];
  result.Source = &this->Source[pixel];
  result.Segment = &this->Segment[pixel];
  result.WorldToNDC = this->WorldToNDC;
  std::fill(result.Color, result.Color + 4, 0.f);
  *result.Depth = 1.f;
  std::fill(result.Normal, result.Normal + 3, 0.f);
  *result.Source = SourceNone;
  *result.Segment = 0;

  vtkVolumeCutRayMarcher::Cast(this->Scene, this->NDCToWorld, this->Width, this->Height, x, y, opaqueLimit, result);
}

//------------------------------------------------------------------------------
vtkVolumeCutRayCaster::vtkVolumeCutRayCaster()
  : Impl(new Internals)
{
  this->Impl->Scene.Styles.resize(2);
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
    this->Impl->Scene.Styles.assign(2, SegmentStyle());
    this->Impl->DefaultStyles = false;
  }
  if (static_cast<int>(this->Impl->Scene.Styles.size()) <= label)
  {
    this->Impl->Scene.Styles.resize(label + 1);
  }
  SegmentStyle& style = this->Impl->Scene.Styles[label];
  for (int c = 0; c < 3; ++c)
  {
    style.Color[c] = static_cast<float>(std::min(1.0, std::max(0.0, color[c])));
    style.SurfaceColor[c] = style.Color[c];
  }
  style.Opacity = std::isfinite(opacity) ? static_cast<float>(std::min(1.0, std::max(0.0, opacity))) : 0.f;
  style.Shape = std::isnan(isoValue);
  style.Iso = style.Shape ? 0.f : static_cast<float>(isoValue);
  style.Defined = true;
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::SetSegmentSurfaceColor(int label, const double color[3])
{
  if (label < 1 || label >= static_cast<int>(this->Impl->Scene.Styles.size()) || !this->Impl->Scene.Styles[label].Defined || !color)
  {
    vtkErrorMacro("SetSegmentSurfaceColor: segment " << label << " has no appearance; call SetSegmentAppearance first");
    return;
  }
  SegmentStyle& style = this->Impl->Scene.Styles[label];
  for (int c = 0; c < 3; ++c)
  {
    style.SurfaceColor[c] = static_cast<float>(std::min(1.0, std::max(0.0, color[c])));
  }
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCaster::RemoveAllSegmentAppearances()
{
  this->Impl->Scene.Styles.assign(2, SegmentStyle());
  this->Impl->DefaultStyles = true;
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkVolumeCutRayCaster::GetNumberOfSegmentAppearances() const
{
  return static_cast<int>(
    std::count_if(this->Impl->Scene.Styles.begin(), this->Impl->Scene.Styles.end(), [](const SegmentStyle& style) { return style.Defined; }));
}

//------------------------------------------------------------------------------
vtkTypeInt64 vtkVolumeCutRayCaster::GetNumberOfLabelSmoothings() const
{
  return this->Impl->LabelSmoothings;
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
const int* vtkVolumeCutRayCaster::GetSegmentBuffer() const
{
  return this->Impl->Segment.empty() ? nullptr : this->Impl->Segment.data();
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
void vtkVolumeCutRayCaster::GetSegmentImage(vtkImageData* image) const
{
  FillImage<vtkIntArray>(image, this->Impl->Width, this->Impl->Height, 1, this->Impl->Segment);
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
    if (const char* error = vtkVolumeCutSceneInputs::CopyAnatomy(anatomy, scalars, impl.AnatomyMatrix, impl.Scene))
    {
      vtkErrorMacro(<< error);
      return false;
    }
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
    if (!impl.Scene.Labels.empty() || !impl.GivenLabels.empty())
    {
      impl.Scene.Labels.clear();
      impl.GivenLabels.clear();
      ++impl.GivenLabelVersion;
      ++impl.LabelVersion;
      sceneChanged = true;
      impl.BlockTime = 0;
    }
  }
  else if (impl.LabelCopyTime < labelMap->GetMTime() || !labelMap->GetPointData()->GetScalars() ||
    impl.LabelCopyTime < labelMap->GetPointData()->GetScalars()->GetMTime())
  {
    vtkDataArray* labelScalars = labelMap->GetPointData()->GetScalars();
    if (!labelScalars || !vtkVolumeCutSceneInputs::SameDimensions(labelMap, anatomy))
    {
      vtkErrorMacro("Render: the label map must have the anatomy's dimensions; rendering without labels");
      impl.GivenLabels.clear();
    }
    else if (vtkVolumeCutSceneInputs::CopyLabels(labelScalars, impl.GivenLabels))
    {
      vtkWarningMacro("Render: label values outside 0..65535 were clamped");
    }
    impl.LabelCopyTime = std::max(labelMap->GetMTime(), labelScalars ? labelScalars->GetMTime() : 0);
    impl.LabelsResolved = false;
    ++impl.GivenLabelVersion;
  }
  else if (sceneChanged)
  {
    impl.LabelsResolved = false; // the CT changed under the same labels
  }
  // Fractional labelmaps, copied to floats 0..1 when any of them changed.
  vtkMTimeType fractionTime = 0;
  for (const auto& entry : impl.FractionInputs)
  {
    vtkImageData* image = entry.second.Image;
    fractionTime = std::max({ fractionTime, image->GetMTime(),
      image->GetPointData()->GetScalars() ? image->GetPointData()->GetScalars()->GetMTime() : vtkMTimeType(0) });
  }
  if (fractionTime > impl.FractionCopyTime || impl.FractionInputs.size() != impl.CopiedFractionInputs || sceneChanged)
  {
    for (size_t n = impl.GivenFractions; n < impl.Scene.Fractions.size(); ++n)
    {
      impl.SmoothedSetAside[impl.Scene.Fractions[n].Label] = std::move(impl.Scene.Fractions[n]);
    }
    impl.Scene.Fractions.clear();
    impl.SmoothedLabels.clear();
    impl.CopiedFractionInputs = impl.FractionInputs.size();
    for (const auto& entry : impl.FractionInputs)
    {
      vtkImageData* image = entry.second.Image;
      vtkDataArray* values = image->GetPointData()->GetScalars();
      if (!values || !vtkVolumeCutSceneInputs::SameDimensions(image, anatomy))
      {
        vtkErrorMacro("Render: the fractional labelmap of segment " << entry.first << " must have the anatomy's dimensions; it is not shown");
        continue;
      }
      vtkVolumeCutRayScene::FractionVolume fraction;
      fraction.Label = entry.first;
      vtkVolumeCutSceneInputs::CopyFraction(values, entry.second.ValueAtZero, entry.second.ValueAtOne, fraction.Values);
      impl.Scene.Fractions.push_back(std::move(fraction));
    }
    impl.GivenFractions = impl.Scene.Fractions.size();
    impl.FractionCopyTime = std::max(fractionTime, vtkMTimeType(1));
    ++impl.LabelVersion;
    impl.BlockTime = 0;
    sceneChanged = true;
  }

  // Segment 1 follows IsoValue until appearances are given.
  if (impl.DefaultStyles)
  {
    SegmentStyle& bone = impl.Scene.Styles[1];
    bone.Color[0] = bone.SurfaceColor[0] = 0.95f;
    bone.Color[1] = bone.SurfaceColor[1] = 0.92f;
    bone.Color[2] = bone.SurfaceColor[2] = 0.84f;
    bone.Opacity = 1.f;
    bone.Iso = static_cast<float>(this->IsoValue);
    bone.Shape = false;
  }
  if (impl.Scene.Styles.size() < 2)
  {
    impl.Scene.Styles.resize(2);
  }

  // Partial-volume voxels go to the shown segment whose material fills
  // them: which ones depends on what the styles show.
  std::vector<float> resolvedStyles;
  for (const SegmentStyle& style : impl.Scene.Styles)
  {
    const bool shown = style.Opacity > 0.f;
    resolvedStyles.insert(resolvedStyles.end(), { shown ? 1.f : 0.f, style.Shape ? 1.f : 0.f, shown && !style.Shape ? style.Iso : 0.f });
  }
  if (!impl.LabelsResolved || resolvedStyles != impl.ResolvedStyles)
  {
    std::vector<uint16_t> resolved;
    if (!impl.GivenLabels.empty())
    {
      vtkVolumeCutPartialVolumeLabels::Resolve(
        impl.GivenLabels, impl.Scene.Values, impl.Scene.Dimensions, impl.Scene.Styles, this->MaximumNumberOfThreads, resolved);
    }
    impl.LabelsResolved = true;
    impl.ResolvedStyles = resolvedStyles;
    if (resolved != impl.Scene.Labels)
    {
      impl.Scene.Labels.swap(resolved);
      ++impl.LabelVersion;
      impl.BlockTime = 0;
      sceneChanged = true;
    }
  }

  // Segments drawn by their shape from the label map alone: fractions from
  // their smoothed indicator, after the given ones, made again when the
  // labels, those segments or the smoothing change.
  std::vector<int> smoothed;
  if (this->LabelSmoothing > 0.0 && !impl.Scene.Labels.empty())
  {
    for (size_t label = 1; label < impl.Scene.Styles.size(); ++label)
    {
      const SegmentStyle& style = impl.Scene.Styles[label];
      if (style.Defined && style.Shape && style.Opacity > 0.f && !impl.FractionInputs.count(static_cast<int>(label)) &&
        impl.FractionInputs.size() + smoothed.size() < static_cast<size_t>(MaximumFractions))
      {
        smoothed.push_back(static_cast<int>(label));
      }
    }
  }
  const bool smoothingSourceChanged = impl.SmoothedSigma != this->LabelSmoothing || impl.SmoothedLabelVersion != impl.GivenLabelVersion;
  if (smoothed != impl.SmoothedLabels || (!smoothed.empty() && smoothingSourceChanged))
  {
    // Those still valid are kept; only segments newly drawn by their shape
    // are smoothed (each is a pass over its box, and a role change would
    // otherwise smooth every shape segment again).
    std::map<int, vtkVolumeCutRayScene::FractionVolume>& kept = impl.SmoothedSetAside;
    for (size_t n = impl.GivenFractions; n < impl.Scene.Fractions.size(); ++n)
    {
      kept[impl.Scene.Fractions[n].Label] = std::move(impl.Scene.Fractions[n]);
    }
    impl.Scene.Fractions.resize(impl.GivenFractions);
    if (smoothingSourceChanged)
    {
      kept.clear();
    }
    std::vector<int> missing;
    std::copy_if(smoothed.begin(), smoothed.end(), std::back_inserter(missing), [&](int label) { return !kept.count(label); });
    double spacing[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      const double column[3] = { impl.Scene.IJKToWorld[axis], impl.Scene.IJKToWorld[4 + axis], impl.Scene.IJKToWorld[8 + axis] };
      spacing[axis] = vtkMath::Norm(column);
    }
    std::vector<vtkVolumeCutRayScene::FractionVolume> made;
    vtkVolumeCutLabelSmoothing::Smooth(impl.Scene.Labels, impl.Scene.Dimensions, spacing, missing, this->LabelSmoothing,
      this->MaximumNumberOfThreads, made);
    impl.LabelSmoothings += static_cast<vtkTypeInt64>(made.size());
    for (vtkVolumeCutRayScene::FractionVolume& fraction : made)
    {
      kept[fraction.Label] = std::move(fraction);
    }
    // In label order, as if all were smoothed now; labels absent from the
    // map have none. Those no longer drawn by their shape are dropped.
    for (int label : smoothed)
    {
      auto found = kept.find(label);
      if (found != kept.end())
      {
        impl.Scene.Fractions.push_back(std::move(found->second));
      }
    }
    kept.clear();
    impl.SmoothedLabels = smoothed;
    impl.SmoothedSigma = this->LabelSmoothing;
    impl.SmoothedLabelVersion = impl.GivenLabelVersion;
    ++impl.LabelVersion;
    impl.BlockTime = 0;
    sceneChanged = true;
  }
  else
  {
    impl.SmoothedSetAside.clear();
  }

  int fractionBlocks[3];
  impl.Scene.GetFractionBlockDimensions(fractionBlocks);
  for (vtkVolumeCutRayScene::FractionVolume& fraction : impl.Scene.Fractions)
  {
    if (fraction.NonZeroBlocks.size() != static_cast<size_t>(fractionBlocks[0]) * fractionBlocks[1] * fractionBlocks[2])
    {
      vtkVolumeCutSceneInputs::MarkNonZeroBlocks(impl.Scene, fraction, this->MaximumNumberOfThreads);
    }
  }

  // Transfer functions (composite mode).
  if (this->BlendMode == CompositeBlend)
  {
    if (!impl.ColorFunction || !impl.OpacityFunction)
    {
      vtkErrorMacro("Render: the composite mode needs colour and opacity transfer functions");
      return false;
    }
    vtkVolumeCutSceneInputs::CopyTransferFunctions(impl.ColorFunction, impl.OpacityFunction, impl.Scene);
  }

  impl.Scene.AnyIsoSegment = false;
  impl.Scene.AnyShapeSegment = false;
  impl.Scene.MinimumIso = std::numeric_limits<double>::infinity();
  for (size_t label = 1; label < impl.Scene.Styles.size(); ++label)
  {
    const SegmentStyle& style = impl.Scene.Styles[label];
    impl.Scene.AnyShapeSegment |= style.Opacity > 0.f && style.Shape;
    if (style.Opacity > 0.f && !style.Shape && (label == 1 || impl.Scene.HasSegments()))
    {
      impl.Scene.AnyIsoSegment = true;
      impl.Scene.MinimumIso = std::min(impl.Scene.MinimumIso, double(style.Iso));
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

  impl.Scene.BlendMode = this->BlendMode;
  impl.Scene.SampleDistance = this->SampleDistance;
  impl.Scene.GradientStep = this->GradientStep;
  impl.Scene.UnitDistance = this->ScalarOpacityUnitDistance;
  impl.Scene.ThinBone = this->ThinBoneShading;
  impl.Scene.ThinBoneThickness = this->ThinBoneThickness;
  impl.Scene.AmbientOcclusion = this->AmbientOcclusion && !this->DraftQuality && this->BlendMode == IsoSurfaceBlend;
  impl.Scene.AmbientOcclusionRadius = this->AmbientOcclusionRadius;
  impl.Scene.Ambient = this->Ambient;
  impl.Scene.Diffuse = this->Diffuse;
  impl.Scene.Specular = this->Specular;
  impl.Scene.SpecularPower = this->SpecularPower;

  // Empty-space blocks.
  if (impl.BlockTime == 0 || sceneChanged)
  {
    impl.Scene.EmptySpace.Build(impl.Scene, this->MaximumNumberOfThreads);
    impl.BlockTime = sceneTime;
  }

  // Cut fields: usable when initialised on the anatomy's grid.
  impl.ActiveCuts.clear();
  impl.Scene.CutFields.clear();
  for (size_t n = 0; n < impl.Cuts.size(); ++n)
  {
    CutEntry& entry = impl.Cuts[n];
    vtkVolumeCutField* field = entry.Field;
    const bool usable = vtkVolumeCutSceneInputs::OnAnatomyGrid(field, dims, impl.Scene.IJKToWorld);
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
      impl.Scene.CutFields.push_back(field);
    }
  }

  vtkVolumeCutSceneInputs::CopyPlanes(impl.Planes, impl.Scene.Planes);

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
  view.Values = impl.Scene.Values.data();
  std::copy(impl.Scene.Dimensions, impl.Scene.Dimensions + 3, view.Dimensions);
  std::copy(impl.Scene.IJKToWorld, impl.Scene.IJKToWorld + 16, view.IJKToWorld);
  std::copy(impl.Scene.WorldToIJK, impl.Scene.WorldToIJK + 16, view.WorldToIJK);
  std::copy(impl.Scene.NormalMatrix, impl.Scene.NormalMatrix + 16, view.NormalMatrix);
  view.Labels = impl.Scene.Labels.empty() ? nullptr : impl.Scene.Labels.data();
  view.Fractions.clear();
  for (const vtkVolumeCutRayScene::FractionVolume& fraction : impl.Scene.Fractions)
  {
    view.Fractions.emplace_back(fraction.Label, fraction.Values.data());
  }
  view.Styles.clear();
  for (const SegmentStyle& style : impl.Scene.Styles)
  {
    view.Styles.push_back({ style.Color[0], style.Color[1], style.Color[2], style.Opacity, style.Iso, style.Shape ? 1.f : 0.f, 0.f, 0.f,
      style.SurfaceColor[0], style.SurfaceColor[1], style.SurfaceColor[2], 0.f });
  }
  std::copy(impl.Scene.EmptySpace.GetDimensions(), impl.Scene.EmptySpace.GetDimensions() + 3, view.BlockDimensions);
  view.BlockOccupied = impl.Scene.EmptySpace.GetOccupied();
  view.BlockLipschitz = impl.Scene.EmptySpace.GetGradientBounds();
  view.BlockReach = impl.Scene.EmptySpace.GetReach();
  std::copy(impl.Scene.EmptySpace.GetCellGroupDimensions(), impl.Scene.EmptySpace.GetCellGroupDimensions() + 3, view.CellGroupDimensions);
  view.CellGroups = impl.Scene.EmptySpace.GetCellGroups();
  view.AnyIsoSegment = impl.Scene.AnyIsoSegment;
  view.MinimumIso = impl.Scene.MinimumIso;
  view.CutFields = impl.Scene.CutFields;
  view.Planes.clear();
  for (const vtkVolumeCutRayScene::PlaneEquation& plane : impl.Scene.Planes)
  {
    view.Planes.push_back({ plane.Normal[0], plane.Normal[1], plane.Normal[2], plane.Offset });
  }
  view.ColorTable = impl.Scene.ColorTable.empty() ? nullptr : impl.Scene.ColorTable.data();
  view.OpacityTable = impl.Scene.OpacityTable.empty() ? nullptr : impl.Scene.OpacityTable.data();
  view.TableSize = TransferTableSize;
  view.TableRange[0] = impl.Scene.TableRange[0];
  view.TableRange[1] = impl.Scene.TableRange[1];
  view.MaximumRefinements = vtkVolumeCutBorderLocator::MaximumRefinements;
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutRayCaster::Render(vtkMatrix4x4* worldToNDC, int width, int height, const float* opaqueDepth)
{
  Internals& impl = *this->Impl;
  this->NumberOfRaysCast = 0;
  this->LastRenderWasLocalized = false;
  this->LastRayCastingTime = 0.0;
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
  const bool sameQuality = this->DraftQuality == impl.LastDraftQuality;
  impl.LastDraftQuality = this->DraftQuality;
  const bool localized = impl.ImageValid && sameCamera && sameOpaque && sameQuality && !sceneChanged;

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
    impl.Segment.assign(pixels, 0);
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
    for (int index : impl.ActiveCuts)
    {
      const CutEntry& entry = impl.Cuts[index];
      const double reach = std::max(impl.Scene.AmbientOcclusion ? impl.Scene.AmbientOcclusionRadius : 0.0,
        impl.Scene.ThinBone ? impl.Scene.ThinBoneThickness : 0.0);
      vtkVolumeCutLocalizedUpdate::MarkModifiedBricks(
        entry.Field, entry.RenderedStamp, reach, matrix, width, height, mask, this->UpdatedRegion);
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
    vtkVolumeCutParallelFor(this->MaximumNumberOfThreads, height, [&](vtkIdType begin, vtkIdType end) {
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

  const double castingStart = vtkTimerLog::GetUniversalTime();
  std::atomic<vtkIdType> cast(0);
  vtkVolumeCutParallelFor(this->MaximumNumberOfThreads, height, [&](vtkIdType begin, vtkIdType end) {
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
  this->LastRayCastingTime = vtkTimerLog::GetUniversalTime() - castingStart;
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
  os << indent << "AmbientOcclusion: " << this->AmbientOcclusion << " (" << this->AmbientOcclusionRadius << " mm)\n";
  os << indent << "LabelSmoothing: " << this->LabelSmoothing << "\n";
  os << indent << "DraftQuality: " << this->DraftQuality << "\n";
  os << indent << "MaximumNumberOfThreads: " << this->MaximumNumberOfThreads << "\n";
  os << indent << "Anatomy: " << this->Impl->Anatomy.GetPointer() << "\n";
  os << indent << "LabelMap: " << this->Impl->LabelMap.GetPointer() << "\n";
  os << indent << "SegmentAppearances: " << this->GetNumberOfSegmentAppearances() << "\n";
  os << indent << "CutFields: " << this->Impl->Cuts.size() << "\n";
  os << indent << "NumberOfRaysCast: " << this->NumberOfRaysCast << (this->LastRenderWasLocalized ? " (localized)" : "") << "\n";
  os << indent << "LastRayCastingTime: " << this->LastRayCastingTime << "\n";
}
