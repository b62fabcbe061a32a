// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutEmptySpace
 * @brief   Empty-space skipping of vtkVolumeCutRayCaster: blocks of 8^3 cells.
 *
 * Per block of BlockSize^3 cells of the anatomy (with the far corners, one
 * voxel of apron): whether a visible object can be there (a shown segment
 * whose surface could lie in it, or any opacity over its CT range in
 * composite mode), and a bound on the CT's trilinear gradient (per voxel)
 * that the border locator uses to decide whether a border could hide between
 * two samples. Rays step over empty blocks in one jump.
 *
 * In iso-surface mode, also per cell (between eight voxels): whether a
 * visible object can be there at all, from the cell's largest CT value and
 * the segments its corners carry. Beside bone most samples fall in cells
 * where none can be (soft tissue under the iso-value): a ray walks through
 * such cells to the next one that may hold a surface, without sampling.
 */
#ifndef vtkVolumeCutEmptySpace_h
#define vtkVolumeCutEmptySpace_h

#include <vtkType.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

struct vtkVolumeCutRayScene;

class vtkVolumeCutEmptySpace
{
public:
  static constexpr int BlockSize = 8;

  /// Classify every block of \a scene (values, segments, styles and tables
  /// already copied), on at most maximumThreads threads.
  void Build(const vtkVolumeCutRayScene& scene, int maximumThreads);

  bool Empty(const double p[3]) const { return !this->Occupied[this->BlockOf(p)]; }

  /// Bound of the CT's gradient (CT units per voxel) in the block holding p.
  float Lipschitz(const double p[3]) const { return this->GradientBound[this->BlockOf(p)]; }

  /**
   * Ray parameter where the ray (direction d in voxels) leaves the empty
   * region around the block holding p: the cube of blocks that are all
   * empty, as far as the nearest occupied block allows (one block where an
   * occupied one touches it). Rays through air cross it in one jump.
   */
  double Exit(const double p[3], const double d[3], double t) const
  {
    int b[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      b[axis] = std::min(std::max(static_cast<int>(p[axis]) / BlockSize, 0), this->Dimensions[axis] - 1);
    }
    const int reach = this->Reach[b[0] + this->Dimensions[0] * (b[1] + static_cast<vtkIdType>(this->Dimensions[1]) * b[2])];
    const int margin = std::max(reach - 1, 0);
    double exit = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis)
    {
      if (std::abs(d[axis]) < 1e-12)
      {
        continue;
      }
      const double wall = d[axis] > 0.0 ? double((b[axis] + 1 + margin) * BlockSize) : double((b[axis] - margin) * BlockSize);
      exit = std::min(exit, t + (wall - p[axis]) / d[axis]);
    }
    return exit;
  }

  /**
   * Ray parameter where the ray (direction d in voxels, from p at t) enters
   * the first cell that may hold a visible object, or tEnd; t itself when
   * p's cell may. Cells are the anatomy's (unit cells between voxels).
   */
  double ExitEmptyCells(const double p[3], const double d[3], double t, double tEnd) const
  {
    if (this->CellGroups.empty())
    {
      return t;
    }
    int cell[3];
    int stepSign[3];
    double next[3];
    double delta[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      cell[axis] = std::min(std::max(static_cast<int>(std::floor(p[axis])), 0), this->CellDimensions[axis] - 1);
      stepSign[axis] = d[axis] > 0.0 ? 1 : -1;
      if (std::abs(d[axis]) < 1e-12)
      {
        next[axis] = delta[axis] = std::numeric_limits<double>::infinity();
        continue;
      }
      const double wall = d[axis] > 0.0 ? cell[axis] + 1.0 : double(cell[axis]);
      next[axis] = t + (wall - p[axis]) / d[axis];
      delta[axis] = 1.0 / std::abs(d[axis]);
    }
    double entry = t;
    while (!this->CellMayHoldObject(cell))
    {
      const int axis = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
      entry = next[axis];
      cell[axis] += stepSign[axis];
      if (!(entry < tEnd) || cell[axis] < 0 || cell[axis] >= this->CellDimensions[axis])
      {
        return tEnd;
      }
      next[axis] += delta[axis];
    }
    return entry;
  }

  /**
   * Whether the cell holding p (IJK, inside the volume) may hold a visible
   * object: where it may not, no sample there is in an object, which lets
   * ambient occlusion count such a point without classifying it.
   */
  bool MayHoldObject(const double p[3]) const
  {
    if (this->CellGroups.empty())
    {
      return true;
    }
    int cell[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      cell[axis] = std::min(std::max(static_cast<int>(std::floor(p[axis])), 0), this->CellDimensions[axis] - 1);
    }
    return this->CellMayHoldObject(cell);
  }

  const int* GetDimensions() const { return this->Dimensions; }
  const uint8_t* GetOccupied() const { return this->Occupied.data(); }
  const uint8_t* GetReach() const { return this->Reach.data(); }
  const float* GetGradientBounds() const { return this->GradientBound.data(); }

  /// Groups of 2 x 2 x 2 cells along each axis (0 where cells are not
  /// classified: composite mode, or a volume of one slice).
  const int* GetCellGroupDimensions() const { return this->GroupDimensions; }
  /// Per group, a byte: bit (i & 1) | (j & 1) << 1 | (k & 1) << 2 set where
  /// cell (i, j, k) may hold a visible object (nullptr when not classified).
  const uint8_t* GetCellGroups() const { return this->CellGroups.empty() ? nullptr : this->CellGroups.data(); }

private:
  vtkIdType BlockOf(const double p[3]) const
  {
    int b[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      b[axis] = std::min(std::max(static_cast<int>(p[axis]) / BlockSize, 0), this->Dimensions[axis] - 1);
    }
    return b[0] + this->Dimensions[0] * (b[1] + this->Dimensions[1] * b[2]);
  }

  /// Chessboard distance in blocks to the nearest occupied block (0 for an
  /// occupied one, at most 255).
  void ComputeReach();
  void BuildCells(const vtkVolumeCutRayScene& scene, int maximumThreads);

  bool CellMayHoldObject(const int cell[3]) const
  {
    const size_t group = static_cast<size_t>(cell[0] >> 1) +
      this->GroupDimensions[0] * (static_cast<size_t>(cell[1] >> 1) + static_cast<size_t>(this->GroupDimensions[1]) * (cell[2] >> 1));
    return (this->CellGroups[group] >> ((cell[0] & 1) | (cell[1] & 1) << 1 | (cell[2] & 1) << 2)) & 1u;
  }

  // Cells: one bit each, in bytes of 2 x 2 x 2 cells, the layout the GPU
  // path uploads as it is (an R8 3D texture, 1/8 of a byte a cell: 16 MiB
  // for a 512^3 CT); a ray's walk through neighbouring cells stays in few
  // bytes. Threads build different layers of groups, so never share a byte.
  int CellDimensions[3] = { 0, 0, 0 };
  int GroupDimensions[3] = { 0, 0, 0 };
  std::vector<uint8_t> CellGroups;

  int Dimensions[3] = { 0, 0, 0 };
  std::vector<uint8_t> Occupied;
  std::vector<uint8_t> Reach;
  std::vector<float> GradientBound;
};

#endif
