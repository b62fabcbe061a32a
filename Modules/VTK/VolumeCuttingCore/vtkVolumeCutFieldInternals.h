// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore (not installed, not wrapped): what the source
// files of vtkVolumeCutField share. The field's implementation is split by
// responsibility (vtkVolumeCutField*.cxx); they all read the same bricks, in
// the same units, through the same small geometric helpers, which stay here
// so that the hot loops of each file can inline them.
#ifndef vtkVolumeCutFieldInternals_h
#define vtkVolumeCutFieldInternals_h

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutKernels.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>

namespace vtkVolumeCutFieldInternals
{
constexpr int BrickSize = vtkVolumeCutField::BrickSize;
constexpr int SamplesPerBrick = BrickSize * BrickSize * BrickSize;
constexpr int16_t Outside = vtkVolumeCutKernels::Outside;
constexpr int16_t Inside = vtkVolumeCutKernels::Inside;
static_assert(Outside == std::numeric_limits<int16_t>::max() && Inside == -Outside, "the band spans the 16-bit range");
static_assert(SamplesPerBrick == vtkVolumeCutKernels::SamplesPerBrick, "kernels work on whole bricks");

inline bool IsFinite(const double v[3])
{
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// out = m * (in, 1), the affine part of a 4x4 row-major matrix.
inline void Transform(const double m[4][4], const double in[3], double out[3])
{
  for (int row = 0; row < 3; ++row)
  {
    out[row] = m[row][0] * in[0] + m[row][1] * in[1] + m[row][2] * in[2] + m[row][3];
  }
}
} // namespace vtkVolumeCutFieldInternals

//------------------------------------------------------------------------------
struct vtkVolumeCutField::Brick
{
  explicit Brick(vtkIdType id)
    : Id(id)
  {
    // Plain stores, which vectorise: no reader sees the brick before the
    // directory publishes it (release).
    int16_t* values = reinterpret_cast<int16_t*>(this->Values);
    std::fill(values, values + vtkVolumeCutFieldInternals::SamplesPerBrick, vtkVolumeCutFieldInternals::Outside);
  }
  const vtkIdType Id;
  // Seqlock: odd while the writer changes the values.
  std::atomic<uint32_t> Sequence{ 0 };
  std::atomic<vtkTypeUInt64> Stamp{ 0 };
  std::atomic<int16_t> Values[vtkVolumeCutFieldInternals::SamplesPerBrick];

  /// The values as the writer thread sees them, for loops that vectorise:
  /// other threads only read, so the writer's own plain reads race with
  /// nothing (lock-free 16-bit atomics have the layout of the integer).
  const int16_t* WriterView() const { return reinterpret_cast<const int16_t*>(this->Values); }

  /// The writer's own record that every sample is Inside: no cut can change
  /// the brick then (Inside is the least value), so strokes skip it.
  bool AllInside = false;
  /// The writer's own record of the stroke (vtkVolumeCutFieldUndoHistory's
  /// stroke serial) whose undo step holds the brick as it was: a stroke's
  /// later changes need no look-up.
  vtkTypeUInt64 RememberedInStroke = 0;
  void UpdateAllInside()
  {
    const int16_t* values = this->WriterView();
    int differing = 0;
    for (int index = 0; index < vtkVolumeCutFieldInternals::SamplesPerBrick; ++index)
    {
      differing |= values[index] != vtkVolumeCutFieldInternals::Inside;
    }
    this->AllInside = differing == 0;
  }
};
static_assert(sizeof(std::atomic<int16_t>) == sizeof(int16_t), "16-bit atomics must have the layout of the integer");

#endif
