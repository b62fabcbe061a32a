// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutSurfaceShader
 * @brief   Step 4 of adaptive sampling (Pflesser et al.): normal and shading of the first visible piece.
 *
 * A visible piece is shaded with the normal of the field whose border starts
 * it: the CT's gray-level gradient (3D Sobel differences GradientStep voxels
 * apart) or the segment's own indicator on object surfaces, coloured as the
 * segment whose material lies under the surface (MaterialOwner), the cut field's
 * gradient on cut surfaces, the plane's or box face's normal on clip
 * surfaces; Phong lighting with a headlight, ambient occlusion
 * (vtkVolumeCutAmbientOcclusion) with, on surfaces that cuts expose, cavity
 * shading (vtkVolumeCutCavityShading), and thin-bone shading
 * (vtkVolumeCutThinBoneShader) where they are on.
 *
 * @sa vtkVolumeCutPieceClassifier (step 3)
 */
#ifndef vtkVolumeCutSurfaceShader_h
#define vtkVolumeCutSurfaceShader_h

#include "vtkVolumeCutAmbientOcclusion.h"
#include "vtkVolumeCutCavityShading.h"
#include "vtkVolumeCutRayResult.h"
#include "vtkVolumeCutThinBoneShader.h"

#include <vtkMath.h>

#include <cmath>

class vtkVolumeCutSurfaceShader
{
public:
  vtkVolumeCutSurfaceShader(const vtkVolumeCutRayScene& scene, const vtkVolumeCutSampleClassifier& classifier)
    : Scene(scene)
    , Classifier(classifier)
    , ThinBone(scene, classifier)
    , Occlusion(scene, classifier)
    , Cavity(scene, classifier)
  {
  }

  /**
   * World unit normal of an object's surface at p (IJK), pointing out of the
   * material: the gradient of its field (the CT, or a shape-defined
   * segment's indicator) by 3D Sobel differences GradientStep voxels apart
   * (SobelGradient).
   */
  void ObjectNormal(int object, const double p[3], double normal[3]) const
  {
    double gradient[3];
    if (this->Scene.HasSegments() && this->Scene.Styles[object].Shape)
    {
      SobelGradient([&](const double q[3]) { return this->Classifier.Indicator(object, q); }, p, this->Scene.GradientStep, gradient);
    }
    else
    {
      SobelGradient([&](const double q[3]) { return double(this->Classifier.Interpolate(q)); }, p, this->Scene.GradientStep, gradient);
    }
    // Outward: against the gradient of the inside-positive field.
    vtkVolumeCutRayMath::TransformVector(this->Scene.NormalMatrix, gradient, normal);
    for (int axis = 0; axis < 3; ++axis)
    {
      normal[axis] = -normal[axis];
    }
    vtkMath::Normalize(normal);
  }

  /**
   * Gradient (IJK, unscaled) of a trilinear field at p by 3D Sobel
   * differences: along each axis, the central differences h voxels apart at
   * the 3 x 3 points h apart across it, weighed 1 2 1 in each direction
   * across. The plain central difference at p alone follows the trilinear
   * interpolant's kinks at the voxel planes: where partial volume ramps a
   * surface over about a voxel, as in every CT, its normal swings by up to
   * 9 degrees with the voxel's phase (16 at the ramp's middle), and a
   * surface almost parallel to a voxel plane shows the swings as contour
   * rings, one per voxel layer it crosses (issue 28, finding 10). Averaged
   * across, the swings of neighbouring phases cancel: 3 degrees at most on a
   * box-filtered sphere, 2 with a scanner's blur. Shading alone pays for it
   * (26 samples instead of 6, once per pixel); the surface's place is not
   * moved. vtkVolumeCutShadingFS.glsl's sobelGradient is the same.
   */
  template <typename Field>
  static void SobelGradient(Field&& field, const double p[3], double h, double gradient[3])
  {
    gradient[0] = gradient[1] = gradient[2] = 0.0;
    for (int k = -1; k <= 1; ++k)
    {
      for (int j = -1; j <= 1; ++j)
      {
        for (int i = -1; i <= 1; ++i)
        {
          if (i == 0 && j == 0 && k == 0)
          {
            continue;
          }
          const double q[3] = { p[0] + h * i, p[1] + h * j, p[2] + h * k };
          const double value = field(q);
          // Weight 2 where the point lies on the axis's line across, 1 off it.
          const double wi = i == 0 ? 2.0 : 1.0;
          const double wj = j == 0 ? 2.0 : 1.0;
          const double wk = k == 0 ? 2.0 : 1.0;
          gradient[0] += i * wj * wk * value;
          gradient[1] += j * wi * wk * value;
          gradient[2] += k * wi * wj * value;
        }
      }
    }
  }

  /// The CT's gradient direction at p (IJK) as a world unit normal, pointing to lower values.
  void IntensityNormal(const double p[3], double normal[3]) const
  {
    double gradient[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      double plus[3] = { p[0], p[1], p[2] };
      double minus[3] = { p[0], p[1], p[2] };
      plus[axis] += this->Scene.GradientStep;
      minus[axis] -= this->Scene.GradientStep;
      gradient[axis] = double(this->Classifier.Interpolate(minus)) - double(this->Classifier.Interpolate(plus));
    }
    vtkVolumeCutRayMath::TransformVector(this->Scene.NormalMatrix, gradient, normal);
    vtkMath::Normalize(normal);
  }

