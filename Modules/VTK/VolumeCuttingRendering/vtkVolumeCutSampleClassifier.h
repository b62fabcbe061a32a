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

  /// The CT value at p (trilinear).
  float Interpolate(const double p[3]) const { return this->InterpolateArray(this->Scene.Values.data(), p); }

  float InterpolateArray(const float* values, const double p[3]) const
  {
    int base[3];
    double f[3];
    this->CellOf(p, base, f);
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
    for (const vtkVolumeCutRayScene::FractionVolume& fraction : scene.Fractions)
    {
      if (!acceptFraction(fraction.Label))
      {
        continue;
      }
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
  int DominantLabel(const double p[3], double& weight) const
  {
    const vtkVolumeCutRayScene& scene = this->Scene;
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
    for (const vtkVolumeCutRayScene::FractionVolume& fraction : scene.Fractions)
    {
      if (fraction.Label == label)
      {
        return this->InterpolateArray(fraction.Values.data(), p);
      }
    }
    if (scene.Labels.empty())
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
  const vtkVolumeCutRayScene& Scene;
};

#endif
