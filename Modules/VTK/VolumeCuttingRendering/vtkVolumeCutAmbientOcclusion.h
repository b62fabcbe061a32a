// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutAmbientOcclusion
 * @brief   Ambient occlusion of a surface point: the depth cue that makes a drilled cavity read.
 *
 * Light from the eye alone shades the floor of a cavity like the bone around
 * it. Here each shaded point is darkened by how much of 14 points over its
 * normal's hemisphere lies in visible material, cuts removed: along the
 * normal at 0.35 and 1 times the radius, and along directions 55 degrees
 * from it, six at 0.35 times the radius and six between them (turned by 30
 * degrees) at the radius. None on a flat or convex
 * surface, about half at the bottom of a pit. The directions are fixed, not
 * random, so that the CPU and the GPU agree and still images do not shimmer.
 *
 * Two things keep the term continuous over a surface, so that a magnified
 * wall shows no arcs or seams (issue 28):
 * - A point counts by its depth in the material (the smaller of its depth
 *   under the object's surface, the field's value over its gradient, and
 *   its distance to the nearest cut), rising smoothly from 0 at the surface
 *   to 1 at RampWidth times its distance from the shaded point (at least a
 *   voxel). Counted as in or out, a point crossing a surface as the shaded
 *   point moves changed the term by a fourteenth at once.
 * - The directions around the normal turn with it smoothly: the fixed
 *   tangent of the camera's axis (towards the eye) carried onto the normal
 *   by the smallest rotation, which is undefined only for a normal facing
 *   away from the eye, never drawn. A tangent chosen by comparing the
 *   normal's components switched where they crossed a threshold.
 * - Where the scan ends, the material ends: a point's depth is also at most
 *   its distance to the volume's faces. Counted fully up to the face and
 *   nothing beyond it, a point crossing an end face drew straight seams
 *   across a cut wall near the scan's border (the own-block journey's
 *   close-up).
 * Points outside material count 0 as before, so flat and convex surfaces
 * stay unoccluded and empty space is still skipped.
 */
#ifndef vtkVolumeCutAmbientOcclusion_h
#define vtkVolumeCutAmbientOcclusion_h

#include "vtkVolumeCutSampleClassifier.h"

#include <vtkMath.h>

#include <algorithm>
#include <cmath>
#include <limits>

class vtkVolumeCutAmbientOcclusion
{
public:
  /// Darkening at full occlusion.
  static constexpr double Strength = 0.9;
  /// Depth (as a share of a point's distance from the shaded point) at which a point counts fully.
  static constexpr double RampWidth = 0.15;
  static constexpr int Points = 14;

  vtkVolumeCutAmbientOcclusion(const vtkVolumeCutRayScene& scene, const vtkVolumeCutSampleClassifier& classifier)
    : Scene(scene)
    , Classifier(classifier)
  {
  }

  /**
   * Occlusion (0..1) of a surface point (IJK) with this outward world
   * normal, facing the eye; \a axis is the camera's axis towards the eye
   * (world, unit), the same for the whole image.
   */
  double Occlusion(const double index[3], const double normal[3], const double axis[3]) const
  {
    double tangent[3];
    double bitangent[3];
    TangentFrame(normal, axis, tangent, bitangent);
    double origin[3];
    this->Classifier.WorldPoint(index, origin);
    static const Directions directions;
    const double voxel = this->LargestVoxelEdge();
    double occupied = 0.0;
    for (int point = 0; point < Points; ++point)
    {
      const double reach = directions.Reach[point];
      double world[3];
      for (int a = 0; a < 3; ++a)
      {
        const double d = directions.Normal[point] * normal[a] + directions.Tangent[point] * tangent[a] +
          directions.Bitangent[point] * bitangent[a];
        world[a] = origin[a] + reach * this->Scene.AmbientOcclusionRadius * d;
      }
      vtkVolumeCutSample s;
      vtkVolumeCutRayMath::TransformPoint(this->Scene.WorldToIJK, world, s.Index);
      bool inside = true;
      for (int a = 0; a < 3; ++a)
      {
        inside &= s.Index[a] >= 0.0 && s.Index[a] <= this->Scene.Dimensions[a] - 1;
      }
      // A point in a cell where no object can be is not in visible
      // material: counted without classifying it (most points over a
      // surface lie in air or soft tissue).
      if (inside && this->Scene.EmptySpace.MayHoldObject(s.Index))
      {
        this->Classifier.EvaluateObject(s);
        if (this->Classifier.Visible(s))
        {
          const double width = std::max(voxel, RampWidth * reach * this->Scene.AmbientOcclusionRadius);
          occupied += Ramp(this->Depth(s) / width);
        }
      }
    }
    return occupied / Points;
  }

  /// Darken a shaded colour by the occlusion at a surface point.
  void Apply(const double index[3], const double normal[3], const double axis[3], float rgb[3]) const
  {
    const float factor = static_cast<float>(1.0 - Strength * this->Occlusion(index, normal, axis));
    for (int c = 0; c < 3; ++c)
    {
      rgb[c] *= factor;
    }
  }

