// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutLocalizedUpdate.h"

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutRayMath.h"

#include <vtkIdList.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

#include <algorithm>
#include <cmath>

//------------------------------------------------------------------------------
void vtkVolumeCutLocalizedUpdate::MarkModifiedBricks(vtkVolumeCutField* field, vtkTypeUInt64 stamp, double reach,
  const double worldToNDC[16], int width, int height, std::vector<uint8_t>& mask, int region[4])
{
  double spacing[3];
  field->GetSubVoxelSpacing(spacing);
  const double margin = std::ceil(reach / std::min({ spacing[0], spacing[1], spacing[2] }));
  vtkNew<vtkIdList> bricks;
  field->GetBricksModifiedSince(stamp, bricks);
  const int* brickDims = field->GetBrickDimensions();
  vtkNew<vtkMatrix4x4> subToWorld;
  field->GetSubVoxelIJKToRAS(subToWorld);
  for (vtkIdType n = 0; n < bricks->GetNumberOfIds(); ++n)
  {
    const vtkIdType id = bricks->GetId(n);
    const int b[3] = { static_cast<int>(id % brickDims[0]), static_cast<int>((id / brickDims[0]) % brickDims[1]),
      static_cast<int>(id / (static_cast<vtkIdType>(brickDims[0]) * brickDims[1])) };
    // A brick's samples reach two sub-voxels beyond it (interpolation and
    // its curvature correction), and shading reaches margin beyond that.
    double lo[2] = { 1e300, 1e300 };
    double hi[2] = { -1e300, -1e300 };
    bool behind = false;
    for (int corner = 0; corner < 8; ++corner)
    {
      double sub[4] = { b[0] * 8.0 + ((corner & 1) ? 10.0 + margin : -3.0 - margin),
        b[1] * 8.0 + ((corner & 2) ? 10.0 + margin : -3.0 - margin), b[2] * 8.0 + ((corner & 4) ? 10.0 + margin : -3.0 - margin), 1.0 };
      double world[4];
      subToWorld->MultiplyPoint(sub, world);
      double clip[4];
      vtkVolumeCutRayMath::Multiply4(worldToNDC, world, clip);
      if (clip[3] <= 1e-12)
      {
        behind = true;
        break;
      }
      for (int axis = 0; axis < 2; ++axis)
      {
        const double ndc = clip[axis] / clip[3];
        const double pixel = (ndc + 1.0) * 0.5 * (axis == 0 ? width : height);
        lo[axis] = std::min(lo[axis], pixel);
        hi[axis] = std::max(hi[axis], pixel);
      }
    }
    if (behind)
    {
      lo[0] = lo[1] = 0.0;
      hi[0] = width;
      hi[1] = height;
    }
    const int x0 = std::max(0, static_cast<int>(std::floor(lo[0])) - 1);
    const int x1 = std::min(width - 1, static_cast<int>(std::ceil(hi[0])) + 1);
    const int y0 = std::max(0, static_cast<int>(std::floor(lo[1])) - 1);
    const int y1 = std::min(height - 1, static_cast<int>(std::ceil(hi[1])) + 1);
    if (x0 > x1 || y0 > y1)
    {
      continue; // out of view: a row's fill would run backwards
    }
    for (int y = y0; y <= y1; ++y)
    {
      std::fill(mask.begin() + static_cast<vtkIdType>(y) * width + x0, mask.begin() + static_cast<vtkIdType>(y) * width + x1 + 1, 1);
    }
    region[0] = std::min(region[0], x0);
    region[1] = std::min(region[1], y0);
    region[2] = std::max(region[2], x1);
    region[3] = std::max(region[3], y1);
  }
}
