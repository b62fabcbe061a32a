// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutNerveMonitorField.h"

#include "vtkSMPTools.h"
#include "vtkVolumeCutLabelSurface.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace
{
/// The smoothed distance stored where the shield is the voxel cubes alone (no smoothing): never the nearer one.
constexpr float NoSmoothedSurface = 1e6f;
/// Marks in the brick directory for bricks without samples.
constexpr int32_t FarOutside = -1;
constexpr int32_t DeepInside = -2;

/// The smoothed levels on the whole mask grid, with the trilinear interpolation whose zero set is the surface.
struct LevelGrid
{
  int Dims[3];
  double Spacing[3];
  std::vector<float> Values;

  vtkIdType Index(int i, int j, int k) const { return i + static_cast<vtkIdType>(this->Dims[0]) * (j + static_cast<vtkIdType>(this->Dims[1]) * k); }

  /// Level and its gradient (per mm) at a point (mm from the first voxel's centre).
  double Evaluate(const double x[3], double gradient[3]) const
  {
    int cell[3];
    double t[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      const double index = std::min(std::max(x[axis] / this->Spacing[axis], 0.0), static_cast<double>(this->Dims[axis] - 1));
      cell[axis] = std::min(static_cast<int>(index), std::max(this->Dims[axis] - 2, 0));
      t[axis] = index - cell[axis];
    }
    double corner[2][2][2];
    for (int c = 0; c < 8; ++c)
    {
      const int a = c & 1, b = (c >> 1) & 1, d = (c >> 2) & 1;
      const int i = std::min(cell[0] + a, this->Dims[0] - 1);
      const int j = std::min(cell[1] + b, this->Dims[1] - 1);
      const int k = std::min(cell[2] + d, this->Dims[2] - 1);
      corner[d][b][a] = this->Values[this->Index(i, j, k)];
    }
    const double x00 = corner[0][0][0] + t[0] * (corner[0][0][1] - corner[0][0][0]);
    const double x10 = corner[0][1][0] + t[0] * (corner[0][1][1] - corner[0][1][0]);
    const double x01 = corner[1][0][0] + t[0] * (corner[1][0][1] - corner[1][0][0]);
    const double x11 = corner[1][1][0] + t[0] * (corner[1][1][1] - corner[1][1][0]);
    const double y0 = x00 + t[1] * (x10 - x00);
    const double y1 = x01 + t[1] * (x11 - x01);
    const double dx0 = (1 - t[1]) * (corner[0][0][1] - corner[0][0][0]) + t[1] * (corner[0][1][1] - corner[0][1][0]);
    const double dx1 = (1 - t[1]) * (corner[1][0][1] - corner[1][0][0]) + t[1] * (corner[1][1][1] - corner[1][1][0]);
    gradient[0] = ((1 - t[2]) * dx0 + t[2] * dx1) / this->Spacing[0];
    gradient[1] = ((1 - t[2]) * (x10 - x00) + t[2] * (x11 - x01)) / this->Spacing[1];
    gradient[2] = (y1 - y0) / this->Spacing[2];
    return y0 + t[2] * (y1 - y0);
  }
};

/// Where a voxel is outside in its slice but inside in the one beside it (an
/// end of the structure across the slices, a floor or a roof nearly parallel
/// to them): at most the level extrapolated from the two slices inside, and
/// no less than the mirror of the last one, as vtkVolumeCutProtection closes
/// the shield there (halfway to the next slice over a flat end).
void CloseAcrossSlices(LevelGrid& grid, int sliceAxis)
{
  const std::vector<float> open = grid.Values;
  const vtkIdType stride = sliceAxis == 0 ? 1 : sliceAxis == 1 ? grid.Dims[0] : static_cast<vtkIdType>(grid.Dims[0]) * grid.Dims[1];
  for (int k = 0; k < grid.Dims[2]; ++k)
  {
    for (int j = 0; j < grid.Dims[1]; ++j)
    {
      for (int i = 0; i < grid.Dims[0]; ++i)
      {
        const int ijk[3] = { i, j, k };
        const int s = ijk[sliceAxis];
        if (s < 2 || s >= grid.Dims[sliceAxis] - 2)
        {
          continue;
        }
        const vtkIdType voxel = grid.Index(i, j, k);
        float closed = open[voxel];
        if (closed < 0.f)
        {
          continue;
        }
        for (const int direction : { -1, 1 })
        {
          const float last = open[voxel + direction * stride];
          const float previous = open[voxel + 2 * direction * stride];
          if (last < 0.f)
          {
            closed = std::min(closed, std::max(2.f * last - previous, std::abs(last)));
          }
        }
        grid.Values[voxel] = closed;
      }
    }
  }
}

/// Each level divided by its gradient's length (central differences, per mm)
/// where that exceeds 1, as the shield does: across the slices the in-slice
/// distance becomes a distance too; its zero stays.
void NormalizeByGradient(LevelGrid& grid)
{
  const std::vector<float> levels = grid.Values;
  const vtkIdType strides[3] = { 1, grid.Dims[0], static_cast<vtkIdType>(grid.Dims[0]) * grid.Dims[1] };
  for (int k = 1; k < grid.Dims[2] - 1; ++k)
  {
    for (int j = 1; j < grid.Dims[1] - 1; ++j)
    {
      for (int i = 1; i < grid.Dims[0] - 1; ++i)
      {
        const vtkIdType voxel = grid.Index(i, j, k);
        double gradient2 = 0.0;
        for (int axis = 0; axis < 3; ++axis)
        {
          const double derivative = (levels[voxel + strides[axis]] - levels[voxel - strides[axis]]) / (2.0 * grid.Spacing[axis]);
          gradient2 += derivative * derivative;
        }
        grid.Values[voxel] = static_cast<float>(levels[voxel] / std::max(1.0, std::sqrt(gradient2)));
      }
    }
  }
}

/// One pass of the exact squared distance from voxel centres to a union of
/// voxel cubes along axis: out(v) = min over u on v's line of in(u) +
/// g(v - u), g(n) = (max(|n| - 1/2, 0) s)^2. Beside v the cost is the
/// parabola s^2 (v - u -+ 1/2)^2, so two lower envelopes of parabolas
/// (Felzenszwalb and Huttenlocher, 2012) with vertices shifted half a voxel
/// either way, and u = v itself, give it in linear time.
void CubeDistancePass(std::vector<float>& values, std::vector<int32_t>& nearest, const int dims[3], const double spacing[3], int axis)
{
  const vtkIdType strides[3] = { 1, dims[0], static_cast<vtkIdType>(dims[0]) * dims[1] };
  const int n = dims[axis];
  const int a1 = axis == 0 ? 1 : 0;
  const int a2 = axis == 2 ? 1 : 2;
  const double s2 = spacing[axis] * spacing[axis];
  // Lines are independent: threads take whole lines, each with its own scratch.
  vtkSMPTools::For(0, static_cast<vtkIdType>(dims[a1]) * dims[a2], [&](vtkIdType begin, vtkIdType end) {
  std::vector<double> line(n), out(n), vertex(n), boundary(n + 1);
  std::vector<int> owner(n);
  std::vector<int32_t> lineNearest(n), outNearest(n);
  for (vtkIdType lineIndex = begin; lineIndex < end; ++lineIndex)
  {
    {
      const int p = static_cast<int>(lineIndex % dims[a1]);
      const int q = static_cast<int>(lineIndex / dims[a1]);
      const vtkIdType first = strides[a1] * p + strides[a2] * q;
      for (int u = 0; u < n; ++u)
      {
        line[u] = values[first + strides[axis] * u];
        out[u] = line[u];
        lineNearest[u] = nearest[first + strides[axis] * u];
        outNearest[u] = lineNearest[u];
      }
      for (const double shift : { 0.5, -0.5 })
      {
        int count = 0;
        for (int u = 0; u < n; ++u)
        {
          if (!std::isfinite(line[u]))
          {
            continue;
          }
          const double c = u + shift;
          while (count > 0)
          {
            const int last = owner[count - 1];
            const double x = ((line[u] + s2 * c * c) - (line[last] + s2 * vertex[count - 1] * vertex[count - 1])) / (2.0 * s2 * (c - vertex[count - 1]));
            if (x > boundary[count - 1])
            {
              boundary[count] = x;
              break;
            }
            --count;
          }
          if (count == 0)
          {
            boundary[0] = -std::numeric_limits<double>::infinity();
          }
          owner[count] = u;
          vertex[count] = c;
          ++count;
        }
        for (int v = 0, k = 0; v < n && count > 0; ++v)
        {
          while (k + 1 < count && boundary[k + 1] < v)
          {
            ++k;
          }
          const double d = v - vertex[k];
          const double candidate = line[owner[k]] + s2 * d * d;
          if (candidate < out[v])
          {
            out[v] = candidate;
            outNearest[v] = lineNearest[owner[k]];
          }
        }
      }
      for (int u = 0; u < n; ++u)
      {
        values[first + strides[axis] * u] = static_cast<float>(out[u]);
        nearest[first + strides[axis] * u] = outNearest[u];
      }
    }
  }
  });
}

/// Squared distance (mm^2) from each voxel centre to the union of the cubes
/// of the voxels whose mask is set (of = true) or clear (of = false), and
/// the voxel whose cube is nearest (-1: none): exact, separable over the
/// three axes.
void CubeDistances(const uint16_t* mask, const int dims[3], const double spacing[3], bool of, std::vector<float>& values,
  std::vector<int32_t>& nearest)
{
  const vtkIdType count = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  values.resize(count);
  nearest.resize(count);
  for (vtkIdType voxel = 0; voxel < count; ++voxel)
  {
    const bool seed = (mask[voxel] != 0) == of;
    values[voxel] = seed ? 0.f : std::numeric_limits<float>::infinity();
    nearest[voxel] = seed ? static_cast<int32_t>(voxel) : -1;
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    CubeDistancePass(values, nearest, dims, spacing, axis);
  }
}

/// The cube distances of CubeDistances over a box of the mask only (the
/// rest of the mask reads as beyond it): the transform costs what the box holds.
struct BoxedCubeDistances
{
  int Box[6];
  int Dims[3];
  int MaskDims[3];
  std::vector<float> Squared;
  std::vector<int32_t> Nearest;

  void Compute(const uint16_t* mask, const int maskDims[3], const int box[6], const double spacing[3], bool of)
  {
    std::copy(box, box + 6, this->Box);
    std::copy(maskDims, maskDims + 3, this->MaskDims);
    for (int axis = 0; axis < 3; ++axis)
    {
      this->Dims[axis] = box[2 * axis + 1] - box[2 * axis] + 1;
    }
    std::vector<uint16_t> boxMask(static_cast<size_t>(this->Dims[0]) * this->Dims[1] * this->Dims[2]);
    for (int k = 0; k < this->Dims[2]; ++k)
    {
      for (int j = 0; j < this->Dims[1]; ++j)
      {
        const uint16_t* row = mask + box[0] + static_cast<size_t>(maskDims[0]) * ((box[2] + j) + static_cast<size_t>(maskDims[1]) * (box[4] + k));
        std::copy(row, row + this->Dims[0], boxMask.begin() + static_cast<size_t>(this->Dims[0]) * (j + static_cast<size_t>(this->Dims[1]) * k));
      }
    }
    CubeDistances(boxMask.data(), this->Dims, spacing, of, this->Squared, this->Nearest);
  }
  /// Index in the box of a mask voxel, -1 outside it.
  vtkIdType Local(int i, int j, int k) const
  {
    if (i < this->Box[0] || i > this->Box[1] || j < this->Box[2] || j > this->Box[3] || k < this->Box[4] || k > this->Box[5])
    {
      return -1;
    }
    return (i - this->Box[0]) + static_cast<vtkIdType>(this->Dims[0]) * ((j - this->Box[2]) + static_cast<vtkIdType>(this->Dims[1]) * (k - this->Box[4]));
  }
  /// Distance (mm) from a voxel centre to the nearest cube; infinite outside the box.
  double DistanceAt(int i, int j, int k) const
  {
    const vtkIdType local = this->Local(i, j, k);
    return local < 0 ? std::numeric_limits<double>::infinity() : std::sqrt(static_cast<double>(this->Squared[local]));
  }
  /// The nearest cube's voxel as a mask index (-1: none, or outside the box).
  int32_t NearestAt(int i, int j, int k) const
  {
    const vtkIdType local = this->Local(i, j, k);
    const int32_t nearest = local < 0 ? -1 : this->Nearest[local];
    if (nearest < 0)
    {
      return -1;
    }
    const int li = nearest % this->Dims[0];
    const int lj = (nearest / this->Dims[0]) % this->Dims[1];
    const int lk = nearest / (this->Dims[0] * this->Dims[1]);
    return static_cast<int32_t>((li + this->Box[0]) + static_cast<vtkIdType>(this->MaskDims[0]) * ((lj + this->Box[2]) + static_cast<vtkIdType>(this->MaskDims[1]) * (lk + this->Box[4])));
  }
};

/// A sample's nearest cube, packed as its offset from the sample (10 bits
/// per axis, within +-511 voxels: the stored band never reaches farther)
/// and which side it is on: no division when a query unpacks it.
constexpr int ReferenceBits = 10;
constexpr int32_t ReferenceMask = (1 << ReferenceBits) - 1;
constexpr int ReferenceOffset = 1 << (ReferenceBits - 1);
int32_t PackCubeReference(int32_t cube, int i, int j, int k, const int dims[3], bool inside)
{
  const int cubeIndex[3] = { cube % dims[0], (cube / dims[0]) % dims[1], cube / (dims[0] * dims[1]) };
  const int sample[3] = { i, j, k };
  int32_t packed = 0;
  for (int axis = 0; axis < 3; ++axis)
  {
    const int offset = cubeIndex[axis] - sample[axis] + ReferenceOffset;
    if (offset < 0 || offset > ReferenceMask)
    {
      return -1;
    }
    packed |= static_cast<int32_t>(offset) << (ReferenceBits * axis);
  }
  return 2 * packed + (inside ? 1 : 0);
}

/// Surface points, and for every voxel the index of the nearest one found so far.
struct FootPoints
{
  /// x, y, z of each point together: the sweeps read them at random, one cache line a point.
  std::vector<float> Points;
  std::vector<int32_t> Nearest;
  std::vector<float> SquaredDistance;

  int32_t Add(const double p[3])
  {
    this->Points.insert(this->Points.end(), { static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]) });
    return static_cast<int32_t>(this->Points.size() / 3 - 1);
  }
  double SquaredDistanceTo(int32_t foot, const double p[3]) const
  {
    const float* point = this->Points.data() + 3 * static_cast<size_t>(foot);
    const double dx = p[0] - point[0], dy = p[1] - point[1], dz = p[2] - point[2];
    return dx * dx + dy * dy + dz * dz;
  }
  void Offer(vtkIdType voxel, int32_t foot, const double p[3])
  {
    const double d2 = this->SquaredDistanceTo(foot, p);
    if (d2 < this->SquaredDistance[voxel])
    {
      this->SquaredDistance[voxel] = static_cast<float>(d2);
      this->Nearest[voxel] = foot;
    }
  }
};