  /**
   * A unit tangent and bitangent of the unit normal n that turn smoothly with
   * it: a tangent of the unit axis a (by comparing a's components: a is the
   * same over the image) carried onto n by the rotation taking a to n.
   * Defined wherever n is not -a.
   */
  static void TangentFrame(const double n[3], const double a[3], double tangent[3], double bitangent[3])
  {
    const double helper[3] = { std::abs(a[0]) < 0.9 ? 1.0 : 0.0, std::abs(a[0]) < 0.9 ? 0.0 : 1.0, 0.0 };
    double t0[3];
    vtkMath::Cross(a, helper, t0);
    vtkMath::Normalize(t0);
    const double c = 1.0 + vtkMath::Dot(n, a);
    const double k = c > 1e-9 ? vtkMath::Dot(n, t0) / c : 0.0;
    for (int axis = 0; axis < 3; ++axis)
    {
      tangent[axis] = t0[axis] - k * (n[axis] + a[axis]);
    }
    vtkMath::Normalize(tangent);
    vtkMath::Cross(n, tangent, bitangent);
  }

private:
  /// 0 at 0, 1 from 1 on, with a continuous slope (smoothstep).
  static double Ramp(double x)
  {
    x = std::min(std::max(x, 0.0), 1.0);
    return x * x * (3.0 - 2.0 * x);
  }

  double LargestVoxelEdge() const
  {
    double largest = 0.0;
    for (int column = 0; column < 3; ++column)
    {
      const double* m = this->Scene.IJKToWorld;
      largest = std::max(largest, std::sqrt(m[column] * m[column] + m[4 + column] * m[4 + column] + m[8 + column] * m[8 + column]));
    }
    return largest;
  }

  /**
   * Depth (mm) of a visible sample in its material: the smallest of its
   * distance to the nearest cut, to the volume's faces, and its object
   * field's value over the field's gradient (central differences a voxel apart), the CT above the
   * segment's iso-value or a shape segment's indicator above 0.5.
   */
  double Depth(vtkVolumeCutSample& s) const
  {
    const vtkVolumeCutRayScene& scene = this->Scene;
    double depth = std::numeric_limits<double>::infinity();
    for (size_t n = 0; n < scene.CutFields.size(); ++n)
    {
      depth = std::min(depth, s.Distance[n]);
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      const double toFace = std::min(s.Index[axis], scene.Dimensions[axis] - 1 - s.Index[axis]);
      depth = std::min(depth, toFace * scene.MillimetresPerIndex[axis]);
    }
    const int label = scene.HasSegments() ? s.Object : 1;
    const bool shape = scene.HasSegments() && scene.Styles[label].Shape;
    const double field = shape ? this->Classifier.Indicator(label, s.Index) - 0.5 : double(s.Value) - scene.Styles[label].Iso;
    double gradient[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      double plus[3] = { s.Index[0], s.Index[1], s.Index[2] };
      double minus[3] = { s.Index[0], s.Index[1], s.Index[2] };
      plus[axis] += 1.0;
      minus[axis] -= 1.0;
      gradient[axis] = 0.5 *
        (shape ? this->Classifier.Indicator(label, plus) - this->Classifier.Indicator(label, minus)
               : double(this->Classifier.Interpolate(plus)) - double(this->Classifier.Interpolate(minus)));
    }
    double world[3];
    vtkVolumeCutRayMath::TransformVector(scene.NormalMatrix, gradient, world);
    const double slope = vtkMath::Norm(world);
    if (slope > 0.0)
    {
      depth = std::min(depth, field / slope);
    }
    return depth;
  }

  /// The points' directions in the normal's frame (normal, tangent, bitangent) and distances (times the radius).
  struct Directions
  {
    double Normal[Points];
    double Tangent[Points];
    double Bitangent[Points];
    double Reach[Points];
    Directions()
    {
      const double cosine = std::cos(vtkMath::RadiansFromDegrees(55.0));
      const double sine = std::sin(vtkMath::RadiansFromDegrees(55.0));
      for (int point = 0; point < Points; ++point)
      {
        // 0, 1: the normal; 2-7: the inner ring every 60 degrees; 8-13: the outer ring between them.
        const bool around = point >= 2;
        const double angle = vtkMath::Pi() / 3.0 * (point - 2) + (point >= 8 ? vtkMath::Pi() / 6.0 : 0.0);
        this->Normal[point] = around ? cosine : 1.0;
        this->Tangent[point] = around ? sine * std::cos(angle) : 0.0;
        this->Bitangent[point] = around ? sine * std::sin(angle) : 0.0;
        this->Reach[point] = point == 0 || (point >= 2 && point < 8) ? 0.35 : 1.0;
      }
    }
  };

  const vtkVolumeCutRayScene& Scene;
  const vtkVolumeCutSampleClassifier& Classifier;
};

#endif
