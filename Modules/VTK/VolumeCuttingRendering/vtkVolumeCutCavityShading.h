// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutCavityShading
 * @brief   Darkens a cut surface by how deep under the material's original surface it lies, seen from the eye.
 *
 * Lit from the eye, the floor of a drilled groove faces the light like the
 * bone around it and its walls turn away: head-on, a groove shades exactly
 * as a ridge of the same shape does, and the eye reads it as raised (issue
 * 28). Ambient occlusion does not tell them apart at a burr's scale: from
 * the floor of a 4 mm burr's groove 1 mm deep its points look out through
 * the opening into air. What tells a cavity is what the surgeon removed: a
 * cut surface point is darkened by the length of material, as it was before
 * any cut, between it and the eye (the line of sight back to where it leaves
 * the original material), up to Range mm, by
 * 1 - Strength (1 - (1 - d / Range)^2): nothing at the rim, where the cut
 * meets the uncut surface, darker with depth down the walls to the floor,
 * and constant (with a continuous slope) from Range on. This holds for
 * every surface a cut exposes, not only the cut's own: where the carve
 * stops on a segment's surface (SoftCut's floor on bone) the ray meets the
 * cut's surface or the segment's a pixel at a time, and both must shade
 * alike. In front of the first surface a ray meets, material is there only
 * where a cut removed it: uncut surfaces and the anatomy's own cavities,
 * with air before them, are left as they are. The length is found by
 * steps of Range / Steps along the line of sight, then bisection, so it
 * changes continuously over a wall (no bands at the steps) and the CPU and
 * the GPU (vtkVolumeCutAmbientOcclusionFS.glsl) agree.
 */
#ifndef vtkVolumeCutCavityShading_h
#define vtkVolumeCutCavityShading_h

#include "vtkVolumeCutSampleClassifier.h"

#include <algorithm>

class vtkVolumeCutCavityShading
{
public:
  /// Darkening at Range and beyond.
  static constexpr double Strength = 0.45;
  /// Range as a share of the ambient occlusion radius (3 mm at the default 6 mm).
  static constexpr double RangeShare = 0.5;
  static constexpr int Steps = 12;
  static constexpr int Bisections = 6;

  vtkVolumeCutCavityShading(const vtkVolumeCutRayScene& scene, const vtkVolumeCutSampleClassifier& classifier)
    : Scene(scene)
    , Classifier(classifier)
  {
  }

  /**
   * Darken a surface's shaded colour by its depth under the original
   * surface. Where the point a quarter step before it is not in original
   * material, the depth is under a quarter step (a shade of at most 2 %
   * at the default radius), taken as none: the colour of every surface with
   * air before it is left exactly as it is, at the cost of one sample.
   */
  void Apply(const double index[3], const double view[3], float rgb[3]) const
  {
    double step[3];
    this->Step(view, step);
    if (!this->InOriginalMaterial(index, step, 0.25))
    {
      return;
    }
    const double share = 1.0 - this->Depth(index, step) / (RangeShare * this->Scene.AmbientOcclusionRadius);
    const float factor = static_cast<float>(1.0 - Strength * (1.0 - share * share));
    for (int c = 0; c < 3; ++c)
    {
      rgb[c] *= factor;
    }
  }

private:
  /**
   * Length (mm, at most the range) of original material between a
   * surface's point (IJK) and the eye, found in steps of \a step (IJK,
   * towards the eye: Step of the view, computed once by Apply).
   */
  double Depth(const double index[3], const double step[3]) const
  {
    const double range = RangeShare * this->Scene.AmbientOcclusionRadius;
    // Last step in the material and first out of it, in steps from the point.
    double inside = 0.0;
    double outside = -1.0;
    for (int n = 1; n <= Steps && outside < 0.0; ++n)
    {
      (this->InOriginalMaterial(index, step, n) ? inside : outside) = n;
    }
    if (outside < 0.0)
    {
      return range;
    }
    for (int n = 0; n < Bisections; ++n)
    {
      const double middle = 0.5 * (inside + outside);
      (this->InOriginalMaterial(index, step, middle) ? inside : outside) = middle;
    }
    return 0.5 * (inside + outside) * range / Steps;
  }

  /// One step (IJK) along \a view (world, unit).
  void Step(const double view[3], double step[3]) const
  {
    vtkVolumeCutRayMath::TransformVector(this->Scene.WorldToIJK, view, step);
    for (int axis = 0; axis < 3; ++axis)
    {
      step[axis] *= RangeShare * this->Scene.AmbientOcclusionRadius / Steps;
    }
  }

  /// Whether index + steps * step (IJK) lies in visible material, cuts ignored (outside the volume: no).
  bool InOriginalMaterial(const double index[3], const double step[3], double steps) const
  {
    vtkVolumeCutSample s;
    for (int axis = 0; axis < 3; ++axis)
    {
      s.Index[axis] = index[axis] + steps * step[axis];
      if (!(s.Index[axis] >= 0.0 && s.Index[axis] <= this->Scene.Dimensions[axis] - 1))
      {
        return false;
      }
    }
    if (!this->Scene.EmptySpace.MayHoldObject(s.Index))
    {
      return false;
    }
    this->Classifier.EvaluateObject(s);
    return s.Object != 0;
  }

  const vtkVolumeCutRayScene& Scene;
  const vtkVolumeCutSampleClassifier& Classifier;
};

#endif
