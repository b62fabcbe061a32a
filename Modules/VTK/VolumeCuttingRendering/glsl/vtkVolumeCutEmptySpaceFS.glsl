// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Empty-space skipping: blocks of 8^3 cells that may hold a visible object,
// and a bound of the CT's gradient in each (vtkVolumeCutEmptySpace.h).
// Replaces the skeleton's VolumeCut::EmptySpace::Dec tag.

uniform sampler3D blockTexture;     // per 8^3 block: (occupied, gradient bound)

ivec3 blockOf(vec3 p) { return clamp(ivec3(p) / BLOCK, ivec3(0), blockDimensions - 1); }

bool blockEmpty(vec3 p) { return texelFetch(blockTexture, blockOf(p), 0).r < 0.5; }

float blockExit(vec3 p, float t)
{
  float exitT = 1e30;
  ivec3 b = blockOf(p);
  for (int axis = 0; axis < 3; ++axis)
  {
    if (abs(rayDirection[axis]) < 1e-12)
    {
      continue;
    }
    float wall = rayDirection[axis] > 0.0 ? float((b[axis] + 1) * BLOCK) : float(b[axis] * BLOCK);
    exitT = min(exitT, t + (wall - p[axis]) / rayDirection[axis]);
  }
  return exitT;
}
