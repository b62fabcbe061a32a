// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Ambient occlusion, the depth cue that makes a cavity read: how much of 14
// points over a surface point's hemisphere lies in visible material, each
// point weighed by its depth in the material, in directions that turn
// smoothly with the normal (vtkVolumeCutAmbientOcclusion.h, which says why).
// Replaces the skeleton's VolumeCut::AmbientOcclusion::Dec tag.

uniform int ambientOcclusion;
uniform float ambientOcclusionRadius;
// 14: the points. A uniform so that the loop, each pass a sample
// evaluation, stays a loop (see bisectionSteps).
uniform int occlusionPoints;

// A unit tangent of n that turns smoothly with it: a tangent of the camera's
// axis a carried onto n by the rotation taking a to n.
vec3 occlusionTangent(vec3 n, vec3 a)
{
  vec3 helper = abs(a.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 t0 = normalize(cross(a, helper));
  float c = 1.0 + dot(n, a);
  float k = c > 1e-6 ? dot(n, t0) / c : 0.0;
  return normalize(t0 - k * (n + a));
}

// Depth (mm) of a visible sample in its material: the smallest of its
// distance to the nearest cut, to the volume's faces, and its object field's
// value over the field's gradient (central differences a voxel apart).
float occlusionDepth(Sample s)
{
  float depth = 1.0e30;
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    depth = min(depth, s.distance[n]);
  }
  // At most the distance to the volume's faces: the material ends where the scan does.
  for (int axis = 0; axis < 3; ++axis)
  {
    depth = min(depth, min(s.index[axis], float(dimensions[axis] - 1) - s.index[axis]) * millimetresPerIndex[axis]);
  }
  int label = hasLabels != 0 ? s.object : 1;
  vec4 surface = styleSurface(label);
  bool shape = hasLabels != 0 && surface.y > 0.5;
  float field = shape ? indicator(label, s.index) - 0.5 : s.value - surface.x;
  vec3 gradient;
  for (int axis = 0; axis < 3; ++axis)
  {
    vec3 plus = s.index;
    vec3 minus = s.index;
    plus[axis] += 1.0;
    minus[axis] -= 1.0;
    gradient[axis] = 0.5 * (shape ? indicator(label, plus) - indicator(label, minus) : intensity(plus) - intensity(minus));
  }
  float slope = length(normalMatrix * gradient);
  return slope > 0.0 ? min(depth, field / slope) : depth;
}

float occlusion(vec3 index, vec3 normal)
{
  vec4 nearH = ndcToWorld * vec4(0.0, 0.0, -1.0, 1.0);
  vec4 farH = ndcToWorld * vec4(0.0, 0.0, 1.0, 1.0);
  vec3 axis = normalize(nearH.xyz / nearH.w - farH.xyz / farH.w);
  vec3 tangent = occlusionTangent(normal, axis);
  vec3 bitangent = cross(normal, tangent);
  vec3 origin = worldPoint(index);
  float voxel = max(length(ijkToWorld[0].xyz), max(length(ijkToWorld[1].xyz), length(ijkToWorld[2].xyz)));
  float cosine = cos(radians(55.0));
  float sine = sin(radians(55.0));
  float occupied = 0.0;
  for (int point = 0; point < occlusionPoints; ++point)
  {
    // 0, 1: the normal; 2-7: the inner ring every 60 degrees; 8-13: the outer ring between them.
    float angle = 3.14159265358979 / 3.0 * float(point - 2) + (point >= 8 ? 3.14159265358979 / 6.0 : 0.0);
    vec3 d = point < 2 ? normal : cosine * normal + sine * (cos(angle) * tangent + sin(angle) * bitangent);
    float reach = point == 0 || (point >= 2 && point < 8) ? 0.35 : 1.0;
    Sample s = sampleAt(0.0);
    s.index = (worldToIJK * vec4(origin + reach * ambientOcclusionRadius * d, 1.0)).xyz;
    if (all(greaterThanEqual(s.index, vec3(0.0))) && all(lessThanEqual(s.index, vec3(dimensions - 1))))
    {
      evaluateObject(s);
      if (visible(s))
      {
        // RampWidth in vtkVolumeCutAmbientOcclusion.h.
        float width = max(voxel, 0.15 * reach * ambientOcclusionRadius);
        occupied += smoothstep(0.0, 1.0, occlusionDepth(s) / width);
      }
    }
  }
  return occupied / 14.0;
}

// Cavity shading (vtkVolumeCutCavityShading.h, which says why): a point of
// a surface a cut exposes darkened by the length of original material, cuts
// ignored, between it and the eye, up to half the occlusion radius: steps
// along the line of sight, then bisection.
bool inOriginalMaterial(vec3 index)
{
  if (!(all(greaterThanEqual(index, vec3(0.0))) && all(lessThanEqual(index, vec3(dimensions - 1)))))
  {
    return false;
  }
  Sample s = sampleAt(0.0);
  s.index = index;
  evaluateObject(s);
  return s.object != 0;
}

float cavityShade(vec3 index, vec3 view)
{
  // RangeShare, Steps, Bisections and Strength in vtkVolumeCutCavityShading.h.
  float range = 0.5 * ambientOcclusionRadius;
  vec3 step = mat3(worldToIJK) * view * (range / 12.0);
  // Air a quarter step before the point: left as it is (Apply in the header says why).
  if (!inOriginalMaterial(index + 0.25 * step))
  {
    return 1.0;
  }
  float inside = 0.0;
  float outside = -1.0;
  for (int n = 1; n <= 12 && outside < 0.0; ++n)
  {
    if (inOriginalMaterial(index + float(n) * step))
    {
      inside = float(n);
    }
    else
    {
      outside = float(n);
    }
  }
  float depth = range;
  if (outside >= 0.0)
  {
    for (int n = 0; n < 6; ++n)
    {
      float middle = 0.5 * (inside + outside);
      if (inOriginalMaterial(index + middle * step))
      {
        inside = middle;
      }
      else
      {
        outside = middle;
      }
    }
    depth = 0.5 * (inside + outside) * range / 12.0;
  }
  float share = 1.0 - depth / range;
  return 1.0 - 0.45 * (1.0 - share * share);
}
