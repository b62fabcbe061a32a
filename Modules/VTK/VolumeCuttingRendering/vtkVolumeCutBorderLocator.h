// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutBorderLocator
 * @brief   Step 2 of adaptive sampling (Pflesser et al.): where each volume's border lies between two samples.
 *
 * Between two samples whose classes differ, each volume's border is located
 * on its own: bisection on the object class (vtkVolumeCutSampleClassifier)
 * (12 halvings) and on each cut field's distance (Illinois regula falsi, at
 * most 22 steps, to 2e-7 of the interval); the
 * volume's box and the clip planes analytically, as the ray's entry and
 * exit. Where a border could hide between two samples that agree (a grazing
 * ray over an edge), MayHideBorders decides from a Lipschitz bound: the CT's
 * largest gradient in the 8^3 block (vtkVolumeCutEmptySpace), then the
 * exact maximum of the trilinear CT along the interval, or the cut field
 * being a distance.
 *
 * @sa vtkVolumeCutSampleClassifier (step 1) vtkVolumeCutPieceClassifier (step 3)
 */
#ifndef vtkVolumeCutBorderLocator_h
#define vtkVolumeCutBorderLocator_h

#include "vtkVolumeCutRayCaster.h"
#include "vtkVolumeCutSampleClassifier.h"

#include <vtkMath.h>

#include <algorithm>
#include <cmath>

/// A border between two samples: where it is and which volume forms it.
struct vtkVolumeCutBorder
{
  double T;
  int Source; // vtkVolumeCutRayCaster::SurfaceSources (SourceCutField + k for cut k)
};

/// One ray: in world (mm) and in the anatomy's IJK, with the part of it inside the volume.
struct vtkVolumeCutRay
{
  double OriginWorld[3];
  double DirectionWorld[3]; // unit
  double View[3];           // towards the eye
  double ViewAxis[3];       // the camera's axis, towards the eye: the same for every ray of an image
  double Origin[3];         // IJK
  double Direction[3];      // IJK per mm
  double VoxelsPerMillimetre = 1.0;
  double TStart = 0.0;
  double TEnd = 0.0;
  int EntrySource = 0;
  double EntryNormal[3];
};

class vtkVolumeCutBorderLocator
{
public:
  /// Halvings of a sample interval (0.5 voxel) for an object's border:
  /// 1.2e-4 voxel, a thousandth of a pixel where a voxel covers ten.
  static constexpr int ObjectBisections = 12;
  /// At most this many steps for a cut field's border; the field is a
  /// distance, so its zero is found by regula falsi in a few.
  static constexpr int CutBisections = 22;
  /// Intervals where a border may hide are split into 2^MaximumRefinements.
  static constexpr int MaximumRefinements = 4;

  vtkVolumeCutBorderLocator(const vtkVolumeCutRayScene& scene, const vtkVolumeCutSampleClassifier& classifier)
    : Scene(scene)
    , Classifier(classifier)
  {
  }

  /**
   * Entry and exit of the ray (TStart, TEnd set to the world ray's near and
   * far limits before): the volume's box (the sample domain), then the clip
   * planes, with the source and normal of the entry surface. Returns false
   * when the ray misses.
   */
  bool ClipToVolume(vtkVolumeCutRay& ray) const
  {
    const double* o = ray.Origin;
    const double* d = ray.Direction;
    ray.EntrySource = vtkVolumeCutRayCaster::SourceClipPlane; // the near plane, when the eye is inside
    std::copy(ray.View, ray.View + 3, ray.EntryNormal);
    for (int axis = 0; axis < 3; ++axis)
    {
      const double lo = 0.0;
      const double hi = this->Scene.Dimensions[axis] - 1.0;
      if (std::abs(d[axis]) < 1e-15)
      {
        if (o[axis] < lo || o[axis] > hi)
        {
          return false;
        }
        continue;
      }
      double t0 = (lo - o[axis]) / d[axis];
      double t1 = (hi - o[axis]) / d[axis];
      const bool forward = t0 < t1;
      if (!forward)
      {
        std::swap(t0, t1);
      }
      if (t0 > ray.TStart)
      {
        ray.TStart = t0;
        ray.EntrySource = vtkVolumeCutRayCaster::SourceVolumeBox;
        double faceNormal[3] = { 0.0, 0.0, 0.0 };
        faceNormal[axis] = forward ? -1.0 : 1.0;
        vtkVolumeCutRayMath::TransformVector(this->Scene.NormalMatrix, faceNormal, ray.EntryNormal);
        vtkMath::Normalize(ray.EntryNormal);
      }
      ray.TEnd = std::min(ray.TEnd, t1);
    }
    for (const vtkVolumeCutRayScene::PlaneEquation& plane : this->Scene.Planes)
    {
      const double f0 = vtkMath::Dot(plane.Normal, ray.OriginWorld) + plane.Offset;
      const double fd = vtkMath::Dot(plane.Normal, ray.DirectionWorld);
      if (std::abs(fd) < 1e-15)
      {
        if (f0 < 0.0)
        {
          return false;
        }
        continue;
      }
      const double t = -f0 / fd;
      if (fd > 0.0)
      {
        if (t > ray.TStart)
        {
          ray.TStart = t;
          ray.EntrySource = vtkVolumeCutRayCaster::SourceClipPlane;
          for (int axis = 0; axis < 3; ++axis)
          {
            ray.EntryNormal[axis] = -plane.Normal[axis];
          }
          vtkMath::Normalize(ray.EntryNormal);
        }
      }
      else
      {
        ray.TEnd = std::min(ray.TEnd, t);
      }
    }
    return ray.TStart < ray.TEnd;
  }

