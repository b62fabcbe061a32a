// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutField's readers, safe while the writer cuts: sample reads, the
// curvature-corrected interpolation of signed distances, partial-volume
// removed fractions and volume, and the exports built from them (removed
// fractions per anatomy voxel, the removed region's surface).
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldInternals.h"
#include "vtkVolumeCutProtection.h"

#include "vtkFlyingEdges3D.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkTransform.h"
#include "vtkTransformPolyDataFilter.h"

#include <algorithm>
#include <cmath>
#include <limits>

using vtkVolumeCutFieldInternals::BrickSize;
using vtkVolumeCutFieldInternals::Inside;
using vtkVolumeCutFieldInternals::IsFinite;
using vtkVolumeCutFieldInternals::Outside;
using vtkVolumeCutFieldInternals::Transform;

//------------------------------------------------------------------------------
int16_t vtkVolumeCutField::ReadSample(int i, int j, int k) const
{
  if (!this->Directory || i < 0 || j < 0 || k < 0 || i >= this->Dimensions[0] || j >= this->Dimensions[1] || k >= this->Dimensions[2])
  {
    return Outside;
  }
  const vtkIdType brickId =
    (static_cast<vtkIdType>(k / BrickSize) * this->BrickDimensions[1] + j / BrickSize) * this->BrickDimensions[0] + i / BrickSize;
  const Brick* brick = this->Directory[brickId].load(std::memory_order_acquire);
  if (!brick)
  {
    return Outside;
  }
  const int local = ((k % BrickSize) * BrickSize + (j % BrickSize)) * BrickSize + (i % BrickSize);
  return brick->Values[local].load(std::memory_order_relaxed);
}

