// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Ambient occlusion, the depth cue that makes a cavity read: the share of 14
// points over a surface point's hemisphere that lie in visible material
// (vtkVolumeCutAmbientOcclusion.h). Replaces the skeleton's
// VolumeCut::AmbientOcclusion::Dec tag.

uniform int ambientOcclusion;
uniform float ambientOcclusionRadius;
// 7: the normal and six directions around it. A uniform so that the loop,
// each pass a sample evaluation, stays a loop (see bisectionSteps).
uniform int occlusionDirections;

float occlusion(vec3 index, vec3 normal)
{
  vec3 helper = abs(normal.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 tangent = normalize(cross(normal, helper));
  vec3 bitangent = cross(normal, tangent);
  vec3 origin = worldPoint(index);
  float cosine = cos(radians(55.0));
  float sine = sin(radians(55.0));
  int occupied = 0;
  for (int direction = 0; direction < occlusionDirections; ++direction)
  {
    float angle = 3.14159265358979 / 3.0 * float(direction);
    vec3 d = direction == 0 ? normal : cosine * normal + sine * (cos(angle) * tangent + sin(angle) * bitangent);
    for (int ring = 0; ring < 2; ++ring)
    {
      float reach = ring == 0 ? 0.35 : 1.0;
      Sample s = sampleAt(0.0);
      s.index = (worldToIJK * vec4(origin + reach * ambientOcclusionRadius * d, 1.0)).xyz;
      if (all(greaterThanEqual(s.index, vec3(0.0))) && all(lessThanEqual(s.index, vec3(dimensions - 1))))
      {
        evaluateObject(s);
        occupied += visible(s) ? 1 : 0;
      }
    }
  }
  return float(occupied) / 14.0;
}
