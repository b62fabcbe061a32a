// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutBoneAhead.h"
#include "vtkVolumeCutField.h"

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkType.h>

#include <algorithm>
#include <cmath>
#include <limits>

vtkStandardNewMacro(vtkVolumeCutBoneAhead);

namespace
{
// The renderer's march (vtkVolumeCutThinBoneShader): quarter-voxel steps, six halvings of the last one.
constexpr double StepInVoxels = 0.25;
constexpr int CrossingHalvings = 6;

void TransformPoint(const double m[16], const double p[3], double out[3])
{
  for (int row = 0; row < 3; ++row)
  {
    out[row] = m[4 * row] * p[0] + m[4 * row + 1] * p[1] + m[4 * row + 2] * p[2] + m[4 * row + 3];
  }
}

template <typename T>
size_t CopyNonZero(const T* values, std::vector<uint8_t>& mask)
{
  size_t nonZero = 0;
  for (size_t n = 0; n < mask.size(); ++n)
  {
    mask[n] = values[n] != T(0) ? 1 : 0;
    nonZero += mask[n];
  }
  return nonZero;
}

void TransformVector(const double m[16], const double v[3], double out[3])
{
  for (int row = 0; row < 3; ++row)
  {
    out[row] = m[4 * row] * v[0] + m[4 * row + 1] * v[1] + m[4 * row + 2] * v[2];
  }
}
} // namespace

//------------------------------------------------------------------------------
vtkVolumeCutBoneAhead::vtkVolumeCutBoneAhead()
{
  vtkMatrix4x4::Identity(this->IJKToRAS);
  vtkMatrix4x4::Identity(this->RASToIJK);
}

//------------------------------------------------------------------------------
vtkVolumeCutBoneAhead::~vtkVolumeCutBoneAhead() = default;