/// One raster sweep over the grid: each voxel takes the nearest of the foot
/// points its already visited neighbours hold (forward: the 13 before it in
/// memory order; backward: the 13 after it, visiting in reverse).
void Sweep(const LevelGrid& grid, FootPoints& feet, bool forward)
{
  int offsets[13][3];
  int n = 0;
  for (int dk = -1; dk <= 1; ++dk)
  {
    for (int dj = -1; dj <= 1; ++dj)
    {
      for (int di = -1; di <= 1; ++di)
      {
        const int linear = di + 3 * (dj + 3 * dk);
        if (forward ? linear < 0 : linear > 0)
        {
          offsets[n][0] = di;
          offsets[n][1] = dj;
          offsets[n][2] = dk;
          ++n;
        }
      }
    }
  }
  const int* dims = grid.Dims;
  vtkIdType linear[13];
  for (int n = 0; n < 13; ++n)
  {
    linear[n] = grid.Index(offsets[n][0], offsets[n][1], offsets[n][2]) - grid.Index(0, 0, 0);
  }
  const int step = forward ? 1 : -1;
  for (int k = forward ? 0 : dims[2] - 1; k >= 0 && k < dims[2]; k += step)
  {
    for (int j = forward ? 0 : dims[1] - 1; j >= 0 && j < dims[1]; j += step)
    {
      const bool innerRow = k > 0 && j > 0 && k < dims[2] - 1 && j < dims[1] - 1;
      for (int i = forward ? 0 : dims[0] - 1; i >= 0 && i < dims[0]; i += step)
      {
        const vtkIdType voxel = grid.Index(i, j, k);
        const double p[3] = { i * grid.Spacing[0], j * grid.Spacing[1], k * grid.Spacing[2] };
        if (innerRow && i > 0 && i < dims[0] - 1)
        {
          // Away from the grid's faces every neighbour exists: no bounds to check.
          for (const vtkIdType offset : linear)
          {
            const int32_t foot = feet.Nearest[voxel + offset];
            if (foot >= 0 && foot != feet.Nearest[voxel])
            {
              feet.Offer(voxel, foot, p);
            }
          }
          continue;
        }
        for (const int* offset : offsets)
        {
          const int ni = i + offset[0], nj = j + offset[1], nk = k + offset[2];
          if (ni < 0 || nj < 0 || nk < 0 || ni >= dims[0] || nj >= dims[1] || nk >= dims[2])
          {
            continue;
          }
          const int32_t foot = feet.Nearest[grid.Index(ni, nj, nk)];
          if (foot >= 0 && foot != feet.Nearest[voxel])
          {
            feet.Offer(voxel, foot, p);
          }
        }
      }
    }
  }
}
}

