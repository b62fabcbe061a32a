// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutCompositor
 * @brief   Composite mode of vtkVolumeCutRayCaster: transfer functions front to back, cuts left out exactly.
 *
 * Each step between two samples is cut into pieces at every cut field's
 * border (vtkVolumeCutBorderLocator); the pieces outside every cut are
 * composited with the transfer functions at their middles, their opacity
 * corrected for their length, and the first piece after a cut border is
 * shaded with the cut's normal, so the cut surface shows as a surface.
 */
#ifndef vtkVolumeCutCompositor_h
#define vtkVolumeCutCompositor_h

#include "vtkVolumeCutSurfaceShader.h"

class vtkVolumeCutCompositor
{
public:
  vtkVolumeCutCompositor(const vtkVolumeCutRayScene& scene, const vtkVolumeCutSampleClassifier& classifier,
    const vtkVolumeCutBorderLocator& locator, const vtkVolumeCutSurfaceShader& shader)
    : Scene(scene)
    , Classifier(classifier)
    , Locator(locator)
    , Shader(shader)
  {
  }

  /// The transfer functions at a CT value (linear between table entries).
  void LookUp(float value, float color[3], float& opacity) const
  {
    constexpr int TableSize = vtkVolumeCutRayScene::TransferTableSize;
    const vtkVolumeCutRayScene& scene = this->Scene;
    const double span = scene.TableRange[1] - scene.TableRange[0];
    double x = span > 0.0 ? (value - scene.TableRange[0]) / span * (TableSize - 1) : 0.0;
    x = std::min(std::max(x, 0.0), double(TableSize - 1));
    const int i = std::min(static_cast<int>(x), TableSize - 2);
    const float f = static_cast<float>(x - i);
    for (int c = 0; c < 3; ++c)
    {
      color[c] = scene.ColorTable[3 * i + c] * (1.f - f) + scene.ColorTable[3 * (i + 1) + c] * f;
    }
    opacity = scene.OpacityTable[i] * (1.f - f) + scene.OpacityTable[i + 1] * f;
  }

  /**
   * Composite the step from a to b. \a lastCutBorder is the cut whose border
   * the next piece starts at (-1 for none), carried from step to step.
   * Returns true when the pixel is opaque.
   */
  bool Step(const vtkVolumeCutRay& ray, vtkVolumeCutSample& a, vtkVolumeCutSample& b, int& lastCutBorder, vtkVolumeCutRayResult& result) const
  {
    this->Classifier.EvaluateCuts(a);
    this->Classifier.EvaluateCuts(b);
    vtkVolumeCutBorder borders[vtkVolumeCutRayScene::MaximumCutFields + 1];
    const int count = this->Locator.FindBorders(ray, a, b, false, borders);
    double start = a.T;
    for (int piece = 0; piece <= count; ++piece)
    {
      const double end = piece < count ? borders[piece].T : b.T;
      if (end > start)
      {
        vtkVolumeCutSample mid = vtkVolumeCutSample::At(ray.Origin, ray.Direction, 0.5 * (start + end));
        this->Classifier.EvaluateObject(mid);
        this->Classifier.EvaluateCuts(mid);
        if (!this->Classifier.Removed(mid))
        {
          float rgb[3];
          float opacity;
          this->LookUp(mid.Value, rgb, opacity);
          if (opacity > 0.f)
          {
            const float alpha =
              1.f - std::pow(1.f - std::min(opacity, 0.9999f), static_cast<float>((end - start) / this->Scene.UnitDistance));
            double normal[3];
            int source = vtkVolumeCutRayCaster::SourceObject;
            if (lastCutBorder >= 0)
            {
              // The first piece after a cut border shows the cut surface.
              double world[3];
              this->Classifier.WorldPoint(mid.Index, world);
              this->Shader.CutNormal(lastCutBorder, world, normal);
              source = vtkVolumeCutRayCaster::SourceCutField + lastCutBorder;
            }
            else
            {
              // Composite mode shades with the CT's gradient whatever the labels.
              this->Shader.IntensityNormal(mid.Index, normal);
            }
            float shaded[3];
            this->Shader.Shade(rgb, normal, ray.View, shaded);
            // Depth and normal belong to the first piece that clearly shows
            // (a cut surface is a surface: its first piece always counts).
            result.Record(ray, start, source, 0, normal, shaded, alpha, lastCutBorder >= 0 ? 0.f : 0.02f);
            if (result.Opaque())
            {
              return true;
            }
          }
          lastCutBorder = -1;
        }
      }
      if (piece < count)
      {
        lastCutBorder =
          borders[piece].Source >= vtkVolumeCutRayCaster::SourceCutField ? borders[piece].Source - vtkVolumeCutRayCaster::SourceCutField : -1;
      }
      start = end;
    }
    return false;
  }

private:
  const vtkVolumeCutRayScene& Scene;
  const vtkVolumeCutSampleClassifier& Classifier;
  const vtkVolumeCutBorderLocator& Locator;
  const vtkVolumeCutSurfaceShader& Shader;
};

#endif
