// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutEmptySpace.h"

#include "vtkVolumeCutParallelFor.h"
#include "vtkVolumeCutRayScene.h"

#include <cmath>

//------------------------------------------------------------------------------
void vtkVolumeCutEmptySpace::Build(const vtkVolumeCutRayScene& scene, int maximumThreads)
{
  static_assert(BlockSize == vtkVolumeCutRayScene::FractionBlockSize, "the fractions' non-zero blocks are these blocks");
  const int* dims = scene.Dimensions;
  for (int axis = 0; axis < 3; ++axis)
  {
    this->Dimensions[axis] = (dims[axis] - 1 + BlockSize - 1) / BlockSize;
  }
  const vtkIdType blockCount = static_cast<vtkIdType>(this->Dimensions[0]) * this->Dimensions[1] * this->Dimensions[2];
  this->Occupied.assign(blockCount, 0);
  this->GradientBound.assign(blockCount, 0.f);
  const bool composite = scene.BlendMode == 1;
  const std::vector<float>& values = scene.Values;
  const std::vector<vtkVolumeCutRayScene::SegmentStyle>& styles = scene.Styles;
  constexpr int TableSize = vtkVolumeCutRayScene::TransferTableSize;
  vtkVolumeCutParallelFor(maximumThreads, this->Dimensions[2], [&](vtkIdType beginZ, vtkIdType endZ) {
    for (vtkIdType bz = beginZ; bz < endZ; ++bz)
    {
      for (int by = 0; by < this->Dimensions[1]; ++by)
      {
        for (int bx = 0; bx < this->Dimensions[0]; ++bx)
        {
          const vtkIdType block = bx + this->Dimensions[0] * (by + static_cast<vtkIdType>(this->Dimensions[1]) * bz);
          // The block's cells and their far corners (one voxel of apron).
          const int k0 = int(bz) * BlockSize;
          const int k1 = std::min((int(bz) + 1) * BlockSize, dims[2] - 1);
          const int j0 = by * BlockSize;
          const int j1 = std::min((by + 1) * BlockSize, dims[1] - 1);
          const int i0 = bx * BlockSize;
          const int i1 = std::min((bx + 1) * BlockSize, dims[0] - 1);
          float lo = std::numeric_limits<float>::infinity();
          float hi = -std::numeric_limits<float>::infinity();
          bool occupied = false;
          float slope[3] = { 0.f, 0.f, 0.f };
          for (int k = k0; k <= k1; ++k)
          {
            for (int j = j0; j <= j1; ++j)
            {
              const vtkIdType row = static_cast<vtkIdType>(dims[0]) * (j + static_cast<vtkIdType>(dims[1]) * k);
              for (int i = i0; i <= i1; ++i)
              {
                const float v = values[row + i];
                lo = v < lo ? v : lo;
                hi = v > hi ? v : hi;
                // Largest change to a neighbour along each axis bounds the
                // trilinear gradient's components.
                if (i + 1 < dims[0])
                {
                  slope[0] = std::max(slope[0], std::abs(values[row + i + 1] - v));
                }
                if (j + 1 < dims[1])
                {
                  slope[1] = std::max(slope[1], std::abs(values[row + dims[0] + i] - v));
                }
                if (k + 1 < dims[2])
                {
                  slope[2] = std::max(slope[2], std::abs(values[row + static_cast<vtkIdType>(dims[0]) * dims[1] + i] - v));
                }
              }
            }
          }
          // Labels: a visible segment whose surface could lie in the block.
          if (!composite && !scene.Labels.empty())
          {
            for (int k = k0; k <= k1 && !occupied; ++k)
            {
              for (int j = j0; j <= j1 && !occupied; ++j)
              {
                const vtkIdType row = static_cast<vtkIdType>(dims[0]) * (j + static_cast<vtkIdType>(dims[1]) * k);
                for (int i = i0; i <= i1; ++i)
                {
                  const int label = scene.Labels[row + i];
                  if (label > 0 && label < static_cast<int>(styles.size()))
                  {
                    const vtkVolumeCutRayScene::SegmentStyle& style = styles[label];
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
            for (const vtkVolumeCutRayScene::FractionVolume& fraction : scene.Fractions)
            {
              const vtkVolumeCutRayScene::SegmentStyle& style =
                fraction.Label < static_cast<int>(styles.size()) ? styles[fraction.Label] : styles[0];
              // The fraction's own blocks are these blocks: one known to be
              // all 0 cannot hold it (smoothed fractions cover a few percent).
              if (occupied || style.Opacity <= 0.f || (!style.Shape && hi < style.Iso) ||
                (fraction.NonZeroBlocks.size() == static_cast<size_t>(blockCount) && !fraction.NonZeroBlocks[block]))
              {
                continue;
              }
              for (int k = k0; k <= k1 && !occupied; ++k)
              {
                for (int j = j0; j <= j1 && !occupied; ++j)
                {
                  const vtkIdType row = static_cast<vtkIdType>(dims[0]) * (j + static_cast<vtkIdType>(dims[1]) * k);
                  for (int i = i0; i <= i1 && !occupied; ++i)
                  {
                    occupied = fraction.Values[row + i] > 0.f;
                  }
                }
              }
            }
          }
          if (!composite && !scene.HasSegments())
          {
            occupied = styles[1].Opacity > 0.f && hi >= styles[1].Iso;
          }
          else if (composite)
          {
            // Any opacity over the block's value range.
            const double span = scene.TableRange[1] - scene.TableRange[0];
            const int first =
              span > 0.0 ? std::max(0, static_cast<int>(std::floor((lo - scene.TableRange[0]) / span * (TableSize - 1)))) : 0;
            const int last = span > 0.0
              ? std::min(TableSize - 1, static_cast<int>(std::ceil((hi - scene.TableRange[0]) / span * (TableSize - 1))))
              : TableSize - 1;
            for (int n = std::min(first, TableSize - 1); n <= last && !occupied; ++n)
            {
              occupied = scene.OpacityTable[n] > 0.f;
            }
          }
          this->Occupied[block] = occupied ? 1 : 0;
          // NaN voxels make the bound infinite: such blocks are always refined.
          const float lipschitz = std::sqrt(slope[0] * slope[0] + slope[1] * slope[1] + slope[2] * slope[2]);
          this->GradientBound[block] = std::isfinite(lipschitz) ? lipschitz : std::numeric_limits<float>::infinity();
        }
      }
    }
  });
  this->ComputeReach();
  this->BuildCells(scene, maximumThreads);
}

//------------------------------------------------------------------------------
void vtkVolumeCutEmptySpace::BuildCells(const vtkVolumeCutRayScene& scene, int maximumThreads)
{
  this->CellGroups.clear();
  std::fill(this->GroupDimensions, this->GroupDimensions + 3, 0);
  const int* dims = scene.Dimensions;
  if (scene.BlendMode == 1 || dims[0] < 2 || dims[1] < 2 || dims[2] < 2)
  {
    return; // composite: every opacity counts; one slice: no cells
  }
  const std::vector<vtkVolumeCutRayScene::SegmentStyle>& styles = scene.Styles;
  constexpr float Never = std::numeric_limits<float>::infinity();
  constexpr float Always = -std::numeric_limits<float>::infinity();
  // The lowest CT value at which a voxel's segment is visible there: a
  // shape-defined segment always, an iso-defined one at its iso-value, a
  // hidden segment or the background never.
  auto visibleFrom = [&](int label) -> float {
    if (label <= 0 || label >= static_cast<int>(styles.size()) || styles[label].Opacity <= 0.f)
    {
      return Never;
    }
    return styles[label].Shape ? Always : styles[label].Iso;
  };
  const bool segments = scene.HasSegments();
  const float unsegmented = segments ? Never : visibleFrom(1);
  for (int axis = 0; axis < 3; ++axis)
  {
    this->CellDimensions[axis] = dims[axis] - 1;
  }
  const int cx = this->CellDimensions[0];
  const int cy = this->CellDimensions[1];
  for (int axis = 0; axis < 3; ++axis)
  {
    this->GroupDimensions[axis] = (this->CellDimensions[axis] + 1) / 2;
  }
  const size_t gx = this->GroupDimensions[0];
  const size_t gy = this->GroupDimensions[1];
  this->CellGroups.assign(gx * gy * this->GroupDimensions[2], 0);
  const vtkIdType sliceSize = static_cast<vtkIdType>(dims[0]) * dims[1];
  constexpr int FractionBlock = vtkVolumeCutRayScene::FractionBlockSize;
  int fractionBlocks[3];
  scene.GetFractionBlockDimensions(fractionBlocks);
  // Each thread builds whole layers of groups (two layers of cells).
  vtkVolumeCutParallelFor(maximumThreads, this->GroupDimensions[2], [&](vtkIdType beginGroupZ, vtkIdType endGroupZ) {
    const vtkIdType beginZ = 2 * beginGroupZ;
    const vtkIdType endZ = std::min<vtkIdType>(2 * endGroupZ, this->CellDimensions[2]);
    // Per slice, the largest value and the lowest visibility of each 2 x 2
    // group of voxels; a cell takes those of its two slices.
    std::vector<float> high[2], low[2];
    auto reduceSlice = [&](int k, std::vector<float>& sliceHigh, std::vector<float>& sliceLow) {
      sliceHigh.assign(static_cast<size_t>(cx) * cy, 0.f);
      sliceLow.assign(static_cast<size_t>(cx) * cy, Never);
      std::vector<float> needed(static_cast<size_t>(sliceSize));
      const vtkIdType offset = sliceSize * k;
      for (vtkIdType v = 0; v < sliceSize; ++v)
      {
        needed[v] = segments && !scene.Labels.empty() ? visibleFrom(scene.Labels[offset + v]) : unsegmented;
      }
      for (const vtkVolumeCutRayScene::FractionVolume& fraction : scene.Fractions)
      {
        const float from = visibleFrom(fraction.Label);
        // A segment drawn by its shape shows where its fraction, its weight
        // there, is at least a half: a cell whose corners all stay under
        // that cannot hold it (the trilinear fraction is at most the
        // largest corner's; the margin covers rounding). Smoothed fractions
        // are above 0 far around their segment, where every sample would
        // otherwise weigh the labels.
        const bool shape = from == Always;
        constexpr float Half = 0.5f * (1.f - 1e-5f);
        auto mark = [&](vtkIdType begin, vtkIdType end) {
          for (vtkIdType v = begin; v < end; ++v)
          {
            const float value = fraction.Values[offset + v];
            if (shape ? value >= Half : value > 0.f)
            {
              needed[v] = std::min(needed[v], from);
            }
          }
        };
        if (fraction.NonZeroBlocks.size() != static_cast<size_t>(fractionBlocks[0]) * fractionBlocks[1] * fractionBlocks[2])
        {
          mark(0, sliceSize);
          continue;
        }
        // Only the runs of voxels in blocks where the fraction is above 0
        // somewhere: a voxel lies in the block of the cells it starts, the
        // last one along an axis in the block of the cell it ends.
        const int blockZ = std::min(k / FractionBlock, fractionBlocks[2] - 1);
        for (int j = 0; j < dims[1]; ++j)
        {
          const int blockY = std::min(j / FractionBlock, fractionBlocks[1] - 1);
          const uint8_t* row =
            fraction.NonZeroBlocks.data() + fractionBlocks[0] * (blockY + static_cast<size_t>(fractionBlocks[1]) * blockZ);
          for (int blockX = 0; blockX < fractionBlocks[0]; ++blockX)
          {
            if (row[blockX])
            {
              const vtkIdType first = static_cast<vtkIdType>(dims[0]) * j + blockX * FractionBlock;
              const vtkIdType last = static_cast<vtkIdType>(dims[0]) * j +
                (blockX + 1 == fractionBlocks[0] ? dims[0] : (blockX + 1) * FractionBlock);
              mark(first, last);
            }
          }
        }
      }
      const float* values = scene.Values.data() + offset;
      for (int j = 0; j < cy; ++j)
      {
        for (int i = 0; i < cx; ++i)
        {
          const vtkIdType v = i + static_cast<vtkIdType>(dims[0]) * j;
          const vtkIdType corners[4] = { v, v + 1, v + dims[0], v + dims[0] + 1 };
          float h = values[corners[0]];
          float l = needed[corners[0]];
          for (int c = 1; c < 4; ++c)
          {
            h = std::max(h, values[corners[c]]);
            l = std::min(l, needed[corners[c]]);
          }
          // NaN voxels: the cell is kept, as every path treats it alike.
          sliceHigh[i + static_cast<size_t>(cx) * j] = std::isnan(h) ? std::numeric_limits<float>::infinity() : h;
          sliceLow[i + static_cast<size_t>(cx) * j] = l;
        }
      }
    };
    reduceSlice(static_cast<int>(beginZ), high[0], low[0]);
    for (vtkIdType k = beginZ; k < endZ; ++k)
    {
      const int current = static_cast<int>(k - beginZ) % 2;
      reduceSlice(static_cast<int>(k) + 1, high[1 - current], low[1 - current]);
      uint8_t* groups = this->CellGroups.data() + static_cast<size_t>(k / 2) * gx * gy;
      const int layerBit = static_cast<int>(k & 1) << 2;
      for (int j = 0; j < cy; ++j)
      {
        for (int i = 0; i < cx; ++i)
        {
          const size_t cell = i + static_cast<size_t>(cx) * j;
          const float h = std::max(high[0][cell], high[1][cell]);
          const float l = std::min(low[0][cell], low[1][cell]);
          if (h >= l)
          {
            groups[(i >> 1) + gx * (j >> 1)] |= static_cast<uint8_t>(1u << ((i & 1) | (j & 1) << 1 | layerBit));
          }
        }
      }
    }
  });
}

//------------------------------------------------------------------------------
void vtkVolumeCutEmptySpace::ComputeReach()
{
  // Two raster passes over the 26 neighbours give the chessboard distance
  // exactly; the block grid is small (64 x 64 x 58 for a 512^2 x 460 CT).
  const int nx = this->Dimensions[0];
  const int ny = this->Dimensions[1];
  const int nz = this->Dimensions[2];
  this->Reach.assign(this->Occupied.size(), 255);
  for (size_t block = 0; block < this->Occupied.size(); ++block)
  {
    if (this->Occupied[block])
    {
      this->Reach[block] = 0;
    }
  }
  auto relax = [&](int x, int y, int z, int sign) {
    uint8_t& reach = this->Reach[x + nx * (y + static_cast<vtkIdType>(ny) * z)];
    for (int dz = -1; dz <= 1; ++dz)
    {
      for (int dy = -1; dy <= 1; ++dy)
      {
        for (int dx = -1; dx <= 1; ++dx)
        {
          // The neighbours the pass has already visited.
          const int order = dz * 9 + dy * 3 + dx;
          if (order * sign >= 0)
          {
            continue;
          }
          const int qx = x + dx, qy = y + dy, qz = z + dz;
          if (qx < 0 || qy < 0 || qz < 0 || qx >= nx || qy >= ny || qz >= nz)
          {
            continue;
          }
          const int neighbour = this->Reach[qx + nx * (qy + static_cast<vtkIdType>(ny) * qz)];
          reach = static_cast<uint8_t>(std::min<int>(reach, neighbour + 1));
        }
      }
    }
  };
  for (int z = 0; z < nz; ++z)
  {
    for (int y = 0; y < ny; ++y)
    {
      for (int x = 0; x < nx; ++x)
      {
        relax(x, y, z, 1);
      }
    }
  }
  for (int z = nz - 1; z >= 0; --z)
  {
    for (int y = ny - 1; y >= 0; --y)
    {
      for (int x = nx - 1; x >= 0; --x)
      {
        relax(x, y, z, -1);
      }
    }
  }
}
