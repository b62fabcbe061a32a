// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutSurfaceShader
 * @brief   Step 4 of adaptive sampling (Pflesser et al.): normal and shading of the first visible piece.
 *
 * A visible piece is shaded with the normal of the field whose border starts
 * it: the CT's gray-level gradient (central differences GradientStep voxels
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

  /// World unit normal of an object's surface at p (IJK), pointing out of the material.
  void ObjectNormal(int object, const double p[3], double normal[3]) const
  {
    const double h = this->Scene.GradientStep;
    double gradient[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      double plus[3] = { p[0], p[1], p[2] };
      double minus[3] = { p[0], p[1], p[2] };
      plus[axis] += h;
      minus[axis] -= h;
      if (this->Scene.HasSegments() && this->Scene.Styles[object].Shape)
      {
        gradient[axis] = this->Classifier.Indicator(object, plus) - this->Classifier.Indicator(object, minus);
      }
      else
      {
        gradient[axis] = double(this->Classifier.Interpolate(plus)) - double(this->Classifier.Interpolate(minus));
      }
    }
    // Outward: against the gradient of the inside-positive field.
    vtkVolumeCutRayMath::TransformVector(this->Scene.NormalMatrix, gradient, normal);
    for (int axis = 0; axis < 3; ++axis)
    {
      normal[axis] = -normal[axis];
    }
    vtkMath::Normalize(normal);
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
      this->Occlusion.Apply(index, normal, ray.ViewAxis, rgb);
      this->Cavity.Apply(index, ray.View, rgb);
    }
    if (this->Scene.ThinBone)
    {
      this->ThinBone.Apply(index, normal, rgb, alpha);
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