//------------------------------------------------------------------------------
bool vtkVolumeCutBoneAhead::SetBone(vtkImageData* labels, vtkMatrix4x4* ijkToRAS)
{
  if (!ijkToRAS)
  {
    vtkErrorMacro("SetBone: no IJK-to-RAS matrix");
    return false;
  }
  if (!(std::abs(ijkToRAS->Determinant()) > 0.0) || !std::isfinite(ijkToRAS->Determinant()))
  {
    vtkErrorMacro("SetBone: the IJK-to-RAS matrix cannot be inverted (a zero spacing?)");
    return false;
  }
  vtkDataArray* scalars = labels && labels->GetPointData() ? labels->GetPointData()->GetScalars() : nullptr;
  if (!scalars || scalars->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro("SetBone: the bone labels must be an image with one scalar component");
    return false;
  }
  std::vector<uint8_t> mask(static_cast<size_t>(scalars->GetNumberOfTuples()));
  size_t boneVoxels = 0;
  // Read in the array's own type: a scan's label map has tens of millions of voxels.
  switch (scalars->GetDataType())
  {
    vtkTemplateMacro(boneVoxels = CopyNonZero(static_cast<const VTK_TT*>(scalars->GetVoidPointer(0)), mask));
    default:
      vtkErrorMacro("SetBone: the bone labels' scalar type " << scalars->GetDataTypeAsString() << " is not a number");
      return false;
  }
  if (boneVoxels == 0)
  {
    vtkErrorMacro("SetBone: the bone labels hold no bone voxel");
    return false;
  }
  this->Mask.swap(mask);
  labels->GetExtent(this->Extent);
  vtkMatrix4x4::DeepCopy(this->IJKToRAS, ijkToRAS);
  vtkMatrix4x4::Invert(this->IJKToRAS, this->RASToIJK);
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutBoneAhead::SetCutField(vtkVolumeCutField* field)
{
  if (this->CutField != field)
  {
    this->CutField = field;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkVolumeCutField* vtkVolumeCutBoneAhead::GetCutField()
{
  return this->CutField;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutBoneAhead::BoneAt(const double index[3], const double ras[3]) const
{
  // The mask trilinearly interpolated: bone where at least one half.
  int base[3];
  double f[3];
  int size[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    size[axis] = this->Extent[2 * axis + 1] - this->Extent[2 * axis] + 1;
    const double local = index[axis] - this->Extent[2 * axis];
    if (local < 0.0 || local > size[axis] - 1)
    {
      return false;
    }
    base[axis] = std::min(static_cast<int>(local), std::max(size[axis] - 2, 0));
    f[axis] = local - base[axis];
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    double weight = 1.0;
    vtkIdType offset = 0;
    vtkIdType stride = 1;
    for (int axis = 0; axis < 3; ++axis)
    {
      const int high = (corner >> axis) & 1;
      weight *= high ? f[axis] : 1.0 - f[axis];
      offset += std::min(base[axis] + high, size[axis] - 1) * stride;
      stride *= size[axis];
    }
    if (weight > 0.0)
    {
      value += weight * this->Mask[offset];
    }
  }
  if (value < 0.5)
  {
    return false;
  }
  vtkVolumeCutField* field = this->CutField;
  return !field || field->GetSignedDistance(ras) >= 0.0;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutBoneAhead::IsBone(const double ras[3]) const
{
  if (this->Mask.empty())
  {
    return false;
  }
  double index[3];
  TransformPoint(this->RASToIJK, ras, index);
  return this->BoneAt(index, ras);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutBoneAhead::BoneAlong(const Line& line, double t, bool& outside) const
{
  double index[3];
  double ras[3];
  outside = false;
  for (int axis = 0; axis < 3; ++axis)
  {
    index[axis] = line.StartIndex[axis] + t * line.DirectionIndex[axis];
    ras[axis] = line.Start[axis] + t * line.Direction[axis];
    if (index[axis] < this->Extent[2 * axis] || index[axis] > this->Extent[2 * axis + 1])
    {
      outside = true;
    }
  }
  return !outside && this->BoneAt(index, ras);
}

//------------------------------------------------------------------------------
double vtkVolumeCutBoneAhead::Crossing(const Line& line, double t0, double t1, bool boneAtT1) const
{
  bool outside = false;
  for (int halving = 0; halving < CrossingHalvings; ++halving)
  {
    const double middle = 0.5 * (t0 + t1);
    (this->BoneAlong(line, middle, outside) == boneAtT1 ? t1 : t0) = middle;
  }
  return 0.5 * (t0 + t1);
}

//------------------------------------------------------------------------------
double vtkVolumeCutBoneAhead::Measure(const double start[3], const double direction[3]) const
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double length = vtkMath::Norm(direction);
  if (this->Mask.empty())
  {
    vtkErrorMacro("Measure: no bone (SetBone first)");
    return nan;
  }
  if (!(length > 0.0) || !std::isfinite(length))
  {
    vtkErrorMacro("Measure: the direction (" << direction[0] << ", " << direction[1] << ", " << direction[2] << ") has no length");
    return nan;
  }
  Line line;
  for (int axis = 0; axis < 3; ++axis)
  {
    line.Start[axis] = start[axis];
    line.Direction[axis] = direction[axis] / length;
  }
  TransformPoint(this->RASToIJK, line.Start, line.StartIndex);
  TransformVector(this->RASToIJK, line.Direction, line.DirectionIndex);
  const double step = StepInVoxels / vtkMath::Norm(line.DirectionIndex);
  const double infinity = std::numeric_limits<double>::infinity();

  // Where the bone begins: at the start (the burr pressed into uncut bone) or within Range.
  bool outside = false;
  double entry = infinity;
  if (this->BoneAlong(line, 0.0, outside))
  {
    entry = 0.0;
  }
  else
  {
    for (double t = step; t <= this->Range + step && entry == infinity; t += step)
    {
      if (this->BoneAlong(line, t, outside))
      {
        entry = this->Crossing(line, t - step, t, true);
      }
    }
  }
  this->LastGap = entry;
  if (entry > this->Range)
  {
    return infinity;
  }
  // Where it ends: a wall at least MaximumThickness thick, or one going on beyond the scan, reads as that.
  double inside = entry;
  for (double t = entry + step; t - entry < this->MaximumThickness; t += step)
  {
    if (!this->BoneAlong(line, t, outside))
    {
      if (outside)
      {
        return this->MaximumThickness;
      }
      return std::min(this->Crossing(line, inside, t, false) - entry, this->MaximumThickness);
    }
    inside = t;
  }
  return this->MaximumThickness;
}

//------------------------------------------------------------------------------
void vtkVolumeCutBoneAhead::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Bone voxels: " << std::count(this->Mask.begin(), this->Mask.end(), uint8_t(1)) << " of " << this->Mask.size() << "\n";
  os << indent << "CutField: " << this->CutField.GetPointer() << "\n";
  os << indent << "Range: " << this->Range << " mm\n";
  os << indent << "MaximumThickness: " << this->MaximumThickness << " mm\n";
}