  /// World unit normal of cut field n's surface at a world point, pointing into the removed region.
  void CutNormal(int n, const double world[3], double normal[3]) const
  {
    const vtkVolumeCutField* field = this->Scene.CutFields[n];
    double spacing[3];
    field->GetSubVoxelSpacing(spacing);
    const double h = 0.25 * std::min({ spacing[0], spacing[1], spacing[2] });
    for (int axis = 0; axis < 3; ++axis)
    {
      double plus[3] = { world[0], world[1], world[2] };
      double minus[3] = { world[0], world[1], world[2] };
      plus[axis] += h;
      minus[axis] -= h;
      // The material's outward normal points into the removed region, where
      // the distance decreases.
      normal[axis] = field->GetSignedDistance(minus) - field->GetSignedDistance(plus);
    }
    vtkMath::Normalize(normal);
  }

  /// Phong lighting with a headlight: the light comes from the eye, so the half vector is the view.
  void Shade(const float color[3], const double normal[3], const double view[3], float out[3]) const
  {
    const double cosine = std::abs(vtkMath::Dot(normal, view));
    const double specular = this->Scene.Specular * std::pow(cosine, this->Scene.SpecularPower);
    for (int c = 0; c < 3; ++c)
    {
      out[c] = static_cast<float>(std::min(1.0, color[c] * (this->Scene.Ambient + this->Scene.Diffuse * cosine) + specular));
    }
  }

  /**
   * A visible piece of \a piece's object starts at ray parameter t, on the
   * border \a source: shade it with that border's normal and composite it.
   * Returns true when the ray is done (opaque, or out of layers).
   */
  bool Enter(const vtkVolumeCutRay& ray, const vtkVolumeCutSample& piece, double t, int source, vtkVolumeCutRayResult& result) const
  {
    double normal[3];
    double index[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      index[axis] = ray.Origin[axis] + t * ray.Direction[axis];
    }
    int owner = piece.Object;
    if (source == vtkVolumeCutRayCaster::SourceObject)
    {
      this->ObjectNormal(piece.Object, index, normal);
      // Coloured as the material under it, not as the voxels it crosses.
      if (this->Scene.HasSegments() && !this->Scene.Styles[piece.Object].Shape)
      {
        const int material = this->Classifier.MaterialOwner(index);
        owner = material > 0 ? material : owner;
      }
    }
    else if (source >= vtkVolumeCutRayCaster::SourceCutField)
    {
      double world[3];
      this->Classifier.WorldPoint(index, world);
      this->CutNormal(source - vtkVolumeCutRayCaster::SourceCutField, world, normal);
    }
    else
    {
      std::copy(ray.EntryNormal, ray.EntryNormal + 3, normal);
    }
    // Lit from the eye whichever way the estimate points; but where the
    // estimate turns away from the eye (at outlines seen edge-on, by a few
    // degrees), the flipped normal points into the material, and thin-bone
    // shading marching against it left the material at once: a one-pixel
    // red rim around thick bone (issue 28). Occlusion and thickness look
    // from the material outwards, so they keep the outward estimate.
    const double outward[3] = { normal[0], normal[1], normal[2] };
    if (vtkMath::Dot(normal, ray.View) < 0.0)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        normal[axis] = -normal[axis];
      }
    }
    const vtkVolumeCutRayScene::SegmentStyle& style = this->Scene.Styles[owner];
    float rgb[3];
    this->Shade(source == vtkVolumeCutRayCaster::SourceObject ? style.SurfaceColor : style.Color, normal, ray.View, rgb);
    float alpha = style.Opacity;
    if (this->Scene.AmbientOcclusion)
    {
      this->Occlusion.Apply(index, outward, ray.ViewAxis, rgb);
      this->Cavity.Apply(index, ray.View, rgb);
    }
    // Only bone's own surfaces and those a cut exposed have a wall under
    // them; where the scan ends or a clip plane cuts, the march along the face
    // runs nearly along the adjacent surfaces at the face's edges, through the
    // partial-volume fringe and its noise, and tinted the edges red.
    if (this->Scene.ThinBone && (source == vtkVolumeCutRayCaster::SourceObject || source >= vtkVolumeCutRayCaster::SourceCutField))
    {
      this->ThinBone.Apply(index, outward, rgb, alpha);
    }
    result.Record(ray, t, source, owner, normal, rgb, alpha, 0.f);
    return result.Opaque() || ++result.Layers >= vtkVolumeCutRayResult::MaximumLayers;
  }

private:
  const vtkVolumeCutRayScene& Scene;
  const vtkVolumeCutSampleClassifier& Classifier;
  vtkVolumeCutThinBoneShader ThinBone;
  vtkVolumeCutAmbientOcclusion Occlusion;
  vtkVolumeCutCavityShading Cavity;
};

#endif
