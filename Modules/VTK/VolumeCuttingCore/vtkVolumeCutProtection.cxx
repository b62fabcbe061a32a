// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutProtectionBrick.h"
#include "vtkVolumeCutSliceDistance.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

vtkStandardNewMacro(vtkVolumeCutProtection);

namespace
{
constexpr int BrickSize = vtkVolumeCutField::BrickSize;

/// Reads the labels of one image's voxels inside the box into the box's label
/// array, keeping the highest label where several structures overlap.
template <typename T>
void ReadLabels(const T* first, const vtkIdType increments[3], const int count[3], const std::vector<uint8_t>& table, uint8_t* labels,
  const int labelIncrements[3])
{
  const vtkIdType tableSize = static_cast<vtkIdType>(table.size());
  for (int z = 0; z < count[2]; ++z)
  {
    for (int y = 0; y < count[1]; ++y)
    {
      const T* voxel = first + z * increments[2] + y * increments[1];
      uint8_t* label = labels + z * labelIncrements[2] + y * labelIncrements[1];
      for (int x = 0; x < count[0]; ++x, voxel += increments[0], ++label)
      {
        const vtkIdType value = static_cast<vtkIdType>(*voxel);
        if (value > 0 && value < tableSize)
        {
          *label = std::max(*label, table[value]);
        }
      }
    }
  }
}
} // namespace

//------------------------------------------------------------------------------
struct vtkVolumeCutProtection::Scratch
{
  std::vector<uint8_t> Labels;
  std::vector<float> Along[3];
  std::vector<float> PassX;
  std::vector<uint8_t> LabelX;
  std::vector<float> PassY;
  std::vector<uint8_t> LabelY;
  std::vector<int> Wanted;
  std::vector<uint8_t> RowFound;
  std::vector<uint8_t> SliceFound;
  std::vector<uint8_t> SliceInside;
  /// The smoothed in-slice distance of every slice of the window, and after the ends' extrapolation.
  std::vector<double> SliceDistance;
  std::vector<double> Extrapolated;
  std::vector<double> Normalized;
  vtkVolumeCutSliceDistance::Scratch Slice;
};

