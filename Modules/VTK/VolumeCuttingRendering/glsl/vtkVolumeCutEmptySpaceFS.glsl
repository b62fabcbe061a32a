// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Empty-space skipping: blocks of 8^3 cells that may hold a visible object,
// with their reach and a bound of the CT's gradient in each, and in
// iso-surface mode the cells themselves (vtkVolumeCutEmptySpace.h).
// Replaces the skeleton's VolumeCut::EmptySpace::Dec tag.

uniform sampler3D blockTexture;     // per 8^3 block: (reach, gradient bound); reach 0: occupied
uniform sampler3D cellTexture;      // per 2 x 2 x 2 cells, R8: a bit per cell that may hold an object
uniform int cellWalk;               // cells are classified (iso-surface mode) and walked
uniform int cellWalkSteps;          // more than the cells a straight ray crosses
uniform int reachJumps;             // jump the cube of empty blocks, not one block

ivec3 blockOf(vec3 p) { return clamp(ivec3(p) / BLOCK, ivec3(0), blockDimensions - 1); }

bool blockEmpty(vec3 p) { return texelFetch(blockTexture, blockOf(p), 0).r > 0.5; }

// Where the ray leaves the cube of empty blocks around p's block
// (vtkVolumeCutEmptySpace::Exit): as far as the nearest occupied block allows.
float blockExit(vec3 p, float t)
{
  float exitT = 1e30;
  ivec3 b = blockOf(p);
  int margin = reachJumps != 0 ? max(int(texelFetch(blockTexture, b, 0).r + 0.5) - 1, 0) : 0;
  for (int axis = 0; axis < 3; ++axis)
  {
    if (abs(rayDirection[axis]) < 1e-12)
    {
      continue;
    }
    float wall = rayDirection[axis] > 0.0 ? float((b[axis] + 1 + margin) * BLOCK) : float((b[axis] - margin) * BLOCK);
    exitT = min(exitT, t + (wall - p[axis]) / rayDirection[axis]);
  }
  return exitT;
}

// The texel is k / 255 for the byte k: rounding gives the byte back exactly.
bool cellMayHoldObject(ivec3 cell)
{
  int bits = int(255.0 * texelFetch(cellTexture, cell >> 1, 0).r + 0.5);
  return ((bits >> ((cell.x & 1) | ((cell.y & 1) << 1) | ((cell.z & 1) << 2))) & 1) != 0;
}

// Ray parameter where the ray from p (at t) enters the first cell that may
// hold a visible object, or tEnd; t itself when p's cell may
// (vtkVolumeCutEmptySpace::ExitEmptyCells, the same walk).
float exitEmptyCells(vec3 p, float t, float tEnd)
{
  if (cellWalk == 0)
  {
    return t;
  }
  ivec3 cells = dimensions - 1;
  ivec3 cell = clamp(ivec3(floor(p)), ivec3(0), cells - 1);
  ivec3 stepSign = ivec3(greaterThan(rayDirection, vec3(0.0))) * 2 - 1;
  vec3 next = vec3(1e30);
  vec3 delta = vec3(1e30);
  for (int axis = 0; axis < 3; ++axis)
  {
    if (abs(rayDirection[axis]) >= 1e-12)
    {
      float wall = rayDirection[axis] > 0.0 ? float(cell[axis] + 1) : float(cell[axis]);
      next[axis] = t + (wall - p[axis]) / rayDirection[axis];
      delta[axis] = 1.0 / abs(rayDirection[axis]);
    }
  }
  float entry = t;
  // The bound keeps a malformed ray from hanging the GPU; where it ends,
  // sampling resumes before the cell not yet looked at.
  for (int guard = 0; guard < cellWalkSteps; ++guard)
  {
    if (cellMayHoldObject(cell))
    {
      return entry;
    }
    int axis = next.x < next.y ? (next.x < next.z ? 0 : 2) : (next.y < next.z ? 1 : 2);
    entry = next[axis];
    cell[axis] += stepSign[axis];
    if (!(entry < tEnd) || cell[axis] < 0 || cell[axis] >= cells[axis])
    {
      return tEnd;
    }
    next[axis] += delta[axis];
  }
  return entry;
}
