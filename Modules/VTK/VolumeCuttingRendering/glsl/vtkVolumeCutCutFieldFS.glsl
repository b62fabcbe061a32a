// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// One cut field: its page table and atlas of 8^3 bricks (only modified
// bricks are uploaded) and its signed distance at a world point, as
// vtkVolumeCutField::GetSignedDistance (trilinear, with the second-difference
// curvature correction near the surface). vtkVolumeCutShaderComposer writes
// one copy per field with @N@ replaced by the field's index.
uniform sampler3D cutPage@N@;
uniform sampler3D cutAtlas@N@;
uniform vec3 cutDimensionsF@N@;
uniform int cutSlots@N@;
uniform mat4 worldToSub@N@;
uniform float cutQuantum@N@;
uniform float cutStep@N@;
uniform float cutCorrectionReach@N@; // in sample units
ivec3 cutDimensions@N@;
// The distance in quanta at atlas texel p: an R16 atlas holds distance +
// 32768, k / 65535 for k; rounding 65535 * texel gives k back exactly.
float cutAtlasAt@N@(ivec3 p)
{
#ifdef CUT_ATLAS_UNORM16_@N@
  return round(65535.0 * texelFetch(cutAtlas@N@, p, 0).r) - 32768.0;
#else
  return texelFetch(cutAtlas@N@, p, 0).r;
#endif
}
float cutSample@N@(ivec3 c)
{
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, cutDimensions@N@)))
  {
    return 32767.0;
  }
  ivec3 b = c / 8;
  float slot = texelFetch(cutPage@N@, b, 0).r;
  if (slot < 0.0)
  {
    return 32767.0;
  }
  int s = int(slot + 0.5);
  ivec3 origin = 8 * ivec3(s % cutSlots@N@, (s / cutSlots@N@) % cutSlots@N@, s / (cutSlots@N@ * cutSlots@N@));
  return cutAtlasAt@N@(origin + (c - 8 * b));
}
float cutDistance@N@(vec3 world)
{
  vec3 index = (worldToSub@N@ * vec4(world, 1.0)).xyz;
  ivec3 i0 = ivec3(floor(index));
  vec3 f = index - vec3(i0);
  float value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    float w = cornerWeight(corner, f);
    if (w != 0.0)
    {
      value += w * cutSample@N@(i0 + cornerOffset(corner));
    }
  }
  // As vtkVolumeCutField::GetSignedDistance: the curvature correction only
  // near the surface, where it matters.
  if (abs(value) > cutCorrectionReach@N@)
  {
    return value * cutQuantum@N@;
  }
  // A second pass re-reads the corners rather than keeping them in arrays:
  // arrays indexed at run time go to slow local memory on NVIDIA (measured
  // on an H100: 179 ms a frame against 84 ms before the change).
  vec3 second = vec3(0.0);
  for (int corner = 0; corner < 8; ++corner)
  {
    float w = cornerWeight(corner, f);
    if (w == 0.0)
    {
      continue;
    }
    float center = cutSample@N@(i0 + cornerOffset(corner));
    if (abs(center) == 32767.0)
    {
      continue;
    }
    ivec3 c = i0 + cornerOffset(corner);
    for (int axis = 0; axis < 3; ++axis)
    {
      ivec3 e = ivec3(0);
      e[axis] = 1;
      float n0 = cutSample@N@(c - e);
      float n1 = cutSample@N@(c + e);
      if (abs(n0) != 32767.0 && abs(n1) != 32767.0)
      {
        second[axis] += w * (n0 - 2.0 * center + n1);
      }
    }
  }
  value -= 0.5 * dot(f * (1.0 - f), second);
  return value * cutQuantum@N@;
}