//------------------------------------------------------------------------------
std::unique_ptr<const vtkVolumeCutNerveMonitorField> vtkVolumeCutNerveMonitorField::Build(const uint16_t* mask, const int dims[3],
  const int origin[3], const double spacing[3], const int labelBox[6], double smoothing, double range, double contactRange)
{
  vtkVolumeCutLabelSurface::Levels levels;
  if (!vtkVolumeCutLabelSurface::Initialize(dims, spacing, labelBox, smoothing, levels))
  {
    return nullptr;
  }
  vtkSMPTools::For(0, vtkVolumeCutLabelSurface::GetNumberOfSlices(labelBox, levels), [&](vtkIdType begin, vtkIdType end) {
    vtkVolumeCutLabelSurface::ComputeSlices(mask, dims, spacing, 1, labelBox, smoothing, static_cast<int>(begin), static_cast<int>(end), levels);
  });
  vtkVolumeCutLabelSurface::ExtrapolateEnds(labelBox, levels);

  LevelGrid grid;
  std::copy(dims, dims + 3, grid.Dims);
  std::copy(spacing, spacing + 3, grid.Spacing);
  const vtkIdType count = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  grid.Values.assign(count, static_cast<float>(levels.Ramp));
  const int* box = levels.Box;
  const float* level = levels.Values.data();
  for (int k = box[4]; k <= box[5]; ++k)
  {
    for (int j = box[2]; j <= box[3]; ++j)
    {
      std::copy(level, level + (box[1] - box[0] + 1), grid.Values.begin() + grid.Index(box[0], j, k));
      level += box[1] - box[0] + 1;
    }
  }

  // The levels as the shield has them (vtkVolumeCutProtection's smoothed
  // brick), so that the monitor's zero is the wall the cut leaves.
  if (smoothing > 0.0)
  {
    CloseAcrossSlices(grid, levels.SliceAxis);
    NormalizeByGradient(grid);
  }
  // The shield also keeps every voxel of the structure whole: the protected
  // region is the smoothed interior and the voxel cubes together, whose
  // distance outside is the smaller of the two distances. Contact needs the
  // cubes' distance within contactRange of them (a burr's radius): the
  // transform of the structure's cubes runs over the label's box grown by
  // that and a brick's diagonal (a brick kept for the cubes has a sample
  // within contactRange and a cell's diagonal of them); without smoothing
  // the cubes are the surface too, wanted across the whole band.
  const bool useSmoothed = smoothing > 0.0;
  const double cellDiagonal = std::sqrt(spacing[0] * spacing[0] + spacing[1] * spacing[1] + spacing[2] * spacing[2]);
  const double cubeBand = useSmoothed ? std::min(contactRange, range) + cellDiagonal : std::numeric_limits<double>::infinity();
  int cubeBox[6];
  int freeBox[6];
  for (int axis = 0; axis < 3; ++axis)
  {
    const double reach = cubeBand + BrickCells * cellDiagonal;
    const int grow = std::isfinite(reach) ? static_cast<int>(std::ceil(reach / spacing[axis])) + 1 : dims[axis];
    cubeBox[2 * axis] = std::max(0, labelBox[2 * axis] - grow);
    cubeBox[2 * axis + 1] = std::min(dims[axis] - 1, labelBox[2 * axis + 1] + grow);
    // Inside, the nearest free voxel is within the structure's box grown by one voxel.
    freeBox[2 * axis] = std::max(0, labelBox[2 * axis] - 1);
    freeBox[2 * axis + 1] = std::min(dims[axis] - 1, labelBox[2 * axis + 1] + 1);
  }
  BoxedCubeDistances outsideCubes, insideCubes;
  outsideCubes.Compute(mask, dims, cubeBox, spacing, true);
  insideCubes.Compute(mask, dims, freeBox, spacing, false);
  const vtkIdType strides[3] = { 1, dims[0], static_cast<vtkIdType>(dims[0]) * dims[1] };
  auto labelled = [&](vtkIdType voxel) { return mask[voxel] != 0; };
  FootPoints feet;
  feet.Nearest.assign(count, -1);
  feet.SquaredDistance.assign(count, std::numeric_limits<float>::infinity());
  const double maximumSpacing = std::max({ spacing[0], spacing[1], spacing[2] });
  std::vector<uint8_t> besideSurface(count, 0);
  // Foot points on the smoothed surface: where its zero set crosses the
  // edges between voxel centres, and where Newton's iteration from the
  // voxels on either side lands.
  for (int k = box[4]; useSmoothed && k <= box[5]; ++k)
  {
    for (int j = box[2]; j <= box[3]; ++j)
    {
      for (int i = box[0]; i <= box[1]; ++i)
      {
        const vtkIdType voxel = grid.Index(i, j, k);
        const double g0 = grid.Values[voxel];
        const int ijk[3] = { i, j, k };
        for (int axis = 0; axis < 3; ++axis)
        {
          if (ijk[axis] + 1 >= dims[axis])
          {
            continue;
          }
          const vtkIdType neighbour = voxel + strides[axis];
          const double g1 = grid.Values[neighbour];
          if ((g0 <= 0.0) == (g1 <= 0.0))
          {
            continue;
          }
          besideSurface[voxel] = besideSurface[neighbour] = 1;
          const double t = g0 / (g0 - g1);
          double p[3] = { i * spacing[0], j * spacing[1], k * spacing[2] };
          p[axis] += t * spacing[axis];
          const int32_t foot = feet.Add(p);
          double at[3] = { i * spacing[0], j * spacing[1], k * spacing[2] };
          feet.Offer(voxel, foot, at);
          at[axis] += spacing[axis];
          feet.Offer(neighbour, foot, at);
        }
      }
    }
  }
  for (vtkIdType voxel = 0; voxel < count; ++voxel)
  {
    if (!besideSurface[voxel])
    {
      continue;
    }
    const int i = static_cast<int>(voxel % dims[0]);
    const int j = static_cast<int>((voxel / dims[0]) % dims[1]);
    const int k = static_cast<int>(voxel / strides[2]);
    const double start[3] = { i * spacing[0], j * spacing[1], k * spacing[2] };
    double x[3] = { start[0], start[1], start[2] };
    double value = 0.0;
    for (int iteration = 0; iteration < 12; ++iteration)
    {
      double gradient[3];
      value = grid.Evaluate(x, gradient);
      const double squaredNorm = gradient[0] * gradient[0] + gradient[1] * gradient[1] + gradient[2] * gradient[2];
      if (std::abs(value) < 1e-7 || squaredNorm < 1e-12)
      {
        break;
      }
      double factor = value / squaredNorm;
      const double length = std::abs(factor) * std::sqrt(squaredNorm);
      factor *= length > 0.5 * maximumSpacing ? 0.5 * maximumSpacing / length : 1.0;
      for (int axis = 0; axis < 3; ++axis)
      {
        x[axis] -= factor * gradient[axis];
      }
    }
    const double moved2 = (x[0] - start[0]) * (x[0] - start[0]) + (x[1] - start[1]) * (x[1] - start[1]) + (x[2] - start[2]) * (x[2] - start[2]);
    if (std::abs(value) < 1e-5 && moved2 < 4.0 * maximumSpacing * maximumSpacing)
    {
      feet.Offer(voxel, feet.Add(x), start);
    }
  }
  std::vector<uint8_t>().swap(besideSurface);

  for (int round = 0; round < 2; ++round)
  {
    Sweep(grid, feet, true);
    Sweep(grid, feet, false);
  }

  auto field = std::unique_ptr<vtkVolumeCutNerveMonitorField>(new vtkVolumeCutNerveMonitorField);
  std::copy(origin, origin + 3, field->Origin);
  std::copy(dims, dims + 3, field->Dimensions);
  std::copy(spacing, spacing + 3, field->Spacing);
  field->Range = range;
  field->SurfaceIsCubes = !useSmoothed;
  field->NumberOfFootPoints = feet.Points.size() / 3;
  for (int axis = 0; axis < 3; ++axis)
  {
    // The smoothed surface may reach a voxel beyond the structure's voxels.
    field->LabelLower[axis] = origin[axis] + labelBox[2 * axis] - 1.0;
    field->LabelUpper[axis] = origin[axis] + labelBox[2 * axis + 1] + 1.0;
    field->BrickCounts[axis] = std::max(1, (dims[axis] - 1 + BrickCells - 1) / BrickCells);
  }
  const vtkIdType brickCount = static_cast<vtkIdType>(field->BrickCounts[0]) * field->BrickCounts[1] * field->BrickCounts[2];
  field->Directory.assign(brickCount, FarOutside);
  constexpr int samplesPerBrick = BrickSamples * BrickSamples * BrickSamples;
  std::vector<float> samples(samplesPerBrick);
  std::vector<int32_t> sampleCubes(samplesPerBrick);
  double protrusion = 0.0;
  for (int bz = 0; bz < field->BrickCounts[2]; ++bz)
  {
    for (int by = 0; by < field->BrickCounts[1]; ++by)
    {
      for (int bx = 0; bx < field->BrickCounts[0]; ++bx)
      {
        double nearest = std::numeric_limits<double>::infinity();
        double nearestCubes = std::numeric_limits<double>::infinity();
        double brickProtrusion = 0.0;
        bool inside = false;
        int n = 0;
        for (int z = 0; z < BrickSamples; ++z)
        {
          const int k = std::min(bz * BrickCells + z, dims[2] - 1);
          for (int y = 0; y < BrickSamples; ++y)
          {
            const int j = std::min(by * BrickCells + y, dims[1] - 1);
            for (int x = 0; x < BrickSamples; ++x, ++n)
            {
              const int i = std::min(bx * BrickCells + x, dims[0] - 1);
              const vtkIdType voxel = grid.Index(i, j, k);
              const double cubes = labelled(voxel) ? -insideCubes.DistanceAt(i, j, k) : outsideCubes.DistanceAt(i, j, k);
              const double smoothed = std::sqrt(static_cast<double>(feet.SquaredDistance[voxel]));
              const double smoothedSigned = grid.Values[voxel] <= 0.f ? -smoothed : smoothed;
              const double surface = useSmoothed ? smoothedSigned : cubes;
              const double shield = std::min(cubes, surface);
              // The smoothed surface's distance is interpolated; the cubes'
              // is computed exactly at query time from the nearest cube of
              // the structure (outside it) or of the free voxels (inside).
              samples[n] = static_cast<float>(useSmoothed ? smoothedSigned : NoSmoothedSurface);
              const int32_t cube = labelled(voxel) ? insideCubes.NearestAt(i, j, k) : outsideCubes.NearestAt(i, j, k);
              sampleCubes[n] = cube < 0 ? -1 : PackCubeReference(cube, i, j, k, dims, labelled(voxel));
              nearest = std::min(nearest, std::abs(shield));
              nearestCubes = std::min(nearestCubes, std::abs(cubes));
              brickProtrusion = std::max(brickProtrusion, surface - shield);
              inside = inside || shield < 0.0;
            }
          }
        }
        const vtkIdType brick = bx + static_cast<vtkIdType>(field->BrickCounts[0]) * (by + static_cast<vtkIdType>(field->BrickCounts[1]) * bz);
        if (nearest <= range)
        {
          field->Directory[brick] = static_cast<int32_t>(field->Bricks.size() / samplesPerBrick);
          field->Bricks.insert(field->Bricks.end(), samples.begin(), samples.end());
          const bool keepCubes = nearestCubes <= cubeBand;
          field->CubeDirectory.push_back(keepCubes ? static_cast<int32_t>(field->NearestCubes.size() / samplesPerBrick) : -1);
          if (keepCubes)
          {
            field->NearestCubes.insert(field->NearestCubes.end(), sampleCubes.begin(), sampleCubes.end());
            protrusion = std::max(protrusion, brickProtrusion);
          }
        }
        else
        {
          field->Directory[brick] = inside ? DeepInside : FarOutside;
        }
      }
    }
  }
  // Between samples the interpolated surface distance and the exact cubes'
  // may part by up to a cell's diagonal more than at the samples.
  field->MaximumProtrusion = protrusion + cellDiagonal;
  field->Bricks.shrink_to_fit();
  field->CubeDirectory.shrink_to_fit();
  field->NearestCubes.shrink_to_fit();
  return field;
}

