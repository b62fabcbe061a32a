// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutRayMarcher
 * @brief   One ray of vtkVolumeCutRayCaster: the stages of adaptive sampling along it, or the compositor in composite mode.
 *
 * The ray runs from the near to the far plane through the pixel's centre,
 * clipped to the volume's box and the clip planes. In iso-surface mode
 * samples every SampleDistance voxels are classified (step 1); between two,
 * the borders and pieces (steps 2 and 3), and the first visible piece is
 * shaded (step 4). Empty blocks, cells where nothing visible can be and the
 * removed depth of a cavity are crossed in one jump.
 *
 * The per-sample stages are inline headers compiled here, so the ray loop
 * is one optimised unit (built with the ray caster's floating-point options).
 */
#ifndef vtkVolumeCutRayMarcher_h
#define vtkVolumeCutRayMarcher_h

struct vtkVolumeCutRayResult;
struct vtkVolumeCutRayScene;

class vtkVolumeCutRayMarcher
{
public:
  /**
   * Cast the ray of pixel (x, y) of a width x height image seen through
   * \a ndcToWorld (row-major) into \a result, whose pixel holds nothing
   * yet. opaqueLimit: the ray's length (mm) to opaque geometry, or nullptr.
   */
  static void Cast(const vtkVolumeCutRayScene& scene, const double ndcToWorld[16], int width, int height, int x, int y,
    const double* opaqueLimit, vtkVolumeCutRayResult& result);
};

#endif