//------------------------------------------------------------------------------
template <typename SampleReader>
double vtkVolumeCutField::Interpolate(const double index[3], SampleReader&& read) const
{
  const int i0 = static_cast<int>(std::floor(index[0]));
  const int j0 = static_cast<int>(std::floor(index[1]));
  const int k0 = static_cast<int>(std::floor(index[2]));
  const double f[3] = { index[0] - i0, index[1] - j0, index[2] - k0 };
  double weights[8];
  double centers[8];
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    weights[corner] =
      ((corner & 1) ? f[0] : 1.0 - f[0]) * (((corner >> 1) & 1) ? f[1] : 1.0 - f[1]) * (((corner >> 2) & 1) ? f[2] : 1.0 - f[2]);
    if (weights[corner] == 0.0)
    {
      continue;
    }
    centers[corner] = read(i0 + (corner & 1), j0 + ((corner >> 1) & 1), k0 + ((corner >> 2) & 1));
    value += weights[corner] * centers[corner];
  }
  if (std::abs(value) * this->Quantum > this->CorrectionReach)
  {
    return value * this->Quantum;
  }
  double secondDifference[3] = { 0.0, 0.0, 0.0 };
  for (int corner = 0; corner < 8; ++corner)
  {
    const double weight = weights[corner];
    const double center = centers[corner];
    if (weight == 0.0 || center == Outside || center == Inside)
    {
      continue; // clamped: no curvature information
    }
    const int c[3] = { i0 + (corner & 1), j0 + ((corner >> 1) & 1), k0 + ((corner >> 2) & 1) };
    const double neighbors[3][2] = { { double(read(c[0] - 1, c[1], c[2])), double(read(c[0] + 1, c[1], c[2])) },
      { double(read(c[0], c[1] - 1, c[2])), double(read(c[0], c[1] + 1, c[2])) },
      { double(read(c[0], c[1], c[2] - 1)), double(read(c[0], c[1], c[2] + 1)) } };
    for (int axis = 0; axis < 3; ++axis)
    {
      if (neighbors[axis][0] != Outside && neighbors[axis][1] != Outside && neighbors[axis][0] != Inside && neighbors[axis][1] != Inside)
      {
        secondDifference[axis] += weight * (neighbors[axis][0] - 2.0 * center + neighbors[axis][1]);
      }
    }
  }
  // Linear interpolation of a curved distance field is biased by half the
  // second derivative times t(1-t) along each axis (h^2/(6R) on average for a
  // sphere of radius R); subtracting that estimate makes the reconstructed
  // surface third-order accurate.
  for (int axis = 0; axis < 3; ++axis)
  {
    value -= 0.5 * f[axis] * (1.0 - f[axis]) * secondDifference[axis];
  }
  return value * this->Quantum;
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::InterpolateAtIndex(const double index[3]) const
{
  // One interpolation reads up to 56 samples (8 corners and their curvature
  // neighbours), all in the 4x4x4 block around the cell, which spans at most
  // 2x2x2 bricks: their pointers and each row's offsets are looked up once,
  // so a read is two table lookups and a load, with the value ReadSample gives.
  const int first[3] = { static_cast<int>(std::floor(index[0])) - 1, static_cast<int>(std::floor(index[1])) - 1,
    static_cast<int>(std::floor(index[2])) - 1 };
  const bool blockInside = this->Directory && first[0] >= 0 && first[1] >= 0 && first[2] >= 0 &&
    first[0] + 3 < this->Dimensions[0] && first[1] + 3 < this->Dimensions[1] && first[2] + 3 < this->Dimensions[2];
  if (!blockInside)
  {
    return this->Interpolate(index, [this](int i, int j, int k) { return this->ReadSample(i, j, k); });
  }
  int brickOf[3][4];
  int offsetOf[3][4];
  int brickCount[3];
  constexpr int strides[3] = { 1, BrickSize, BrickSize * BrickSize };
  for (int axis = 0; axis < 3; ++axis)
  {
    const int firstBrick = first[axis] / BrickSize;
    for (int n = 0; n < 4; ++n)
    {
      brickOf[axis][n] = (first[axis] + n) / BrickSize - firstBrick;
      offsetOf[axis][n] = ((first[axis] + n) % BrickSize) * strides[axis];
    }
    brickCount[axis] = brickOf[axis][3] + 1;
  }
  const Brick* bricks[2][2][2] = {};
  for (int dk = 0; dk < brickCount[2]; ++dk)
  {
    for (int dj = 0; dj < brickCount[1]; ++dj)
    {
      for (int di = 0; di < brickCount[0]; ++di)
      {
        const vtkIdType brickId = (static_cast<vtkIdType>(first[2] / BrickSize + dk) * this->BrickDimensions[1] + first[1] / BrickSize + dj) *
            this->BrickDimensions[0] + first[0] / BrickSize + di;
        bricks[dk][dj][di] = this->Directory[brickId].load(std::memory_order_acquire);
      }
    }
  }
  return this->Interpolate(index, [&](int i, int j, int k) -> int16_t {
    const int a = i - first[0];
    const int b = j - first[1];
    const int c = k - first[2];
    const Brick* brick = bricks[brickOf[2][c]][brickOf[1][b]][brickOf[0][a]];
    return brick ? brick->Values[offsetOf[0][a] + offsetOf[1][b] + offsetOf[2][c]].load(std::memory_order_relaxed) : Outside;
  });
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::GetSignedDistance(const double ras[3]) const
{
  if (!this->Directory || !ras || !IsFinite(ras))
  {
    return this->BandWidth;
  }
  double index[3];
  Transform(this->RASToSubIJK, ras, index);
  return this->InterpolateAtIndex(index);
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::GetRemovedFraction(int i, int j, int k) const
{
  const int f = std::max(this->SubVoxelFactor, 1);
  if (this->ReadSample(i, j, k) >= 0 && i >= 0 && j >= 0 && k >= 0 && this->Protection->GetShieldLabel(i / f, j / f, k / f) != 0)
  {
    return 0.0;
  }
  return this->ComputeRemovedFraction(i, j, k);
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::ComputeRemovedFraction(int i, int j, int k) const
{
  const int16_t sample = this->ReadSample(i, j, k);
  const double distance = sample * this->Quantum;
  // No part of the surface is nearer the sample than its distance: a cell
  // whose half diagonal is shorter lies wholly on one side.
  if (std::abs(distance) >= this->HalfDiagonal)
  {
    return distance < 0.0 ? 1.0 : 0.0;
  }
  // Cut cells: average, over n^3 points of the cell, the partial-volume ramp
  // of the reconstructed distance across a sub-cell's extent along the
  // surface normal.
  const double gradientIndex[3] = { 0.5 * (this->ReadSample(i + 1, j, k) - this->ReadSample(i - 1, j, k)),
    0.5 * (this->ReadSample(i, j + 1, k) - this->ReadSample(i, j - 1, k)), 0.5 * (this->ReadSample(i, j, k + 1) - this->ReadSample(i, j, k - 1)) };
  double gradient[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    gradient[axis] =
      this->RASToSubIJK[0][axis] * gradientIndex[0] + this->RASToSubIJK[1][axis] * gradientIndex[1] + this->RASToSubIJK[2][axis] * gradientIndex[2];
  }
  const double norm = vtkMath::Norm(gradient);
  double width = 0.0;
  for (int axis = 0; axis < 3; ++axis)
  {
    width += norm > 0.0
      ? std::abs(this->SubIJKToRAS[0][axis] * gradient[0] + this->SubIJKToRAS[1][axis] * gradient[1] + this->SubIJKToRAS[2][axis] * gradient[2]) / norm
      : 0.0;
  }
  constexpr int n = 4;
  const double subWidth = std::max(width / n, 1e-12);
  // The points read samples at most two away: read those 5^3 once, not
  // up to 56 per point through the brick directory.
  int16_t block[5][5][5];
  for (int dk = 0; dk < 5; ++dk)
  {
    for (int dj = 0; dj < 5; ++dj)
    {
      for (int di = 0; di < 5; ++di)
      {
        block[dk][dj][di] = this->ReadSample(i + di - 2, j + dj - 2, k + dk - 2);
      }
    }
  }
  auto fromBlock = [&](int si, int sj, int sk) { return block[sk - k + 2][sj - j + 2][si - i + 2]; };
  double fraction = 0.0;
  for (int c = 0; c < n; ++c)
  {
    for (int b = 0; b < n; ++b)
    {
      for (int a = 0; a < n; ++a)
      {
        const double index[3] = { i - 0.5 + (a + 0.5) / n, j - 0.5 + (b + 0.5) / n, k - 0.5 + (c + 0.5) / n };
        fraction += std::min(1.0, std::max(0.0, 0.5 - this->Interpolate(index, fromBlock) / subWidth));
      }
    }
  }
  return fraction / (n * n * n);
}

//------------------------------------------------------------------------------
template <typename Visitor>
void vtkVolumeCutField::ForEachSampleOfBrickWithShield(vtkIdType brickId, Visitor&& visit) const
{
  const int f = std::max(this->SubVoxelFactor, 1);
  const int anatomyPerBrick = BrickSize / f; // bricks hold whole anatomy voxels
  uint8_t shield[BrickSize * BrickSize * BrickSize];
  int b[3];
  this->GetBrickIndex(brickId, b);
  const int voxelLower[3] = { b[0] * anatomyPerBrick, b[1] * anatomyPerBrick, b[2] * anatomyPerBrick };
  const int voxelUpper[3] = { voxelLower[0] + anatomyPerBrick - 1, voxelLower[1] + anatomyPerBrick - 1, voxelLower[2] + anatomyPerBrick - 1 };
  this->Protection->GetShieldLabels(voxelLower, voxelUpper, shield);
  for (int k = b[2] * BrickSize; k < std::min((b[2] + 1) * BrickSize, this->Dimensions[2]); ++k)
  {
    for (int j = b[1] * BrickSize; j < std::min((b[1] + 1) * BrickSize, this->Dimensions[1]); ++j)
    {
      const uint8_t* shieldRow = &shield[((k / f - voxelLower[2]) * anatomyPerBrick + (j / f - voxelLower[1])) * anatomyPerBrick];
      for (int i = b[0] * BrickSize; i < std::min((b[0] + 1) * BrickSize, this->Dimensions[0]); ++i)
      {
        visit(i, j, k, shieldRow[i / f - voxelLower[0]] != 0);
      }
    }
  }
}

//------------------------------------------------------------------------------
double vtkVolumeCutField::ComputeRemovedVolume() const
{
  if (!this->Directory)
  {
    return 0.0;
  }
  double removed = 0.0;
  const vtkIdType count = this->NumberOfAllocatedBricks.load(std::memory_order_acquire);
  for (vtkIdType n = 0; n < count; ++n)
  {
    this->ForEachSampleOfBrickWithShield(this->AllocatedBrickIds[n].load(std::memory_order_relaxed), [&](int i, int j, int k, bool shielded) {
      if (!shielded || this->ReadSample(i, j, k) < 0)
      {
        removed += this->ComputeRemovedFraction(i, j, k);
      }
    });
  }
  const double subVoxelVolume = std::abs(vtkMatrix4x4::Determinant(&this->SubIJKToRAS[0][0]));
  return removed * subVoxelVolume;
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ExportRemovedFraction(vtkImageData* anatomyFraction) const
{
  if (!anatomyFraction)
  {
    vtkErrorMacro("ExportRemovedFraction: no output image");
    return;
  }
  const int f = std::max(this->SubVoxelFactor, 1);
  const int dims[3] = { this->Dimensions[0] / f, this->Dimensions[1] / f, this->Dimensions[2] / f };
  anatomyFraction->SetOrigin(0.0, 0.0, 0.0);
  anatomyFraction->SetSpacing(1.0, 1.0, 1.0);
  anatomyFraction->SetDimensions(std::max(dims[0], 1), std::max(dims[1], 1), std::max(dims[2], 1));
  anatomyFraction->AllocateScalars(VTK_FLOAT, 1);
  vtkFloatArray* scalars = vtkFloatArray::SafeDownCast(anatomyFraction->GetPointData()->GetScalars());
  scalars->SetName("RemovedFraction");
  scalars->FillValue(0.0f);
  if (!this->Directory)
  {
    return;
  }
  vtkNew<vtkIdTypeArray> voxelIds;
  vtkNew<vtkFloatArray> fractions;
  this->ExportRemovedVoxels(voxelIds, fractions);
  float* values = scalars->GetPointer(0);
  for (vtkIdType n = 0; n < voxelIds->GetNumberOfValues(); ++n)
  {
    values[voxelIds->GetValue(n)] = fractions->GetValue(n);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ExportRemovedVoxels(vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const
{
  if (!anatomyVoxelIds || !fractions)
  {
    vtkErrorMacro("ExportRemovedVoxels: no output arrays");
    return;
  }
  anatomyVoxelIds->Reset();
  fractions->Reset();
  fractions->SetName("RemovedFraction");
  const vtkIdType count = this->Directory ? this->NumberOfAllocatedBricks.load(std::memory_order_acquire) : 0;
  for (vtkIdType n = 0; n < count; ++n)
  {
    this->AppendRemovedVoxelsOfBrick(this->AllocatedBrickIds[n].load(std::memory_order_relaxed), anatomyVoxelIds, fractions);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::AppendRemovedVoxelsOfBrick(vtkIdType brickId, vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const
{
  const vtkIdType total = static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1] * this->BrickDimensions[2];
  if (!anatomyVoxelIds || !fractions || !this->Directory || brickId < 0 || brickId >= total ||
    !this->Directory[brickId].load(std::memory_order_acquire))
  {
    return;
  }
  // Bricks hold whole anatomy voxels: sum each voxel's sub-voxels here.
  const int f = std::max(this->SubVoxelFactor, 1);
  const int anatomyPerBrick = BrickSize / f;
  const int dims[3] = { this->Dimensions[0] / f, this->Dimensions[1] / f, this->Dimensions[2] / f };
  int b[3];
  this->GetBrickIndex(brickId, b);
  double sums[BrickSize * BrickSize * BrickSize] = {};
  this->ForEachSampleOfBrickWithShield(brickId, [&](int i, int j, int k, bool shielded) {
    if (shielded && this->ReadSample(i, j, k) >= 0)
    {
      return;
    }
    const int local = ((k / f - b[2] * anatomyPerBrick) * anatomyPerBrick + (j / f - b[1] * anatomyPerBrick)) * anatomyPerBrick + (i / f - b[0] * anatomyPerBrick);
    sums[local] += this->ComputeRemovedFraction(i, j, k);
  });
  const double perSubVoxel = 1.0 / (f * f * f);
  for (int local = 0; local < anatomyPerBrick * anatomyPerBrick * anatomyPerBrick; ++local)
  {
    const int v[3] = { b[0] * anatomyPerBrick + local % anatomyPerBrick, b[1] * anatomyPerBrick + (local / anatomyPerBrick) % anatomyPerBrick,
      b[2] * anatomyPerBrick + local / (anatomyPerBrick * anatomyPerBrick) };
    if (sums[local] > 0.0 && v[0] < dims[0] && v[1] < dims[1] && v[2] < dims[2])
    {
      anatomyVoxelIds->InsertNextValue((static_cast<vtkIdType>(v[2]) * dims[1] + v[1]) * dims[0] + v[0]);
      fractions->InsertNextValue(static_cast<float>(std::min(1.0, sums[local] * perSubVoxel)));
    }
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutField::ExtractRemovedSurface(vtkPolyData* surface) const
{
  if (!surface)
  {
    return;
  }
  surface->Initialize();
  const vtkIdType count = this->NumberOfAllocatedBricks.load(std::memory_order_acquire);
  if (!this->Directory || count == 0)
  {
    return;
  }
  // Sub-voxel box of the allocated bricks, one sample wider on each side so
  // that the surface closes where the removed region meets the volume's edge.
  int lower[3] = { std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), std::numeric_limits<int>::max() };
  int upper[3] = { std::numeric_limits<int>::min(), std::numeric_limits<int>::min(), std::numeric_limits<int>::min() };
  for (vtkIdType n = 0; n < count; ++n)
  {
    const vtkIdType brickId = this->AllocatedBrickIds[n].load(std::memory_order_relaxed);
    int b[3];
    this->GetBrickIndex(brickId, b);
    for (int axis = 0; axis < 3; ++axis)
    {
      lower[axis] = std::min(lower[axis], b[axis] * BrickSize - 1);
      upper[axis] = std::max(upper[axis], b[axis] * BrickSize + BrickSize);
    }
  }
  vtkNew<vtkImageData> samples;
  samples->SetExtent(lower[0], upper[0], lower[1], upper[1], lower[2], upper[2]);
  samples->AllocateScalars(VTK_FLOAT, 1);
  float* values = static_cast<float*>(samples->GetScalarPointer());
  vtkIdType index = 0;
  for (int k = lower[2]; k <= upper[2]; ++k)
  {
    for (int j = lower[1]; j <= upper[1]; ++j)
    {
      for (int i = lower[0]; i <= upper[0]; ++i, ++index)
      {
        values[index] = static_cast<float>(this->ReadSample(i, j, k) * this->Quantum);
      }
    }
  }
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(samples);
  contour->SetValue(0, 0.0);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  // Index space to RAS.
  vtkNew<vtkTransform> subToRas;
  subToRas->SetMatrix(&this->SubIJKToRAS[0][0]);
  vtkNew<vtkTransformPolyDataFilter> toRas;
  toRas->SetInputConnection(contour->GetOutputPort());
  toRas->SetTransform(subToRas);
  toRas->Update();
  surface->ShallowCopy(toRas->GetOutput());
}