//------------------------------------------------------------------------------
double vtkVolumeCutNerveMonitorField::GetDistance(const double ijk[3]) const
{
  double surface, shield;
  if (this->SurfaceIsCubes)
  {
    this->GetDistances(ijk, surface, shield);
    return surface;
  }
  double local[3];
  int brick[3];
  int cell[3];
  double t[3];
  const float* s = this->Locate(ijk, local, brick, cell, t, surface);
  return s ? this->Interpolate(s, t) : surface;
}

//------------------------------------------------------------------------------
void vtkVolumeCutNerveMonitorField::GetDistances(const double ijk[3], double& surface, double& shield) const
{
  double local[3];
  int brick[3];
  int cell[3];
  double t[3];
  const float* s = this->Locate(ijk, local, brick, cell, t, surface);
  if (!s)
  {
    shield = surface;
    return;
  }
  const size_t stored = static_cast<size_t>(s - this->Bricks.data()) / (BrickSamples * BrickSamples * BrickSamples);
  const int32_t cubes = this->CubeDirectory[stored];
  const double smoothed = this->SurfaceIsCubes ? static_cast<double>(NoSmoothedSurface) : this->Interpolate(s, t);
  if (cubes < 0)
  {
    // No cube within ContactRange of this brick: the shield is the smoothed surface here, or both are farther.
    surface = shield = smoothed;
    return;
  }
  const size_t inBrick = static_cast<size_t>(s - this->Bricks.data()) - stored * BrickSamples * BrickSamples * BrickSamples;
  shield = this->GetShieldDistance(this->NearestCubes.data() + static_cast<size_t>(cubes) * BrickSamples * BrickSamples * BrickSamples + inBrick,
    brick, cell, local, t, smoothed);
  surface = this->SurfaceIsCubes ? shield : smoothed;
}

