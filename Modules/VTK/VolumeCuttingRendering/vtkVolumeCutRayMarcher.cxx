// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutRayMarcher.h"

// The stages of adaptive sampling, one private header each (Pflesser et al.):
// 1 classification, 2 border location, 3 piece classification, 4 shading.
#include "vtkVolumeCutBorderLocator.h"
#include "vtkVolumeCutCompositor.h"
#include "vtkVolumeCutEmptySpace.h"
#include "vtkVolumeCutPieceClassifier.h"
#include "vtkVolumeCutRayCaster.h"
#include "vtkVolumeCutRayMath.h"
#include "vtkVolumeCutRayResult.h"
#include "vtkVolumeCutRayScene.h"
#include "vtkVolumeCutSampleClassifier.h"
#include "vtkVolumeCutSurfaceShader.h"

#include <vtkMath.h>

#include <algorithm>
#include <cmath>

using vtkVolumeCutRayMath::Multiply4;
using vtkVolumeCutRayMath::TransformPoint;
using vtkVolumeCutRayMath::TransformVector;

//------------------------------------------------------------------------------
void vtkVolumeCutRayMarcher::Cast(const vtkVolumeCutRayScene& scene, const double ndcToWorld[16], int width, int height, int x,
  int y, const double* opaqueLimit, vtkVolumeCutRayResult& result)
{
  // The ray through the pixel's centre, from the near to the far plane.
  const double ndcX = 2.0 * (x + 0.5) / width - 1.0;
  const double ndcY = 2.0 * (y + 0.5) / height - 1.0;
  const double nearH[4] = { ndcX, ndcY, -1.0, 1.0 };
  const double farH[4] = { ndcX, ndcY, 1.0, 1.0 };
  double nearW[4];
  double farW[4];
  Multiply4(ndcToWorld, nearH, nearW);
  Multiply4(ndcToWorld, farH, farW);
  vtkVolumeCutRay ray;
  for (int axis = 0; axis < 3; ++axis)
  {
    ray.OriginWorld[axis] = nearW[axis] / nearW[3];
    ray.DirectionWorld[axis] = farW[axis] / farW[3] - ray.OriginWorld[axis];
  }
  ray.TEnd = vtkMath::Normalize(ray.DirectionWorld);
  if (opaqueLimit)
  {
    ray.TEnd = std::min(ray.TEnd, *opaqueLimit);
  }
  for (int axis = 0; axis < 3; ++axis)
  {
    ray.View[axis] = -ray.DirectionWorld[axis];
  }
  // The ray through the image's centre, reversed (as the GLSL computes it).
  const double centreNearH[4] = { 0.0, 0.0, -1.0, 1.0 };
  const double centreFarH[4] = { 0.0, 0.0, 1.0, 1.0 };
  double centreNear[4];
  double centreFar[4];
  Multiply4(ndcToWorld, centreNearH, centreNear);
  Multiply4(ndcToWorld, centreFarH, centreFar);
  for (int axis = 0; axis < 3; ++axis)
  {
    ray.ViewAxis[axis] = centreNear[axis] / centreNear[3] - centreFar[axis] / centreFar[3];
  }
  vtkMath::Normalize(ray.ViewAxis);
  TransformPoint(scene.WorldToIJK, ray.OriginWorld, ray.Origin);
  TransformVector(scene.WorldToIJK, ray.DirectionWorld, ray.Direction);

  const vtkVolumeCutSampleClassifier classifier(scene);
  const vtkVolumeCutBorderLocator locator(scene, classifier);
  const vtkVolumeCutSurfaceShader shader(scene, classifier);
  // Entry and exit: the volume's box (sample domain), then the clip planes.
  if (!locator.ClipToVolume(ray))
  {
    return;
  }
  const double* o = ray.Origin;
  const double* d = ray.Direction;
  const double tEnd = ray.TEnd;

  // World length of one voxel step along this ray.
  ray.VoxelsPerMillimetre = vtkMath::Norm(d);
  const double step = scene.SampleDistance / ray.VoxelsPerMillimetre;
  const bool composite = scene.BlendMode == vtkVolumeCutRayCaster::CompositeBlend;
  const vtkVolumeCutEmptySpace& emptySpace = scene.EmptySpace;
  // Nothing visible in the sample's block: jump it to where the ray leaves it, unless
  // that is within a step.
  auto skipBlock = [&](vtkVolumeCutSample& sample) -> bool {
    const double exit = std::min(emptySpace.Exit(sample.Index, d, sample.T) + 1e-9, tEnd);
    if (!(exit > sample.T + step))
    {
      return false;
    }
    sample = vtkVolumeCutSample::At(o, d, exit);
    classifier.EvaluateObject(sample);
    return true;
  };

  if (composite)
  {
    const vtkVolumeCutCompositor compositor(scene, classifier, locator, shader);
    vtkVolumeCutSample a = vtkVolumeCutSample::At(o, d, ray.TStart);
    classifier.EvaluateObject(a);
    classifier.EvaluateCuts(a);
    int lastCutBorder = -1; // the cut whose border the next piece starts at
    while (a.T < tEnd)
    {
      if (emptySpace.Empty(a.Index) && skipBlock(a))
      {
        classifier.EvaluateCuts(a);
        lastCutBorder = -1;
        continue;
      }
      vtkVolumeCutSample b = vtkVolumeCutSample::At(o, d, std::min(a.T + step, tEnd));
      classifier.EvaluateObject(b);
      if (compositor.Step(ray, a, b, lastCutBorder, result))
      {
        return;
      }
      a = b;
    }
    return;
  }

  // Iso-surface mode: samples every SampleDistance voxels, classified (step
  // 1); between two, the borders and pieces (steps 2 and 3), the first
  // visible piece shaded (step 4).
  const vtkVolumeCutPieceClassifier pieces(classifier, locator, shader);
  vtkVolumeCutSample a = vtkVolumeCutSample::At(o, d, ray.TStart);
  classifier.EvaluateObject(a);
  bool insideVisible = classifier.Visible(a);
  if (insideVisible && shader.Enter(ray, a, ray.TStart, ray.EntrySource, result))
  {
    return;
  }
  while (a.T < tEnd)
  {
    if (a.Object == 0 && emptySpace.Empty(a.Index) && skipBlock(a))
    {
      insideVisible = classifier.Visible(a);
      if (insideVisible && shader.Enter(ray, a, a.T, vtkVolumeCutRayCaster::SourceObject, result))
      {
        return;
      }
      continue;
    }
    // Where nothing can show ahead, the ray jumps to the last sample on its
    // sample grid before it may (the samples stay where a march without the
    // jump puts them, so that the same grazing rays catch a surface's rim as
    // on the GPU):
    double clearUntil = a.T;
    if (a.Object == 0)
    {
      // through cells where nothing visible can be, to the next that may
      // hold a surface;
      clearUntil = emptySpace.ExitEmptyCells(a.Index, d, a.T, tEnd);
    }
    else if (!insideVisible && a.CutsKnown)
    {
      // deep in a cavity, across the removed depth of this sample (the cut
      // fields are distances, 1 mm per mm).
      for (size_t n = 0; n < scene.CutFields.size(); ++n)
      {
        clearUntil = std::max(clearUntil, a.T - a.Distance[n]);
      }
    }
    const double landing = a.T + std::floor((std::min(clearUntil, tEnd) - a.T) / step) * step;
    vtkVolumeCutSample landed = vtkVolumeCutSample::At(o, d, landing);
    bool landedVisible = false;
    if (landing > a.T + step)
    {
      classifier.EvaluateObject(landed);
      landedVisible = classifier.Visible(landed);
    }
    // A cut field's value is not always the distance along the ray (SoftCut's
    // region is a depth along the plan's normal): a jump across the removed
    // depth that lands in visible material overshot the cut's surface, and
    // would shade the pixel with the CT's normal inside the tissue, a dark
    // or bright speck on a carved floor (issue 28). The ray marches on instead.
    if (landing > a.T + step && !(landedVisible && a.Object != 0))
    {
      a = landed;
      insideVisible = landedVisible;
      if (insideVisible && shader.Enter(ray, a, a.T, vtkVolumeCutRayCaster::SourceObject, result))
      {
        return;
      }
      continue;
    }
    vtkVolumeCutSample b = vtkVolumeCutSample::At(o, d, std::min(a.T + step, tEnd));
    classifier.EvaluateObject(b);
    if (pieces.Interval(ray, a, b, insideVisible, result))
    {
      return;
    }
    a = b;
  }
}
