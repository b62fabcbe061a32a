// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutPieceClassifier
 * @brief   Step 3 of adaptive sampling (Pflesser et al.): classification of the pieces between borders.
 *
 * In iso-surface mode, between two samples: the borders of every volume
 * (vtkVolumeCutBorderLocator) sorted along the ray cut the interval into
 * pieces, each classified at its middle (vtkVolumeCutSampleClassifier); the
 * first visible piece after an invisible one is handed to the surface shader
 * (vtkVolumeCutSurfaceShader, step 4). An interval where a border could hide
 * between samples that agree is split into 2^MaximumRefinements parts first,
 * as the GPU does.
 *
 * @sa vtkVolumeCutBorderLocator (step 2) vtkVolumeCutSurfaceShader (step 4)
 */
#ifndef vtkVolumeCutPieceClassifier_h
#define vtkVolumeCutPieceClassifier_h

#include "vtkVolumeCutSurfaceShader.h"

class vtkVolumeCutPieceClassifier
{
public:
  vtkVolumeCutPieceClassifier(
    const vtkVolumeCutSampleClassifier& classifier, const vtkVolumeCutBorderLocator& locator, const vtkVolumeCutSurfaceShader& shader)
    : Classifier(classifier)
    , Locator(locator)
    , Shader(shader)
  {
  }

  /**
   * The interval from a to b of the ray (both classified by object): shade
   * and composite its visible pieces. \a insideVisible says whether the ray
   * is inside visible material at a, and is updated to b. Returns true when
   * the ray is done. b may gain its cut distances.
   */
  bool Interval(const vtkVolumeCutRay& ray, vtkVolumeCutSample& a, vtkVolumeCutSample& b, bool& insideVisible,
    vtkVolumeCutRayResult& result, int depth = 0) const
  {
    if (a.Object != 0 || b.Object != 0)
    {
      this->Classifier.EvaluateCuts(a);
      this->Classifier.EvaluateCuts(b);
    }
    if (depth == 0 && this->Locator.MayHideBorders(a, b, (b.T - a.T) * ray.VoxelsPerMillimetre, b.T - a.T))
    {
      constexpr int parts = 1 << vtkVolumeCutBorderLocator::MaximumRefinements;
      vtkVolumeCutSample from = a;
      for (int part = 1; part <= parts; ++part)
      {
        vtkVolumeCutSample to = part == parts ? b : vtkVolumeCutSample::At(ray.Origin, ray.Direction, a.T + (b.T - a.T) * part / parts);
        if (part < parts)
        {
          this->Classifier.EvaluateObject(to);
        }
        if (this->Interval(ray, from, to, insideVisible, result, 1))
        {
          return true;
        }
        from = to;
      }
      b = from;
      return false;
    }
    // A border exactly at the previous sample leaves a piece of no length
    // whose middle is classified as what lies before it: the visible
    // material that starts at a is entered here, not missed.
    if (!insideVisible && this->Classifier.Visible(a))
    {
      if (this->Shader.Enter(ray, a, a.T, vtkVolumeCutRayCaster::SourceObject, result))
      {
        return true;
      }
      insideVisible = true;
    }
    vtkVolumeCutBorder borders[vtkVolumeCutRayScene::MaximumCutFields + 1];
    const int count = this->Locator.FindBorders(ray, a, b, true, borders);
    for (int border = 0; border < count; ++border)
    {
      const double end = border + 1 < count ? borders[border + 1].T : b.T;
      vtkVolumeCutSample mid = vtkVolumeCutSample::At(ray.Origin, ray.Direction, 0.5 * (borders[border].T + end));
      this->Classifier.EvaluateObject(mid);
      const bool visible = this->Classifier.Visible(mid);
      if (visible && !insideVisible && this->Shader.Enter(ray, mid, borders[border].T, borders[border].Source, result))
      {
        return true;
      }
      insideVisible = visible;
    }
    return false;
  }

private:
  const vtkVolumeCutSampleClassifier& Classifier;
  const vtkVolumeCutBorderLocator& Locator;
  const vtkVolumeCutSurfaceShader& Shader;
};

#endif