//------------------------------------------------------------------------------
const float* vtkVolumeCutNerveMonitorField::Locate(const double ijk[3], double local[3], int brick[3], int cell[3], double t[3], double& outside) const
{
  for (int axis = 0; axis < 3; ++axis)
  {
    local[axis] = ijk[axis] - this->Origin[axis];
    if (!(local[axis] >= 0.0 && local[axis] <= this->Dimensions[axis] - 1)) // NaN too
    {
      outside = this->GetFarDistance(ijk);
      return nullptr;
    }
    brick[axis] = std::min(static_cast<int>(local[axis]) / BrickCells, this->BrickCounts[axis] - 1);
    const double inBrick = local[axis] - brick[axis] * BrickCells;
    cell[axis] = std::min(static_cast<int>(inBrick), BrickCells - 1);
    t[axis] = inBrick - cell[axis];
  }
  const int32_t index = this->Directory[brick[0] + static_cast<size_t>(this->BrickCounts[0]) * (brick[1] + static_cast<size_t>(this->BrickCounts[1]) * brick[2])];
  if (index < 0)
  {
    outside = index == DeepInside ? -this->Range : this->GetFarDistance(ijk);
    return nullptr;
  }
  return this->Bricks.data() + static_cast<size_t>(index) * BrickSamples * BrickSamples * BrickSamples + cell[0] +
    BrickSamples * (cell[1] + BrickSamples * cell[2]);
}

