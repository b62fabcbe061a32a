// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutLocalizedUpdate
 * @brief   Localized ray casting (Wang and Kaufman, seed 004): which pixels a cut's change can touch.
 *
 * When only cut fields changed since the last image with the same camera,
 * only the rays whose pixels cover a brick modified since then (its stamp)
 * are recast: each brick's box, widened by the two sub-voxels that
 * interpolation and its curvature correction reach, projected to the image.
 */
#ifndef vtkVolumeCutLocalizedUpdate_h
#define vtkVolumeCutLocalizedUpdate_h

#include <vtkType.h>

#include <cstdint>
#include <vector>

class vtkVolumeCutField;

class vtkVolumeCutLocalizedUpdate
{
public:
  /**
   * Set to 1 the pixels of \a mask (width x height, row 0 at the bottom)
   * whose rays may meet a brick of \a field modified since \a stamp, or
   * whose shading looks up to \a reach (mm) from their surface into one
   * (ambient occlusion, thin bone), seen through \a worldToNDC (row-major),
   * and grow \a region (x0, y0, x1, y1, inclusive) to hold them.
   */
  static void MarkModifiedBricks(vtkVolumeCutField* field, vtkTypeUInt64 stamp, double reach, const double worldToNDC[16], int width,
    int height, std::vector<uint8_t>& mask, int region[4]);
};

#endif