//------------------------------------------------------------------------------
vtkVolumeCutProtection::vtkVolumeCutProtection()
  : SmoothingKernel(vtkVolumeCutSliceDistance::GaussianKernel(1.0))
  , BuildScratch(new Scratch)
  , PrepareScratch(new Scratch)
{
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::SetSurfaceSmoothing(double sigma)
{
  const double clamped = std::max(0.0, std::min(8.0, std::isfinite(sigma) ? sigma : 0.0));
  if (clamped == this->SurfaceSmoothing)
  {
    return;
  }
  this->SurfaceSmoothing = clamped;
  this->SmoothingKernel = clamped > 0.0 ? vtkVolumeCutSliceDistance::GaussianKernel(clamped) : std::vector<double>();
  this->ClearBricks();
  this->Modified();
}

//------------------------------------------------------------------------------
vtkVolumeCutProtection::~vtkVolumeCutProtection()
{
  this->ReleaseBricks();
}

//------------------------------------------------------------------------------
int vtkVolumeCutProtection::AddLabelImage(vtkImageData* image)
{
  vtkDataArray* scalars = image ? image->GetPointData()->GetScalars() : nullptr;
  if (!scalars || !scalars->IsIntegral() || scalars->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro("AddLabelImage: a label image needs one integer scalar component");
    return -1;
  }
  LabelImage entry;
  entry.Image = image;
  this->LabelImages.push_back(std::move(entry));
  this->ClearBricks();
  this->Modified();
  return static_cast<int>(this->LabelImages.size()) - 1;
}

//------------------------------------------------------------------------------
vtkImageData* vtkVolumeCutProtection::GetLabelImage(int index) const
{
  return index >= 0 && index < this->GetNumberOfLabelImages() ? this->LabelImages[index].Image.GetPointer() : nullptr;
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::RemoveAllLabelImages()
{
  if (this->LabelImages.empty())
  {
    return;
  }
  this->LabelImages.clear();
  this->ClearBricks();
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutProtection::SetShieldLabel(int imageIndex, int value, int label)
{
  if (imageIndex < 0 || imageIndex >= this->GetNumberOfLabelImages())
  {
    vtkErrorMacro("SetShieldLabel: there is no label image " << imageIndex);
    return false;
  }
  if (value < 1 || value > MaximumLabelValue || label < 0 || label > 255)
  {
    vtkErrorMacro("SetShieldLabel: value " << value << " (1.." << MaximumLabelValue << ") or structure label " << label << " (0..255) is out of range");
    return false;
  }
  std::vector<uint8_t>& table = this->LabelImages[imageIndex].Labels;
  if (static_cast<int>(table.size()) <= value)
  {
    if (label == 0)
    {
      return true;
    }
    table.resize(static_cast<size_t>(value) + 1, 0);
  }
  if (table[value] == label)
  {
    return true;
  }
  table[value] = static_cast<uint8_t>(label);
  this->ClearBricks();
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::RemoveAllShieldLabels()
{
  if (!this->HasShieldedLabels())
  {
    return;
  }
  for (LabelImage& entry : this->LabelImages)
  {
    entry.Labels.clear();
  }
  this->ClearBricks();
  this->Modified();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutProtection::HasShieldedLabels() const
{
  for (const LabelImage& entry : this->LabelImages)
  {
    if (std::any_of(entry.Labels.begin(), entry.Labels.end(), [](uint8_t label) { return label != 0; }))
    {
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::GetShieldLabels(const int voxelLower[3], const int voxelUpper[3], uint8_t* labels) const
{
  const int size[3] = { voxelUpper[0] - voxelLower[0] + 1, voxelUpper[1] - voxelLower[1] + 1, voxelUpper[2] - voxelLower[2] + 1 };
  if (size[0] <= 0 || size[1] <= 0 || size[2] <= 0)
  {
    return;
  }
  std::fill(labels, labels + static_cast<size_t>(size[0]) * size[1] * size[2], uint8_t(0));
  const int labelIncrements[3] = { 1, size[0], size[0] * size[1] };
  for (const LabelImage& entry : this->LabelImages)
  {
    if (entry.Labels.empty())
    {
      continue;
    }
    vtkImageData* image = entry.Image;
    int extent[6];
    image->GetExtent(extent);
    int lower[3];
    int count[3];
    bool empty = false;
    for (int axis = 0; axis < 3; ++axis)
    {
      // Only the anatomy's voxels can be shielded.
      lower[axis] = std::max({ voxelLower[axis], extent[2 * axis], 0 });
      const int upper = std::min({ voxelUpper[axis], extent[2 * axis + 1], this->AnatomyDimensions[axis] - 1 });
      count[axis] = upper - lower[axis] + 1;
      empty |= count[axis] <= 0;
    }
    if (empty)
    {
      continue;
    }
    vtkIdType increments[3];
    image->GetIncrements(increments);
    void* first = image->GetScalarPointer(lower[0], lower[1], lower[2]);
    uint8_t* target = labels + (lower[0] - voxelLower[0]) * labelIncrements[0] + (lower[1] - voxelLower[1]) * labelIncrements[1] +
      (lower[2] - voxelLower[2]) * labelIncrements[2];
    switch (image->GetScalarType())
    {
      vtkTemplateMacro(ReadLabels(static_cast<const VTK_TT*>(first), increments, count, entry.Labels, target, labelIncrements));
    }
  }
}

//------------------------------------------------------------------------------
int vtkVolumeCutProtection::GetShieldLabel(int i, int j, int k) const
{
  const int voxel[3] = { i, j, k };
  uint8_t label = 0;
  this->GetShieldLabels(voxel, voxel, &label);
  return label;
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::SetFieldGeometry(
  const int anatomyDimensions[3], int subVoxelFactor, const double anatomySpacing[3], double bandWidth, double quantum)
{
  for (int axis = 0; axis < 3; ++axis)
  {
    this->AnatomyDimensions[axis] = anatomyDimensions[axis];
    this->AnatomySpacing[axis] = anatomySpacing[axis];
    this->BrickDimensions[axis] = (anatomyDimensions[axis] * subVoxelFactor + BrickSize - 1) / BrickSize;
    // Voxels farther than the band along an axis cannot be within the band.
    this->Reach[axis] = static_cast<int>(std::ceil(bandWidth / anatomySpacing[axis])) + 1;
  }
  this->SubVoxelFactor = subVoxelFactor;
  this->BandWidth = bandWidth;
  this->Quantum = quantum;
  std::lock_guard<std::mutex> preparer(this->PreparerMutex);
  this->ReleaseBricks();
  const vtkIdType size = static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1] * this->BrickDimensions[2];
  if (size != this->DirectorySize)
  {
    this->Directory.reset(size > 0 ? new std::atomic<Brick*>[size] : nullptr);
    this->DirectorySize = size > 0 ? size : 0;
    for (vtkIdType n = 0; n < this->DirectorySize; ++n)
    {
      this->Directory[n].store(nullptr, std::memory_order_relaxed);
    }
  }
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::ClearBricks()
{
  std::lock_guard<std::mutex> preparer(this->PreparerMutex);
  this->ReleaseBricks();
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::ReleaseBricks()
{
  Brick* const freeBrick = FreeBrick();
  for (vtkIdType n = 0; n < this->DirectorySize; ++n)
  {
    Brick* brick = this->Directory[n].exchange(nullptr, std::memory_order_acq_rel);
    if (brick != freeBrick)
    {
      delete brick;
    }
  }
  this->BuiltBricks.store(0, std::memory_order_release);
  this->ShieldBricks.store(0, std::memory_order_release);
  this->PreparedBricks.store(0, std::memory_order_release);
  this->BricksBuiltOnDemand = 0;
}

//------------------------------------------------------------------------------
vtkVolumeCutProtection::Brick* vtkVolumeCutProtection::FreeBrick()
{
  // An address no brick can have; only compared, never read.
  static char mark;
  return reinterpret_cast<Brick*>(&mark);
}

//------------------------------------------------------------------------------
const vtkVolumeCutProtection::Brick* vtkVolumeCutProtection::Publish(vtkIdType brickId, std::unique_ptr<Brick> built)
{
  Brick* const value = built ? built.get() : FreeBrick();
  Brick* expected = nullptr;
  if (this->Directory[brickId].compare_exchange_strong(expected, value, std::memory_order_acq_rel, std::memory_order_acquire))
  {
    const bool shielded = built != nullptr;
    built.release(); // the directory owns it now
    this->BuiltBricks.fetch_add(1, std::memory_order_acq_rel);
    this->ShieldBricks.fetch_add(shielded ? 1 : 0, std::memory_order_acq_rel);
    return shielded ? value : nullptr;
  }
  // The other side was first: its brick is the same shield; ours is dropped.
  return expected == FreeBrick() ? nullptr : expected;
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutProtection::PrepareBricks(const vtkIdType* brickIds, vtkIdType count)
{
  if (!brickIds || count <= 0 || this->SubVoxelFactor < 1 || this->LabelImages.empty())
  {
    return 0;
  }
  std::lock_guard<std::mutex> preparer(this->PreparerMutex);
  vtkIdType built = 0;
  for (vtkIdType n = 0; n < count; ++n)
  {
    const vtkIdType brickId = brickIds[n];
    if (brickId < 0 || brickId >= this->DirectorySize || this->Directory[brickId].load(std::memory_order_acquire))
    {
      continue;
    }
    this->Publish(brickId, this->BuildBrick(brickId, *this->PrepareScratch));
    ++built;
    this->PreparedBricks.fetch_add(1, std::memory_order_acq_rel);
  }
  return built;
}

//------------------------------------------------------------------------------
const vtkVolumeCutProtection::Brick* vtkVolumeCutProtection::GetBrick(vtkIdType brickId)
{
  if (this->SubVoxelFactor < 1 || this->LabelImages.empty() || brickId < 0 || brickId >= this->DirectorySize)
  {
    return nullptr;
  }
  Brick* const found = this->Directory[brickId].load(std::memory_order_acquire);
  if (found)
  {
    return found == FreeBrick() ? nullptr : found;
  }
  ++this->BricksBuiltOnDemand;
  return this->Publish(brickId, this->BuildBrick(brickId, *this->BuildScratch));
}

//------------------------------------------------------------------------------
std::unique_ptr<vtkVolumeCutProtection::Brick> vtkVolumeCutProtection::BuildBrick(vtkIdType brickId, Scratch& scratch) const
{
  return this->SurfaceSmoothing > 0.0 ? this->BuildSmoothedBrick(brickId, scratch) : this->BuildVoxelFaceBrick(brickId, scratch);
}

//------------------------------------------------------------------------------
std::unique_ptr<vtkVolumeCutProtection::Brick> vtkVolumeCutProtection::BuildVoxelFaceBrick(vtkIdType brickId, Scratch& scratch) const
{
  const int f = this->SubVoxelFactor;
  const int brickIndex[3] = { static_cast<int>(brickId % this->BrickDimensions[0]),
    static_cast<int>((brickId / this->BrickDimensions[0]) % this->BrickDimensions[1]),
    static_cast<int>(brickId / (static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1])) };
  // Per axis: each sample's continuous anatomy index, the voxel it lies in,
  // and the box of voxels within the band of any sample.
  double position[3][BrickSize];
  int own[3][BrickSize];
  int lower[3];
  int upper[3];
  int size[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    for (int n = 0; n < BrickSize; ++n)
    {
      position[axis][n] = (brickIndex[axis] * BrickSize + n + 0.5) / f - 0.5;
      own[axis][n] = static_cast<int>(std::lround(position[axis][n]));
    }
    lower[axis] = own[axis][0] - this->Reach[axis];
    upper[axis] = own[axis][BrickSize - 1] + this->Reach[axis];
    size[axis] = upper[axis] - lower[axis] + 1;
  }
  const size_t blockCount = static_cast<size_t>(size[0]) * size[1] * size[2];
  scratch.Labels.resize(blockCount);
  uint8_t* labels = scratch.Labels.data();
  this->GetShieldLabels(lower, upper, labels);
  if (std::none_of(labels, labels + blockCount, [](uint8_t label) { return label != 0; }))
  {
    return nullptr; // nothing shielded within the band: the tool cuts freely
  }
  auto labelAt = [&](int x, int y, int z) { return labels[(static_cast<size_t>(z) * size[1] + y) * size[0] + x]; };

  // Which distances are needed: to shielded cubes from samples outside them,
  // to free cubes from samples inside.
  bool needed[2] = { false, false };
  for (int p = 0; p < BrickSize; ++p)
  {
    for (int m = 0; m < BrickSize; ++m)
    {
      for (int n = 0; n < BrickSize; ++n)
      {
        needed[labelAt(own[0][n] - lower[0], own[1][m] - lower[1], own[2][p] - lower[2]) != 0 ? 1 : 0] = true;
      }
    }
  }

  // Squared distance along one axis from a sample to a voxel cube (cubes
  // span the voxel's index +-0.5).
  for (int axis = 0; axis < 3; ++axis)
  {
    scratch.Along[axis].resize(static_cast<size_t>(BrickSize) * size[axis]);
    for (int n = 0; n < BrickSize; ++n)
    {
      for (int c = 0; c < size[axis]; ++c)
      {
        const float excess = static_cast<float>(std::max(0.0, std::abs(position[axis][n] - (lower[axis] + c)) - 0.5) * this->AnatomySpacing[axis]);
        scratch.Along[axis][static_cast<size_t>(n) * size[axis] + c] = excess * excess;
      }
    }
  }

  // The distance to a union of cubes is a minimum over a product of axes, so
  // it separates: min over x, then over y, then over z, each with its own
  // sample positions (Saito and Toriwaki's decomposition on the cubes'
  // per-axis excess). Rows, columns and slices holding none of the wanted
  // cubes are skipped: near a long thin structure most are empty.
  constexpr float Far = std::numeric_limits<float>::max();
  scratch.PassX.resize(static_cast<size_t>(size[2]) * size[1] * BrickSize);
  scratch.LabelX.resize(scratch.PassX.size());
  scratch.PassY.resize(static_cast<size_t>(size[2]) * BrickSize * BrickSize);
  scratch.LabelY.resize(scratch.PassY.size());
  scratch.Wanted.resize(static_cast<size_t>(size[0]));
  scratch.RowFound.resize(static_cast<size_t>(size[2]) * size[1]);
  scratch.SliceFound.resize(static_cast<size_t>(size[2]));
  float nearest[2][Brick::Samples];
  uint8_t nearestLabel[Brick::Samples];
  for (int set = 0; set < 2; ++set)
  {
    if (!needed[set])
    {
      continue;
    }
    const bool towardShielded = set == 0;
    for (int z = 0; z < size[2]; ++z)
    {
      bool sliceFound = false;
      for (int y = 0; y < size[1]; ++y)
      {
        int wantedCount = 0;
        const uint8_t* row = labels + (static_cast<size_t>(z) * size[1] + y) * size[0];
        for (int x = 0; x < size[0]; ++x)
        {
          if ((row[x] != 0) == towardShielded)
          {
            scratch.Wanted[wantedCount++] = x;
          }
        }
        const size_t rowIndex = static_cast<size_t>(z) * size[1] + y;
        scratch.RowFound[rowIndex] = wantedCount > 0;
        sliceFound |= wantedCount > 0;
        float* out = &scratch.PassX[rowIndex * BrickSize];
        uint8_t* outLabel = &scratch.LabelX[rowIndex * BrickSize];
        for (int n = 0; n < BrickSize; ++n)
        {
          const float* cost = &scratch.Along[0][static_cast<size_t>(n) * size[0]];
          float best = Far;
          uint8_t bestLabel = 0;
          for (int w = 0; w < wantedCount; ++w)
          {
            const int x = scratch.Wanted[w];
            if (cost[x] < best)
            {
              best = cost[x];
              bestLabel = row[x];
            }
          }
          out[n] = best;
          outLabel[n] = bestLabel;
        }
      }
      scratch.SliceFound[z] = sliceFound;
    }
    for (int z = 0; z < size[2]; ++z)
    {
      for (int m = 0; m < BrickSize; ++m)
      {
        const float* cost = &scratch.Along[1][static_cast<size_t>(m) * size[1]];
        float* out = &scratch.PassY[(static_cast<size_t>(z) * BrickSize + m) * BrickSize];
        uint8_t* outLabel = &scratch.LabelY[(static_cast<size_t>(z) * BrickSize + m) * BrickSize];
        std::fill(out, out + BrickSize, Far);
        std::fill(outLabel, outLabel + BrickSize, uint8_t(0));
        if (!scratch.SliceFound[z])
        {
          continue;
        }
        for (int y = 0; y < size[1]; ++y)
        {
          const size_t rowIndex = static_cast<size_t>(z) * size[1] + y;
          if (!scratch.RowFound[rowIndex])
          {
            continue;
          }
          const float* from = &scratch.PassX[rowIndex * BrickSize];
          const uint8_t* fromLabel = &scratch.LabelX[rowIndex * BrickSize];
          for (int n = 0; n < BrickSize; ++n)
          {
            const float candidate = cost[y] + from[n];
            if (candidate < out[n])
            {
              out[n] = candidate;
              outLabel[n] = fromLabel[n];
            }
          }
        }
      }
    }
    for (int p = 0; p < BrickSize; ++p)
    {
      const float* cost = &scratch.Along[2][static_cast<size_t>(p) * size[2]];
      float* out = nearest[set] + p * BrickSize * BrickSize;
      uint8_t* outLabel = nearestLabel + p * BrickSize * BrickSize;
      std::fill(out, out + BrickSize * BrickSize, Far);
      if (towardShielded)
      {
        std::fill(outLabel, outLabel + BrickSize * BrickSize, uint8_t(0));
      }
      for (int z = 0; z < size[2]; ++z)
      {
        if (!scratch.SliceFound[z])
        {
          continue;
        }
        const float* from = &scratch.PassY[static_cast<size_t>(z) * BrickSize * BrickSize];
        const uint8_t* fromLabel = &scratch.LabelY[static_cast<size_t>(z) * BrickSize * BrickSize];
        for (int mn = 0; mn < BrickSize * BrickSize; ++mn)
        {
          const float candidate = cost[z] + from[mn];
          if (candidate < out[mn])
          {
            out[mn] = candidate;
            if (towardShielded)
            {
              outLabel[mn] = fromLabel[mn];
            }
          }
        }
      }
    }
  }

  std::unique_ptr<Brick> brick(new Brick);
  const double inverseQuantum = 1.0 / this->Quantum;
  bool useful = false;
  for (int p = 0; p < BrickSize; ++p)
  {
    for (int m = 0; m < BrickSize; ++m)
    {
      for (int n = 0; n < BrickSize; ++n)
      {
        const int local = (p * BrickSize + m) * BrickSize + n;
        const uint8_t ownLabel = labelAt(own[0][n] - lower[0], own[1][m] - lower[1], own[2][p] - lower[2]);
        // Inside: the distance to the nearest free cube; outside: to the
        // nearest shielded one. Voxels beyond the box are beyond the band.
        const float squared = nearest[ownLabel != 0 ? 1 : 0][local];
        const double distance = squared >= Far ? this->BandWidth : std::min(this->BandWidth, std::sqrt(static_cast<double>(squared)));
        const double signedDistance = ownLabel != 0 ? -distance : distance;
        brick->Distance[local] = static_cast<int16_t>(std::lround(signedDistance * inverseQuantum));
        brick->Label[local] = ownLabel != 0 ? ownLabel : nearestLabel[local];
        useful |= signedDistance < this->BandWidth;
      }
    }
  }
  return useful ? std::move(brick) : nullptr;
}

//------------------------------------------------------------------------------
std::unique_ptr<vtkVolumeCutProtection::Brick> vtkVolumeCutProtection::BuildSmoothedBrick(vtkIdType brickId, Scratch& scratch) const
{
  const int f = this->SubVoxelFactor;
  const int brickIndex[3] = { static_cast<int>(brickId % this->BrickDimensions[0]),
    static_cast<int>((brickId / this->BrickDimensions[0]) % this->BrickDimensions[1]),
    static_cast<int>(brickId / (static_cast<vtkIdType>(this->BrickDimensions[0]) * this->BrickDimensions[1])) };
  const double* spacing = this->AnatomySpacing;
  // Slices across the axis of largest spacing, as the renderer's smoothing.
  int w = 2;
  for (int axis = 1; axis >= 0; --axis)
  {
    w = spacing[axis] > spacing[w] ? axis : w;
  }
  const int u = w == 0 ? 1 : 0;
  const int v = w == 2 ? 1 : 2;
  const std::vector<double>& kernel = this->SmoothingKernel;
  const int kernelRadius = static_cast<int>(kernel.size() / 2);
  // The in-slice distance is needed exactly up to the band plus what the
  // Gaussian and the interpolation reach; beyond, it is bounded. The window
  // holds every outline within that bound of the pixels used, so that
  // neighbouring bricks find the same surface on their common faces.
  const double bound = this->BandWidth + (kernelRadius + 2) * std::max(spacing[u], spacing[v]);

  // Per axis: each sample's continuous anatomy index, the voxel centre below
  // it (the interpolation's first corner), the voxel it lies in, and the window.
  double position[3][BrickSize];
  int below[3][BrickSize];
  int own[3][BrickSize];
  int lower[3];
  int upper[3];
  int size[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    for (int n = 0; n < BrickSize; ++n)
    {
      position[axis][n] = (brickIndex[axis] * BrickSize + n + 0.5) / f - 0.5;
      below[axis][n] = static_cast<int>(std::floor(position[axis][n]));
      own[axis][n] = static_cast<int>(std::lround(position[axis][n]));
    }
    // Along the slices' normal two more slices each side for the ends'
    // extrapolation, beyond the one the gradient reads.
    const int margin = axis == w ? 3 : static_cast<int>(std::ceil(bound / spacing[axis])) + kernelRadius + 1;
    lower[axis] = below[axis][0] - margin;
    upper[axis] = below[axis][BrickSize - 1] + 1 + margin;
    size[axis] = upper[axis] - lower[axis] + 1;
  }
  // Most bricks a tool reaches hold no shield: find them from a smaller box
  // first. The smoothed surface lies within the Gaussian's mean reach
  // (1.25 sigma in a slice) and half a voxel of the voxel faces; two voxels
  // more cover the interpolation and the gradient's normalisation.
  {
    const double maximumSpacing = std::max({ spacing[0], spacing[1], spacing[2] });
    const double reach = this->BandWidth + (1.25 * this->SurfaceSmoothing + 2.5) * maximumSpacing;
    int nearLower[3];
    int nearUpper[3];
    size_t nearCount = 1;
    for (int axis = 0; axis < 3; ++axis)
    {
      const int voxels = static_cast<int>(std::ceil(reach / spacing[axis]));
      nearLower[axis] = std::max(lower[axis], below[axis][0] - voxels);
      nearUpper[axis] = std::min(upper[axis], below[axis][BrickSize - 1] + 1 + voxels);
      nearCount *= static_cast<size_t>(nearUpper[axis] - nearLower[axis] + 1);
    }
    scratch.Labels.resize(nearCount);
    this->GetShieldLabels(nearLower, nearUpper, scratch.Labels.data());
    if (std::none_of(scratch.Labels.begin(), scratch.Labels.end(), [](uint8_t label) { return label != 0; }))
    {
      return nullptr; // nothing shielded within reach: the tool cuts freely
    }
  }
  const size_t blockCount = static_cast<size_t>(size[0]) * size[1] * size[2];
  scratch.Labels.resize(blockCount);
  this->GetShieldLabels(lower, upper, scratch.Labels.data());
  uint8_t onlyLabel = 0;
  bool severalLabels = false;
  for (uint8_t label : scratch.Labels)
  {
    if (label != 0 && label != onlyLabel)
    {
      severalLabels |= onlyLabel != 0;
      onlyLabel = std::max(onlyLabel, label);
    }
  }
  if (onlyLabel == 0)
  {
    return nullptr; // nothing shielded within reach: the tool cuts freely
  }
  // Which structure each sample lies in or is nearest to, for contacts: the
  // voxel cubes' brick knows where several structures are near.
  std::unique_ptr<Brick> brick = severalLabels ? this->BuildVoxelFaceBrick(brickId, scratch) : nullptr;
  if (severalLabels)
  {
    scratch.Labels.resize(blockCount);
    this->GetShieldLabels(lower, upper, scratch.Labels.data()); // the cubes' brick used the same memory
  }
  const bool labelled = brick != nullptr;
  if (!brick)
  {
    brick.reset(new Brick);
  }
  const uint8_t* labels = scratch.Labels.data();
  const size_t stride[3] = { 1, static_cast<size_t>(size[0]), static_cast<size_t>(size[0]) * size[1] };

  // Each slice's smoothed signed distance to the structures' outline.
  const int nu = size[u];
  const int nv = size[v];
  const size_t sliceSize = static_cast<size_t>(nu) * nv;
  // Only the pixels the samples interpolate between, and their neighbours
  // for the gradient, need their distance (which itself reads the window).
  const int region[4] = { below[u][0] - lower[u] - 1, below[u][BrickSize - 1] + 2 - lower[u], below[v][0] - lower[v] - 1,
    below[v][BrickSize - 1] + 2 - lower[v] };
  scratch.SliceInside.resize(sliceSize);
  scratch.SliceDistance.resize(sliceSize * size[w]);
  for (int slice = 0; slice < size[w]; ++slice)
  {
    size_t insideCount = 0;
    for (int b = 0; b < nv; ++b)
    {
      for (int a = 0; a < nu; ++a)
      {
        const bool in = labels[stride[u] * a + stride[v] * b + stride[w] * slice] != 0;
        scratch.SliceInside[a + static_cast<size_t>(nu) * b] = in ? 1 : 0;
        insideCount += in ? 1 : 0;
      }
    }
    double* distance = &scratch.SliceDistance[sliceSize * slice];
    if (insideCount == 0 || insideCount == sliceSize)
    {
      std::fill(distance, distance + sliceSize, insideCount == 0 ? bound : -bound);
      continue;
    }
    vtkVolumeCutSliceDistance::SmoothedSignedDistance(
      scratch.SliceInside.data(), nu, nv, spacing[u], spacing[v], bound, kernel, region, distance, scratch.Slice);
  }
  // Where a pixel is outside the structure in a slice but inside in the one
  // beside it (an end of the structure along the slices' normal, or a floor
  // or roof nearly parallel to the slices): at most the distance
  // extrapolated from the two slices inside, so that a tapering end (a
  // ball's pole) closes where its outlines shrink to, but no further than
  // halfway to the next slice over the last outline (its mirror), as the
  // renderer's smoothing closes the ends. Taking the smaller keeps an
  // oblique wall's in-slice distance and changes nothing abruptly where a
  // farther part of the outline enters the slice.
  scratch.Extrapolated.resize(scratch.SliceDistance.size());
  for (int slice = 2; slice < size[w] - 2; ++slice)
  {
    for (int b = region[2]; b <= region[3]; ++b)
    {
      for (int a = region[0]; a <= region[1]; ++a)
      {
        const size_t pixel = a + static_cast<size_t>(nu) * b;
        double& closed = scratch.Extrapolated[sliceSize * slice + pixel];
        closed = scratch.SliceDistance[sliceSize * slice + pixel];
        if (closed < 0.0)
        {
          continue;
        }
        for (int direction : { -1, 1 })
        {
          const double last = scratch.SliceDistance[sliceSize * (slice + direction) + pixel];
          const double previous = scratch.SliceDistance[sliceSize * (slice + 2 * direction) + pixel];
          if (last < 0.0)
          {
            closed = std::min(closed, std::max(2.0 * last - previous, std::abs(last)));
          }
        }
      }
    }
  }

  // At the voxel centres the samples interpolate between: the in-slice
  // distance divided by its gradient's length. Its zero, the surface, stays;
  // across the slices it becomes a distance too (an oblique surface's
  // in-slice distance grows faster than the distance to it), as the field's
  // reconstruction and its curvature correction expect.
  const double* smoothed = scratch.Extrapolated.data();
  auto smoothedAt = [&](const int index[3]) { return smoothed[sliceSize * index[w] + index[u] + static_cast<size_t>(nu) * index[v]]; };
  int first[3];
  int count[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    first[axis] = below[axis][0] - lower[axis];
    count[axis] = below[axis][BrickSize - 1] + 2 - below[axis][0];
  }
  scratch.Normalized.resize(static_cast<size_t>(count[0]) * count[1] * count[2]);
  for (int z = 0; z < count[2]; ++z)
  {
    for (int y = 0; y < count[1]; ++y)
    {
      for (int x = 0; x < count[0]; ++x)
      {
        const int index[3] = { first[0] + x, first[1] + y, first[2] + z };
        double gradient2 = 0.0;
        for (int axis = 0; axis < 3; ++axis)
        {
          int next[3] = { index[0], index[1], index[2] };
          int previous[3] = { index[0], index[1], index[2] };
          ++next[axis];
          --previous[axis];
          const double derivative = (smoothedAt(next) - smoothedAt(previous)) / (2.0 * spacing[axis]);
          gradient2 += derivative * derivative;
        }
        scratch.Normalized[(static_cast<size_t>(z) * count[1] + y) * count[0] + x] = smoothedAt(index) / std::max(1.0, std::sqrt(gradient2));
      }
    }
  }

  // Each sample: that distance interpolated between the voxel centres
  // around it (trilinear, as the renderer samples its fractions), and inside
  // a shielded voxel never outside the shield.
  const double inverseQuantum = 1.0 / this->Quantum;
  bool useful = false;
  for (int p = 0; p < BrickSize; ++p)
  {
    for (int m = 0; m < BrickSize; ++m)
    {
      for (int n = 0; n < BrickSize; ++n)
      {
        const int corner[3] = { below[0][n] - below[0][0], below[1][m] - below[1][0], below[2][p] - below[2][0] };
        const double t[3] = { position[0][n] - below[0][n], position[1][m] - below[1][m], position[2][p] - below[2][p] };
        double interpolated = 0.0;
        for (int c = 0; c < 8; ++c)
        {
          int index[3];
          double weight = 1.0;
          for (int axis = 0; axis < 3; ++axis)
          {
            const int upperCorner = (c >> axis) & 1;
            index[axis] = corner[axis] + upperCorner;
            weight *= upperCorner ? t[axis] : 1.0 - t[axis];
          }
          interpolated += weight * scratch.Normalized[(static_cast<size_t>(index[2]) * count[1] + index[1]) * count[0] + index[0]];
        }
        const int local = (p * BrickSize + m) * BrickSize + n;
        const uint8_t ownLabel = labels[stride[0] * (own[0][n] - lower[0]) + stride[1] * (own[1][m] - lower[1]) + stride[2] * (own[2][p] - lower[2])];
        const double signedDistance = std::max(-this->BandWidth, std::min(this->BandWidth, interpolated));
        long quantized = std::lround(signedDistance * inverseQuantum);
        if (ownLabel != 0)
        {
          quantized = std::min(quantized, -1L);
        }
        brick->Distance[local] = static_cast<int16_t>(quantized);
        if (ownLabel != 0 || !labelled)
        {
          brick->Label[local] = ownLabel != 0 ? ownLabel : onlyLabel;
        }
        useful |= quantized * this->Quantum < this->BandWidth;
      }
    }
  }
  return useful ? std::move(brick) : nullptr;
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutProtection::GetMemorySize() const
{
  size_t bytes = static_cast<size_t>(this->GetNumberOfShieldBricks()) * sizeof(Brick);
  bytes += static_cast<size_t>(this->DirectorySize) * sizeof(std::atomic<Brick*>);
  for (const LabelImage& entry : this->LabelImages)
  {
    bytes += entry.Labels.capacity();
  }
  return bytes;
}

//------------------------------------------------------------------------------
void vtkVolumeCutProtection::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LabelImages: " << this->LabelImages.size() << "\n";
  os << indent << "HasShieldedLabels: " << (this->HasShieldedLabels() ? "yes" : "no") << "\n";
  os << indent << "SurfaceSmoothing: " << this->SurfaceSmoothing << "\n";
  os << indent << "Reach (voxels): " << this->Reach[0] << " " << this->Reach[1] << " " << this->Reach[2] << "\n";
  os << indent << "BuiltBricks: " << this->GetNumberOfBuiltBricks() << " (" << this->GetNumberOfShieldBricks() << " with a shield)\n";
  os << indent << "BricksBuiltOnDemand: " << this->BricksBuiltOnDemand << "\n";
  os << indent << "PreparedBricks: " << this->GetNumberOfPreparedBricks() << "\n";
  os << indent << "MemorySize: " << this->GetMemorySize() << " bytes\n";
}