//------------------------------------------------------------------------------
double vtkVolumeCutNerveMonitorField::Interpolate(const float* s, const double t[3])
{
  constexpr int sy = BrickSamples;
  constexpr int sz = BrickSamples * BrickSamples;
  const double x00 = s[0] + t[0] * (s[1] - s[0]);
  const double x10 = s[sy] + t[0] * (s[sy + 1] - s[sy]);
  const double x01 = s[sz] + t[0] * (s[sz + 1] - s[sz]);
  const double x11 = s[sz + sy] + t[0] * (s[sz + sy + 1] - s[sz + sy]);
  const double y0 = x00 + t[1] * (x10 - x00);
  const double y1 = x01 + t[1] * (x11 - x01);
  return y0 + t[2] * (y1 - y0);
}

//------------------------------------------------------------------------------
double vtkVolumeCutNerveMonitorField::GetShieldDistance(const int32_t* nearest, const int brick[3], const int cell[3], const double local[3],
  const double t[3], double smoothed) const
{
  constexpr int sy = BrickSamples;
  constexpr int sz = BrickSamples * BrickSamples;
  // The voxel cubes' distance bends at their edges and corners, which
  // interpolation would miss: it is computed exactly to the cubes nearest
  // to the cell's corners. Outside the cubes (the voxel holding the point,
  // the nearest corner, is free): the distance to the structure's cubes
  // nearest to the free corners; inside: minus the distance to the free
  // cubes nearest to the structure's corners.
  const int ownCorner = (t[0] >= 0.5 ? 1 : 0) + (t[1] >= 0.5 ? sy : 0) + (t[2] >= 0.5 ? sz : 0);
  const int32_t insideFlag = nearest[ownCorner] & 1;
  double squared = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 8; ++c)
  {
    const int corner[3] = { c & 1, (c >> 1) & 1, (c >> 2) & 1 };
    const int32_t reference = nearest[corner[0] + corner[1] * sy + corner[2] * sz];
    int cubeIndex[3];
    if (reference < 0)
    {
      continue; // no voxel of that side in the mask
    }
    if ((reference & 1) == insideFlag)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        const int sample = std::min(brick[axis] * BrickCells + cell[axis] + corner[axis], this->Dimensions[axis] - 1);
        cubeIndex[axis] = sample + ((reference >> (1 + ReferenceBits * axis)) & ReferenceMask) - ReferenceOffset;
      }
    }
    else
    {
      // A corner on the other side: its own voxel's cube is one of those sought.
      for (int axis = 0; axis < 3; ++axis)
      {
        cubeIndex[axis] = brick[axis] * BrickCells + cell[axis] + corner[axis];
      }
    }
    double sum = 0.0;
    for (int axis = 0; axis < 3; ++axis)
    {
      const double gap = std::max(std::abs(local[axis] - cubeIndex[axis]) - 0.5, 0.0) * this->Spacing[axis];
      sum += gap * gap;
    }
    squared = std::min(squared, sum);
  }
  const double cubes = std::sqrt(squared);
  return std::min(smoothed, insideFlag ? -cubes : cubes);
}

//------------------------------------------------------------------------------
double vtkVolumeCutNerveMonitorField::GetFarDistance(const double ijk[3]) const
{
  double squared = 0.0;
  for (int axis = 0; axis < 3; ++axis)
  {
    const double gap = std::max({ this->LabelLower[axis] - ijk[axis], ijk[axis] - this->LabelUpper[axis], 0.0 }) * this->Spacing[axis];
    squared += gap * gap;
  }
  const double distance = std::sqrt(squared);
  return distance > this->Range ? distance : this->Range; // NaN positions give Range
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutNerveMonitorField::GetMemorySize() const
{
  return sizeof(*this) + this->Directory.capacity() * sizeof(int32_t) + this->Bricks.capacity() * sizeof(float) +
    this->CubeDirectory.capacity() * sizeof(int32_t) + this->NearestCubes.capacity() * sizeof(int32_t);
}
