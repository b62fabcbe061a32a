// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutRayResult
 * @brief   What one ray of vtkVolumeCutRayCaster accumulates, written into its pixel.
 *
 * Premultiplied colour composited front to back, and, for the first layer
 * that clearly shows, its window depth, world normal, source (which border
 * forms it) and segment (whose material it is).
 */
#ifndef vtkVolumeCutRayResult_h
#define vtkVolumeCutRayResult_h

#include "vtkVolumeCutBorderLocator.h"

struct vtkVolumeCutRayResult
{
  /// A pixel is done once it is this opaque.
  static constexpr float OpaqueAlpha = 0.995f;
  /// Translucent layers composited at most.
  static constexpr int MaximumLayers = 8;

  float* Color = nullptr;  // 4
  float* Depth = nullptr;  // 1
  float* Normal = nullptr; // 3
  int* Source = nullptr;   // 1
  int* Segment = nullptr;  // 1
  const double* WorldToNDC = nullptr;
  bool First = true;
  int Layers = 0;

  /// Composite a layer (rgb, alpha) found at ray parameter t; the first
  /// layer of at least minimumAlpha gives the pixel its depth, normal, source and segment.
  void Record(const vtkVolumeCutRay& ray, double t, int source, int segment, const double normal[3], const float rgb[3], float alpha,
    float minimumAlpha)
  {
    const float remaining = 1.f - this->Color[3];
    for (int c = 0; c < 3; ++c)
    {
      this->Color[c] += remaining * alpha * rgb[c];
    }
    this->Color[3] += remaining * alpha;
    if (this->First && alpha >= minimumAlpha)
    {
      this->First = false;
      double world[4] = { ray.OriginWorld[0] + t * ray.DirectionWorld[0], ray.OriginWorld[1] + t * ray.DirectionWorld[1],
        ray.OriginWorld[2] + t * ray.DirectionWorld[2], 1.0 };
      double clip[4];
      vtkVolumeCutRayMath::Multiply4(this->WorldToNDC, world, clip);
      *this->Depth = static_cast<float>(std::min(1.0, std::max(0.0, 0.5 * clip[2] / clip[3] + 0.5)));
      for (int axis = 0; axis < 3; ++axis)
      {
        this->Normal[axis] = static_cast<float>(normal[axis]);
      }
      *this->Source = source;
      *this->Segment = segment;
    }
  }

  bool Opaque() const { return this->Color[3] >= OpaqueAlpha; }
};

#endif
