// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutAmbientOcclusion
 * @brief   Ambient occlusion of a surface point: the depth cue that makes a drilled cavity read.
 *
 * Light from the eye alone shades the floor of a cavity like the bone around
 * it. Here each shaded point is darkened by the share of 14 points over its
 * normal's hemisphere (the normal and six directions 55 degrees from it, at
 * 0.35 and 1 times the radius) that lie in visible material, cuts removed:
 * none on a flat or convex surface, about half at the bottom of a pit. The
 * directions are fixed, not random, so that the CPU and the GPU agree and
 * still images do not shimmer.
 */
#ifndef vtkVolumeCutAmbientOcclusion_h
#define vtkVolumeCutAmbientOcclusion_h

#include "vtkVolumeCutSampleClassifier.h"

#include <vtkMath.h>

#include <cmath>

class vtkVolumeCutAmbientOcclusion
{
public:
  /// Darkening at full occlusion.
  static constexpr double Strength = 0.9;

  vtkVolumeCutAmbientOcclusion(const vtkVolumeCutRayScene& scene, const vtkVolumeCutSampleClassifier& classifier)
    : Scene(scene)
    , Classifier(classifier)
  {
  }

  /// Share (0..1) of the points around a surface point (IJK) with this outward world normal that are in visible material.
  double Occlusion(const double index[3], const double normal[3]) const
  {
    double tangent[3];
    const double helper[3] = { std::abs(normal[0]) < 0.9 ? 1.0 : 0.0, std::abs(normal[0]) < 0.9 ? 0.0 : 1.0, 0.0 };
    vtkMath::Cross(normal, helper, tangent);
    vtkMath::Normalize(tangent);
    double bitangent[3];
    vtkMath::Cross(normal, tangent, bitangent);
    double origin[3];
    this->Classifier.WorldPoint(index, origin);
    // The fixed directions' sines and cosines, once: the same values as
    // computed for each point before, so the image does not change.
    static const Directions directions;
    int occupied = 0;
    for (int direction = 0; direction < 7; ++direction)
    {
      double d[3];
      for (int axis = 0; axis < 3; ++axis)
      {
        d[axis] = direction == 0 ? normal[axis]
                                 : directions.Cosine * normal[axis] +
            directions.Sine * (directions.AroundCosine[direction] * tangent[axis] + directions.AroundSine[direction] * bitangent[axis]);
      }
      for (double reach : { 0.35, 1.0 })
      {
        double world[3];
        for (int axis = 0; axis < 3; ++axis)
        {
          world[axis] = origin[axis] + reach * this->Scene.AmbientOcclusionRadius * d[axis];
        }
        vtkVolumeCutSample s;
        vtkVolumeCutRayMath::TransformPoint(this->Scene.WorldToIJK, world, s.Index);
        bool inside = true;
        for (int axis = 0; axis < 3; ++axis)
        {
          inside &= s.Index[axis] >= 0.0 && s.Index[axis] <= this->Scene.Dimensions[axis] - 1;
        }
        // A point in a cell where no object can be is not in visible
        // material: counted without classifying it (most points over a
        // surface lie in air or soft tissue).
        if (inside && this->Scene.EmptySpace.MayHoldObject(s.Index))
        {
          this->Classifier.EvaluateObject(s);
          occupied += this->Classifier.Visible(s) ? 1 : 0;
        }
      }
    }
    return occupied / 14.0;
  }

  /// Darken a shaded colour by the occlusion at a surface point.
  void Apply(const double index[3], const double normal[3], float rgb[3]) const
  {
    const float factor = static_cast<float>(1.0 - Strength * this->Occlusion(index, normal));
    for (int c = 0; c < 3; ++c)
    {
      rgb[c] *= factor;
    }
  }

private:
  struct Directions
  {
    double Cosine = std::cos(vtkMath::RadiansFromDegrees(55.0));
    double Sine = std::sin(vtkMath::RadiansFromDegrees(55.0));
    double AroundCosine[7];
    double AroundSine[7];
    Directions()
    {
      for (int direction = 0; direction < 7; ++direction)
      {
        const double angle = vtkMath::Pi() / 3.0 * direction;
        this->AroundCosine[direction] = std::cos(angle);
        this->AroundSine[direction] = std::sin(angle);
      }
    }
  };

  const vtkVolumeCutRayScene& Scene;
  const vtkVolumeCutSampleClassifier& Classifier;
};

#endif
