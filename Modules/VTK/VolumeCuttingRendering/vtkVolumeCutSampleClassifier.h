// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutSampleClassifier
 * @brief   Step 1 of adaptive sampling (Pflesser et al.): classification at a sample point.
 *
 * Which segment's object is at a point of the anatomy (the segment of
 * greatest trilinear weight among the cell's corners, or its fractional
 * labelmap, then inside its surface: the CT iso-value or the segment's own
 * shape), the interpolated CT value there, and each cut field's signed
 * distance (removed where negative). Fields are interpolated in the
 * anatomy's IJK coordinates, cut fields in world coordinates.
 *
 * @sa vtkVolumeCutBorderLocator (step 2)
 */
#ifndef vtkVolumeCutSampleClassifier_h
#define vtkVolumeCutSampleClassifier_h

#include "vtkVolumeCutRayScene.h"

#include "vtkVolumeCutField.h"

#include <algorithm>
#include <cmath>
#include <limits>

/// One point of a ray and what is there.
struct vtkVolumeCutSample
{
  double T = 0.0;
  double Index[3] = { 0.0, 0.0, 0.0 };
  int Object = 0;
  float Value = 0.f;
  bool CutsKnown = false;
  double Distance[vtkVolumeCutRayScene::MaximumCutFields];

  /// The point at ray parameter t of the ray o + t d (IJK).
  static vtkVolumeCutSample At(const double o[3], const double d[3], double t)
  {
    vtkVolumeCutSample s;
    s.T = t;
    for (int axis = 0; axis < 3; ++axis)
    {
      s.Index[axis] = o[axis] + t * d[axis];
    }
    return s;
  }
};

class vtkVolumeCutSampleClassifier
{
public:
  explicit vtkVolumeCutSampleClassifier(const vtkVolumeCutRayScene& scene)
    : Scene(scene)
  {
  }

