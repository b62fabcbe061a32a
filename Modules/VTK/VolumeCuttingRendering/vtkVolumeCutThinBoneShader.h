// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutThinBoneShader
 * @brief   Thin-bone shading (Morris et al., seed 003): bone thinner than a threshold turns red and translucent.
 *
 * From a surface point, marches inward (against the outward normal) in
 * quarter-voxel steps until no visible material is left, whatever its
 * segment (cortical over trabecular bone is one wall), up to the threshold;
 * a wall thinner than that is tinted red and made translucent in proportion,
 * so that what lies behind it shows through. Where the march leaves the
 * material, the crossing is found by halving the last step (to 1/256 of a
 * voxel), so that the thickness, and the tint, vary continuously over a
 * surface instead of in quarter-voxel steps that a magnified view shows as
 * blotches (issue 28).
 *
 * Where two shown segments meet (cortex over trabecular bone), each one's
 * smoothed label weight falls below one half a little before the other's
 * rises above it, so a sliver of about a quarter voxel between them belongs
 * to neither. The march used to end there: a thick wall read as thin
 * wherever a step landed in the sliver, which gave red flecks and bands
 * across drilled floors (issue 28). A segment drawn slice by slice has
 * slices drawn a little larger than the next: each leaves a ledge one slice
 * thick over a notch about a voxel deep, and a march from the ledge down
 * through it left the material there, so every terrace of the temporal
 * bone's mastoid drew a line of red flecks (issue 28, finding 9). A gap of
 * no material shorter than GapBridgeSteps steps (a voxel and a half), with
 * material again beyond it, is therefore crossed as part of the wall; no
 * air cell or canal a CT resolves is that thin (it takes two voxels to
 * show air between bone).
 */
#ifndef vtkVolumeCutThinBoneShader_h
#define vtkVolumeCutThinBoneShader_h

#include "vtkVolumeCutSampleClassifier.h"

#include <vtkMath.h>

class vtkVolumeCutThinBoneShader
{
public:
  vtkVolumeCutThinBoneShader(const vtkVolumeCutRayScene& scene, const vtkVolumeCutSampleClassifier& classifier)
    : Scene(scene)
    , Classifier(classifier)
  {
  }

  /// Thickness (mm, at most the threshold) of the wall under a surface point (IJK) with this outward world normal.
  double MeasureThickness(const double index[3], const double normalWorld[3]) const
  {
    const double threshold = this->Scene.ThinBoneThickness;
    double inward[3] = { -normalWorld[0], -normalWorld[1], -normalWorld[2] };
    double inwardIndex[3];
    vtkVolumeCutRayMath::TransformVector(this->Scene.WorldToIJK, inward, inwardIndex);
    const double voxelsPerMillimetre = vtkMath::Norm(inwardIndex);
    if (voxelsPerMillimetre <= 0.0)
    {
      return threshold;
    }
    const double step = 0.25 / voxelsPerMillimetre;
    for (double travelled = step; travelled < threshold; travelled += step)
    {
      bool inVolume = true;
      if (!this->VisibleAlong(index, inwardIndex, travelled, inVolume))
      {
        if (!inVolume)
        {
          return threshold;
        }
        double beyond = travelled;
        if (!this->MaterialAgainWithin(index, inwardIndex, step, beyond))
        {
          return this->Crossing(index, inwardIndex, travelled - step, travelled);
        }
        travelled = beyond;
      }
    }
    return threshold;
  }

  /// Halvings of the last step of the march when it leaves the material.
  static constexpr int CrossingHalvings = 6;

  /// The longest gap without material (in march steps, a quarter voxel each) still counted as part of a wall.
  static constexpr int GapBridgeSteps = 6;

  /// Tint a shaded surface colour and its opacity by the wall's thickness there.
  void Apply(const double index[3], const double normalWorld[3], float rgb[3], float& alpha) const
  {
    const double thickness = this->MeasureThickness(index, normalWorld);
    if (thickness < this->Scene.ThinBoneThickness)
    {
      const float f = static_cast<float>(thickness / this->Scene.ThinBoneThickness);
      const float red[3] = { 1.f, 0.12f, 0.08f };
      for (int c = 0; c < 3; ++c)
      {
        rgb[c] = red[c] * (1.f - f) + rgb[c] * f;
      }
      alpha *= 0.3f + 0.7f * f;
    }
  }

private:
  bool VisibleAt(vtkVolumeCutSample& s) const
  {
    this->Classifier.EvaluateObject(s);
    return this->Classifier.Visible(s);
  }

  /// Whether material is visible at a distance (mm) along the inward direction; \a inVolume false off the volume.
  bool VisibleAlong(const double index[3], const double inwardIndex[3], double distance, bool& inVolume) const
  {
    vtkVolumeCutSample s;
    for (int axis = 0; axis < 3; ++axis)
    {
      s.Index[axis] = index[axis] + distance * inwardIndex[axis];
      if (s.Index[axis] < 0.0 || s.Index[axis] > this->Scene.Dimensions[axis] - 1)
      {
        inVolume = false;
        return false;
      }
    }
    inVolume = true;
    return this->VisibleAt(s);
  }

  /// Whether material is visible again within GapBridgeSteps steps beyond \a distance (a sample without it);
  /// if so, \a distance becomes where.
  bool MaterialAgainWithin(const double index[3], const double inwardIndex[3], double step, double& distance) const
  {
    for (int ahead = 1; ahead <= GapBridgeSteps; ++ahead)
    {
      bool inVolume = true;
      if (this->VisibleAlong(index, inwardIndex, distance + ahead * step, inVolume))
      {
        distance += ahead * step;
        return true;
      }
      if (!inVolume)
      {
        return false;
      }
    }
    return false;
  }

  /// Where the material ends between two distances (mm) along the inward
  /// direction from a surface point: in it at \a inside, out at \a outside.
  double Crossing(const double index[3], const double inwardIndex[3], double inside, double outside) const
  {
    for (int halving = 0; halving < CrossingHalvings; ++halving)
    {
      const double middle = 0.5 * (inside + outside);
      vtkVolumeCutSample s;
      for (int axis = 0; axis < 3; ++axis)
      {
        s.Index[axis] = index[axis] + middle * inwardIndex[axis];
      }
      (this->VisibleAt(s) ? inside : outside) = middle;
    }
    return 0.5 * (inside + outside);
  }

  const vtkVolumeCutRayScene& Scene;
  const vtkVolumeCutSampleClassifier& Classifier;
};

#endif