  /// The object's border between a and b (their objects differ).
  double BisectObject(const vtkVolumeCutRay& ray, const vtkVolumeCutSample& a, const vtkVolumeCutSample& b) const
  {
    double lo = a.T;
    double hi = b.T;
    for (int iteration = 0; iteration < ObjectBisections; ++iteration)
    {
      vtkVolumeCutSample mid = vtkVolumeCutSample::At(ray.Origin, ray.Direction, 0.5 * (lo + hi));
      this->Classifier.EvaluateObject(mid);
      (mid.Object == a.Object ? lo : hi) = mid.T;
    }
    return 0.5 * (lo + hi);
  }

  /// Cut field n's border between a and b (one of them removed by it).
  double BisectCut(int n, const vtkVolumeCutRay& ray, const vtkVolumeCutSample& a, const vtkVolumeCutSample& b) const
  {
    const vtkVolumeCutField* field = this->Scene.CutFields[n];
    double lo = a.T;
    double hi = b.T;
    double distanceLo = a.Distance[n];
    double distanceHi = b.Distance[n];
    const bool loRemoved = distanceLo < 0.0;
    // Illinois regula falsi: the bracket always holds the border, and the
    // end that stays put has its distance halved so that both ends move.
    const double resolved = (hi - lo) * std::ldexp(1.0, -CutBisections);
    int keptEnd = 0;
    for (int iteration = 0; iteration < CutBisections && hi - lo > resolved; ++iteration)
    {
      double t = distanceHi != distanceLo ? (lo * distanceHi - hi * distanceLo) / (distanceHi - distanceLo) : 0.5 * (lo + hi);
      if (!(t > lo && t < hi))
      {
        t = 0.5 * (lo + hi);
      }
      double index[3];
      double world[3];
      for (int axis = 0; axis < 3; ++axis)
      {
        index[axis] = ray.Origin[axis] + t * ray.Direction[axis];
      }
      this->Classifier.WorldPoint(index, world);
      const double distance = field->GetSignedDistance(world);
      if (distance == 0.0 || std::abs(distance) < 1e-9)
      {
        return t;
      }
      if ((distance < 0.0) == loRemoved)
      {
        lo = t;
        distanceLo = distance;
        distanceHi *= keptEnd == 1 ? 0.5 : 1.0;
        keptEnd = 1;
      }
      else
      {
        hi = t;
        distanceHi = distance;
        distanceLo *= keptEnd == -1 ? 0.5 : 1.0;
        keptEnd = -1;
      }
    }
    return 0.5 * (lo + hi);
  }

  /**
   * Every border of every volume between two samples, in ray order: the
   * object's (withObject: iso-surface mode) and each cut field's. Returns
   * their number (at most MaximumCutFields + 1).
   */
  int FindBorders(const vtkVolumeCutRay& ray, const vtkVolumeCutSample& a, const vtkVolumeCutSample& b, bool withObject,
    vtkVolumeCutBorder* borders) const
  {
    int count = 0;
    if (withObject && a.Object != b.Object)
    {
      borders[count++] = { this->BisectObject(ray, a, b), vtkVolumeCutRayCaster::SourceObject };
    }
    if (a.CutsKnown && b.CutsKnown)
    {
      for (size_t n = 0; n < this->Scene.CutFields.size(); ++n)
      {
        if ((a.Distance[n] < 0.0) != (b.Distance[n] < 0.0))
        {
          borders[count++] = { this->BisectCut(static_cast<int>(n), ray, a, b), vtkVolumeCutRayCaster::SourceCutField + static_cast<int>(n) };
        }
      }
    }
    std::sort(borders, borders + count, [](const vtkVolumeCutBorder& l, const vtkVolumeCutBorder& r) { return l.T < r.T; });
    return count;
  }

  /// Whether a border could lie between two samples without showing at them:
  /// bounds from the CT's largest gradient in the blocks (voxels) and from the
  /// cut fields being distances (1 mm per mm).
  bool MayHideBorders(const vtkVolumeCutSample& a, const vtkVolumeCutSample& b, double lengthVoxels, double lengthMillimetres) const
  {
    if (a.Object == 0 && b.Object == 0)
    {
      if (!this->Scene.AnyIsoSegment)
      {
        return false;
      }
      const double slope = std::max(this->Scene.EmptySpace.Lipschitz(a.Index), this->Scene.EmptySpace.Lipschitz(b.Index));
      if (0.5 * (double(a.Value) + double(b.Value) + slope * lengthVoxels) < this->Scene.MinimumIso)
      {
        return false;
      }
      // The block's gradient bound is loose beside bone, where it would have
      // every step split; the exact maximum of the trilinear CT along the
      // interval settles those.
      return this->Classifier.Reaches(a.Index, b.Index, static_cast<float>(this->Scene.MinimumIso));
    }
    if (!a.CutsKnown || !b.CutsKnown)
    {
      return false;
    }
    for (size_t n = 0; n < this->Scene.CutFields.size(); ++n)
    {
      const double da = a.Distance[n];
      const double db = b.Distance[n];
      if ((da >= 0.0) == (db >= 0.0) && std::abs(da) + std::abs(db) < lengthMillimetres)
      {
        return true;
      }
    }
    return false;
  }

private:
  const vtkVolumeCutRayScene& Scene;
  const vtkVolumeCutSampleClassifier& Classifier;
};

#endif