  /// The cell holding p (clamped to the volume) and p's offsets in it.
  void CellOf(const double p[3], int base[3], double f[3]) const
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      const double x = std::min(std::max(p[axis], 0.0), double(this->Scene.Dimensions[axis] - 1));
      base[axis] = std::min(static_cast<int>(x), this->Scene.Dimensions[axis] - 2);
      f[axis] = x - base[axis];
    }
  }

  /**
   * The largest CT value at the corners of the cells that the box from p to
   * q touches: no trilinear value on the segment pq exceeds it.
   */
  float MaximumAround(const double p[3], const double q[3]) const
  {
    int low[3], high[3];
    double f[3];
    this->CellOf(p, low, f);
    this->CellOf(q, high, f);
    for (int axis = 0; axis < 3; ++axis)
    {
      if (low[axis] > high[axis])
      {
        std::swap(low[axis], high[axis]);
      }
    }
    const vtkIdType sy = this->Scene.Dimensions[0];
    const vtkIdType sz = static_cast<vtkIdType>(this->Scene.Dimensions[0]) * this->Scene.Dimensions[1];
    float maximum = -std::numeric_limits<float>::infinity();
    for (int k = low[2]; k <= high[2] + 1; ++k)
    {
      for (int j = low[1]; j <= high[1] + 1; ++j)
      {
        const float* row = this->Scene.Values.data() + j * sy + k * sz;
        for (int i = low[0]; i <= high[0] + 1; ++i)
        {
          maximum = std::max(maximum, row[i]);
        }
      }
    }
    return maximum;
  }

  /**
   * Whether the trilinear CT value reaches \a level somewhere on the segment
   * from p to q (IJK). Exact up to rounding: in each cell the segment
   * crosses, the value along it is a cubic in the ray parameter, whose
   * maximum lies at an end of the piece or where its derivative vanishes.
   */
  bool Reaches(const double p[3], const double q[3], float level) const
  {
    if (this->MaximumAround(p, q) < level)
    {
      return false;
    }
    double d[3];
    // Cell walls the segment crosses split it into pieces, one cell each.
    double cuts[8] = { 0.0, 1.0 };
    int count = 2;
    for (int axis = 0; axis < 3; ++axis)
    {
      d[axis] = q[axis] - p[axis];
      if (std::abs(d[axis]) < 1e-12)
      {
        continue;
      }
      const double from = std::min(p[axis], q[axis]);
      const double to = std::max(p[axis], q[axis]);
      for (double wall = std::floor(from) + 1.0; wall < to && count < 8; wall += 1.0)
      {
        cuts[count++] = (wall - p[axis]) / d[axis];
      }
    }
    std::sort(cuts, cuts + count);
    const vtkIdType sy = this->Scene.Dimensions[0];
    const vtkIdType sz = static_cast<vtkIdType>(this->Scene.Dimensions[0]) * this->Scene.Dimensions[1];
    for (int piece = 0; piece + 1 < count; ++piece)
    {
      const double t0 = cuts[piece];
      const double t1 = cuts[piece + 1];
      if (!(t1 > t0))
      {
        continue;
      }
      const double middle[3] = { p[0] + 0.5 * (t0 + t1) * d[0], p[1] + 0.5 * (t0 + t1) * d[1], p[2] + 0.5 * (t0 + t1) * d[2] };
      int base[3];
      double f[3];
      this->CellOf(middle, base, f);
      const float* v = this->Scene.Values.data() + base[0] + base[1] * sy + base[2] * sz;
      // Trilinear value as A + Bx + Cy + Dz + Exy + Fxz + Gyz + Hxyz.
      const double A = v[0];
      const double B = v[1] - v[0];
      const double C = v[sy] - v[0];
      const double D = v[sz] - v[0];
      const double E = v[sy + 1] - v[sy] - v[1] + v[0];
      const double F = v[sz + 1] - v[sz] - v[1] + v[0];
      const double G = v[sz + sy] - v[sz] - v[sy] + v[0];
      const double H = v[sz + sy + 1] - v[sz + sy] - v[sz + 1] - v[sy + 1] + v[sz] + v[sy] + v[1] - v[0];
      // Local coordinates along the piece: x = x0 + t dx (t is the segment's parameter).
      const double x0 = p[0] - base[0], y0 = p[1] - base[1], z0 = p[2] - base[2];
      const double dx = d[0], dy = d[1], dz = d[2];
      const double k0 = A + B * x0 + C * y0 + D * z0 + E * x0 * y0 + F * x0 * z0 + G * y0 * z0 + H * x0 * y0 * z0;
      const double k1 = B * dx + C * dy + D * dz + E * (x0 * dy + y0 * dx) + F * (x0 * dz + z0 * dx) + G * (y0 * dz + z0 * dy) +
        H * (dx * y0 * z0 + x0 * dy * z0 + x0 * y0 * dz);
      const double k2 = E * dx * dy + F * dx * dz + G * dy * dz + H * (dx * dy * z0 + dx * y0 * dz + x0 * dy * dz);
      const double k3 = H * dx * dy * dz;
      auto value = [&](double t) { return k0 + t * (k1 + t * (k2 + t * k3)); };
      // A margin of a millionth of the level's scale covers rounding.
      const double margin = 1e-6 * (std::abs(double(level)) + 1.0);
      if (value(t0) + margin >= level || value(t1) + margin >= level)
      {
        return true;
      }
      // Stationary points: roots of k1 + 2 k2 t + 3 k3 t^2.
      double roots[2];
      int found = 0;
      const double a2 = 3.0 * k3, a1 = 2.0 * k2, a0 = k1;
      if (std::abs(a2) > 1e-300)
      {
        const double discriminant = a1 * a1 - 4.0 * a2 * a0;
        if (discriminant >= 0.0)
        {
          const double root = std::sqrt(discriminant);
          roots[found++] = (-a1 - root) / (2.0 * a2);
          roots[found++] = (-a1 + root) / (2.0 * a2);
        }
      }
      else if (std::abs(a1) > 1e-300)
      {
        roots[found++] = -a0 / a1;
      }
      for (int r = 0; r < found; ++r)
      {
        if (roots[r] > t0 && roots[r] < t1 && value(roots[r]) + margin >= level)
        {
          return true;
        }
      }
    }
    return false;
  }

  /// The CT value at p (trilinear).
  float Interpolate(const double p[3]) const { return this->InterpolateArray(this->Scene.Values.data(), p); }

  float InterpolateArray(const float* values, const double p[3]) const
  {
    int base[3];
    double f[3];
    this->CellOf(p, base, f);
    return this->InterpolateInCell(values, base, f);
  }

  /// The trilinear value of \a values in the cell at \a base, at offsets \a f in it.
  float InterpolateInCell(const float* values, const int base[3], const double f[3]) const
  {
    const vtkIdType sx = 1;
    const vtkIdType sy = this->Scene.Dimensions[0];
    const vtkIdType sz = static_cast<vtkIdType>(this->Scene.Dimensions[0]) * this->Scene.Dimensions[1];
    const float* v = values + base[0] + base[1] * sy + base[2] * sz;
    const double c00 = v[0] + f[0] * (v[sx] - v[0]);
    const double c10 = v[sy] + f[0] * (v[sy + sx] - v[sy]);
    const double c01 = v[sz] + f[0] * (v[sz + sx] - v[sz]);
    const double c11 = v[sz + sy] + f[0] * (v[sz + sy + sx] - v[sz + sy]);
    const double c0 = c00 + f[1] * (c10 - c00);
    const double c1 = c01 + f[1] * (c11 - c01);
    return static_cast<float>(c0 + f[2] * (c1 - c0));
  }

  /**
   * The segment of greatest weight at p, and that weight: each label's
   * trilinear weight among the corners of p's cell that \a acceptCorner(label,
   * voxel, weight) takes, replaced by the interpolated fraction for segments
   * with a fractional labelmap that \a acceptFraction(label) takes (the label
   * map's indicator is the binary special case of a fraction). Ties go to
   * the lower label so that every path decides the same way; 0 when none.
   */
  template <typename CornerFilter, typename FractionFilter>
  int StrongestLabel(const double p[3], CornerFilter&& acceptCorner, FractionFilter&& acceptFraction, double& weight) const
  {
    const vtkVolumeCutRayScene& scene = this->Scene;
    int base[3];
    double f[3];
    this->CellOf(p, base, f);
    int labels[8 + vtkVolumeCutRayScene::MaximumFractions];
    double weights[8 + vtkVolumeCutRayScene::MaximumFractions];
    int count = 0;
    for (int corner = 0; corner < 8 && !scene.Labels.empty(); ++corner)
    {
      const int c[3] = { base[0] + (corner & 1), base[1] + ((corner >> 1) & 1), base[2] + ((corner >> 2) & 1) };
      const vtkIdType voxel = c[0] + static_cast<vtkIdType>(scene.Dimensions[0]) * (c[1] + static_cast<vtkIdType>(scene.Dimensions[1]) * c[2]);
      const int label = scene.Labels[voxel];
      const double w =
        ((corner & 1) ? f[0] : 1.0 - f[0]) * (((corner >> 1) & 1) ? f[1] : 1.0 - f[1]) * (((corner >> 2) & 1) ? f[2] : 1.0 - f[2]);
      if (!acceptCorner(label, voxel, w))
      {
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
    const vtkIdType block = scene.Fractions.empty() ? 0 : scene.FractionBlockOf(base);
    for (const vtkVolumeCutRayScene::FractionVolume& fraction : scene.Fractions)
    {
      if (!acceptFraction(fraction.Label))
      {
        continue;
      }
      // The cell found once for all fractions; 0 where every corner is.
      const double w = this->FractionInCell(fraction, block, base, f);
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
      if (weights[slot] > weight || (weights[slot] == weight && weight > 0.0 && labels[slot] < best))
      {
        best = labels[slot];
        weight = weights[slot];
      }
    }
    return best;
  }

  /// The segment label with the largest trilinear weight among the cell's
  /// corners (hidden segments included, background not), and that weight (the
  /// label's interpolated indicator). Where two segments meet, their border is
  /// where their weights are equal, a smooth surface; where a segment meets
  /// the background, the CT's iso-surface (or the indicator at 0.5) decides.
  /// The label map read here is resolved first (vtkVolumeCutPartialVolumeLabels):
  /// hidden voxels below every iso-value are background, and partial-volume
  /// voxels beside a shown iso segment are that segment's, so neither cuts
  /// its iso-surface flat at the labels' border.
  int DominantLabel(const double p[3], double& weight) const
  {
    const vtkVolumeCutRayScene& scene = this->Scene;
    if (scene.Fractions.empty() && !scene.Labels.empty())
    {
      // Most cells lie inside one segment or in the background: all eight
      // corners agree, and so does every weighing below.
      int base[3];
      double f[3];
      this->CellOf(p, base, f);
      const vtkIdType sy = scene.Dimensions[0];
      const vtkIdType sz = static_cast<vtkIdType>(scene.Dimensions[0]) * scene.Dimensions[1];
      const uint16_t* l = scene.Labels.data() + base[0] + base[1] * sy + base[2] * sz;
      const uint16_t label = l[0];
      if (l[1] == label && l[sy] == label && l[sy + 1] == label && l[sz] == label && l[sz + 1] == label && l[sz + sy] == label &&
        l[sz + sy + 1] == label)
      {
        weight = label == 0 ? 0.0 : 1.0;
        return label;
      }
      // A cell where segments meet (every surface's border search lands in
      // one): the weighing below without fractions, summed in the same
      // order, so that it decides exactly as StrongestLabel does.
      const vtkIdType offsets[8] = { 0, 1, sy, sy + 1, sz, sz + 1, sz + sy, sz + sy + 1 };
      int labels[8];
      double weights[8];
      for (int corner = 0; corner < 8; ++corner)
      {
        labels[corner] = l[offsets[corner]];
        weights[corner] =
          ((corner & 1) ? f[0] : 1.0 - f[0]) * (((corner >> 1) & 1) ? f[1] : 1.0 - f[1]) * (((corner >> 2) & 1) ? f[2] : 1.0 - f[2]);
      }
      const vtkIdType first = base[0] + base[1] * sy + base[2] * sz;
      double unlabelledBright = 0.0;
      int best = 0;
      weight = 0.0;
      for (int corner = 0; corner < 8; ++corner)
      {
        const int candidate = labels[corner];
        if (candidate == 0)
        {
          if (scene.AnyIsoSegment && scene.Values[first + offsets[corner]] >= scene.MinimumIso)
          {
            unlabelledBright += weights[corner];
          }
          continue;
        }
        bool seen = false;
        for (int earlier = 0; earlier < corner && !seen; ++earlier)
        {
          seen = labels[earlier] == candidate;
        }
        if (seen)
        {
          continue;
        }
        double sum = 0.0;
        for (int later = corner; later < 8; ++later)
        {
          if (labels[later] == candidate)
          {
            sum += weights[later];
          }
        }
        if (sum > weight || (sum == weight && weight > 0.0 && candidate < best))
        {
          best = candidate;
          weight = sum;
        }
      }
      return unlabelledBright > weight ? 0 : best;
    }
    double unlabelledBright = 0.0;
    const int best = this->StrongestLabel(
      p,
      [&](int label, vtkIdType voxel, double w) {
        if (label == 0)
        {
          // Material above the surface value that no shown segment claims
          // competes like a segment: its border with a shown one is smooth,
          // not the cell faces where a labelled voxel first counts.
          if (scene.AnyIsoSegment && scene.Values[voxel] >= scene.MinimumIso)
          {
            unlabelledBright += w;
          }
          return false;
        }
        return true;
      },
      [](int) { return true; }, weight);
    return unlabelledBright > weight ? 0 : best;
  }

  /// Whether a label is a shown segment whose surface is a CT iso-surface.
  bool ShownIsoSegment(int label) const
  {
    const std::vector<vtkVolumeCutRayScene::SegmentStyle>& styles = this->Scene.Styles;
    return label > 0 && label < static_cast<int>(styles.size()) && styles[label].Opacity > 0.f && !styles[label].Shape;
  }

  /**
   * The segment whose material lies under a point p (IJK) of an iso-surface:
   * among the corners of p's cell inside the surface (CT value at or above
   * their segment's iso-value), the shown, iso-defined segment of greatest
   * weight (fractional labelmaps weigh their fraction); 0 if there is none.
   * The voxels an iso-surface crosses hold part bone, part surroundings:
   * those outside it often carry another label (or none) than the bone
   * behind, whose colour the surface should show.
   */
  int MaterialOwner(const double p[3]) const
  {
    const vtkVolumeCutRayScene& scene = this->Scene;
    double weight = 0.0;
    return this->StrongestLabel(
      p,
      [&](int label, vtkIdType voxel, double) {
        return this->ShownIsoSegment(label) && scene.Values[voxel] >= scene.Styles[label].Iso;
      },
      [&](int label) { return this->ShownIsoSegment(label); }, weight);
  }

  /// Interpolated indicator of one label (for shape-defined segments' normals).
  double Indicator(int label, const double p[3]) const
  {
    const vtkVolumeCutRayScene& scene = this->Scene;
    int base[3];
    double f[3];
    this->CellOf(p, base, f);
    for (const vtkVolumeCutRayScene::FractionVolume& fraction : scene.Fractions)
    {
      if (fraction.Label == label)
      {
        return this->FractionInCell(fraction, scene.FractionBlockOf(base), base, f);
      }
    }
    if (scene.Labels.empty())
    {
      return 0.0;
    }
    double value = 0.0;
    for (int corner = 0; corner < 8; ++corner)
    {
      const int c[3] = { base[0] + (corner & 1), base[1] + ((corner >> 1) & 1), base[2] + ((corner >> 2) & 1) };
      if (scene.Labels[c[0] + static_cast<vtkIdType>(scene.Dimensions[0]) * (c[1] + static_cast<vtkIdType>(scene.Dimensions[1]) * c[2])] ==
        label)
      {
        value += ((corner & 1) ? f[0] : 1.0 - f[0]) * (((corner >> 1) & 1) ? f[1] : 1.0 - f[1]) * (((corner >> 2) & 1) ? f[2] : 1.0 - f[2]);
      }
    }
    return value;
  }

  /// Which visible object is at p (0 for none), and the CT value there.
  int ObjectAt(const double p[3], float& value) const
  {
    const vtkVolumeCutRayScene& scene = this->Scene;
    value = this->Interpolate(p);
    if (!scene.HasSegments())
    {
      const vtkVolumeCutRayScene::SegmentStyle& style = scene.Styles[1];
      return (style.Opacity > 0.f && value >= style.Iso) ? 1 : 0;
    }
    if (!scene.AnyShapeSegment && !(double(value) >= scene.MinimumIso))
    {
      // Under every shown segment's iso-value and no segment drawn by its
      // shape: no label can be visible here, whichever dominates (most
      // samples in soft tissue beside bone, and most ambient occlusion's).
      return 0;
    }
    double weight = 0.0;
    const int label = this->DominantLabel(p, weight);
    if (label == 0 || label >= static_cast<int>(scene.Styles.size()) || scene.Styles[label].Opacity <= 0.f)
    {
      return 0; // background, or a hidden segment
    }
    const vtkVolumeCutRayScene::SegmentStyle& style = scene.Styles[label];
    const bool inside = style.Shape ? weight >= 0.5 : value >= style.Iso;
    return inside ? label : 0;
  }

  void EvaluateObject(vtkVolumeCutSample& s) const { s.Object = this->ObjectAt(s.Index, s.Value); }

  void WorldPoint(const double index[3], double world[3]) const { vtkVolumeCutRayMath::TransformPoint(this->Scene.IJKToWorld, index, world); }

  /// Each cut field's signed distance at the sample (once).
  void EvaluateCuts(vtkVolumeCutSample& s) const
  {
    if (s.CutsKnown)
    {
      return;
    }
    double world[3];
    this->WorldPoint(s.Index, world);
    for (size_t n = 0; n < this->Scene.CutFields.size(); ++n)
    {
      s.Distance[n] = this->Scene.CutFields[n]->GetSignedDistance(world);
    }
    s.CutsKnown = true;
  }

  bool Removed(const vtkVolumeCutSample& s) const
  {
    for (size_t n = 0; n < this->Scene.CutFields.size(); ++n)
    {
      if (s.Distance[n] < 0.0)
      {
        return true;
      }
    }
    return false;
  }

  /// An object that no cut removed.
  bool Visible(vtkVolumeCutSample& s) const
  {
    if (s.Object == 0)
    {
      return false;
    }
    this->EvaluateCuts(s);
    return !this->Removed(s);
  }

private:
  /// A fraction in the cell at \a base (in fraction block \a block): exactly
  /// what InterpolateArray gives, 0 without reading where all corners are.
  float FractionInCell(const vtkVolumeCutRayScene::FractionVolume& fraction, vtkIdType block, const int base[3], const double f[3]) const
  {
    if (!fraction.NonZeroBlocks.empty() && !fraction.NonZeroBlocks[block])
    {
      return 0.f;
    }
    return this->InterpolateInCell(fraction.Values.data(), base, f);
  }

  const vtkVolumeCutRayScene& Scene;
};

#endif
